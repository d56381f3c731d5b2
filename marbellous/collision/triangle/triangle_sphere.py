"""Sphere against one triangle by the separating-axis test of the lecture, reporting the winning feature.

The candidate separating axes of a sphere (centre ``P``, radius ``r``) and a triangle ``ABC`` are

- the face plane: ``n = normalize((B - A) x (C - A))``, ``d = n.A``; separated iff ``n.P - d > r``;
- the three vertex axes ``A - P``, ``B - P``, ``C - P``: the axis through ``A`` separates iff
  ``|P - A| > r`` and ``B`` and ``C`` lie on the far side of the plane through ``A`` with normal
  ``P - A``, i.e. ``(B - A).(P - A) <= 0`` and ``(C - A).(P - A) <= 0``;
- the three edge axes ``P - Q`` with ``Q`` the projection of ``P`` on an edge, e.g. ``AB``: the axis
  separates iff ``|P - Q| > r`` and ``C`` lies on the other side of the plane through ``AB`` with
  normal ``P - Q``.

The side conditions say exactly in which Voronoi region of the triangle ``P`` lies, so one
classification (Ericson, Real-Time Collision Detection 5.1.5, in barycentric form) picks the one
axis that matters; the closest point ``Q`` of the triangle is then the feature's point and the
sphere overlaps iff ``|P - Q| <= r``.  Points exactly on a region boundary count as the face, so a
sphere above a shared edge of a flat mesh reports the face normal from both triangles.

Triangles are one-sided, like planes: the solid lies behind the face (``n`` follows the
counter-clockwise winding by the right-hand rule).  A face contact has depth ``r - n.(P - A)``,
which keeps pushing the sphere out to the front while its centre is up to ``r`` behind the face.
"""
import math

from ..._numba.jit import njit_inline
from ..vec3 import dot, madd, sub

#: Feature codes of a triangle (the low part of a contact's feature id).
FACE = 0
EDGE_AB = 1
EDGE_BC = 2
EDGE_CA = 3
VERTEX_A = 4
VERTEX_B = 5
VERTEX_C = 6


@njit_inline
def closest_feature(p, a, b, c, n):
    """The triangle feature whose Voronoi region holds ``p``, and the closest point on it.

    ``p``, ``a``, ``b``, ``c`` points (3-tuples, m), ``n`` the unit face normal.
    Returns ``(feature, q)`` with ``feature`` one of ``FACE``, ``EDGE_*``, ``VERTEX_*``.
    """
    ab = sub(b, a)
    ac = sub(c, a)
    ap = sub(p, a)
    d1 = dot(ab, ap)
    d2 = dot(ac, ap)
    if d1 < 0.0 and d2 < 0.0:             # B and C behind the plane through A with normal P - A
        return VERTEX_A, a
    bp = sub(p, b)
    d3 = dot(ab, bp)
    d4 = dot(ac, bp)
    if d3 > 0.0 and d4 < d3:              # A and C behind the plane through B with normal P - B
        return VERTEX_B, b
    vc = d1 * d4 - d3 * d2
    if vc < 0.0 and d1 >= 0.0 and d3 <= 0.0:   # C beyond the plane through AB with normal P - Q
        return EDGE_AB, madd(a, d1 / (d1 - d3), ab)
    cp = sub(p, c)
    d5 = dot(ab, cp)
    d6 = dot(ac, cp)
    if d6 > 0.0 and d5 < d6:              # A and B behind the plane through C with normal P - C
        return VERTEX_C, c
    vb = d5 * d2 - d1 * d6
    if vb < 0.0 and d2 >= 0.0 and d6 <= 0.0:   # B beyond the plane through CA
        return EDGE_CA, madd(a, d2 / (d2 - d6), ac)
    va = d3 * d6 - d5 * d4
    if va < 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:   # A beyond the plane through BC
        return EDGE_BC, madd(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b))
    return FACE, madd(p, -dot(n, ap), n)    # inside the prism: the face plane is the axis


@njit_inline
def sphere_triangle(p, r, a, b, c, n, prediction):
    """Sphere (centre ``p``, radius ``r``, m) against triangle ``abc`` with unit normal ``n``.

    Returns ``(feature, q, normal, depth)``: ``feature`` is -1 when an axis separates the shapes by
    more than ``prediction`` (or the centre is more than ``r`` behind the face); else ``q`` is the
    closest point of the triangle, ``normal`` the unit contact normal from the sphere to the
    triangle, ``depth = r - distance`` (m, > 0 overlap).
    """
    feature, q = closest_feature(p, a, b, c, n)
    if feature == FACE:
        s = dot(n, sub(p, a))
        if s > r + prediction or s < -r:
            return -1, q, n, 0.0
        return FACE, q, (-n[0], -n[1], -n[2]), r - s
    pq = sub(q, p)
    dist = math.sqrt(dot(pq, pq))
    if dist > r + prediction:
        return -1, q, n, 0.0
    if dist <= 1e-12 * r:                  # centre on the boundary: the face decides the direction
        return feature, q, (-n[0], -n[1], -n[2]), r
    inv = 1.0 / dist
    return feature, q, (pq[0] * inv, pq[1] * inv, pq[2] * inv), r - dist
