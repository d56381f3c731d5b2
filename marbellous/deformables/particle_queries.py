"""Ray casts against the particles (spheres of their radii) and the cloths' triangles, brute force over the
live rows."""
import math

from .._numba.jit import njit
from .particle_layout import P_CLOTH, P_POS, P_RADIUS, T_A


@njit
def raycast_particles(pf, pi, n, origin, direction, max_distance, hit):
    """The nearest particle (not a cloth's vertex) the ray ``origin + t direction`` (unit ``direction``) hits
    for ``0 <= t < max_distance``: its row, with ``hit[0] = t``, ``hit[2:5]`` the point, ``hit[5:8]`` the
    outward normal; -1 (``hit`` unchanged) when none.  A ray starting inside a particle hits it at ``t = 0``."""
    best = -1
    nearest = max_distance
    for p in range(n):
        if pi[p, P_CLOTH] >= 0:
            continue
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


@njit
def raycast_triangles(pf, tri, n_tri, origin, direction, max_distance, hit):
    """The nearest cloth triangle the ray hits for ``0 <= t < max_distance`` (Moeller and Trumbore 1997: solve
    ``origin + t d = a + u (b - a) + v (c - a)``, ``u, v >= 0``, ``u + v <= 1``): its row, with ``hit`` as in
    :func:`raycast_particles`, the normal the triangle's, turned to face the ray; -1 when none."""
    best = -1
    nearest = max_distance
    for t in range(n_tri):
        a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
        e1 = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
        e2 = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
        q = (direction[1] * e2[2] - direction[2] * e2[1], direction[2] * e2[0] - direction[0] * e2[2],
             direction[0] * e2[1] - direction[1] * e2[0])
        det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2]
        if abs(det) < 1e-20:
            continue
        s = (origin[0] - pf[a, P_POS], origin[1] - pf[a, P_POS + 1], origin[2] - pf[a, P_POS + 2])
        u = (s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) / det
        if u < 0.0 or u > 1.0:
            continue
        r = (s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0])
        v = (direction[0] * r[0] + direction[1] * r[1] + direction[2] * r[2]) / det
        if v < 0.0 or u + v > 1.0:
            continue
        distance = (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) / det
        if 0.0 <= distance < nearest:
            nearest = distance
            best = t
    if best >= 0:
        a, b, c = tri[best, T_A], tri[best, T_A + 1], tri[best, T_A + 2]
        e1 = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
        e2 = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        size = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        facing = -1.0 if n[0] * direction[0] + n[1] * direction[1] + n[2] * direction[2] > 0.0 else 1.0
        hit[0] = nearest
        for k in range(3):
            hit[2 + k] = origin[k] + nearest * direction[k]
            hit[5 + k] = facing * n[k] / size
    return best
