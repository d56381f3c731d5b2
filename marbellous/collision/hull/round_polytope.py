"""A sphere or capsule (a point or segment grown by a radius) against a convex polytope.

While the core (the centre, or the capsule's axis segment) lies outside the polytope, the contact comes from
their closest points: the closest point of a convex polytope lies on a face that the core is in front of,
so the least of the core's distances to those faces' polygons is exact (a polygon's distance: the point
where the segment crosses its plane inside it, the endpoints' projections that fall inside it, and the
closest points to each of its edges).  Normal ``(q_core - q_polytope) / dist``, depth ``radius - dist``.

A core reaching inside (a deep contact) takes the separating-axis test instead: the polytope's face normals
(separation ``min_{core} n . x - d``) and, for a capsule, the axes ``e x s`` of each polytope edge ``e`` and
the segment ``s`` that lie on the edge's Gauss-map arc (``polytope``).

A capsule lying along a face (within ``tolerances.PARALLEL_SIN``) gets two points: its segment clipped to
the face's side planes, so that it rests without rocking.  Feature ids: ``2 face + end`` for those,
``2 face`` for a single point, ``face`` the face most aligned with the normal.
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..pairs.contact_output import add_contact
from ..pairs.segment import closest_segment_params
from ..tolerances import FACE_BIAS, PARALLEL_SIN
from ..vec3 import cross, dot, madd, scale, sub
from .polytope import edge_arc, edge_segment, normal, on_edge_arc, vertex


@njit
def _inside_face(x, nrm, verts, loops, k0, k1):
    """True if ``x`` (on face plane) lies inside the face's convex polygon ``loops[k0:k1]``."""
    m = k1 - k0
    for k in range(m):
        u = vertex(verts, loops[k0 + k])
        w = vertex(verts, loops[k0 + (k + 1) % m])
        if dot(cross(sub(w, u), nrm), sub(x, u)) > 0.0:
            return False
    return True


@njit
def _segment_face(p, d, verts, planes, starts, loops, f):
    """Closest points of the segment ``p + s d`` and face ``f``'s polygon: ``(dist^2, q_core, q_face)``."""
    nrm = normal(planes, f)
    k0, k1 = starts[f], starts[f + 1]
    h0 = dot(nrm, p) - planes[f, 3]
    e = madd(p, 1.0, d)
    h1 = dot(nrm, e) - planes[f, 3]
    if (h0 > 0.0) != (h1 > 0.0):
        x = madd(p, h0 / (h0 - h1), d)
        if _inside_face(x, nrm, verts, loops, k0, k1):
            return 0.0, x, x
    best = np.inf
    qc = p
    qf = p
    for end, h in ((p, h0), (e, h1)):
        x = madd(end, -h, nrm)
        if h * h < best and _inside_face(x, nrm, verts, loops, k0, k1):
            best, qc, qf = h * h, end, x
    m = k1 - k0
    for k in range(m):
        u = vertex(verts, loops[k0 + k])
        w = sub(vertex(verts, loops[k0 + (k + 1) % m]), u)
        s, t = closest_segment_params(p, d, u, w)
        a = madd(p, s, d)
        b = madd(u, t, w)
        g = sub(a, b)
        d2 = dot(g, g)
        if d2 < best:
            best, qc, qf = d2, a, b
    return best, qc, qf


@njit
def _emit(core_is_a, q_core, nrm, dist, radius, feature, out_f, out_i, n):
    """Append the contact of core point ``q_core`` at signed distance ``dist`` (m) in front of the polytope
    along ``nrm`` (unit, polytope -> core)."""
    depth = radius - dist
    if core_is_a:
        return add_contact(out_f, out_i, n, madd(q_core, -radius, nrm), scale(nrm, -1.0), depth, feature)
    return add_contact(out_f, out_i, n, madd(q_core, -dist, nrm), nrm, depth, feature)


@njit
def _aligned_face(planes, direction):
    """The face whose outward normal is most aligned with ``direction``."""
    best = -np.inf
    face = 0
    for f in range(planes.shape[0]):
        a = dot(normal(planes, f), direction)
        if a > best:
            best, face = a, f
    return face


