"""Static triangle meshes: an artist's level, queried through a 2D grid, a BVH or brute force.

``TriangleMesh(vertices, triangles, *, accel="grid2d")`` checks and stores the mesh, builds the
adjacency that keeps contacts free of ghost collisions on internal edges (``collision/
triangle_contact.py``) and the chosen acceleration structure.  Triangles are one-sided: the front
is where ``(B - A) x (C - A)`` points (counter-clockwise seen from the front) and the solid lies
behind, like a ``Plane``.

Kernel record (``_params()``, see ``collision/mesh_layout.py`` for the blob sections)::

    [n_vertices, n_triangles, accel (0 brute, 1 grid2d, 2 bvh), grid_x0, grid_z0, grid_cell,
     grid_nx, grid_nz]
"""
from __future__ import annotations

import math
import os
import warnings

import numpy as np
from numpy.typing import ArrayLike

from .._validate import MAX_COORD, as_choice, as_direction, as_float, as_real_array, as_vec3
from ..collision import shape_types as st
from ..collision.mesh import mesh_layout as ml
from ..collision.mesh.bvh_static import build_bvh
from ..collision.mesh.grid2d import FAT_MARGIN, build_grid
from ..collision.mesh.mesh_check import MeshReport, check_mesh
from ..collision.ray.raycast_static import raycast_static
from ..collision.triangle.triangle_adjacency import build_adjacency
from .mesh_file import FILE_TYPES, read_mesh_file  # noqa: F401  (FILE_TYPES: re-exported)
from .primitives import Shape

#: Most triangles (and vertices) a mesh may have (a 2M-triangle level builds in about 10 s).
MAX_TRIANGLES = 1 << 22
#: Largest mesh file ``TriangleMesh.load`` reads, bytes.
MAX_FILE_BYTES = 1 << 30
#: Most grid cells of the 2D grid, per triangle.
CELLS_PER_TRIANGLE = 4
#: Most entries of the 2D grid's (grown) cell lists, per triangle: overlapping or duplicated triangles
#: make the cells bigger instead of filling every small cell with every triangle.
ENTRIES_PER_TRIANGLE = 64


def _as_vertices(vertices):
    if isinstance(vertices, np.ndarray) and vertices.ndim == 2 and vertices.shape[0] > MAX_TRIANGLES:
        raise ValueError(f"vertices: at most {MAX_TRIANGLES} vertices are supported, got {vertices.shape[0]}")
    v = as_real_array("vertices", vertices)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (V, 3), got {v.shape}")
    if v.shape[0] < 3:
        raise ValueError(f"vertices must hold at least 3 vertices, got {v.shape[0]}")
    if v.shape[0] > MAX_TRIANGLES:
        raise ValueError(f"vertices: at most {MAX_TRIANGLES} vertices are supported, got {v.shape[0]}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"vertices must be finite (no NaN or inf); bad rows: "
                         f"{np.nonzero(~np.all(np.isfinite(v), axis=1))[0][:10].tolist()}")
    if np.any(np.abs(v) > MAX_COORD):
        raise ValueError(f"vertices must be within +-{MAX_COORD:g} m")
    return v


def _as_triangles(triangles, n_vertices):
    if isinstance(triangles, (str, bytes, dict, set)) or triangles is None:
        raise TypeError("triangles must be an array of shape (T, 3) of integer vertex indices")
    try:
        arr = np.asarray(triangles)
    except (TypeError, ValueError, OverflowError):
        raise TypeError("triangles must be a (non-ragged) array of shape (T, 3) of integer vertex indices") from None
    if arr.dtype == object or arr.dtype.kind not in "iuf":
        raise TypeError("triangles must be an array of shape (T, 3) of integer vertex indices")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"triangles must have shape (T, 3), got {arr.shape}")
    if arr.shape[0] == 0:
        raise ValueError("triangles must not be empty")
    if arr.shape[0] > MAX_TRIANGLES:
        raise ValueError(f"triangles: at most {MAX_TRIANGLES} triangles are supported, got {arr.shape[0]}")
    if np.issubdtype(arr.dtype, np.floating):
        if not np.all(np.isfinite(arr)) or np.any(arr != np.round(arr)):
            raise ValueError("triangles must hold whole-number vertex indices")
    t = arr.astype(np.int64)
    if t.min() < 0 or t.max() >= n_vertices:
        raise ValueError(f"triangles must index vertices 0..{n_vertices - 1}, got indices from "
                         f"{int(t.min())} to {int(t.max())}")
    return np.ascontiguousarray(t)


