"""A convex polytope placed in the world, as the hull pair tests read it, and the pieces they share.

A placed polytope is five arrays: ``verts`` (n, 3) world vertices (m), ``planes`` (f, 4) world face planes
``n . x = d`` (unit outward ``n``, ``d`` m), and the frame-free topology of ``hull_layout``: ``starts``
(f + 1) and ``loops`` (the faces' vertex loops, counter-clockwise from outside), ``edges`` (flat, 4 per
edge: v0, v1, left face, right face).  A hull is placed from its blob; a box is the unit cube's topology
with its own vertices, so that box-hull pairs run the same test as hull-hull pairs.

The Gauss map: the outward normals at an edge sweep the arc from its left face's normal ``a`` to its right
face's ``b`` (about ``a x b``, which runs along the edge ``v0 -> v1``).  A direction ``L`` square to the
edge lies on that arc iff ``(a x L) . (a x b) >= 0`` and ``(L x b) . (a x b) >= 0``; only then does the
polytope's support along ``L`` lie on that edge.
"""
import numpy as np

from ..._numba.jit import njit
from ..vec3 import cross, dot, sub, to_world
from . import hull_layout as hl

# The unit cube: vertex k at (+-1, +-1, +-1), + where bit 0 (x), 1 (y), 2 (z) of k is set; faces +x, -x, +y,
# -y, +z, -z (face 2 axis + (0 if + else 1)), counter-clockwise from outside.
_CUBE_LOOPS = ((1, 3, 7, 5), (0, 4, 6, 2), (2, 6, 7, 3), (0, 1, 5, 4), (4, 5, 7, 6), (0, 2, 3, 1))
BOX_STARTS = np.arange(0, 25, 4, dtype=np.int64)
BOX_LOOPS = np.array(_CUBE_LOOPS, dtype=np.int64).ravel()
BOX_EDGES = np.array(hl.edges_from_loops(_CUBE_LOOPS), dtype=np.int64).ravel()


@njit
def hull_polytope(pos, rot, geom_f, geom_i, off_f, off_i):
    """The hull at ``off_f``/``off_i`` of the blobs placed at ``pos`` (3,) with rotation ``rot`` (3, 3):
    ``(verts, planes, starts, loops, edges)`` (module docstring); the topology arrays are views of ``geom_i``."""
    nv, nf, ne = hl.counts(geom_i, off_i)
    verts = np.empty((nv, 3))
    for k in range(nv):
        w = to_world(rot, (geom_f[off_f + 3 * k], geom_f[off_f + 3 * k + 1], geom_f[off_f + 3 * k + 2]))
        for m in range(3):
            verts[k, m] = w[m] + pos[m]
    planes = np.empty((nf, 4))
    p0 = hl.planes_start(geom_i, off_f, off_i)
    for f in range(nf):
        nw = to_world(rot, (geom_f[p0 + 4 * f], geom_f[p0 + 4 * f + 1], geom_f[p0 + 4 * f + 2]))
        for m in range(3):
            planes[f, m] = nw[m]
        planes[f, 3] = geom_f[p0 + 4 * f + 3] + nw[0] * pos[0] + nw[1] * pos[1] + nw[2] * pos[2]
    s0 = hl.face_starts(geom_i, off_i)
    l0 = hl.loops_start(geom_i, off_i)
    e0 = hl.edges_start(geom_i, off_i)
    return (verts, planes, geom_i[s0:s0 + nf + 1], geom_i[l0:l0 + geom_i[off_i + hl.I_LOOP_TOTAL]],
            geom_i[e0:e0 + hl.EDGE_COLS * ne])