@njit
def _lying_contacts(core_is_a, p, d, radius, verts, planes, starts, loops, f, prediction, out_f, out_i, n):
    """Two points for a segment lying along face ``f``: the segment clipped to the face's side planes.
    Returns the new count, or -1 when clipping leaves nothing."""
    nrm = normal(planes, f)
    k0, k1 = starts[f], starts[f + 1]
    m = k1 - k0
    s0, s1 = 0.0, 1.0
    for k in range(m):
        u = vertex(verts, loops[k0 + k])
        side = cross(sub(vertex(verts, loops[k0 + (k + 1) % m]), u), nrm)
        a = dot(side, sub(p, u))
        b = dot(side, d)
        if b == 0.0:
            if a > 0.0:
                return -1
            continue
        t = -a / b
        if b > 0.0:
            s1 = min(s1, t)
        else:
            s0 = max(s0, t)
    if s0 > s1:
        return -1
    for end in range(2):
        x = madd(p, s0 if end == 0 else s1, d)
        dist = dot(nrm, x) - planes[f, 3]
        if radius - dist >= -prediction:
            n = _emit(core_is_a, x, nrm, dist, radius, 2 * f + end, out_f, out_i, n)
    return n


@njit
def _deep_axis(p, d, verts, planes, edges):
    """Separating-axis test of a core reaching into the polytope: ``(sep, normal, q_core, face)`` with
    ``q_core`` the core's point deepest along the axis; ``face`` -1 for an edge axis."""
    e = madd(p, 1.0, d)
    best = -np.inf
    face = 0
    for f in range(planes.shape[0]):
        nrm = normal(planes, f)
        s = min(dot(nrm, p), dot(nrm, e)) - planes[f, 3]
        if s > best:
            best, face = s, f
    nrm = normal(planes, face)
    q = p if dot(nrm, p) <= dot(nrm, e) else e
    bias = FACE_BIAS * math.sqrt(dot(d, d))
    if bias == 0.0:
        return best, nrm, q, face
    best_edge = -np.inf
    for k in range(edges.shape[0] // 4):
        u, w = edge_segment(verts, edges, k)
        axis = cross(w, d)
        la = math.sqrt(dot(axis, axis))
        if la == 0.0:
            continue
        axis = scale(axis, 1.0 / la)
        a, b = edge_arc(planes, edges, k)
        if not on_edge_arc(axis, a, b):
            axis = scale(axis, -1.0)
            if not on_edge_arc(axis, a, b):
                continue
        s = dot(axis, sub(p, u))
        if s > best + bias and s > best_edge:
            s_core, _ = closest_segment_params(p, d, u, w)
            best_edge, nrm, q = s, axis, madd(p, s_core, d)
    if best_edge > -np.inf:
        return best_edge, nrm, q, -1
    return best, nrm, q, face


@njit
def collide_segment_polytope(core_is_a, p, d, radius, verts, planes, starts, loops, edges, prediction,
                             out_f, out_i, n):
    """Contacts of the sphere or capsule with core segment ``p + s d`` (``d`` zero for a sphere) and
    ``radius`` (m) with the placed polytope (``polytope``); ``core_is_a`` says which one is shape a (normals
    from a to b).  Appends rows from ``n``; returns the new count."""
    e = madd(p, 1.0, d)
    reach = radius + prediction
    outside = False
    for f in range(planes.shape[0]):
        nrm = normal(planes, f)
        lo = min(dot(nrm, p), dot(nrm, e)) - planes[f, 3]
        if lo > reach:
            return n                                   # a face plane separates them
        if max(dot(nrm, p), dot(nrm, e)) - planes[f, 3] > 0.0:
            outside = True
    best = np.inf
    qc = p
    qf = p
    if outside:
        for f in range(planes.shape[0]):
            nrm = normal(planes, f)
            if max(dot(nrm, p), dot(nrm, e)) - planes[f, 3] <= 0.0:
                continue                               # the core is behind this face
            d2, a, b = _segment_face(p, d, verts, planes, starts, loops, f)
            if d2 < best:
                best, qc, qf = d2, a, b
    if best > 0.0 and best < np.inf:
        dist = math.sqrt(best)
        if dist > reach:
            return n
        nrm = scale(sub(qc, qf), 1.0 / dist)
        face = _aligned_face(planes, nrm)
    else:
        dist, nrm, qc, face = _deep_axis(p, d, verts, planes, edges)
        if face < 0:
            return _emit(core_is_a, qc, nrm, dist, radius, 2 * _aligned_face(planes, nrm), out_f, out_i, n)
    ld = math.sqrt(dot(d, d))
    fn = normal(planes, face)
    if ld > 0.0 and abs(dot(fn, d)) < PARALLEL_SIN * ld and dot(fn, nrm) > 1.0 - 1e-9:
        m = _lying_contacts(core_is_a, p, d, radius, verts, planes, starts, loops, face, prediction,
                            out_f, out_i, n)
        if m >= 0:
            return m
    return _emit(core_is_a, qc, nrm, dist, radius, 2 * face, out_f, out_i, n)
