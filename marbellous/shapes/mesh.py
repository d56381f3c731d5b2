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
import math
import os
import warnings

import numpy as np

from .._validate import as_choice, as_float, as_vec3
from ..collision import shape_types as st
from ..collision.mesh import mesh_layout as ml
from ..collision.mesh.bvh_static import build_bvh
from ..collision.mesh.grid2d import FAT_MARGIN, build_grid
from ..collision.mesh.mesh_check import MeshReport, check_mesh
from ..collision.ray.raycast_static import raycast_static
from ..collision.triangle.triangle_adjacency import build_adjacency
from .primitives import Shape

#: Most triangles (and vertices) a mesh may have.
MAX_TRIANGLES = 1 << 24
#: Largest mesh file ``TriangleMesh.load`` reads, bytes.
MAX_FILE_BYTES = 1 << 30
#: File types ``TriangleMesh.load`` reads (through trimesh).
FILE_TYPES = (".obj", ".stl", ".ply", ".glb", ".gltf")
#: Most grid cells of the 2D grid, per triangle.
CELLS_PER_TRIANGLE = 4


def _as_vertices(vertices):
    try:
        v = np.array(vertices, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError("vertices must be an array of shape (V, 3) of numbers") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (V, 3), got {v.shape}")
    if v.shape[0] < 3:
        raise ValueError(f"vertices must hold at least 3 vertices, got {v.shape[0]}")
    if v.shape[0] > MAX_TRIANGLES:
        raise ValueError(f"vertices: at most {MAX_TRIANGLES} vertices are supported, got {v.shape[0]}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"vertices must be finite (no NaN or inf); bad rows: "
                         f"{np.nonzero(~np.all(np.isfinite(v), axis=1))[0][:10].tolist()}")
    return v


def _as_triangles(triangles, n_vertices):
    arr = np.asarray(triangles)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)):
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


