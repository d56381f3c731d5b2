"""Convex hulls: any convex solid a dynamic body can be, from points or a mesh.

``ConvexHull(points)`` takes the convex hull of the points (Qhull, through SciPy), merges coplanar
triangles into polygon faces (a cube has six square faces), and recentres the solid on its centre of mass:
``centroid`` is where that centre was in the points' frame, and ``vertices`` are relative to it.  Mass
properties are exact for the polytope (``trimesh``'s integration over its triangles).

The kernels read the hull from the blobs (layout in ``collision/hull/hull_layout.py``).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .._validate import MAX_COORD, MAX_SIZE, MIN_SIZE, as_real_array
from ..collision import shape_types as st
from ..collision.hull import hull_layout as hl
from ..collision.hull.polytope_polytope import MAX_VERTICES
from .primitives import Shape

#: Two triangles of the hull lie on one face when their unit normals differ by less than this, and their
#: offsets by less than this times the hull's size.
COPLANAR = 1e-9


def _hull_triangles(p):
    """Triangles of the convex hull of ``p`` (indices into ``p``), counter-clockwise from outside, and each
    triangle's plane ``(n, d)``."""
    from scipy.spatial import ConvexHull as Qhull
    from scipy.spatial import QhullError
    try:
        qh = Qhull(p)
    except QhullError:
        raise ValueError("points span no volume (they lie on a plane, a line or a point); a convex hull "
                         "needs four points that are not coplanar") from None
    tri = qh.simplices.copy()
    normals = qh.equations[:, :3]
    offsets = -qh.equations[:, 3]
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), normals) < 0.0
    tri[flip, 1], tri[flip, 2] = tri[flip, 2], tri[flip, 1].copy()
    return tri, normals, offsets


def _merge_faces(p, tri, normals, offsets, size):
    """Group coplanar triangles into faces: ``(loops, planes)``, each loop counter-clockwise from outside
    with collinear points dropped."""
    group = -np.ones(len(tri), np.int64)
    loops, planes = [], []
    for t in range(len(tri)):
        if group[t] >= 0:
            continue
        same = (np.abs(normals - normals[t]).max(axis=1) < COPLANAR) & \
               (np.abs(offsets - offsets[t]) < COPLANAR * size) & (group < 0)
        group[same] = len(loops)
        n = normals[same].mean(axis=0)
        n /= np.linalg.norm(n)
        ids = np.unique(tri[same])
        t1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        q = p[ids] - p[ids].mean(axis=0)
        ring = list(ids[np.argsort(np.arctan2(q @ t2, q @ t1))])
        k = 0
        while k < len(ring) and len(ring) > 3:      # drop points on the straight part of an edge
            u, v, w = p[ring[k - 1]], p[ring[k]], p[ring[(k + 1) % len(ring)]]
            if np.dot(np.cross(v - u, w - v), n) <= COPLANAR * size * size:
                ring.pop(k)
                k = max(k - 1, 0)
            else:
                k += 1
        loops.append(ring)
        planes.append((n, float(np.mean(p[ring] @ n))))
    return loops, planes


