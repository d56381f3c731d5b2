"""Standard scenes, written once and used by tests, benchmarks and demos.

Each function builds its bodies into a :class:`marbellous.World` (a new default one if none is given)
and returns the world and the bodies it made.
"""
from .articulated import hinged_chain, plank_bridge, ragdoll, stairs
from .stacks import box_pyramid, box_tower, sphere_pile

__all__ = ["box_pyramid", "box_tower", "sphere_pile", "hinged_chain", "plank_bridge", "ragdoll", "stairs"]