class TriangleMesh(Shape):
    """A static triangle mesh (a level).  ``vertices`` (V, 3) in metres, ``triangles`` (T, 3) indices.

    ``accel``: ``"brute"`` (test every triangle), ``"grid2d"`` (the lecture's 2D grid in x-z,
    cell side ``cell_size`` m, default about two triangle sizes; each cell lists its triangles, and
    again those within half a cell of it, so a marble-sized query reads one list) or ``"bvh"``
    (for overhangs).
    All three give bit-identical contacts.  ``weld_tolerance`` (m, default 1e-7 of the mesh's
    diagonal): vertices closer than this count as one for adjacency.

    Problems (degenerate, duplicate or flipped triangles, non-manifold edges) give a warning with
    their counts; :meth:`check` returns the full report.  Degenerate triangles never collide.
    """

    _type = st.MESH
    is_static_only = True

    def __init__(self, vertices, triangles, *, accel="grid2d", cell_size=None, weld_tolerance=None):
        self.vertices = _as_vertices(vertices)
        self.triangles = _as_triangles(triangles, self.vertices.shape[0])
        self.accel = as_choice("accel", accel, ml.ACCELS)
        lo, hi = self.vertices.min(axis=0), self.vertices.max(axis=0)
        diag = float(np.linalg.norm(hi - lo))
        if not diag > 0.0:
            raise ValueError("vertices must not all coincide (the mesh has no extent)")
        if weld_tolerance is None:
            weld_tolerance = 1e-7 * diag
        self.weld_tolerance = as_float("weld_tolerance", weld_tolerance, positive=True)
        if cell_size is not None:
            cell_size = as_float("cell_size", cell_size, positive=True)
        self._lo, self._hi = lo, hi
        self._adj = build_adjacency(self.vertices, self.triangles, self.weld_tolerance)
        self._report = check_mesh(self.vertices, self.triangles, self._adj)
        if self._report.has_problems:
            warnings.warn(f"TriangleMesh: {self._report.summary()} (see TriangleMesh.check())",
                          stacklevel=2)
        self._grid = (0.0, 0.0, 0.0, 0, 0)
        self._build_accel(cell_size)
        self.vertices.flags.writeable = False       # the kernels' copies would not follow edits
        self.triangles.flags.writeable = False

    # -- construction -------------------------------------------------------------------------
    def _build_accel(self, cell_size):
        v, t, adj = self.vertices, self.triangles, self._adj
        empty_i = np.zeros(0, np.int64)
        cell_start = cell_tris = fat_start = fat_tris = order = empty_i
        nodes = np.zeros((0, ml.NODE_RECORD))
        if self.accel == "grid2d":
            ex = max(self._hi[0] - self._lo[0], 0.0)
            ez = max(self._hi[2] - self._lo[2], 0.0)
            live = max(int(np.count_nonzero(~adj.degenerate)), 1)
            if cell_size is None:
                area = max(ex * ez, (max(ex, ez) ** 2) / live)
                cell_size = 2.0 * math.sqrt(area / live)
            cell = max(cell_size, 1e-9 * max(ex, ez, 1e-300))
            while (math.floor(ex / cell) + 1) * (math.floor(ez / cell) + 1) > CELLS_PER_TRIANGLE * live + 16:
                cell *= 1.5
            nx, nz = int(math.floor(ex / cell)) + 1, int(math.floor(ez / cell)) + 1
            x0, z0 = float(self._lo[0]), float(self._lo[2])
            cell_start, cell_tris = build_grid(v, t, adj.degenerate, x0, z0, cell, nx, nz, 0.0)
            fat_start, fat_tris = build_grid(v, t, adj.degenerate, x0, z0, cell, nx, nz, FAT_MARGIN * cell)
            self._grid = (x0, z0, cell, nx, nz)
        elif self.accel == "bvh":
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
        self._geom_i = np.concatenate([header] + [np.asarray(a, np.int64) for a in sections_i])
        self._geom_f = np.concatenate([np.asarray(a, np.float64) for a in sections_f])

    # -- Shape interface ----------------------------------------------------------------------
    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self.vertices.shape[0]
        p[1] = self.triangles.shape[0]
        p[2] = ml.ACCELS.index(self.accel)
        p[3:8] = self._grid
        return p

    def _geometry(self):
        return self._geom_f, self._geom_i

    def local_aabb(self):
        """``(min, max)`` corners (m) of the mesh's box in its own frame (new arrays)."""
        return self._lo.copy(), self._hi.copy()

    def bounding_radius(self):
        """Radius (m) of a sphere about the shape's origin that contains every vertex."""
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", self.vertices, self.vertices))))

    # -- queries ------------------------------------------------------------------------------
    def check(self):
        """The :class:`~marbellous.collision.mesh.mesh_check.MeshReport` of this mesh."""
        return self._report

    def raycast(self, origin, direction, max_distance=math.inf):
        """Nearest hit of a ray in the mesh's frame: ``(distance, point, normal)`` or ``None``.

        ``direction`` is normalised; both sides of a triangle are hit and ``normal`` faces the ray.
        """
        o = as_vec3("origin", origin)
        d = as_vec3("direction", direction)
        length = float(np.linalg.norm(d))
        if length < 1e-12:
            raise ValueError("direction must be a non-zero vector")
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True)
        out = np.zeros(8)
        hit = raycast_static(st.MESH, np.zeros(3), np.eye(3), self._params(), self._geom_f, self._geom_i,
                             0, 0, o, d / length, max_distance, out)
        if not hit:
            return None
        return float(out[0]), out[1:4].copy(), out[4:7].copy()

    @classmethod
    def load(cls, path, **kw):
        """Read a mesh file (OBJ, STL, PLY, GLB/GLTF, through trimesh) into a ``TriangleMesh``.

        ``kw`` go to the constructor (``accel``, ``cell_size``, ``weld_tolerance``).  A missing,
        too large (over 1 GiB), unknown or malformed file raises ``ValueError`` naming ``path``.
        Scenes are flattened into one mesh in their world placement.
        """
        import trimesh

        p = os.fspath(path)
        ext = os.path.splitext(p)[1].lower()
        if ext not in FILE_TYPES:
            raise ValueError(f"path must name a {', '.join(FILE_TYPES)} file, got {p!r}")
        if not os.path.isfile(p):
            raise ValueError(f"path: no such file {p!r}")
        size = os.path.getsize(p)
        if size > MAX_FILE_BYTES:
            raise ValueError(f"path: file {p!r} is {size} bytes, more than the limit {MAX_FILE_BYTES}")
        if size == 0:
            raise ValueError(f"path: file {p!r} is empty")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                loaded = trimesh.load(p, force="mesh", process=False)
        except Exception as exc:   # trimesh raises many kinds of errors for malformed files
            raise ValueError(f"path: could not read mesh file {p!r}: {type(exc).__name__}: {exc}") from None
        verts = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
        faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
        if verts.ndim != 2 or faces.ndim != 2 or faces.shape[0] == 0:
            raise ValueError(f"path: file {p!r} contains no triangles")
        try:
            return cls(verts, faces, **kw)
        except (ValueError, TypeError) as exc:
            raise type(exc)(f"path {p!r}: {exc}") from None

    def __repr__(self):
        return (f"TriangleMesh({self.vertices.shape[0]} vertices, {self.triangles.shape[0]} triangles, "
                f"accel={self.accel!r})")


__all__ = ["TriangleMesh", "MeshReport"]