@njit
def box_polytope(pos, rot, h):
    """The box of half extents ``h`` (m) placed at ``pos`` (3,) with rotation ``rot`` (3, 3), as a polytope."""
    verts = np.empty((8, 3))
    for k in range(8):
        for m in range(3):
            verts[k, m] = pos[m]
        for i in range(3):
            s = h[i] if (k >> i) & 1 else -h[i]
            for m in range(3):
                verts[k, m] += s * rot[m, i]
    planes = np.empty((6, 4))
    for f in range(6):
        i = f // 2
        s = 1.0 if f % 2 == 0 else -1.0
        for m in range(3):
            planes[f, m] = s * rot[m, i]
        planes[f, 3] = s * (rot[0, i] * pos[0] + rot[1, i] * pos[1] + rot[2, i] * pos[2]) + h[i]
    return verts, planes, BOX_STARTS, BOX_LOOPS, BOX_EDGES


@njit
def lowest(verts, axis):
    """``min_k axis . verts[k]`` (m): how far the polytope reaches against ``axis``."""
    best = np.inf
    for k in range(verts.shape[0]):
        best = min(best, axis[0] * verts[k, 0] + axis[1] * verts[k, 1] + axis[2] * verts[k, 2])
    return best


@njit
def highest(verts, axis):
    """``max_k axis . verts[k]`` (m): how far the polytope reaches along ``axis``."""
    best = -np.inf
    for k in range(verts.shape[0]):
        best = max(best, axis[0] * verts[k, 0] + axis[1] * verts[k, 1] + axis[2] * verts[k, 2])
    return best


@njit
def vertex(verts, k):
    """Vertex ``k`` as a 3-tuple (m)."""
    return verts[k, 0], verts[k, 1], verts[k, 2]


@njit
def normal(planes, f):
    """Unit outward normal of face ``f`` as a 3-tuple."""
    return planes[f, 0], planes[f, 1], planes[f, 2]


@njit
def on_edge_arc(axis, a, b):
    """True if the unit ``axis`` (square to the edge) lies on the edge's Gauss-map arc from ``a`` to ``b``."""
    ab = cross(a, b)
    return dot(cross(a, axis), ab) >= 0.0 and dot(cross(axis, b), ab) >= 0.0


@njit
def arcs_cross(a, b, c, d):
    """True if the Gauss-map arc of an edge of A (face normals ``a`` to ``b``) crosses the arc of an edge of B
    (``c`` to ``d``) negated: the two edges then support A and B along the cross product of their directions,
    and that axis is a face of the Minkowski difference A - B (Gregorius, GDC 2013): with ``b x a`` and
    ``d x c`` square to the arcs' planes, ``(c.(b x a)) (d.(b x a)) < 0``, ``(a.(d x c)) (b.(d x c)) < 0``, and
    the arcs on one hemisphere, ``(c.(b x a)) (b.(d x c)) < 0``.  Four dot products, no square root."""
    bxa = cross(b, a)
    dxc = cross(d, c)
    cba = -dot(c, bxa)
    dba = -dot(d, bxa)
    adc = dot(a, dxc)
    bdc = dot(b, dxc)
    return cba * dba < 0.0 and adc * bdc < 0.0 and cba * bdc > 0.0


@njit
def edge_arc(planes, edges, e):
    """The normals ``(a, b)`` of the faces left and right of edge ``e``."""
    return normal(planes, edges[4 * e + 2]), normal(planes, edges[4 * e + 3])


@njit
def edge_segment(verts, edges, e):
    """Edge ``e`` as ``(start, direction)`` 3-tuples (m): ``v0`` and ``v1 - v0``."""
    p = vertex(verts, edges[4 * e])
    return p, sub(vertex(verts, edges[4 * e + 1]), p)


@njit
def most_opposed_face(planes, direction):
    """The face whose outward normal is most opposed to ``direction``: the least ``n . direction``."""
    best = np.inf
    face = 0
    for f in range(planes.shape[0]):
        d = planes[f, 0] * direction[0] + planes[f, 1] * direction[1] + planes[f, 2] * direction[2]
        if d < best:
            best = d
            face = f
    return face


@njit
def no_polytope():
    """Empty polytope arrays, the ``poly`` argument of pair tests whose shape is not a hull."""
    return (np.empty((0, 3)), np.empty((0, 4)), np.empty(0, np.int64), np.empty(0, np.int64),
            np.empty(0, np.int64))
