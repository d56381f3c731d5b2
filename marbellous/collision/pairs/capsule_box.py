"""Capsule-box contact: the capsule's axis segment against the box, widened by the radius.

Everything runs in the box frame, where the box is ``|x_k| <= h_k``.  The capsule is the segment
``p0 + s d`` (``s`` in [0, 1]) swept by a ball of radius ``r``, so:

- If the segment misses the box, the gap is ``|x_b - x_s| - r`` for the closest points ``x_s`` of
  the segment and ``x_b`` of the box; they lie on a segment end against the box (clamping) or on the
  segment against one of the 12 box edges.  The normal runs from ``x_s`` to ``x_b``.
- If the segment meets the box, the separating-axis test over the 3 face normals and the 3 axes
  ``u x e_k`` gives the least overlap ``o`` (exact for a segment and a box), and ``depth = r + o``.

When the least overlap is along a box face normal, or (apart) the closest points are within
``PARALLEL_SIN`` of a face normal with the axis parallel to that face, the points come from that
face: the segment clipped to the face's rectangle, ``depth = r - (height of the point above the
face)``; both ends of the clipped part when the axis lies parallel to the face, else the deeper end.
Otherwise one point from the closest features.

Feature ids: face points ``1 + 2 * face + end`` (face ``2 k + (0 if +e_k else 1)``, end 0 towards
the capsule's -y end), edge points ``16 + 4 k + code``, any other single point 0.
"""
import math

from ..._numba.jit import njit
from ..tolerances import CROSS_AXIS_MIN, FACE_BIAS, PARALLEL_SIN
from ..vec3 import column, cross, dot, length, load, madd, scale, sub, to_local, to_world
from .contact_output import add_contact
from .segment import closest_segment_params


@njit
def _clip_to_slabs(p0, d, h, skip):
    """Parameter range ``(s0, s1)`` of the segment inside ``|x_k| <= h_k`` for every ``k != skip``.

    Liang-Barsky clipping; ``s0 > s1`` when the segment misses.
    """
    s0 = 0.0
    s1 = 1.0
    for k in range(3):
        if k == skip:
            continue
        if abs(d[k]) < 1e-300:
            if abs(p0[k]) > h[k]:
                return 1.0, 0.0
            continue
        ta = (-h[k] - p0[k]) / d[k]
        tb = (h[k] - p0[k]) / d[k]
        if ta > tb:
            ta, tb = tb, ta
        s0 = max(s0, ta)
        s1 = min(s1, tb)
    return s0, s1


@njit
def _box_point_to_world(pos_b, rot_b, x):
    """World point of the box-frame point ``x``: ``p_b + R_b x``."""
    w = to_world(rot_b, x)
    return (pos_b[0] + w[0], pos_b[1] + w[1], pos_b[2] + w[2])


@njit
def _box_edge(h, k, code):
    """Start point and direction (box frame) of the box edge along ``e_k`` with corner signs ``code``.

    Bit 0 of ``code`` is the sign of the ``(k + 1) % 3`` coordinate, bit 1 that of ``(k + 2) % 3``.
    """
    j = (k + 1) % 3
    m = (k + 2) % 3
    sj = h[j] if code & 1 else -h[j]
    sm = h[m] if code & 2 else -h[m]
    e0 = (-h[0] if k == 0 else (sj if j == 0 else sm),
          -h[1] if k == 1 else (sj if j == 1 else sm),
          -h[2] if k == 2 else (sj if j == 2 else sm))
    ed = (2.0 * h[0] if k == 0 else 0.0, 2.0 * h[1] if k == 1 else 0.0, 2.0 * h[2] if k == 2 else 0.0)
    return e0, ed


@njit
def _face_points(pos_b, rot_b, p0, d, u, r, h, k, sgn, prediction, out_f, out_i, n):
    """Contacts of the capsule against box face ``sgn * e_k``; returns -1 if the axis misses the face.

    The segment is clipped to the face's rectangle; depth of a point x is ``r - (sgn x_k - h_k)``.
    """
    s0, s1 = _clip_to_slabs(p0, d, h, k)
    if s0 > s1:
        return -1
    face = 2 * k + (0 if sgn > 0.0 else 1)
    normal = to_world(rot_b, (-sgn if k == 0 else 0.0, -sgn if k == 1 else 0.0, -sgn if k == 2 else 0.0))
    depth0 = r - (sgn * (p0[k] + s0 * d[k]) - h[k])
    depth1 = r - (sgn * (p0[k] + s1 * d[k]) - h[k])
    both = abs(u[k]) < PARALLEL_SIN and (s1 - s0) * length(d) > 1e-3 * r
    for end in range(2):
        depth = depth0 if end == 0 else depth1
        if not both and ((end == 0 and depth0 < depth1) or (end == 1 and depth1 <= depth0)):
            continue
        if depth < -prediction:
            continue
        x = madd(p0, s0 if end == 0 else s1, d)
        p_on_a = madd(_box_point_to_world(pos_b, rot_b, x), r, normal)
        n = add_contact(out_f, out_i, n, p_on_a, normal, depth, 1 + 2 * face + end)
    return n


