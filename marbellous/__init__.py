"""Marbellous: a fast 3D game-physics engine for Python, and the marble game it is named after.

SI units, y up, quaternions (w, x, y, z).  Start with :class:`World`::

    import marbellous as mb
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.5), position=(0, 2, 0))
    w.step(1 / 60)

Look at any world with ``mb.show(w)`` (a window) or ``mb.record(w, "out.mp4", seconds=5)`` (headless).
"""
from .body import Body
from .constraints import Cable, Rod, Spring
from .pipeline.profile import StepProfile
from .query import ContactPoint, collide
from .shapes import Box, Capsule, HeightField, Plane, Shape, Sphere, TriangleMesh
from .reports import Contact, RayHit, StepReport
from .state.snapshot import Snapshot
from .world import World

__version__ = "0.1.0"

from .app.envs import register_envs  # noqa: E402  (after the API: the environment builds worlds)
from .app.record import record, render_image  # noqa: E402  (rendering packages load on first call)
from .app.viewer import show  # noqa: E402

register_envs()

__all__ = ["World", "Body", "Snapshot", "Contact", "Shape", "Sphere", "Box", "Capsule", "Plane", "HeightField",
           "TriangleMesh", "Spring", "Rod", "Cable", "RayHit", "collide", "ContactPoint", "StepProfile", "StepReport",
           "show", "record", "render_image", "__version__"]