class ConvexHull(Shape):
    """A solid convex polytope: the convex hull of ``points``, recentred on its centre of mass.

    ``points`` is an ``(N, 3)`` array-like (m), or anything with ``.vertices`` (a ``TriangleMesh``, a
    ``trimesh.Trimesh``); points inside the hull are ignored.  The hull needs volume (four points that are
    not coplanar), at most 512 corners, and a size within [1e-6, 1e6] m.

    ``centroid`` is where the centre of mass lies in the points' frame: place the body at
    ``position + centroid`` to put the hull where its points were.  Inertia: exact for the polytope, about
    its centre of mass, in its frame (not diagonal in general).
    """

    __slots__ = ("_vertices", "_loops", "_centroid", "_volume", "_inertia", "_params_arr", "_geom_f", "_geom_i")
    _type = st.HULL

    def __init__(self, points: ArrayLike) -> None:
        source = points.vertices if hasattr(points, "vertices") and not isinstance(points, np.ndarray) else points
        p = as_real_array("points", source)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 4:
            raise ValueError(f"points must have shape (N, 3) with N >= 4, got {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError("points must be finite (no NaN or inf)")
        if np.any(np.abs(p) > MAX_COORD):
            raise ValueError(f"points must be within +-{MAX_COORD:g} m")
        p = np.ascontiguousarray(p, dtype=np.float64)
        size = float(np.ptp(p, axis=0).max())
        if not MIN_SIZE <= size <= 2.0 * MAX_SIZE:
            raise ValueError(f"points: the hull's size must lie within [{MIN_SIZE:g}, {MAX_SIZE:g}] m, "
                             f"the points span {size:.3g} m")
        tri, normals, offsets = _hull_triangles(p)
        import trimesh      # (here: importing it takes a while, and only hulls need it)
        props = trimesh.triangles.mass_properties(p[tri], density=1.0)
        loops, planes = _merge_faces(p, tri, normals, offsets, size)
        used = np.unique(np.concatenate([np.asarray(lp) for lp in loops]))
        if len(used) > MAX_VERTICES:
            raise ValueError(f"points: the hull has {len(used)} corners, at most {MAX_VERTICES} are supported "
                             "(simplify the mesh first, e.g. trimesh's simplify_quadric_decimation)")
        index = -np.ones(len(p), np.int64)
        index[used] = np.arange(len(used))
        com = np.asarray(props.center_mass, np.float64)
        verts = p[used] - com
        loops = [index[np.asarray(lp)] for lp in loops]
        plane_rows = np.array([[*n, d - float(n @ com)] for n, d in planes])
        edges = np.array(hl.edges_from_loops([lp.tolist() for lp in loops]), np.int64)
        inner = float(plane_rows[:, 3].min())
        outer = float(np.linalg.norm(verts, axis=1).max())
        if not (inner >= MIN_SIZE and outer <= MAX_SIZE):
            raise ValueError(f"points: the hull's size must lie within [{MIN_SIZE:g}, {MAX_SIZE:g}] m (it reaches "
                             f"{outer:.3g} m from its centre of mass and is {2 * max(inner, 0.0):.3g} m thick there)")
        lo, hi = verts.min(axis=0), verts.max(axis=0)
        params = np.zeros(st.N_SHAPE_PARAMS)
        params[0:3] = 0.5 * (hi - lo)
        params[3:6] = 0.5 * (hi + lo)
        params[6] = inner
        starts = np.cumsum([0] + [len(lp) for lp in loops])
        geom_i = np.concatenate([[len(verts), len(loops), len(edges), starts[-1]], starts,
                                 np.concatenate(loops), edges.ravel()]).astype(np.int64)
        geom_f = np.concatenate([verts.ravel(), plane_rows.ravel()])
        for arr in (verts, com, params):
            arr.flags.writeable = False
        for lp in loops:
            lp.flags.writeable = False
        self._init(_vertices=verts, _loops=tuple(loops), _centroid=com, _volume=float(props.volume),
                   _inertia=np.asarray(props.inertia, np.float64), _params_arr=params, _geom_f=geom_f,
                   _geom_i=geom_i)

    @property
    def vertices(self) -> np.ndarray:
        """The hull's corners (m), relative to its centre of mass, ``(V, 3)``, a read-only view."""
        return self._vertices.view()

    @property
    def faces(self) -> tuple[np.ndarray, ...]:
        """The faces, each a read-only array of indices into ``vertices``, counter-clockwise seen from outside."""
        return tuple(loop.view() for loop in self._loops)

    @property
    def centroid(self) -> np.ndarray:
        """Where the centre of mass lies in the frame of the points the hull was made from (m), new array."""
        return self._centroid.copy()

    @property
    def inner_radius(self) -> float:
        """Radius (m) of the largest ball about the centre of mass inside the hull."""
        return float(self._params_arr[6])

    def _params(self):
        return self._params_arr.copy()

    def _geometry(self):
        return self._geom_f, self._geom_i

    def volume(self) -> float:
        """Volume in m^3."""
        return self._volume

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        return density * self._volume, density * self._inertia

    def bounding_radius(self) -> float:
        return float(np.linalg.norm(self._vertices, axis=1).max())

    def __repr__(self):
        return f"ConvexHull({len(self._vertices)} vertices, {len(self._loops)} faces, volume={self._volume:.6g})"
