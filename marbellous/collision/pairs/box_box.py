"""Box-box contact: the separating-axis test over 15 axes, then face clipping or edge-edge points.

Axes: the 3 face normals of each box and the 9 cross products of their edge directions.  Along a
unit axis ``L`` the boxes (centres ``p_a``, ``p_b``, axes ``u_i``, half extents ``h_i``) are
separated by

    sep(L) = |(p_b - p_a) . L| - sum_i h_a,i |u_a,i . L| - sum_i h_b,i |u_b,i . L|

and the overlap is least along the axis of largest ``sep``.  A face axis is preferred unless another
axis beats it by ``FACE_BIAS`` times the smallest half extent (stable reference faces for stacks),
or separates the boxes while the face does not (so apart boxes never report an overlap).

- Face axis: the face of the reference box facing the other box is the reference face; the face
  of the other box most opposed to it (the incident face) is clipped against the reference face's
  four side planes (Sutherland-Hodgman).  Every clipped point below the reference plane (or within
  ``prediction`` above it) is a contact with ``depth = -height above the reference plane``; more
  than four are reduced to four: the deepest, the one farthest from it, the one spanning the largest
  triangle with those two, and the one adding the most area outside that triangle.
- Edge axis: the two edges supporting the boxes along the axis give one point from their closest
  points, with the separating-axis depth.

Feature ids: for face contacts ``((ref_is_b * 6 + ref_face) * 6 + incident_face) * 64 + 8 * e_in + e_out``
where faces are ``2 axis + (0 if positive else 1)`` and a clipped point is named by the two polygon
edges meeting at it (incident-face edges 0-3, reference side planes 4-7); for the edge contact
``4608 + ((i * 3 + j) * 4 + edge_a) * 4 + edge_b``.
"""
import numpy as np

from ..._numba.jit import njit
from ..tolerances import CLIP_SLOP, CROSS_AXIS_MIN, FACE_BIAS
from ..vec3 import column, cross, dot, length, load, madd, scale, sub
from .contact_output import add_contact
from .manifold import clip_polygon, reduce_to_four
from .segment import closest_segment_params

_EDGE_ID_BASE = 4608


@njit
def _radius(rot, h, axis):
    """Half length of the box's projection on the unit ``axis``: ``sum_i h_i |u_i . axis|``."""
    return (h[0] * abs(dot(column(rot, 0), axis)) + h[1] * abs(dot(column(rot, 1), axis))
            + h[2] * abs(dot(column(rot, 2), axis)))


@njit
def _dominant_sign(v):
    """The sign (1.0 or -1.0) of the component of ``v`` of largest magnitude (the first of equals; 1.0 for
    the zero vector): unlike the first non-zero component, rounding-sized components cannot change it."""
    x = v[0]
    if abs(v[1]) > abs(x):
        x = v[1]
    if abs(v[2]) > abs(x):
        x = v[2]
    return 1.0 if x >= 0.0 else -1.0


@njit
def _side(d, axis):
    """The sign (1.0 or -1.0) that turns ``axis`` towards ``d`` (the centre offset from the reference box to
    the other).  When ``d`` is square to the axis, to rounding (``|d . axis| <= 1e-12 |d|``), the overlap is
    the same either way: the normal ``side * axis`` then takes the direction whose dominant component has
    the sign of ``d``'s dominant component, a choice that does not depend on which way the axis points
    and that flips when the boxes swap (negating ``d``), as the normal must."""
    t = dot(d, axis)
    if abs(t) <= 1e-12 * length(d):
        return _dominant_sign(d) * _dominant_sign(axis)
    return 1.0 if t > 0.0 else -1.0


