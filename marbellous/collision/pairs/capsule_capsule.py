"""Capsule-capsule contact: closest points of the two axis segments, widened by the radii.

With ``s, t`` the parameters of the closest points ``x_a, x_b`` of the segments,
``depth = r_a + r_b - |x_b - x_a|`` along ``normal = (x_b - x_a) / |x_b - x_a|``.  When the axes are
parallel (``|u_a x u_b| < PARALLEL_SIN``) and their projections overlap, the manifold has two points,
at the ends of the overlap on a's axis, each paired with the closest point of b's segment (its own
normal and depth from that pair: exactly the common ones when the axes are parallel).  Coincident or
crossing axes fall back to ``u_a x u_b`` or to a direction perpendicular to a's axis, oriented from a's
centre towards b's.
"""
from ..._numba.jit import njit
from ..tolerances import PARALLEL_SIN
from ..vec3 import any_perpendicular, column, cross, dot, length, load, madd, scale, sub
from .contact_output import add_contact
from .segment import closest_on_segment, closest_segment_params


@njit
def _touching_normal(ua, ub, ca, cb):
    """Unit normal for axes that meet: ``u_a x u_b``, else the part of ``c_b - c_a`` across ``u_a``."""
    c = cross(ua, ub)
    lc = length(c)
    if lc > 1e-9:
        if dot(c, sub(cb, ca)) < 0.0:
            lc = -lc
        return scale(c, 1.0 / lc)
    off = sub(cb, ca)
    across = madd(off, -dot(off, ua), ua)
    la = length(across)
    if la > 1e-12 * (1.0 + length(off)):
        return scale(across, 1.0 / la)
    return any_perpendicular(ua)


@njit
def collide_capsule_capsule(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of capsules a and b (``[radius, half_height]``, axis local y).

    One point (feature id 0), or two for parallel overlapping axes (ids 1 and 2: the ends of the
    overlap towards ``-y`` and ``+y`` of a).
    """
    ra, ha = params_a[0], params_a[1]
    rb, hb = params_b[0], params_b[1]
    ca, cb = load(pos_a), load(pos_b)
    ua, ub = column(rot_a, 1), column(rot_b, 1)
    a0 = madd(ca, -ha, ua)
    da = scale(ua, 2.0 * ha)
    b0 = madd(cb, -hb, ub)
    db = scale(ub, 2.0 * hb)
    s, t = closest_segment_params(a0, da, b0, db)
    xa = madd(a0, s, da)
    xb = madd(b0, t, db)
    d = sub(xb, xa)
    dist = length(d)
    if ra + rb - dist < -prediction:
        return n
    if dist > 1e-12 * (ra + rb):
        normal = scale(d, 1.0 / dist)
    else:
        normal = _touching_normal(ua, ub, ca, cb)
    c = cross(ua, ub)
    if dot(c, c) < PARALLEL_SIN * PARALLEL_SIN:
        # overlap of b's segment projected on a's axis, in a's axial coordinate
        sb0 = dot(sub(b0, ca), ua)
        sb1 = sb0 + 2.0 * hb * dot(ub, ua)
        lo = max(-ha, min(sb0, sb1))
        hi = min(ha, max(sb0, sb1))
        if hi - lo > 1e-3 * (ra + rb):
            for k in range(2):
                x = madd(ca, lo if k == 0 else hi, ua)
                y = madd(b0, closest_on_segment(b0, db, x), db)
                g = sub(y, x)
                gap = length(g)
                nk = scale(g, 1.0 / gap) if gap > 1e-12 * (ra + rb) else normal
                if ra + rb - gap >= -prediction:
                    n = add_contact(out_f, out_i, n, madd(x, ra, nk), nk, ra + rb - gap, 1 + k)
            return n
    return add_contact(out_f, out_i, n, madd(xa, ra, normal), normal, ra + rb - dist, 0)
