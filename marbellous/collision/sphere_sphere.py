"""Sphere-sphere contact: the separating axis is the line through the two centres.

``depth = r_a + r_b - |c_b - c_a|``, ``normal = (c_b - c_a) / |c_b - c_a|`` (a fixed fallback when the
centres coincide), contact point midway between the surfaces along the normal.
"""
from .._jit import njit
from .contact_output import add_contact
from .vec3 import length, load, madd, scale, sub


@njit
def ball_ball_contact(ca, ra, offset, rb, fallback, prediction, feature, out_f, out_i, n):
    """Append the contact of the ball ``(ca, ra)`` with a ball of radius ``rb`` at ``ca + offset``.

    3-tuples in m.  Also serves the pairs whose closest features reduce to two points with radii
    (sphere and capsule axis points).  ``fallback`` is the unit normal used when the centres
    coincide (within ``1e-12 (r_a + r_b)``).  Nothing is added when the gap exceeds ``prediction``.
    """
    dist = length(offset)
    depth = ra + rb - dist
    if depth < -prediction:
        return n
    if dist > 1e-12 * (ra + rb):
        normal = scale(offset, 1.0 / dist)
    else:
        normal = fallback
    return add_contact(out_f, out_i, n, madd(ca, ra, normal), normal, depth, feature)


@njit
def collide_sphere_sphere(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of sphere a (params ``[radius]``) and sphere b; at most one point, feature id 0.

    Coincident centres push b along world +y.
    """
    ca = load(pos_a)
    return ball_ball_contact(ca, params_a[0], sub(load(pos_b), ca), params_b[0], (0.0, 1.0, 0.0),
                             prediction, 0, out_f, out_i, n)
