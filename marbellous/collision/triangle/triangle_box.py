"""Box against one triangle by the separating-axis test (13 axes), with a clipped contact manifold.

Axes, each ``L`` unit length: the triangle's normal ``n``, the box's three face normals ``u_k``,
and the nine edge-edge axes ``u_k x e_j``.  On an axis the box projects to
``L.c +- sum_i h_i |u_i.L|`` and the triangle to ``[min, max]`` of its vertices.  The triangle is
one-sided, so its overlap on an axis is measured in the direction that pushes the box to the
triangle's front (both directions for axes in the triangle's plane).  Any axis with a gap
larger than ``prediction`` separates them.  The axis of least overlap wins, with a bias
(``tolerances.FACE_BIAS``) towards the triangle's face and then the box's faces, so a resting box
keeps its reference face.

Internal edges: an axis other than the face normal is only true if it lies in the triangle's
normal cone on the whole surface, i.e. does not point into any neighbour across an edge
(``L.m2_j <= 0`` for the neighbour directions ``m2_j`` of ``triangle_contact``).  Otherwise the
triangle's face normal is used instead, so boxes slide over flat seams without catching.

Contacts: for the triangle's face, the box face most opposed to ``n`` clipped by the triangle's
three side planes; for a box face, the triangle clipped by that face's four side planes (both
Sutherland-Hodgman), keeping points within ``prediction`` of the reference plane; for an edge pair
the closest points of the two edges.
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..pairs.segment import closest_segment_params
from ..tolerances import CROSS_AXIS_MIN, FACE_BIAS
from ..vec3 import column, cross, dot, madd, scale, sub
from .triangle_contact import GHOST_ROUNDING, write_row

#: An axis with ``|L.n|`` below this lies in the triangle's plane: both directions push the box
#: off the triangle sideways.
_IN_PLANE = 1e-9
#: Feature codes of box contacts: clipped polygon vertex ``i`` is ``CLIP_FIRST + i``; edge pair.
CLIP_FIRST = 8
EDGE_PAIR = 15


@njit
def _project_box(c, u, h, axis):
    """Centre ``axis.c`` and radius ``sum_i h_i |u_i.axis|`` of the box projected on ``axis``."""
    rb = h[0] * abs(dot(u[0], axis)) + h[1] * abs(dot(u[1], axis)) + h[2] * abs(dot(u[2], axis))
    return dot(axis, c), rb


@njit
def _axis_overlap(c, u, h, a, b, cc, n, axis):
    """Overlap of box and triangle on ``axis``: ``(gap test, overlap, L)``.

    The gap test is the smaller of the two ways to push them apart (< 0: separated on this axis).
    The overlap (m) is the smaller of the ways that push the box to the triangle's front
    (``L.n >= 0``, with ``L`` the direction from the triangle towards the box), as the triangle
    is one-sided.
    """
    cl, rb = _project_box(c, u, h, axis)
    pa, pb, pc = dot(axis, a), dot(axis, b), dot(axis, cc)
    tmin = min(pa, min(pb, pc))
    tmax = max(pa, max(pb, pc))
    low = tmax - (cl - rb)          # push the box along +axis
    high = (cl + rb) - tmin         # push the box along -axis
    an = dot(axis, n)
    if an > _IN_PLANE:
        return min(low, high), low, axis
    if an < -_IN_PLANE:
        return min(low, high), high, (-axis[0], -axis[1], -axis[2])
    if low <= high:
        return low, low, axis
    return high, high, (-axis[0], -axis[1], -axis[2])


@njit
def _clip(src, ns, dst, m, offset):
    """Sutherland-Hodgman: keep the part of polygon ``src[:ns]`` with ``m.X >= offset``."""
    nd = 0
    for i in range(ns):
        x = (src[i, 0], src[i, 1], src[i, 2])
        j = (i + 1) % ns
        y = (src[j, 0], src[j, 1], src[j, 2])
        fx = dot(m, x) - offset
        fy = dot(m, y) - offset
        if fx >= 0.0:
            dst[nd, 0], dst[nd, 1], dst[nd, 2] = x
            nd += 1
        if (fx >= 0.0) != (fy >= 0.0):
            z = madd(x, fx / (fx - fy), sub(y, x))
            dst[nd, 0], dst[nd, 1], dst[nd, 2] = z
            nd += 1
    return nd


@njit
def box_triangle(c, rot, h, a, b, cc, n, m2ab, m2bc, m2ca, prediction, scratch):
    """Contacts of the box (centre ``c``, rotation ``rot`` (3, 3), half extents ``h``, m) with
    triangle ``a b cc`` (unit normal ``n``).

    Writes rows of ``scratch`` (layout in ``triangle_contact``) and returns their number.
    """
    u = (column(rot, 0), column(rot, 1), column(rot, 2))
    hs = (h[0], h[1], h[2])
    hmin = min(hs[0], min(hs[1], hs[2]))
    bias = FACE_BIAS * hmin
    cl, rb = _project_box(c, u, hs, n)
    height = cl - dot(n, a)
    if height < -rb:                     # the whole box is behind the one-sided face
        return 0
    face_depth = rb - height
    if face_depth < -prediction:
        return 0
    best = face_depth
    kind = 0                             # 0 triangle face, 1 box face, 2 edge pair
    best_l = n
    best_k = 0
    best_j = 0
    for k in range(3):
        gap, ov, l = _axis_overlap(c, u, hs, a, b, cc, n, u[k])
        if gap < -prediction:
            return 0
        if ov < best - bias:
            best, kind, best_l, best_k = ov, 1, l, k
    edges = (sub(b, a), sub(cc, b), sub(a, cc))
    for k in range(3):
        for j in range(3):
            e = edges[j]
            le = math.sqrt(dot(e, e))
            if le == 0.0:
                continue
            axis = cross(u[k], scale(e, 1.0 / le))
            la = math.sqrt(dot(axis, axis))
            if la < CROSS_AXIS_MIN:
                continue
            gap, ov, l = _axis_overlap(c, u, hs, a, b, cc, n, scale(axis, 1.0 / la))
            if gap < -prediction:
                return 0
            if ov < best - 2.0 * bias:
                best, kind, best_l, best_k, best_j = ov, 2, l, k, j
    if kind != 0 and (dot(best_l, m2ab) > GHOST_ROUNDING or dot(best_l, m2bc) > GHOST_ROUNDING
                      or dot(best_l, m2ca) > GHOST_ROUNDING):
        kind, best, best_l = 0, face_depth, n     # not in the surface's normal cone: a ghost axis
    normal = (-best_l[0], -best_l[1], -best_l[2])
    if kind == 2:
        k, j = best_k, best_j
        corner = c
        for i in range(3):
            if i != k:
                corner = madd(corner, hs[i] if dot(u[i], normal) >= 0.0 else -hs[i], u[i])
        p0 = madd(corner, -hs[k], u[k])
        d = scale(u[k], 2.0 * hs[k])
        v = (a, b, cc)[j]
        s, t = closest_segment_params(p0, d, v, edges[j])
        return write_row(scratch, 0, madd(v, t, edges[j]), normal, best, EDGE_PAIR, madd(p0, s, d))
    poly = np.empty((2, 8, 3))
    if kind == 0:
        k = 0
        for i in range(1, 3):
            if abs(dot(u[i], n)) > abs(dot(u[k], n)):
                k = i
        f = scale(u[k], -1.0 if dot(u[k], n) > 0.0 else 1.0)    # box face turned towards -n
        i1, i2 = (k + 1) % 3, (k + 2) % 3
        fc = madd(c, hs[k], f)
        signs = ((1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0))
        for q in range(4):
            x = madd(madd(fc, signs[q][0] * hs[i1], u[i1]), signs[q][1] * hs[i2], u[i2])
            poly[0, q, 0], poly[0, q, 1], poly[0, q, 2] = x
        m = 4
        src = 0
        for j in range(3):
            v = (a, b, cc)[j]
            side = cross(n, edges[j])
            m = _clip(poly[src], m, poly[1 - src], side, dot(side, v))
            src = 1 - src
        plane = dot(n, a)
        count = 0
        for q in range(m):
            x = (poly[src, q, 0], poly[src, q, 1], poly[src, q, 2])
            depth = plane - dot(n, x)
            if depth >= -prediction and count < scratch.shape[0]:
                count = write_row(scratch, count, madd(x, depth, n), normal, depth, CLIP_FIRST + q, x)
        return count
    k = best_k
    f = normal                                   # the box's reference face, pointing at the triangle
    for q in range(3):
        poly[0, q, 0], poly[0, q, 1], poly[0, q, 2] = (a, b, cc)[q]
    m = 3
    src = 0
    for i in range(3):
        if i == k:
            continue
        ci = dot(u[i], c)
        m = _clip(poly[src], m, poly[1 - src], u[i], ci - hs[i])
        src = 1 - src
        m = _clip(poly[src], m, poly[1 - src], scale(u[i], -1.0), -ci - hs[i])
        src = 1 - src
    plane = dot(f, c) + hs[k]
    count = 0
    for q in range(m):
        x = (poly[src, q, 0], poly[src, q, 1], poly[src, q, 2])
        depth = plane - dot(f, x)
        if depth >= -prediction and count < scratch.shape[0]:
            count = write_row(scratch, count, x, normal, depth, CLIP_FIRST + q, x)
    return count
