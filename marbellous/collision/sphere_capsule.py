"""Sphere-capsule contact: the sphere against the closest point of the capsule's axis segment.

A capsule is the set of points within ``radius`` of its segment ``c + y u`` (``|y| <= half_height``),
so the pair reduces to two balls: the sphere and a ball of the capsule's radius at the closest
axis point.  With ``v = c_sphere - c`` and ``y = v.u``: beyond an end (``|y| > half_height``) that
point is the end; otherwise the sphere's centre is ``w = v - y u`` away from the axis, across it.
"""
from .._jit import njit
from .sphere_sphere import ball_ball_contact
from .vec3 import any_perpendicular, column, dot, load, madd, scale, sub


@njit
def collide_sphere_capsule(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of sphere a (``[radius]``) and capsule b (``[radius, half_height]``); one point, id 0.

    A centre on the axis leaves across it (a fixed direction perpendicular to the axis).
    """
    ca = load(pos_a)
    cb = load(pos_b)
    hh = params_b[1]
    u = column(rot_b, 1)
    v = sub(ca, cb)
    y = dot(v, u)
    if y > hh or y < -hh:
        offset = sub(madd(cb, hh if y > 0.0 else -hh, u), ca)
    else:
        offset = scale(madd(v, -y, u), -1.0)
    return ball_ball_contact(ca, params_a[0], offset, params_b[0], any_perpendicular(u), prediction, 0,
                             out_f, out_i, n)
