"""``SoftBody``, ``tet_box`` and ``tetrahedralize``: deformable solids by finite elements, their nodes particles
of the world's particle step (``deformables/``).

A soft body is a mesh of tetrahedra.  Each is a linear finite element whose elastic forces follow Hooke's law
with the element's rotation removed (corotated linear elasticity, ``deformables/soft_elements.py``); the nodes
carry the mass (a quarter of each element's), and the world advances their velocities by one implicit (backward
Euler) step solved with conjugate gradients (``deformables/soft_step.py``).  The nodes are spheres of a small
radius that collide as particles do: with every shape (two ways), with other soft bodies and with particles.
A handle reads copies and validates what it writes; once its soft body is removed (or dropped by a restore)
it raises on use.
"""
from __future__ import annotations

import os
import tempfile

import numpy as np
from numpy.typing import ArrayLike

from ._validate import (MAX_COORD, MAX_DAMPING, MAX_DENSITY, MAX_SIZE, MAX_STIFFNESS, MIN_DENSITY, MIN_SIZE, as_float,
                        as_int, as_quat, as_size, as_vec3)
from .deformables import particle_layout as P
from .deformables.soft_state import SoftRecord, element_rows, surface_triangles, tet_volumes
from .material import validated
from .math3d import quat_to_matrix_np
from .deformable import Deformable
from .particles import MAX_PARTICLES, as_integers, as_points

#: most cells along a side of ``tet_box``
MAX_CELLS = 1024
#: the default node radius: this fraction of the shortest edge of the mesh
RADIUS_OF_EDGE = 0.25
#: the smallest surface ``tetrahedralize`` fills: the diagonal of its box (m)
MIN_SURFACE = 1e-5


