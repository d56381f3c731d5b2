"""Marbellous: a fast 3D game-physics engine for Python, and the marble game it is named after.

SI units, y up, quaternions (w, x, y, z).  Start with :class:`World`::

    import marbellous as mb
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.5), position=(0, 2, 0))
    w.step(1 / 60)

Look at any world with ``mb.show(w)`` (a window) or ``mb.record(w, "out.mp4", seconds=5)`` (headless).

The public names load on first use (``mb.World`` imports the engine), so ``import marbellous`` and
commands that need no physics (``marbellous levels``) start in a fraction of a second.
"""
import importlib
from typing import TYPE_CHECKING

__version__ = "0.1.0"

#: the module (relative to the package) that defines each public name
_HOME = {
    "World": ".world", "Body": ".body", "Snapshot": ".state.snapshot", "Contact": ".reports",
    "ContactEvent": ".reports", "RayHit": ".reports", "StepReport": ".reports", "Shape": ".shapes",
    "Sphere": ".shapes", "Box": ".shapes", "Capsule": ".shapes", "ConvexHull": ".shapes",
    "Plane": ".shapes", "HeightField": ".shapes", "TriangleMesh": ".shapes",
    "Spring": ".constraints", "Rod": ".constraints", "Cable": ".constraints", "Joint": ".constraints",
    "BallJoint": ".constraints", "Hinge": ".constraints", "Slider": ".constraints", "FixedJoint": ".constraints",
    "collide": ".query", "ContactPoint": ".query", "StepProfile": ".pipeline.profile",
    "show": ".app.viewer", "record": ".app.record", "render_image": ".app.record",
    "Particles": ".particles", "Network": ".particles", "Cloth": ".cloth", "cloth_grid": ".cloth",
    "SoftBody": ".soft", "tet_box": ".soft", "tetrahedralize": ".soft", "Fluid": ".fluid",
    "step_worlds": ".batch", "sweep": ".sweeps", "grid": ".sweeps", "write_table": ".sweeps",
}

__all__ = ["World", "Body", "Snapshot", "Contact", "ContactEvent", "Shape", "Sphere", "Box", "Capsule",
           "ConvexHull", "Plane", "HeightField", "TriangleMesh", "Spring", "Rod", "Cable", "Joint", "BallJoint",
           "Hinge", "Slider", "FixedJoint", "RayHit", "collide", "ContactPoint", "StepProfile", "StepReport", "show",
           "record", "render_image", "Particles", "Network", "Cloth", "cloth_grid", "SoftBody", "Fluid", "tet_box",
           "tetrahedralize", "step_worlds", "sweep", "grid", "write_table", "__version__"]

if TYPE_CHECKING:      # for type checkers and the API reference; at run time the names load on first use
    from .app.record import record, render_image
    from .app.viewer import show
    from .batch import step_worlds
    from .body import Body
    from .cloth import Cloth, cloth_grid
    from .constraints import BallJoint, Cable, FixedJoint, Hinge, Joint, Rod, Slider, Spring
    from .fluid import Fluid
    from .particles import Network, Particles
    from .pipeline.profile import StepProfile
    from .query import ContactPoint, collide
    from .reports import Contact, ContactEvent, RayHit, StepReport
    from .soft import SoftBody, tet_box, tetrahedralize
    from .shapes import Box, Capsule, ConvexHull, HeightField, Plane, Shape, Sphere, TriangleMesh
    from .state.snapshot import Snapshot
    from .sweeps import grid, sweep, write_table
    from .world import World


def __getattr__(name):
    """A public name, imported from its module on first use (PEP 562)."""
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module 'marbellous' has no attribute {name!r}")
    value = getattr(importlib.import_module(home, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_HOME))


from .app.envs import register_when_imported  # noqa: E402  (gymnasium's registry names the environment's module lazily)

register_when_imported()