@njit
def _clip_incident_face(ref_h, axis, slop, poly, labels):
    """Clip the incident quad ``poly[0, :4]`` against the reference face's side planes.

    ``poly[b, v] = (u_1, u_2, height)`` in the reference face frame, ``labels[b, v] = (edge in,
    edge out)``; side plane ``p`` (labelled ``4 + p``) is ``+-u_1 <= h_j + slop`` or ``+-u_2 <= h_k + slop``.
    Returns ``(buffer, count)`` of the clipped polygon.
    """
    j = (axis + 1) % 3
    k = (axis + 2) % 3
    src = 0
    count = 4
    for plane in range(4):
        coord = plane >> 1
        sgn = 1.0 - 2.0 * (plane & 1)
        lim = (ref_h[j] if coord == 0 else ref_h[k]) + slop
        side = (sgn, 0.0, 0.0) if coord == 0 else (0.0, sgn, 0.0)
        count = clip_polygon(poly, labels, src, count, side, lim, 4 + plane)
        src = 1 - src
        if count == 0:
            break
    return src, count


@njit
def _face_contact(pos_r, rot_r, h_r, axis, pos_i, rot_i, h_i, ref_is_b, slop, prediction,
                  out_f, out_i, n):
    """Points of the reference face ``axis`` of box r (facing box i) clipped with i's incident face."""
    cr = load(pos_r)
    ci = load(pos_i)
    ar = column(rot_r, axis)
    s = _side(sub(ci, cr), ar)
    nref = scale(ar, s)
    uj = column(rot_r, (axis + 1) % 3)
    uk = column(rot_r, (axis + 2) % 3)
    fc = madd(cr, s * h_r[axis], ar)
    # incident face: the face of box i whose normal is most opposed to nref
    inc = 0
    best = dot(column(rot_i, 0), nref)
    for m in range(1, 3):
        dm = dot(column(rot_i, m), nref)
        if abs(dm) > abs(best):
            best = dm
            inc = m
    si = -1.0 if best > 0.0 else 1.0
    bu = column(rot_i, inc)
    bv = column(rot_i, (inc + 1) % 3)
    bw = column(rot_i, (inc + 2) % 3)
    ic = madd(ci, si * h_i[inc], bu)
    hv = h_i[(inc + 1) % 3]
    hw = h_i[(inc + 2) % 3]
    poly = np.empty((2, 8, 3))
    # one integer scratch array: polygon edge labels (2 x 8 x 2), kept points (8), chosen (4)
    scratch = np.empty(44, np.int64)
    labels = scratch[:32].reshape((2, 8, 2))
    keep = scratch[32:40]
    chosen = scratch[40:44]
    for v in range(4):
        sv = 1.0 if v == 0 or v == 3 else -1.0
        sw = 1.0 if v < 2 else -1.0
        x = sub(madd(madd(ic, sv * hv, bv), sw * hw, bw), fc)
        poly[0, v, 0] = dot(x, uj)
        poly[0, v, 1] = dot(x, uk)
        poly[0, v, 2] = dot(x, nref)
        labels[0, v, 0] = (v + 3) % 4
        labels[0, v, 1] = v
    buf, count = _clip_incident_face(h_r, axis, slop, poly, labels)
    pts = poly[buf]
    m = 0
    for q in range(count):
        if -pts[q, 2] >= -prediction:
            keep[m] = q
            m += 1
    m = reduce_to_four(pts, keep, m, chosen)
    face_r = 2 * axis + (0 if s > 0.0 else 1)
    face_i = 2 * inc + (0 if si > 0.0 else 1)
    base = ((ref_is_b * 6 + face_r) * 6 + face_i) * 64
    normal = nref if ref_is_b == 0 else scale(nref, -1.0)
    for q in range(m):
        v = chosen[q]
        on_ref = madd(madd(fc, pts[v, 0], uj), pts[v, 1], uk)
        depth = -pts[v, 2]
        p_on_a = on_ref if ref_is_b == 0 else madd(on_ref, pts[v, 2], nref)
        feature = base + 8 * labels[buf, v, 0] + labels[buf, v, 1]
        n = add_contact(out_f, out_i, n, p_on_a, normal, depth, feature)
    return n