def _grid_cell(v, t, degenerate, lo, hi, cell_size):
    """Cell side (m) and counts ``(cell, nx, nz)`` of the 2D grid.

    The default side is about two triangle sizes (``2 sqrt(area / live triangles)``); it grows by half
    while the grid would have more than ``CELLS_PER_TRIANGLE`` cells per triangle, or its grown cell
    lists more than ``ENTRIES_PER_TRIANGLE`` entries per triangle (counted from each triangle's box,
    an upper bound of its rasterised cells): stacked, duplicated or huge overlapping triangles give
    big cells rather than a quadratic build."""
    ex = max(hi[0] - lo[0], 0.0)
    ez = max(hi[2] - lo[2], 0.0)
    live = max(int(np.count_nonzero(~degenerate)), 1)
    if cell_size is None:
        area = max(ex * ez, (max(ex, ez) ** 2) / live)
        cell_size = 2.0 * math.sqrt(area / live)
    cell = max(cell_size, 1e-9 * max(ex, ez, 1e-300))
    while (math.floor(ex / cell) + 1) * (math.floor(ez / cell) + 1) > CELLS_PER_TRIANGLE * live + 16:
        cell *= 1.5
    corners = v[t[~degenerate]]
    wx = corners[:, :, 0].max(axis=1) - corners[:, :, 0].min(axis=1)
    wz = corners[:, :, 2].max(axis=1) - corners[:, :, 2].min(axis=1)
    while cell < 2.0 * max(ex, ez):
        # Cells a triangle's box touches, grown by the fat lists' margin on each side (+1 for rounding).
        entries = np.sum((np.floor(wx / cell) + 2.0 + 2 * FAT_MARGIN) * (np.floor(wz / cell) + 2.0 + 2 * FAT_MARGIN))
        if entries <= ENTRIES_PER_TRIANGLE * live:
            break
        cell *= 1.5
    return cell, int(math.floor(ex / cell)) + 1, int(math.floor(ez / cell)) + 1


def _build_accel(v, t, adj, accel, lo, hi, cell_size):
    """The chosen acceleration structure and the kernels' geometry: ``(grid record (x0, z0, cell, nx, nz),
    geom_f, geom_i)`` (see ``collision/mesh/mesh_layout.py``)."""
    grid = (0.0, 0.0, 0.0, 0, 0)
    empty_i = np.zeros(0, np.int64)
    cell_start = cell_tris = fat_start = fat_tris = order = empty_i
    nodes = np.zeros((0, ml.NODE_RECORD))
    if accel == "grid2d":
        cell, nx, nz = _grid_cell(v, t, adj.degenerate, lo, hi, cell_size)
        x0, z0 = float(lo[0]), float(lo[2])
        cell_start, cell_tris = build_grid(v, t, adj.degenerate, x0, z0, cell, nx, nz, 0.0)
        fat_start, fat_tris = build_grid(v, t, adj.degenerate, x0, z0, cell, nx, nz, FAT_MARGIN * cell)
        grid = (x0, z0, cell, nx, nz)
    elif accel == "bvh":
        nodes, order = build_bvh(v, t, adj.degenerate)
    records = np.concatenate([v[t[:, 0]], v[t[:, 1]], v[t[:, 2]], adj.normals], axis=1)
    sections_i = [t.reshape(-1), adj.weld, adj.ring_start, adj.ring, cell_start, cell_tris, order, fat_start,
                  fat_tris]
    sections_f = [v.reshape(-1), records.reshape(-1), adj.m2.reshape(-1), nodes.reshape(-1)]
    header = np.zeros(ml.HEADER, np.int64)
    pos = ml.HEADER
    for slot, arr in zip((ml.I_TRIS, ml.I_WELD, ml.I_RING_START, ml.I_RING, ml.I_CELL_START,
                          ml.I_CELL_TRIS, ml.I_ORDER, ml.I_FAT_START, ml.I_FAT_TRIS), sections_i):
        header[slot] = pos
        pos += arr.shape[0]
    header[ml.I_N_NODES] = nodes.shape[0]
    fpos = 0
    for slot, arr in zip((ml.F_VERTS, ml.F_TRIS, ml.F_M2, ml.F_NODES), sections_f):
        header[slot] = fpos
        fpos += arr.shape[0]
    geom_i = np.concatenate([header] + [np.asarray(a, np.int64) for a in sections_i])
    geom_f = np.concatenate([np.asarray(a, np.float64) for a in sections_f])
    return grid, geom_f, geom_i


