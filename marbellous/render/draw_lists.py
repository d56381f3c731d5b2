"""What a drawable reads (:class:`WorldFrame`) and what it hands the renderer: instanced solids, spheres,
surfaces, lines and points.

Every kind of object in a world is drawn by a drawable (``drawables.py``) that turns the world into a
list of :class:`Solids`, :class:`Spheres`, :class:`Surface`, :class:`Lines` and :class:`Points`; the renderer
knows only these five.
"""
from dataclasses import dataclass, field

import numpy as np

from .shape_meshes import ShapeMesh

#: Surface patterns of :class:`Solids` (shader codes): a plain colour, a world-space grid that shows
#: the scale (static bodies), two-tone octants that show a round body's spin; and of a :class:`Surface`, a
#: thin sheet (cloth): plain, and lit on both faces (the sun on one face shows through on the other).
PLAIN, GRID, OCTANTS, SHEET = 0, 1, 2, 3


@dataclass
class WorldFrame:
    """One frame of a world as drawables read it: the ``world``, the camera's ``focus`` (m, the point it
    orbits) and ``distance`` (m, from the eye to the focus).  :attr:`bodies` and :attr:`contacts` are
    read from the world once per frame and shared by every drawable."""

    world: object
    focus: np.ndarray
    distance: float
    _contacts: list = field(default=None, repr=False)
    _bodies: list = field(default=None, repr=False)

    @property
    def bodies(self):
        """``world.bodies``, read once."""
        if self._bodies is None:
            self._bodies = self.world.bodies
        return self._bodies

    @property
    def contacts(self):
        """``world.contacts()``, read once."""
        if self._contacts is None:
            self._contacts = self.world.contacts()
        return self._contacts


@dataclass
class Solids:
    """Instances of one mesh: ``models`` (N, 4, 4) world matrices (column vectors, m), ``colors`` (N, 3)
    RGB in [0, 1], ``patterns`` (N,) pattern codes; all drawn with opacity ``alpha`` in (0, 1] (below 1:
    translucent, drawn after the opaque solids and casting no shadow)."""

    mesh: ShapeMesh
    models: np.ndarray
    colors: np.ndarray
    patterns: np.ndarray
    alpha: float = 1.0


@dataclass
class Spheres:
    """Many spheres, lit and shadowed like solids, each drawn from one point (round at any zoom, and cheap:
    16k particles are one draw call of 16k vertices; ``world_shaders.SPHERES_*``): ``centers`` (N, 3) (m),
    ``radii`` (N,) (m), ``colors`` (N, 3) RGB in [0, 1]."""

    centers: np.ndarray
    radii: np.ndarray
    colors: np.ndarray


@dataclass
class Surface:
    """A triangle mesh in world space whose vertices move every frame (a cloth, a soft body's surface), lit
    and shadowed like solids, both faces: ``positions`` (V, 3) (m), ``normals`` (V, 3) unit per-vertex
    normals (interpolated across each triangle), ``triangles`` (T, 3) vertex indices (counter-clockwise seen
    from the side the normals point to), ``color`` (3,) RGB in [0, 1], ``pattern`` a pattern code
    (:data:`SHEET`)."""

    positions: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    color: np.ndarray
    pattern: int = SHEET


@dataclass
class Lines:
    """Line segments: ``segments`` (K, 2, 3) end points (m), ``colors`` (K, 3) RGB in [0, 1], ``width`` in
    pixels; drawn over the scene, or with ``in_scene`` among the solids (hidden behind what is in front of
    them)."""

    segments: np.ndarray
    colors: np.ndarray
    width: float = 2.0
    in_scene: bool = False


@dataclass
class Points:
    """Round dots drawn over the scene: ``positions`` (K, 3) (m), ``colors`` (K, 3) RGB in [0, 1],
    ``size`` (diameter) in pixels."""

    positions: np.ndarray
    colors: np.ndarray
    size: float = 8.0
