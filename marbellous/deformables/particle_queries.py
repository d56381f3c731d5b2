"""Ray casts against the particles (spheres of their radii), brute force over the live rows."""
import math

from .._numba.jit import njit
from .particle_layout import P_POS, P_RADIUS


@njit
def raycast_particles(pf, n, origin, direction, max_distance, hit):
    """The nearest particle the ray ``origin + t direction`` (unit ``direction``) hits for
    ``0 <= t < max_distance``: its row, with ``hit[0] = t``, ``hit[2:5]`` the point, ``hit[5:8]`` the outward
    normal; -1 (``hit`` unchanged) when none.  A ray starting inside a particle hits it at ``t = 0``."""
    best = -1
    nearest = max_distance
    for p in range(n):
        r = pf[p, P_RADIUS]
        m0 = origin[0] - pf[p, P_POS]
        m1 = origin[1] - pf[p, P_POS + 1]
        m2 = origin[2] - pf[p, P_POS + 2]
        # |m + t d|^2 = r^2:  t^2 + 2 b t + c = 0
        b = m0 * direction[0] + m1 * direction[1] + m2 * direction[2]
        c = m0 * m0 + m1 * m1 + m2 * m2 - r * r
        if c > 0.0 and b > 0.0:
            continue
        disc = b * b - c
        if disc < 0.0:
            continue
        t = max(0.0, -b - math.sqrt(disc))
        if t < nearest:
            nearest = t
            best = p
    if best >= 0:
        hit[0] = nearest
        for k in range(3):
            x = origin[k] + nearest * direction[k]
            hit[2 + k] = x
            hit[5 + k] = (x - pf[best, P_POS + k]) / pf[best, P_RADIUS]
    return best