class TriangleMesh(Shape):
    """A static triangle mesh (a level).  ``vertices`` (V, 3) in metres, ``triangles`` (T, 3) indices.

    ``accel``: ``"brute"`` (test every triangle), ``"grid2d"`` (the lecture's 2D grid in x-z,
    cell side ``cell_size`` m, default about two triangle sizes; each cell lists its triangles, and
    again those within half a cell of it, so a marble-sized query reads one list) or ``"bvh"``
    (for overhangs).
    All three give bit-identical contacts.  ``weld_tolerance`` (m, default 1e-7 of the mesh's
    diagonal): vertices closer than this count as one for adjacency.

    Problems (degenerate, duplicate or flipped triangles, non-manifold edges) give a warning with
    their counts; :meth:`check` returns the full report.  Degenerate triangles never collide; a mesh
    whose triangles are all degenerate is refused (ValueError).  Limits: at most ``MAX_TRIANGLES``
    triangles and vertices, vertices within +-1e12 m, ``weld_tolerance`` between 1e-12 and 1 times the
    mesh's diagonal.  Immutable: ``vertices`` and ``triangles`` are read-only arrays, and assigning any
    attribute raises AttributeError.
    """

    __slots__ = ("_vertices", "_triangles", "_accel", "_weld_tolerance", "_lo", "_hi", "_adj", "_report",
                 "_grid", "_geom_f", "_geom_i")
    _type = st.MESH
    is_static_only = True

    def __init__(self, vertices: ArrayLike, triangles: ArrayLike, *, accel: str = "grid2d",
                 cell_size: float | None = None, weld_tolerance: float | None = None) -> None:
        v = _as_vertices(vertices)
        t = _as_triangles(triangles, v.shape[0])
        accel = as_choice("accel", accel, ml.ACCELS)
        lo, hi = v.min(axis=0), v.max(axis=0)
        diag = float(np.linalg.norm(hi - lo))
        if not diag > 0.0:
            raise ValueError("vertices must not all coincide (the mesh has no extent)")
        if weld_tolerance is None:
            weld_tolerance = 1e-7 * diag
        else:
            # (the weld grid counts cells of this size across the mesh in int64)
            weld_tolerance = as_float("weld_tolerance", weld_tolerance, lo=1e-12 * diag, hi=diag, unit="m")
        if cell_size is not None:
            cell_size = as_float("cell_size", cell_size, positive=True, hi=1e12, unit="m")
        adj = build_adjacency(v, t, weld_tolerance)
        if np.all(adj.degenerate):
            raise ValueError(f"triangles are all degenerate (zero area, or corners closer than the weld "
                             f"tolerance {weld_tolerance:.3g} m): the mesh has no surface")
        report = check_mesh(v, t, adj)
        if report.has_problems:
            warnings.warn(f"TriangleMesh: {report.summary()} (see TriangleMesh.check())", stacklevel=2)
        grid, geom_f, geom_i = _build_accel(v, t, adj, accel, lo, hi, cell_size)
        for arr in (v, t, lo, hi):      # (after the build: the kernels take writeable arrays)
            arr.flags.writeable = False
        self._init(_vertices=v, _triangles=t, _accel=accel, _weld_tolerance=weld_tolerance, _lo=lo, _hi=hi,
                   _adj=adj, _report=report, _grid=grid, _geom_f=geom_f, _geom_i=geom_i)

    @property
    def vertices(self) -> np.ndarray:
        """Vertices (m), shape (V, 3), a read-only array."""
        return self._vertices.view()

    @property
    def triangles(self) -> np.ndarray:
        """Vertex indices of the triangles, shape (T, 3) int64, a read-only array."""
        return self._triangles.view()

    @property
    def accel(self) -> str:
        """The acceleration structure: ``"brute"``, ``"grid2d"`` or ``"bvh"``."""
        return self._accel

    @property
    def weld_tolerance(self) -> float:
        """Vertices closer than this (m) count as one for adjacency."""
        return self._weld_tolerance

    # -- Shape interface ----------------------------------------------------------------------
    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self._vertices.shape[0]
        p[1] = self._triangles.shape[0]
        p[2] = ml.ACCELS.index(self._accel)
        p[3:8] = self._grid
        return p

    def _geometry(self):
        return self._geom_f, self._geom_i

    def local_aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """``(min, max)`` corners (m) of the mesh's box in its own frame (new arrays)."""
        return self._lo.copy(), self._hi.copy()

    def bounding_radius(self) -> float:
        """Radius (m) of a sphere about the shape's origin that contains every vertex."""
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", self._vertices, self._vertices))))

    # -- queries ------------------------------------------------------------------------------
    def check(self) -> MeshReport:
        """The :class:`~marbellous.collision.mesh.mesh_check.MeshReport` of this mesh."""
        return self._report

    def raycast(self, origin: ArrayLike, direction: ArrayLike, max_distance: float = math.inf):
        """Nearest hit of a ray in the mesh's frame: ``(distance, point, normal)`` or ``None``.

        ``direction`` is normalised; both sides of a triangle are hit and ``normal`` faces the ray.
        """
        o = as_vec3("origin", origin)
        d = as_direction("direction", direction)
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True)
        out = np.zeros(8)
        hit = raycast_static(st.MESH, np.zeros(3), np.eye(3), self._params(), self._geom_f, self._geom_i,
                             0, 0, o, d, max_distance, out)
        if not hit:
            return None
        return float(out[0]), out[1:4].copy(), out[4:7].copy()

    @classmethod
    def load(cls, path: str | os.PathLike, **kw) -> TriangleMesh:
        """Read a mesh file (OBJ, STL, PLY, GLB/GLTF) into a ``TriangleMesh``.

        ``kw`` go to the constructor (``accel``, ``cell_size``, ``weld_tolerance``).  A missing, too
        large (over 1 GiB), unknown, truncated or malformed file, one with more than ``MAX_TRIANGLES``
        triangles, or one whose triangles are all degenerate raises ``ValueError`` naming ``path``
        (see ``shapes/mesh_file.py``: OBJ in any text encoding is read without charset detection).
        Scenes are flattened into one mesh in their world placement.
        """
        verts, faces = read_mesh_file(path, MAX_TRIANGLES, MAX_FILE_BYTES)
        p = os.fsdecode(path)
        try:
            return cls(verts, faces, **kw)
        except (ValueError, TypeError) as exc:
            raise type(exc)(f"path {p!r}: {exc}") from None

    def __repr__(self):
        return (f"TriangleMesh({self._vertices.shape[0]} vertices, {self._triangles.shape[0]} triangles, "
                f"accel={self._accel!r})")


__all__ = ["TriangleMesh", "MeshReport"]
