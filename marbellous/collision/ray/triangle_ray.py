"""Ray against one triangle (Moeller-Trumbore), hitting both sides.

For the ray ``o + t d`` and triangle ``abc`` solve ``o + t d = a + u (b - a) + v (c - a)`` by
Cramer's rule: ``p = d x e2``, ``det = e1.p``, ``u = (o - a).p / det``, ``q = (o - a) x e1``,
``v = d.q / det``, ``t = e2.q / det``; a hit needs ``u, v >= 0``, ``u + v <= 1`` and
``0 <= t <= t_max``.  Every acceleration structure calls this same function on the same
triangle, so they return bit-identical distances.
"""
import math

from ..._numba.jit import njit
from ..vec3 import cross, dot, sub


@njit
def ray_triangle(o, d, a, b, c, t_max):
    """Distance ``t`` (m, along the unit direction ``d``) to triangle ``abc``, or ``inf``."""
    e1 = sub(b, a)
    e2 = sub(c, a)
    p = cross(d, e2)
    det = dot(e1, p)
    if det == 0.0:
        return math.inf
    inv = 1.0 / det
    s = sub(o, a)
    u = dot(s, p) * inv
    if u < 0.0 or u > 1.0:
        return math.inf
    q = cross(s, e1)
    v = dot(d, q) * inv
    if v < 0.0 or u + v > 1.0:
        return math.inf
    t = dot(e2, q) * inv
    if t < 0.0 or t > t_max:
        return math.inf
    return t