@njit
def _edge_contact(pos_a, rot_a, ha, i, pos_b, rot_b, hb, j, axis, sep, out_f, out_i, n):
    """One point from the closest points of a's edge along ``u_a,i`` and b's along ``u_b,j``.

    ``axis`` is the unit normal from a to b; each edge is the one supporting its box along it.
    """
    ea = load(pos_a)
    code_a = 0
    for q in range(2):
        k = (i + 1 + q) % 3
        uk = column(rot_a, k)
        sk = 1.0 if dot(uk, axis) >= 0.0 else -1.0
        if sk > 0.0:
            code_a |= 1 << q
        ea = madd(ea, sk * ha[k], uk)
    eb = load(pos_b)
    code_b = 0
    for q in range(2):
        k = (j + 1 + q) % 3
        uk = column(rot_b, k)
        sk = 1.0 if dot(uk, axis) <= 0.0 else -1.0
        if sk > 0.0:
            code_b |= 1 << q
        eb = madd(eb, sk * hb[k], uk)
    ua = column(rot_a, i)
    ub = column(rot_b, j)
    a0 = madd(ea, -ha[i], ua)
    b0 = madd(eb, -hb[j], ub)
    s, _ = closest_segment_params(a0, scale(ua, 2.0 * ha[i]), b0, scale(ub, 2.0 * hb[j]))
    p_on_a = madd(a0, 2.0 * ha[i] * s, ua)
    feature = _EDGE_ID_BASE + ((i * 3 + j) * 4 + code_a) * 4 + code_b
    return add_contact(out_f, out_i, n, p_on_a, axis, -sep, feature)


@njit
def collide_box_box(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact manifold of box a and box b (``[hx, hy, hz]``): up to 4 points (see module doc)."""
    ha = (params_a[0], params_a[1], params_a[2])
    hb = (params_b[0], params_b[1], params_b[2])
    t = sub(load(pos_b), load(pos_a))
    best_a = -np.inf
    face_a = 0
    for i in range(3):
        ui = column(rot_a, i)
        sep = abs(dot(t, ui)) - ha[i] - _radius(rot_b, hb, ui)
        if sep > prediction:
            return n
        if sep > best_a:
            best_a = sep
            face_a = i
    best_b = -np.inf
    face_b = 0
    for j in range(3):
        uj = column(rot_b, j)
        sep = abs(dot(t, uj)) - hb[j] - _radius(rot_a, ha, uj)
        if sep > prediction:
            return n
        if sep > best_b:
            best_b = sep
            face_b = j
    best_e = -np.inf
    edge_i = -1
    edge_j = -1
    edge_axis = (0.0, 0.0, 0.0)
    for i in range(3):
        ui = column(rot_a, i)
        for j in range(3):
            axis = cross(ui, column(rot_b, j))
            la = length(axis)
            if la < CROSS_AXIS_MIN:
                continue
            axis = scale(axis, 1.0 / la)
            tl = dot(t, axis)
            sep = abs(tl) - _radius(rot_a, ha, axis) - _radius(rot_b, hb, axis)
            if sep > prediction:
                return n
            if sep > best_e:
                best_e = sep
                edge_i = i
                edge_j = j
                edge_axis = scale(axis, _side(t, axis))
    size = min(min(ha[0], ha[1]), min(ha[2], min(min(hb[0], hb[1]), hb[2])))
    bias = FACE_BIAS * size
    use_b = best_b > best_a + bias or best_a <= 0.0 < best_b
    best_face = best_b if use_b else best_a
    if edge_i >= 0 and (best_e > best_face + bias or best_face <= 0.0 < best_e):
        return _edge_contact(pos_a, rot_a, ha, edge_i, pos_b, rot_b, hb, edge_j, edge_axis, best_e,
                             out_f, out_i, n)
    slop = CLIP_SLOP * size
    if use_b:
        return _face_contact(pos_b, rot_b, hb, face_b, pos_a, rot_a, ha, 1, slop, prediction,
                             out_f, out_i, n)
    return _face_contact(pos_a, rot_a, ha, face_a, pos_b, rot_b, hb, 0, slop, prediction,
                         out_f, out_i, n)