def tet_box(half_extents: ArrayLike, resolution: int | ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """A box of tetrahedra centred on the origin: ``(vertices (V, 3), tetrahedra (K, 4))``.

    ``half_extents`` (m, a 3-vector); ``resolution``: cells ``(nx, ny, nz)`` along x, y and z (or one number
    for all three).  Each cell is cut into six tetrahedra around its diagonal from its lowest to its highest
    corner (Kuhn's subdivision: the cuts of neighbouring cells meet face to face); every tetrahedron has a
    positive volume (corners 1, 2, 3 counter-clockwise seen from corner 0's far side)."""
    half = as_vec3("half_extents", half_extents)
    if np.any(half < MIN_SIZE) or np.any(half > MAX_SIZE):
        raise ValueError(f"half_extents must each be in [{MIN_SIZE:g}, {MAX_SIZE:g}] m, got {tuple(half)}")
    if np.ndim(resolution) == 0:
        cells = (as_int("resolution", resolution, lo=1, hi=MAX_CELLS),) * 3
    else:
        arr = as_integers("resolution", resolution).reshape(-1)
        if arr.shape[0] != 3:
            raise ValueError(f"resolution must be a number or (nx, ny, nz), got {arr.shape[0]} numbers")
        cells = tuple(as_int("resolution", int(c), lo=1, hi=MAX_CELLS) for c in arr)
    nx, ny, nz = cells
    axes = [np.linspace(-half[k], half[k], cells[k] + 1) for k in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    vertices = np.stack([x.reshape(-1), y.reshape(-1), z.reshape(-1)], axis=1)

    def corner(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    i, j, k = (a.reshape(-1) for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"))
    tets = []
    # the six paths from corner (0, 0, 0) to (1, 1, 1) along the cell's edges, one axis at a time
    for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
        step = np.zeros(3, dtype=np.int64)
        path = [corner(i, j, k)]
        for axis in order:
            step[axis] = 1
            path.append(corner(i + step[0], j + step[1], k + step[2]))
        tets.append(np.stack(path, axis=1))
    tets = np.concatenate(tets).astype(np.int64)
    return vertices, _positive(vertices, tets)


def _positive(vertices, tets):
    """``tets`` with corners 2 and 3 swapped where the volume is negative."""
    flip = tet_volumes(vertices, tets) < 0.0
    tets[flip, 2], tets[flip, 3] = tets[flip, 3].copy(), tets[flip, 2].copy()
    return tets


def tetrahedralize(surface_vertices: ArrayLike, surface_triangles: ArrayLike, *,
                   max_volume: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Fill a closed triangle mesh with tetrahedra: ``(vertices (V, 3), tetrahedra (K, 4))``.

    ``surface_vertices`` (m, ``(N, 3)``) and ``surface_triangles`` (``(T, 3)`` vertex indices) should enclose
    a volume (fTetWild, the mesher used, also repairs small gaps and self-intersections, keeping the surface
    within 0.1% of the box's diagonal).  ``max_volume`` (m^3): the tetrahedra's target size, as the volume of a
    regular tetrahedron of the target edge length (None: edges about 5% of the box's diagonal).  The
    mesher is the optional package ``pytetwild`` (fTetWild's bindings, MPL-2.0):
    ``pip install "marbellous[mesh]"``.  Its meshes differ slightly from run to run (a few percent in the
    number of tetrahedra): keep the arrays to repeat a simulation exactly."""
    vertices = as_points("surface_vertices", surface_vertices, None, MAX_COORD, "m")
    if vertices.shape[0] < 4:
        raise ValueError(f"surface_vertices must hold at least 4 vertices, got {vertices.shape[0]}")
    triangles = as_integers("surface_triangles", surface_triangles)
    if triangles.ndim != 2 or triangles.shape[1] != 3 or triangles.shape[0] < 4:
        raise ValueError(f"surface_triangles must have shape (T, 3) with T >= 4, got {triangles.shape}")
    if triangles.min() < 0 or triangles.max() >= vertices.shape[0]:
        raise ValueError(f"surface_triangles must be vertex indices in [0, {vertices.shape[0]})")
    if np.any((triangles[:, 0] == triangles[:, 1]) | (triangles[:, 1] == triangles[:, 2])
              | (triangles[:, 0] == triangles[:, 2])):
        raise ValueError("surface_triangles must join three different vertices (a triangle repeats a vertex)")
    # (fTetWild crashes on a surface that encloses nothing or is smaller than about 1e-7 m)
    diagonal = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    if not diagonal >= MIN_SURFACE:
        raise ValueError(f"surface_vertices must span at least {MIN_SURFACE:g} m, got {diagonal:g} m")
    corners = vertices[triangles]
    enclosed = abs(float(np.sum(np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2]))))) / 6
    if not enclosed > 1e-6 * diagonal ** 3:
        raise ValueError("surface_vertices and surface_triangles must enclose a volume (the surface is flat or open)")
    edge = None
    if max_volume is not None:
        # a regular tetrahedron of edge a has the volume a^3 / (6 sqrt 2)
        edge = (6.0 * np.sqrt(2.0) * as_float("max_volume", max_volume, positive=True, hi=MAX_COORD, unit="m^3"))
        edge = edge ** (1.0 / 3.0)
    try:
        import pytetwild
    except ImportError:
        raise ImportError('tetrahedralize needs the optional package pytetwild: pip install "marbellous[mesh]"') \
            from None
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as scratch:      # (fTetWild writes a file of its own where it runs)
        os.chdir(scratch)
        try:
            out_v, out_t = pytetwild.tetrahedralize(vertices, triangles.astype(np.int32), edge_length_abs=edge)
        finally:
            os.chdir(here)
    out_v = np.ascontiguousarray(out_v, dtype=np.float64)
    out_t = np.asarray(out_t, dtype=np.int64)
    if out_t.shape[0] == 0:
        raise ValueError("surface_vertices and surface_triangles enclose no volume to fill")
    used, out_t = np.unique(out_t, return_inverse=True)
    return out_v[used], _positive(out_v[used], out_t.reshape(-1, 4))


def _as_tetrahedra(tetrahedra, rest):
    """``tetrahedra`` as ``(K, 4)`` vertex indices of positive volume (reordered where negative), each vertex a
    corner of some tetrahedron."""
    t = as_integers("tetrahedra", tetrahedra)
    n = rest.shape[0]
    if t.ndim != 2 or t.shape[1] != 4 or t.shape[0] == 0:
        raise ValueError(f"tetrahedra must have shape (K, 4) with K >= 1, got {t.shape}")
    if t.min() < 0 or t.max() >= n:
        raise ValueError(f"tetrahedra must be vertex indices in [0, {n}), got values from {t.min()} to {t.max()}")
    unused = np.setdiff1d(np.arange(n), t.reshape(-1))
    if unused.size:
        raise ValueError(f"vertices must all be corners of tetrahedra; vertex {unused[0]} is in none")
    volumes = np.abs(tet_volumes(rest, t))
    flat = volumes <= 1e-9 * max(float(np.max(volumes)), 1e-300)
    if np.any(flat) or not np.all(np.isfinite(volumes)):
        raise ValueError(f"vertices and tetrahedra must make tetrahedra with a volume: tetrahedron "
                         f"{int(np.argmax(flat))} has none")
    return _positive(rest, t.copy())


def _edge_lengths(rest, tets):
    """The lengths (m) of the tetrahedra's six edges, ``(K, 6)``."""
    pairs = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
    return np.stack([np.linalg.norm(rest[tets[:, a]] - rest[tets[:, b]], axis=1) for a, b in pairs], axis=1)


def new_soft_body(vertices, tetrahedra, density, young_modulus, poisson_ratio, damping, friction, position,
                  orientation, radius):
    """The validated ``(record, node rows f, i, element rows f, i)`` of a new soft body
    (``World.add_soft_body``'s arguments)."""
    rest = as_points("vertices", vertices, None, MAX_COORD, "m")
    if rest.shape[0] < 4 or rest.shape[0] > MAX_PARTICLES:
        raise ValueError(f"vertices must hold 4 to {MAX_PARTICLES} vertices, got {rest.shape[0]}")
    tets = _as_tetrahedra(tetrahedra, rest)
    density = as_float("density", density, lo=MIN_DENSITY, hi=MAX_DENSITY, unit="kg/m^3")
    young_modulus = as_float("young_modulus", young_modulus, positive=True, hi=MAX_STIFFNESS, unit="Pa")
    poisson_ratio = as_float("poisson_ratio", poisson_ratio, lo=-0.99, hi=0.49)
    damping = as_float("damping", damping, nonnegative=True, hi=MAX_DAMPING, unit="s")
    friction = validated("friction", friction)
    q = as_quat("orientation", orientation)
    placed = rest @ quat_to_matrix_np(q).T + as_vec3("position", position)
    if np.any(np.abs(placed) > MAX_COORD):
        raise ValueError(f"position and orientation put vertices beyond +-{MAX_COORD:g} m")
    if radius is None:
        radius = RADIUS_OF_EDGE * float(np.min(_edge_lengths(rest, tets)))
        if not radius >= MIN_SIZE:
            raise ValueError(f"vertices make an edge {radius / RADIUS_OF_EDGE:g} m long: too short for the default "
                             f"node radius (a quarter of the shortest edge, at least {MIN_SIZE:g} m); give radius")
    radius = as_size("radius", radius)
    tf, ti, mass = element_rows(rest, tets, density, young_modulus, poisson_ratio, damping, q)
    n = rest.shape[0]
    f = np.zeros((n, P.PF_COLS))
    i = np.zeros((n, P.PI_COLS), dtype=np.int64)
    f[:, P.P_POS:P.P_POS + 3] = placed
    f[:, P.P_REST:P.P_REST + 3] = rest
    f[:, P.P_MASS] = mass
    f[:, P.P_INV_MASS] = 1.0 / mass
    f[:, P.P_RADIUS] = radius
    f[:, P.P_FRICTION] = friction
    f[:, P.P_STATIC_FRICTION] = friction
    i[:, P.P_FLAGS] = P.PP_SOFT | P.PP_COLLIDE
    i[:, P.P_PIN_BODY] = -1
    i[:, P.P_CLOTH] = -1
    return SoftRecord(0, float(np.sum(tf[:, P.S_VOLUME])), surface_triangles(tets)), f, i, tf, ti


class SoftBody(Deformable):
    """A soft body in a world (``World.add_soft_body``): its points are its nodes, indexed from 0 in the order
    of the vertices it was made from.  A node's mass is a quarter of the mass of each tetrahedron it is a
    corner of."""

    __slots__ = ()
    noun = "soft body"

    @property
    def radius(self) -> float:
        """The nodes' radius (m): how far they keep from shapes and other soft bodies' nodes."""
        return float(self._live().radius[0])

    @property
    def tetrahedra(self) -> np.ndarray:
        """The tetrahedra, ``(K, 4)`` node indices (each with a positive rest volume)."""
        self._live()
        g, s = self._record.elements, self._record.set
        ps = self._world._state.particles
        return ps.ti[g.start:g.start + g.count, P.S_NODES:P.S_NODES + 4] - s.start

    @property
    def surface_triangles(self) -> np.ndarray:
        """The boundary of the mesh, ``(T, 3)`` node indices: the faces of one tetrahedron only, counter-clockwise
        seen from outside (what other soft bodies, cloths and particles collide with, and rays hit)."""
        self._live()
        return self._record.surface.copy()

    @property
    def volume(self) -> float:
        """The volume now (m^3): the sum of the tetrahedra's signed volumes."""
        return float(np.sum(tet_volumes(self.positions, self.tetrahedra)))

    @property
    def rest_volume(self) -> float:
        """The volume at rest (m^3)."""
        self._live()
        return self._record.rest_volume

    def __repr__(self):
        if self._world is None or not self._record.alive:
            return "<SoftBody (removed)>"
        return f"<SoftBody {self._record.set.count} nodes, {self._record.elements.count} tetrahedra>"
