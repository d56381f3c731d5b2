"""``Cloth`` and ``cloth_grid``: cloth from a triangle mesh, its vertices particles of the world's particle
step (``deformables/``).

Each vertex is a point mass (the cloth's mass spread by area) with the radius ``thickness / 2``; each edge of
the triangles a stiff spring (stretch), each pair of triangles that share an edge a hinge (bending); the
triangles keep points (its own vertices, other cloths', colliding particles) ``thickness`` away on the side
they came from.  A handle reads copies and validates what it writes; once its cloth is removed (or dropped by
a restore) it raises on use.
"""
from __future__ import annotations

import numpy as np

from ._validate import (MAX_COORD, MAX_DAMPING, MAX_MASS, MAX_SIZE, MAX_STIFFNESS, MIN_MASS, as_flag, as_float,
                        as_int, as_quat, as_size, as_vec3)
from .deformables import particle_layout as P
from .deformables.cloth_state import ClothRecord, edge_table, vertex_rows
from .deformables.cloth_topology import triangle_areas
from .material import validated
from .math3d import quat_to_matrix_np
from .deformable import Deformable
from .particles import MAX_PARTICLES, as_integers, as_points

#: most vertices along a side of ``cloth_grid``
MAX_GRID = 4096


def cloth_grid(width: float, depth: float, nx: int, nz: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat sheet of ``width`` x ``depth`` metres in the x-z plane at y = 0, centred on the origin:
    ``(vertices (nx nz, 3), triangles (2 (nx - 1) (nz - 1), 3))``, ``nx`` x ``nz`` vertices (vertex
    ``i nz + j`` at column ``i`` along x, row ``j`` along z).  Each cell is cut along a diagonal, the diagonals
    alternating like a chequerboard (so the sheet bends and stretches alike both ways); the triangles face +y
    (counter-clockwise seen from above)."""
    w = as_size("width", width)
    d = as_size("depth", depth)
    nx = as_int("nx", nx, lo=2, hi=MAX_GRID)
    nz = as_int("nz", nz, lo=2, hi=MAX_GRID)
    x, z = np.meshgrid(np.linspace(-w / 2, w / 2, nx), np.linspace(-d / 2, d / 2, nz), indexing="ij")
    vertices = np.stack([x.reshape(-1), np.zeros(nx * nz), z.reshape(-1)], axis=1)
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(nz - 1), indexing="ij")
    i, j = i.reshape(-1), j.reshape(-1)
    a, b, c, e = i * nz + j, i * nz + j + 1, (i + 1) * nz + j, (i + 1) * nz + j + 1   # a b / c e: +z, +x
    even = (i + j) % 2 == 0
    first = np.where(even[:, None], np.stack([a, b, c], 1), np.stack([a, b, e], 1))
    second = np.where(even[:, None], np.stack([b, e, c], 1), np.stack([a, e, c], 1))
    return vertices, np.concatenate([first, second]).astype(np.int64)


def _as_triangles(triangles, n_vertices):
    """``triangles`` as ``(T, 3)`` vertex indices: each in range, three different vertices, and every vertex
    a corner of some triangle."""
    t = as_integers("triangles", triangles)
    if t.ndim != 2 or t.shape[1] != 3 or t.shape[0] == 0:
        raise ValueError(f"triangles must have shape (T, 3) with T >= 1, got {t.shape}")
    if t.min() < 0 or t.max() >= n_vertices:
        raise ValueError(f"triangles must be vertex indices in [0, {n_vertices}), got values from {t.min()} to "
                         f"{t.max()}")
    if np.any((t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 0] == t[:, 2])):
        raise ValueError("triangles must join three different vertices (a triangle repeats a vertex)")
    unused = np.setdiff1d(np.arange(n_vertices), t.reshape(-1))
    if unused.size:
        raise ValueError(f"vertices must all be corners of triangles; vertex {unused[0]} is in none")
    return t


def new_cloth(vertices, triangles, mass, stretch_stiffness, bend_stiffness, damping, thickness, friction,
              self_collision, tear_strain, position, orientation):
    """The validated ``(record, vertex rows f, i, edge rows f, i)`` of a new cloth (``World.add_cloth``'s
    arguments)."""
    rest = as_points("vertices", vertices, None, MAX_COORD, "m")
    if rest.shape[0] < 3 or rest.shape[0] > MAX_PARTICLES:
        raise ValueError(f"vertices must hold 3 to {MAX_PARTICLES} vertices, got {rest.shape[0]}")
    tri = _as_triangles(triangles, rest.shape[0])
    areas = triangle_areas(rest, tri)
    if np.any(areas <= 1e-12 * max(float(np.max(areas)), 1e-300)) or not np.all(np.isfinite(areas)):
        raise ValueError(f"vertices and triangles must make triangles with an area: triangle "
                         f"{int(np.argmin(areas))} has none")
    mass = as_float("mass", mass, lo=MIN_MASS, hi=MAX_MASS, unit="kg")
    tear = np.inf if tear_strain is None else as_float("tear_strain", tear_strain, positive=True, hi=MAX_SIZE)
    record = ClothRecord(0, tri, mass / float(np.sum(areas)),
                         as_float("stretch_stiffness", stretch_stiffness, positive=True, hi=MAX_STIFFNESS, unit="N/m"),
                         as_float("bend_stiffness", bend_stiffness, nonnegative=True, hi=MAX_STIFFNESS, unit="N m"),
                         as_size("thickness", thickness), tear, as_flag("self_collision", self_collision))
    damping = as_float("damping", damping, nonnegative=True, hi=MAX_DAMPING, unit="1/s")
    friction = validated("friction", friction)
    rot = quat_to_matrix_np(as_quat("orientation", orientation))
    placed = rest @ rot.T + as_vec3("position", position)
    if np.any(np.abs(placed) > MAX_COORD):
        raise ValueError(f"position and orientation put vertices beyond +-{MAX_COORD:g} m")
    f, i = vertex_rows(record, placed, rest, friction, friction)
    f[:, P.P_DAMPING] = damping
    ef, ei = edge_table(record, rest, np.zeros((0, 2), dtype=np.int64))
    return record, f, i, ef, ei


class Cloth(Deformable):
    """A cloth in a world (``World.add_cloth``): its points are its vertices.  Vertex indices count from 0
    within the cloth; tearing adds vertices at the end (the vertices along a tear are duplicated), never
    renumbers the others.  Its mass is spread over the vertices by area: a third of the area of its triangles
    at each vertex times the cloth's density."""

    __slots__ = ()
    noun = "cloth"

    @property
    def triangles(self) -> np.ndarray:
        """The triangles, ``(T, 3)`` vertex indices, as they are now (a tear gives the triangles on its two
        sides different vertices)."""
        self._live()
        return self._record.triangles.copy()

    @property
    def torn(self) -> int:
        """How many edges have torn so far."""
        self._live()
        return self._record.torn

    @property
    def thickness(self) -> float:
        """The thickness (m): how far points stay from the triangles (each vertex a sphere of half of it)."""
        self._live()
        return self._record.thickness

    def __repr__(self):
        alive = self._world is not None and self._record.alive
        if not alive:
            return "<Cloth (removed)>"
        return f"<Cloth {self._record.set.count} vertices, {self._record.triangles.shape[0]} triangles>"