@njit
def collide_capsule_box(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of capsule a (``[radius, half_height]``) and box b (``[hx, hy, hz]``): 1 or 2 points."""
    r, hh = params_a[0], params_a[1]
    h = (params_b[0], params_b[1], params_b[2])
    c = to_local(rot_b, sub(load(pos_a), load(pos_b)))
    u = to_local(rot_b, column(rot_a, 1))
    p0 = madd(c, -hh, u)
    d = scale(u, 2.0 * hh)
    s0, s1 = _clip_to_slabs(p0, d, h, -1)
    if s0 > s1:
        # separated segment: closest points over the segment ends and the 12 box edges
        best = math.inf
        xs = p0
        xb = p0
        feature = 0
        for end in range(2):
            p = madd(p0, float(end), d)
            q = (min(max(p[0], -h[0]), h[0]), min(max(p[1], -h[1]), h[1]), min(max(p[2], -h[2]), h[2]))
            g = sub(q, p)
            dist2 = dot(g, g)
            if dist2 < best:
                best = dist2
                xs = p
                xb = q
                feature = 0
        for k in range(3):
            for code in range(4):
                e0, ed = _box_edge(h, k, code)
                s, t = closest_segment_params(p0, d, e0, ed)
                p = madd(p0, s, d)
                q = madd(e0, t, ed)
                g = sub(q, p)
                dist2 = dot(g, g)
                if dist2 < best:
                    best = dist2
                    xs = p
                    xb = q
                    feature = 16 + 4 * k + code
        dist = math.sqrt(best)
        if r - dist < -prediction:
            return n
        if dist > 0.0:
            nl = scale(sub(xb, xs), 1.0 / dist)
            k = 0
            for m in range(1, 3):
                if abs(nl[m]) > abs(nl[k]):
                    k = m
            if nl[k] * nl[k] > 1.0 - PARALLEL_SIN * PARALLEL_SIN and abs(u[k]) < PARALLEL_SIN:
                done = _face_points(pos_b, rot_b, p0, d, u, r, h, k, -1.0 if nl[k] > 0.0 else 1.0,
                                    prediction, out_f, out_i, n)
                if done >= 0:
                    return done
            normal = to_world(rot_b, nl)
            p_on_a = madd(_box_point_to_world(pos_b, rot_b, xs), r, normal)
            return add_contact(out_f, out_i, n, p_on_a, normal, r - dist, feature)
        # dist == 0: the segment grazes the box (a rounding-level miss); measure it as meeting
    # the segment meets the box: least overlap over the face axes and the axes u x e_k
    best_face = math.inf
    face_k = 0
    for k in range(3):
        overlap = h[k] + hh * abs(u[k]) - abs(c[k])
        if overlap < best_face:
            best_face = overlap
            face_k = k
    best_cross = math.inf
    cross_k = -1
    cross_axis = (0.0, 0.0, 0.0)
    for k in range(3):
        ek = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
        axis = cross(u, ek)
        la = length(axis)
        if la < CROSS_AXIS_MIN:
            continue
        axis = scale(axis, 1.0 / la)
        overlap = h[0] * abs(axis[0]) + h[1] * abs(axis[1]) + h[2] * abs(axis[2]) - abs(dot(c, axis))
        if overlap < best_cross:
            best_cross = overlap
            cross_k = k
            cross_axis = axis
    size = min(min(h[0], h[1]), min(h[2], r))
    if cross_k < 0 or best_cross >= best_face - FACE_BIAS * size:
        sgn = 1.0 if c[face_k] >= 0.0 else -1.0
        return _face_points(pos_b, rot_b, p0, d, u, r, h, face_k, sgn, prediction, out_f, out_i, n)
    # edge of the box along e_k that supports it towards the capsule, against the segment
    nl = cross_axis if dot(c, cross_axis) < 0.0 else scale(cross_axis, -1.0)
    k = cross_k
    code = (1 if nl[(k + 1) % 3] <= 0.0 else 0) | (2 if nl[(k + 2) % 3] <= 0.0 else 0)
    e0, ed = _box_edge(h, k, code)
    s, _ = closest_segment_params(p0, d, e0, ed)
    normal = to_world(rot_b, nl)
    p_on_a = madd(_box_point_to_world(pos_b, rot_b, madd(p0, s, d)), r, normal)
    return add_contact(out_f, out_i, n, p_on_a, normal, r + best_cross, 16 + 4 * k + code)
