"""The registry of drawables: for each kind of object in a world, how it is drawn.

A :class:`Drawable` has a ``name`` (the layer it can be toggled by), a ``draw`` function that turns a
:class:`~marbellous.render.draw_lists.WorldFrame` into a list of ``Solids``, ``Spheres``, ``Lines`` and
``Points``, and whether it is ``shown`` by default.  The renderer draws the layers asked for in registry order.
A new kind of object is drawn by registering one more drawable, as cloth is::

    register(Drawable("cloth", cloth_surfaces, shown=True, help="every cloth as a shaded surface"))
"""
from collections.abc import Callable
from dataclasses import dataclass

from .body_solids import body_solids
from .cloth_drawing import cloth_surfaces, soft_body_surfaces
from .fluid_drawing import fluid_arrows, fluids
from .overlays import box_outlines, constraint_lines, contact_marks, event_marks
from .particle_drawing import network_lines, particle_spheres


@dataclass(frozen=True)
class Drawable:
    """A layer of the drawing: ``draw(frame) -> list`` of draw lists; ``shown`` by default or not;
    ``help`` says in a few words what it shows."""

    name: str
    draw: Callable
    shown: bool
    help: str


#: The drawables by name, in drawing order.
DRAWABLES = {}


def register(drawable):
    """Add ``drawable`` (a :class:`Drawable`) to :data:`DRAWABLES`; its name must be new."""
    if not isinstance(drawable, Drawable):
        raise TypeError(f"drawable must be a Drawable, got {drawable!r}")
    if drawable.name in DRAWABLES:
        raise ValueError(f"drawable name {drawable.name!r} is already registered")
    DRAWABLES[drawable.name] = drawable


def default_layers():
    """Names of the drawables shown by default, in drawing order."""
    return tuple(name for name, d in DRAWABLES.items() if d.shown)


def check_layers(layers):
    """``layers`` (names of drawables) as a tuple, or ``ValueError`` naming ``layers`` and the known names."""
    if isinstance(layers, str):
        raise TypeError(f"layers must be a collection of layer names, got the string {layers!r}")
    names = tuple(layers)
    unknown = [n for n in names if n not in DRAWABLES]
    if unknown:
        known = "; ".join(f"{name} ({d.help})" for name, d in DRAWABLES.items())
        raise ValueError(f"layers: unknown {', '.join(map(repr, unknown))}; known: {known}")
    return names


def constraints_and_networks(frame):
    """The lines of the constraints between bodies (``overlays.constraint_lines``) and of the edges of the
    particle networks (``particle_drawing.network_lines``)."""
    return constraint_lines(frame) + network_lines(frame)


register(Drawable("bodies", body_solids, shown=True, help="every body's shapes"))
register(Drawable("particles", particle_spheres, shown=True, help="every particle as a sphere, pinned ones raspberry"))
register(Drawable("cloth", cloth_surfaces, shown=True, help="every cloth as a shaded surface, lit on both faces"))
register(Drawable("soft", soft_body_surfaces, shown=True,
                  help="every soft body as its surface, pinned nodes raspberry"))
register(Drawable("fluids", fluids, shown=True, help="every fluid's box, surface and dye"))
register(Drawable("flow", fluid_arrows, shown=True, help="fluid velocity arrows on the middle slices, by speed"))
register(Drawable("constraints", constraints_and_networks, shown=True,
                  help="springs, rods, cables and joints, and the edges of particle networks"))
register(Drawable("contacts", contact_marks, shown=False, help="contact points and normals"))
register(Drawable("events", event_marks, shown=False, help="where pairs began (red) and stopped touching"))
register(Drawable("boxes", box_outlines, shown=False, help="broad-phase bounding boxes"))
