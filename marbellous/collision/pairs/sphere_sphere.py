"""Sphere-sphere contact: the separating axis is the line through the two centres.

``depth = r_a + r_b - |c_b - c_a|``, ``normal = (c_b - c_a) / |c_b - c_a|`` (a fixed fallback when the
centres coincide), contact point midway between the surfaces along the normal.
"""
from ..._numba.jit import njit
from ..vec3 import length, load, madd, scale, sub
from .contact_output import add_contact


@njit
def ball_ball(ca, ra, offset, rb, fallback, prediction):
    """The contact of the ball ``(ca, ra)`` with a ball of radius ``rb`` at ``ca + offset``, as values.

    3-tuples in m.  Also serves the pairs whose closest features reduce to two points with radii
    (sphere and capsule axis points).  ``fallback`` is the unit normal used when the centres
    coincide (within ``1e-12 (r_a + r_b)``).  Returns ``(hit, p_on_a, normal, depth)``: ``hit`` is
    False when the gap exceeds ``prediction``; ``p_on_a`` is a's deepest point towards b.
    The value-returning pair tests take no array, so Numba counts no references (see
    ``collide_sphere_primitive``).
    """
    dist = length(offset)
    depth = ra + rb - dist
    if depth < -prediction:
        return False, ca, fallback, depth
    if dist > 1e-12 * (ra + rb):
        normal = scale(offset, 1.0 / dist)
    else:
        normal = fallback
    return True, madd(ca, ra, normal), normal, depth


@njit
def ball_ball_contact(ca, ra, offset, rb, fallback, prediction, feature, out_f, out_i, n):
    """``ball_ball`` appended to the contact buffer with ``feature``; returns the new count."""
    hit, p, normal, depth = ball_ball(ca, ra, offset, rb, fallback, prediction)
    return add_contact(out_f, out_i, n, p, normal, depth, feature) if hit else n


@njit
def sphere_sphere(ca, ra, cb, rb, prediction):
    """Contact of the sphere ``(ca, ra)`` with the sphere ``(cb, rb)`` (centres 3-tuples, radii, m), as
    ``ball_ball``'s values.  Coincident centres push b along world +y."""
    return ball_ball(ca, ra, sub(cb, ca), rb, (0.0, 1.0, 0.0), prediction)


@njit
def collide_sphere_sphere(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of sphere a (params ``[radius]``) and sphere b; at most one point, feature id 0.

    Coincident centres push b along world +y.
    """
    hit, p, normal, depth = sphere_sphere(load(pos_a), params_a[0], load(pos_b), params_b[0], prediction)
    return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n
