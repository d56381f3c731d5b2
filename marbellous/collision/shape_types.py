"""Integer codes of the shape kinds, in the canonical pair order (a pair test takes the lower code first)."""

SPHERE = 0
CAPSULE = 1
BOX = 2
PLANE = 3
HEIGHTFIELD = 4
MESH = 5
#: a convex hull moves and takes its geometry from the blobs; its pair tests take it first (``hull/``)
HULL = 6

#: Number of float parameters every shape carries in its kernel record (unused slots are 0).
N_SHAPE_PARAMS = 8

NAMES = ("sphere", "capsule", "box", "plane", "heightfield", "mesh", "hull")

# Coverage: which pair tests a world's step can need, from the kinds of shape its bodies have.  A world's
# step is compiled for its coverage (``pipeline/step.py``), so that a first run compiles only the pair
# tests its scene can meet (static shapes never meet each other):
#: every moving shape a sphere, no mesh, height field or hull: the sphere-primitive tests alone
COVER_SPHERES = 0
#: every moving shape a sphere, triangle meshes too but no height field or hull (the marble on its level)
COVER_MESHES = 1
#: every moving shape a sphere, height fields or static hulls too
COVER_GROUND = 2
#: capsules, boxes or hulls that move: every pair test
COVER_ALL = 3
#: the number of coverages
COVERAGES = 4


def sphere_coverage(kind):
    """The coverage a sphere needs to meet a shape of ``kind``: ``COVER_SPHERES`` for a sphere, capsule, box or
    plane, ``COVER_MESHES`` for a triangle mesh, ``COVER_GROUND`` for a height field or hull."""
    if kind <= PLANE:
        return COVER_SPHERES
    return COVER_MESHES if kind == MESH else COVER_GROUND
