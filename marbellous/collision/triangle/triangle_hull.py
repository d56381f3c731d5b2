"""A convex hull against one triangle by the separating-axis test, with a clipped contact manifold.

Axes, as for the box (``triangle_box``), with the hull's support taken over its vertices: the triangle's
normal ``n`` (one-sided: a hull wholly behind the face does not touch it), the hull's face normals, and the
axes ``e_hull x e_triangle`` of edge pairs whose Gauss-map arcs cross (``hull/polytope``; a triangle's edge
supports it along every direction square to the edge that points away from the triangle in its plane).
``L`` runs from the triangle to the hull; an axis that would push the hull behind the triangle
(``L . n < 0``) still separates but is not a contact normal.  The axis of largest separation wins, with
``tolerances.FACE_BIAS`` times the hull's inner radius in favour of the triangle's face, then the hull's
faces.  Internal edges: an axis other than ``n`` that points into a neighbour (``L . m2 > 0``) is a ghost
and the triangle's normal is used instead, so hulls slide over flat seams.

Contacts: for the triangle's face, the hull's face most opposed to ``n`` clipped by the triangle's side
planes; for a hull face, the triangle clipped by that face's side planes; of the points within
``prediction``, the touching ones reduced to four and then the nearest, seven in all.  For an edge pair,
the edges' closest points.
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..hull.polytope import edge_arc, edge_segment, highest, lowest, most_opposed_face, normal, on_edge_arc, vertex
from ..pairs.manifold import clip_polygon, reduce_on_plane
from ..pairs.segment import closest_segment_params
from ..tolerances import CROSS_AXIS_MIN, FACE_BIAS
from ..vec3 import cross, dot, madd, scale, sub
from .triangle_box import _IN_PLANE, CLIP_FIRST, EDGE_PAIR
from .triangle_contact import GHOST_ROUNDING, write_row


@njit
def _clipped_rows(poly, src, count, ref_n, ref_d, normal_out, on_triangle, prediction, scratch):
    """Rows for the clipped polygon ``poly[src, :count]`` against the reference plane ``ref_n . x = ref_d``
    (depth ``ref_d - ref_n . x``), those within ``prediction``, touching first, seven at most; ``on_triangle``:
    the polygon lies on the triangle (else on the hull, and its points are moved onto the triangle's plane).
    Returns the number of rows."""
    # (feature codes CLIP_FIRST + k stay below EDGE_PAIR)
    heights, chosen, kept = reduce_on_plane(poly[src], count, ref_n, ref_d, prediction, EDGE_PAIR - CLIP_FIRST)
    for k in range(min(kept, scratch.shape[0])):
        q = chosen[k]
        x = (poly[src, q, 0], poly[src, q, 1], poly[src, q, 2])
        depth = -heights[q]
        on = x if on_triangle else madd(x, depth, ref_n)
        write_row(scratch, k, on, normal_out, depth, CLIP_FIRST + k, x)
    return min(kept, scratch.shape[0])


@njit
def hull_triangle(poly, size, a, b, cc, n, m2ab, m2bc, m2ca, prediction, scratch):
    """Contacts of the placed hull ``poly`` (``hull/polytope``, in the triangle's frame; ``size`` its inner
    radius, m) with triangle ``a b cc`` (unit normal ``n``; neighbour directions ``m2*``).  Writes rows of
    ``scratch`` (layout in ``triangle_contact``) and returns their number."""
    verts, planes, starts, loops, edges = poly
    plane = dot(n, a)
    if highest(verts, n) < plane:
        return 0                                       # the whole hull is behind the one-sided face
    face_sep = lowest(verts, n) - plane
    if face_sep > prediction:
        return 0
    bias = FACE_BIAS * size
    best, kind, best_l, best_k, best_j = face_sep, 0, n, 0, 0
    for f in range(planes.shape[0]):
        u = normal(planes, f)
        sep = min(dot(u, a), min(dot(u, b), dot(u, cc))) - planes[f, 3]
        if sep > prediction:
            return 0
        if dot(u, n) <= _IN_PLANE and sep > best + bias:
            best, kind, best_l, best_k = sep, 1, scale(u, -1.0), f
    tri = (a, b, cc)
    for i in range(edges.shape[0] // 4):
        p, d = edge_segment(verts, edges, i)
        ha, hb = edge_arc(planes, edges, i)
        ld = math.sqrt(dot(d, d))
        for j in range(3):
            v = tri[j]
            e = sub(tri[(j + 1) % 3], v)
            le = math.sqrt(dot(e, e))
            axis = cross(d, e)
            la = math.sqrt(dot(axis, axis))
            if le == 0.0 or la < CROSS_AXIS_MIN * ld * le:
                continue
            axis = scale(axis, 1.0 / la)
            out = cross(e, n)
            if dot(axis, out) >= 0.0 and on_edge_arc(scale(axis, -1.0), ha, hb):
                l_th = axis
            elif dot(axis, out) <= 0.0 and on_edge_arc(axis, ha, hb):
                l_th = scale(axis, -1.0)
            else:
                continue
            sep = dot(l_th, sub(p, v))
            if sep > prediction:
                return 0
            if dot(l_th, n) >= -_IN_PLANE and sep > best + 2.0 * bias:
                best, kind, best_l, best_k, best_j = sep, 2, l_th, i, j
    if kind != 0 and (dot(best_l, m2ab) > GHOST_ROUNDING or dot(best_l, m2bc) > GHOST_ROUNDING
                      or dot(best_l, m2ca) > GHOST_ROUNDING):
        best, kind, best_l = face_sep, 0, n           # not in the surface's normal cone: a ghost axis
    normal_out = scale(best_l, -1.0)
    if kind == 2:
        p, d = edge_segment(verts, edges, best_k)
        v = tri[best_j]
        e = sub(tri[(best_j + 1) % 3], v)
        s, t = closest_segment_params(p, d, v, e)
        return write_row(scratch, 0, madd(v, t, e), normal_out, -best, EDGE_PAIR, madd(p, s, d))
    if kind == 0:
        inc = most_opposed_face(planes, n)
        k0 = starts[inc]
        m = starts[inc + 1] - k0
        clip = np.empty((2, m + 4, 3))
        labels = np.zeros((2, m + 4, 2), np.int64)
        for q in range(m):
            for c in range(3):
                clip[0, q, c] = verts[loops[k0 + q], c]
        src = 0
        for j in range(3):
            side = cross(sub(tri[(j + 1) % 3], tri[j]), n)
            m = clip_polygon(clip, labels, src, m, side, dot(side, tri[j]), 0)
            src = 1 - src
            if m == 0:
                return 0
        return _clipped_rows(clip, src, m, n, plane, normal_out, False, prediction, scratch)
    u = normal_out                                     # the hull's reference face, facing the triangle
    k0 = starts[best_k]
    mr = starts[best_k + 1] - k0
    clip = np.empty((2, mr + 4, 3))
    labels = np.zeros((2, mr + 4, 2), np.int64)
    for q in range(3):
        for c in range(3):
            clip[0, q, c] = tri[q][c]
    m = 3
    src = 0
    for k in range(mr):
        w0 = vertex(verts, loops[k0 + k])
        side = cross(sub(vertex(verts, loops[k0 + (k + 1) % mr]), w0), u)
        m = clip_polygon(clip, labels, src, m, side, dot(side, w0), 0)
        src = 1 - src
        if m == 0:
            return 0
    return _clipped_rows(clip, src, m, u, planes[best_k, 3], normal_out, True, prediction, scratch)
