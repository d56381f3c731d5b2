"""Two convex polytopes (hull-hull, hull-box): the separating-axis test, then face clipping or an edge pair.

Axes (``polytope`` has the placed polytopes and the Gauss map):

- a face ``f`` of A (normal ``n``, plane ``d``): ``sep = min_{v in B} n . v - d``; likewise B's faces;
- an edge of A and an edge of B: ``L = e_A x e_B`` (unit), only when the two edges' Gauss-map arcs cross
  (``L`` on A's arc and ``-L`` on B's, ``polytope.arcs_cross``: four dot products), which is exactly when both
  edges support their polytopes along ``L``; then ``sep = L . (p_B - p_A)`` for points ``p`` on the edges
  (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013).  Pruned this way, edge pairs
  cost no support search.

Any ``sep > prediction`` separates them.  Otherwise the axis of largest ``sep`` is the contact normal, with
``tolerances.FACE_BIAS`` times the smaller inner radius in favour of A's faces, then B's, over edges (so a
resting hull keeps its reference face).  For a face axis the incident face of the other polytope (its face
most opposed to the normal) is clipped against the reference face's side planes (Sutherland-Hodgman); points
within ``prediction`` of the reference plane are reduced as for a plane (``hull_plane``): the touching ones
to four, then the nearest, eight in all.
For an edge axis the edges' closest points give one contact.

Feature ids: a face contact ``(((ref_is_b * 1024 + ref_face) * 1024 + incident_face) * 512 + in) * 512
+ out``, a clipped point being named by the two polygon edges meeting there (incident edges ``0..``,
reference side planes ``256 + k``); an edge contact ``EDGE_FEATURES + edge_a * 4096 + edge_b``.  Hulls
have at most ``MAX_VERTICES`` vertices, so that these fit (faces <= 2 V - 4, edges <= 3 V - 6).
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..pairs.contact_output import add_contact
from ..pairs.manifold import clip_polygon, reduce_on_plane
from ..pairs.segment import closest_segment_params
from ..tolerances import CLIP_SLOP, CROSS_AXIS_MIN, FACE_BIAS
from ..vec3 import cross, dot, madd, scale, sub
from .hull_plane import MOST_CONTACTS
from .polytope import arcs_cross, edge_arc, edge_segment, lowest, most_opposed_face, normal, vertex

#: Most vertices of a hull (and of one face's loop).
MAX_VERTICES = 512
#: Label of reference side plane ``k`` in a clipped point's name.
SIDE_LABEL = 256
#: First feature id of edge contacts.
EDGE_FEATURES = 1 << 42


@njit
def face_separation(planes, f, verts_other):
    """``min_{v in other} n_f . v - d_f`` (m): how far the other polytope lies in front of face ``f``."""
    n = normal(planes, f)
    return lowest(verts_other, n) - planes[f, 3]


@njit
def best_face(planes, verts_other, prediction):
    """``(sep, face)``: the face of largest separation from the other polytope; ``sep > prediction``
    stops the search (the polytopes are apart)."""
    best = -np.inf
    face = 0
    for f in range(planes.shape[0]):
        s = face_separation(planes, f, verts_other)
        if s > best:
            best = s
            face = f
            if s > prediction:
                break
    return best, face


@njit
def _best_edge_pair(va, pa, ea, vb, pb, eb, prediction):
    """``(sep, edge_a, edge_b, L)``: the supporting edge pair of largest separation (module docstring),
    ``L`` unit from A to B; ``edge_a = -1`` when no pair's arcs cross."""
    best = -np.inf
    best_i = -1
    best_j = -1
    best_l = (0.0, 0.0, 0.0)
    for i in range(ea.shape[0] // 4):
        p, d = edge_segment(va, ea, i)
        a, b = edge_arc(pa, ea, i)
        ld = math.sqrt(dot(d, d))
        ab = (a[0] + b[0], a[1] + b[1], a[2] + b[2])
        for j in range(eb.shape[0] // 4):
            c, g = edge_arc(pb, eb, j)
            if not arcs_cross(a, b, c, g):
                continue
            q, e = edge_segment(vb, eb, j)
            axis = cross(d, e)
            la = math.sqrt(dot(axis, axis))
            if la < CROSS_AXIS_MIN * ld * math.sqrt(dot(e, e)):
                continue
            # on A's arc (which spans less than half a turn), the axis points to the side of a + b
            l_ab = scale(axis, (1.0 if dot(axis, ab) >= 0.0 else -1.0) / la)
            s = dot(l_ab, sub(q, p))
            if s > best:
                best, best_i, best_j, best_l = s, i, j, l_ab
                if s > prediction:
                    return best, best_i, best_j, best_l
    return best, best_i, best_j, best_l


@njit
def _face_contact(vr, pr, sr, lr, face, vi, pi, si, li, ref_is_b, slop, prediction, out_f, out_i, n):
    """Contacts of reference face ``face`` of polytope r with the incident face of polytope i."""
    nref = normal(pr, face)
    inc = most_opposed_face(pi, nref)
    k0 = si[inc]
    m = si[inc + 1] - k0
    r0 = sr[face]
    mr = sr[face + 1] - r0
    cap = m + mr + 1
    poly = np.empty((2, cap, 3))
    labels = np.empty((2, cap, 2), np.int64)
    for q in range(m):
        for c in range(3):
            poly[0, q, c] = vi[li[k0 + q], c]
        labels[0, q, 0] = (q + m - 1) % m
        labels[0, q, 1] = q
    src = 0
    count = m
    for k in range(mr):
        u = vertex(vr, lr[r0 + k])
        w = vertex(vr, lr[r0 + (k + 1) % mr])
        side = cross(sub(w, u), nref)
        ls = math.sqrt(dot(side, side))
        if ls == 0.0:
            continue
        side = scale(side, 1.0 / ls)
        count = clip_polygon(poly, labels, src, count, side, dot(side, u) + slop, SIDE_LABEL + k)
        src = 1 - src
        if count == 0:
            return n
    heights, chosen, kept = reduce_on_plane(poly[src], count, nref, pr[face, 3], prediction, MOST_CONTACTS)
    base = ((ref_is_b * 1024 + face) * 1024 + inc) * 512
    nab = nref if ref_is_b == 0 else scale(nref, -1.0)
    for k in range(kept):
        q = chosen[k]
        x = (poly[src, q, 0], poly[src, q, 1], poly[src, q, 2])
        height = heights[q]
        p_on_a = madd(x, -height, nref) if ref_is_b == 0 else x
        feature = (base + labels[src, q, 0]) * 512 + labels[src, q, 1]
        n = add_contact(out_f, out_i, n, p_on_a, nab, -height, feature)
    return n


@njit
def collide_polytopes(va, pa, sa, la, ea, size_a, vb, pb, sb, lb, eb, size_b, prediction, out_f, out_i, n):
    """Contact manifold of placed polytopes A and B (``polytope``; ``size_*`` their inner radii, m): up to
    ``MOST_CONTACTS`` points, normals from A to B, appended from row ``n``; returns the new count."""
    sep_a, face_a = best_face(pa, vb, prediction)
    if sep_a > prediction:
        return n
    sep_b, face_b = best_face(pb, va, prediction)
    if sep_b > prediction:
        return n
    sep_e, edge_a, edge_b, axis = _best_edge_pair(va, pa, ea, vb, pb, eb, prediction)
    if sep_e > prediction:
        return n
    size = min(size_a, size_b)
    bias = FACE_BIAS * size
    use_b = sep_b > sep_a + bias or sep_a <= 0.0 < sep_b
    sep_face = sep_b if use_b else sep_a
    if edge_a >= 0 and (sep_e > sep_face + bias or sep_face <= 0.0 < sep_e):
        p, d = edge_segment(va, ea, edge_a)
        q, e = edge_segment(vb, eb, edge_b)
        s, _ = closest_segment_params(p, d, q, e)
        return add_contact(out_f, out_i, n, madd(p, s, d), axis, -sep_e,
                           EDGE_FEATURES + edge_a * 4096 + edge_b)
    slop = CLIP_SLOP * size
    if use_b:
        return _face_contact(vb, pb, sb, lb, face_b, va, pa, sa, la, 1, slop, prediction, out_f, out_i, n)
    return _face_contact(va, pa, sa, la, face_a, vb, pb, sb, lb, 0, slop, prediction, out_f, out_i, n)
