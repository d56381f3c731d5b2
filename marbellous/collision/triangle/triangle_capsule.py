"""Capsule against one triangle: a sphere swept along a segment, tested on the same axes as a sphere.

The capsule is the segment ``P0 P1`` grown by ``r``.  Two cases, by the separating axes of the
sphere test (``triangle_sphere``) applied to points of the segment:

- face axis: the part ``[u0, u1]`` of the segment whose projection lies inside the triangle
  (clipping ``P0 + u (P1 - P0)`` against the three side planes ``(X - V_i).m_i >= 0``, ``m_i =
  n x e_i`` pointing inwards).  If it is not empty, each end ``X`` of it touches the face with depth
  ``r - n.(X - A)``: two points for a capsule lying on the face, so it does not rock.
- edge and vertex axes: where the segment leaves the triangle's prism (or passes outside it), its
  closest point ``X`` to the triangle's boundary lies on one of the three edges' closest point pairs
  (``closest_segment_params``), and the sphere of radius ``r`` at ``X`` gives the contact on that
  edge or vertex, reported when it is nearer than the face points (and kept by the caller only if
  its Voronoi test on the whole surface passes, see ``triangle_contact``).
"""
import math

from ..._numba.jit import njit
from ..pairs.segment import closest_segment_params
from ..vec3 import cross, dot, madd, sub
from .triangle_contact import write_row
from .triangle_sphere import EDGE_AB, FACE, VERTEX_A

#: Feature code of the second face point of a capsule lying on a face (the first is ``FACE``).
FACE_SECOND = 7


@njit
def _clip_side(u0, u1, p0, d, v, m):
    """Clip ``[u0, u1]`` to the half-space ``(p0 + u d - v).m >= 0``; empty when ``u0 > u1``."""
    f0 = dot(sub(p0, v), m)
    fd = dot(d, m)
    if fd == 0.0:
        if f0 < 0.0:
            return 1.0, 0.0
        return u0, u1
    u = -f0 / fd
    if fd > 0.0:
        return max(u0, u), u1
    return u0, min(u1, u)


@njit
def capsule_triangle(p0, p1, r, a, b, c, n, prediction, scratch):
    """Contacts of the capsule ``P0 P1`` (radius ``r``, m) with triangle ``abc`` (unit normal ``n``).

    Writes
    rows of ``scratch`` (layout in ``triangle_contact``) and returns their number (0 to 3).
    """
    d = sub(p1, p0)
    u0, u1 = 0.0, 1.0
    u0, u1 = _clip_side(u0, u1, p0, d, a, cross(n, sub(b, a)))
    u0, u1 = _clip_side(u0, u1, p0, d, b, cross(n, sub(c, b)))
    u0, u1 = _clip_side(u0, u1, p0, d, c, cross(n, sub(a, c)))
    nn = (-n[0], -n[1], -n[2])
    k = 0
    nearest_face = math.inf
    if u0 <= u1:
        ends = 1 if u1 - u0 <= 1e-9 else 2
        for e in range(ends):
            x = madd(p0, u0 if e == 0 else u1, d)
            s = dot(n, sub(x, a))
            nearest_face = min(nearest_face, s)
            if -r <= s <= r + prediction:
                k = write_row(scratch, k, madd(x, -s, n), nn, r - s, FACE if e == 0 else FACE_SECOND, x)
        if u0 <= 0.0 and u1 >= 1.0:
            return k
    best = math.inf
    best_x = p0
    best_q = a
    best_feature = -1
    verts = ((a, b), (b, c), (c, a))
    for i in range(3):
        v, w = verts[i]
        e = sub(w, v)
        s, t = closest_segment_params(p0, d, v, e)
        x = madd(p0, s, d)
        q = madd(v, t, e)
        xq = sub(q, x)
        dist2 = dot(xq, xq)
        if dist2 < best:
            best = dist2
            best_x = x
            best_q = q
            if t <= 0.0:
                best_feature = VERTEX_A + i
            elif t >= 1.0:
                best_feature = VERTEX_A + (i + 1) % 3
            else:
                best_feature = EDGE_AB + i
    dist = math.sqrt(best)
    if dist > r + prediction or dist >= nearest_face - 1e-12 * r:
        return k
    if dist <= 1e-12 * r:
        return write_row(scratch, k, best_q, nn, r, best_feature, best_x)
    xq = sub(best_q, best_x)
    return write_row(scratch, k, best_q, (xq[0] / dist, xq[1] / dist, xq[2] / dist), r - dist,
                     best_feature, best_x)
