"""Sphere-capsule contact: the sphere against the closest point of the capsule's axis segment.

A capsule is the set of points within ``radius`` of its segment ``c + y u`` (``|y| <= half_height``),
so the pair reduces to two balls: the sphere and a ball of the capsule's radius at the closest
axis point.  With ``v = c_sphere - c`` and ``y = v.u``: beyond an end (``|y| > half_height``) that
point is the end; otherwise the sphere's centre is ``w = v - y u`` away from the axis, across it.
"""
from ..._numba.jit import njit
from ..vec3 import any_perpendicular, column, dot, load, madd, scale, sub
from .contact_output import add_contact
from .sphere_sphere import ball_ball


@njit
def sphere_capsule(ca, ra, cb, u, rb, hh, prediction):
    """Contact of the sphere ``(ca, ra)`` with the capsule at ``cb`` with unit axis ``u`` (3-tuples),
    radius ``rb`` and half height ``hh`` (m), as values ``(hit, p_on_a, normal, depth)``.

    A centre on the axis leaves across it (a fixed direction perpendicular to the axis).
    """
    v = sub(ca, cb)
    y = dot(v, u)
    if y > hh or y < -hh:
        offset = sub(madd(cb, hh if y > 0.0 else -hh, u), ca)
    else:
        offset = scale(madd(v, -y, u), -1.0)
    return ball_ball(ca, ra, offset, rb, any_perpendicular(u), prediction)


@njit
def collide_sphere_capsule(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of sphere a (``[radius]``) and capsule b (``[radius, half_height]``); one point, id 0.

    A centre on the axis leaves across it (a fixed direction perpendicular to the axis).
    """
    hit, p, normal, depth = sphere_capsule(load(pos_a), params_a[0], load(pos_b), column(rot_b, 1), params_b[0],
                                           params_b[1], prediction)
    return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n
