"""Integer codes of the shape kinds, in the canonical pair order (a pair test takes the lower code first)."""

SPHERE = 0
CAPSULE = 1
BOX = 2
PLANE = 3
HEIGHTFIELD = 4
MESH = 5

#: Number of float parameters every shape carries in its kernel record (unused slots are 0).
N_SHAPE_PARAMS = 8

NAMES = ("sphere", "capsule", "box", "plane", "heightfield", "mesh")
