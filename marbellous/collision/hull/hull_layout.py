"""Where a convex hull keeps its geometry in the blobs, and how the kernels read it.

A hull is a convex polytope in its own frame, centred on its centre of mass.  Its faces are the merged
coplanar facets (a cube has 6 square faces, not 12 triangles), each a loop of vertex indices,
counter-clockwise seen from outside; its edges are listed once, each with the two faces that meet there.

``geom_f`` (float64), from the shape's offset::

    vertices  (n_vertices x 3, m)       then
    planes    (n_faces x 4): unit outward normal n and offset d, the face being n . x = d (m)

``geom_i`` (int64), from the shape's offset::

    [n_vertices, n_faces, n_edges, loop_total]
    face_start (n_faces + 1): face f's loop is loops[face_start[f]:face_start[f + 1]]
    loops      (loop_total)
    edges      (n_edges x 4): vertex v0, vertex v1, face on the left of v0 -> v1, face on its right

Kernel record (``_params()``)::

    [ex, ey, ez, cx, cy, cz, inner_radius, 0]

the half extents and centre of the hull's bounding box in its frame (m), and the radius of the largest
ball about its centre of mass that it contains (m, the smallest face offset).
"""
from ..._numba.jit import njit_inline

#: Header of the int blob.
I_NV = 0
I_NF = 1
I_NE = 2
I_LOOP_TOTAL = 3
I_HEADER = 4
#: Columns of an edge row.
EDGE_COLS = 4


@njit_inline
def counts(geom_i, off_i):
    """``(n_vertices, n_faces, n_edges)`` of the hull at ``off_i``."""
    return geom_i[off_i + I_NV], geom_i[off_i + I_NF], geom_i[off_i + I_NE]


@njit_inline
def face_starts(geom_i, off_i):
    """Index in ``geom_i`` of the hull's ``face_start`` section."""
    return off_i + I_HEADER


@njit_inline
def loops_start(geom_i, off_i):
    """Index in ``geom_i`` of the hull's ``loops`` section."""
    return off_i + I_HEADER + geom_i[off_i + I_NF] + 1


@njit_inline
def edges_start(geom_i, off_i):
    """Index in ``geom_i`` of the hull's ``edges`` section."""
    return loops_start(geom_i, off_i) + geom_i[off_i + I_LOOP_TOTAL]


@njit_inline
def planes_start(geom_i, off_f, off_i):
    """Index in ``geom_f`` of the hull's ``planes`` section."""
    return off_f + 3 * geom_i[off_i + I_NV]


def edges_from_loops(loops):
    """Edge rows ``(v0, v1, left face, right face)`` of a closed polytope whose faces are the vertex ``loops``
    (each counter-clockwise seen from outside), one row per edge with ``v0 < v1``: the left face runs
    ``v0 -> v1``, the right face ``v1 -> v0``.  Raises ``ValueError`` when an edge is not shared by exactly
    two faces running it in opposite directions (the loops do not close a convex solid)."""
    directed = {}
    for f, loop in enumerate(loops):
        for k, u in enumerate(loop):
            w = loop[(k + 1) % len(loop)]
            if (u, w) in directed:
                raise ValueError(f"edge {u}-{w} runs the same way in faces {directed[(u, w)]} and {f}")
            directed[(u, w)] = f
    rows = []
    for (u, w), f in directed.items():
        if u < w:
            if (w, u) not in directed:
                raise ValueError(f"edge {u}-{w} belongs to one face only")
            rows.append((u, w, f, directed[(w, u)]))
    return sorted(rows)
