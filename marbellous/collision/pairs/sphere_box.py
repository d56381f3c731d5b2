"""Sphere-box contact: the closest point of the box to the sphere's centre (the lecture's goal area).

In the box frame the closest point is ``q = clamp(c, -h, h)``.  If the centre is outside,
``depth = r - |c - q|`` and the normal runs from the centre towards ``q``.  If the centre is inside,
the box face of least penetration ``k = argmin(h_k - |c_k|)`` pushes the sphere out:
``depth = r + h_k - |c_k|`` along that face's normal.
"""
import math

from ..._numba.jit import njit
from ..vec3 import load, madd, mat_to_local, mat_to_world, matrix, scale, sub
from .contact_output import add_contact


@njit
def sphere_box(ca, r, cb, mb, h, prediction):
    """Contact of the sphere ``(ca, r)`` with the box at ``cb`` with rotation ``mb`` (row-major
    9-tuple, ``vec3.matrix``) and half extents ``h`` (3-tuple, m), as values
    ``(hit, p_on_a, normal, depth)`` (``sphere_sphere.ball_ball``)."""
    c = mat_to_local(mb, sub(ca, cb))
    q = (min(max(c[0], -h[0]), h[0]),
         min(max(c[1], -h[1]), h[1]),
         min(max(c[2], -h[2]), h[2]))
    d = sub(q, c)
    dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    if dist2 > 1e-200:
        dist = math.sqrt(dist2)
        depth = r - dist
        if depth < -prediction:
            return False, ca, d, depth
        local_normal = scale(d, 1.0 / dist)
    else:
        k = 0
        best = h[0] - abs(c[0])
        for m in range(1, 3):
            gap = h[m] - abs(c[m])
            if gap < best:
                best = gap
                k = m
        depth = r + best
        s = -1.0 if c[k] >= 0.0 else 1.0
        local_normal = (s if k == 0 else 0.0, s if k == 1 else 0.0, s if k == 2 else 0.0)
    normal = mat_to_world(mb, local_normal)
    return True, madd(ca, r, normal), normal, depth


@njit
def collide_sphere_box(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Contact of sphere a (``[radius]``) and box b (``[hx, hy, hz]``); one point, feature id 0."""
    hit, p, normal, depth = sphere_box(load(pos_a), params_a[0], load(pos_b), matrix(rot_b),
                                       (params_b[0], params_b[1], params_b[2]), prediction)
    return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n
