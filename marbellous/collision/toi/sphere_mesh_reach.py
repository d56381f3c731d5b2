"""Whether a sphere reaches one triangle of a static mesh or height field within a horizon, tested at a few
times: a sufficient answer that spares the time-of-impact search (``conservative_advancement``) its usual case.

A marble rolling over a mesh has, most steps, a speculative contact with the next triangle ahead, and the
time-of-impact stage asks whether anything reaches it (a MISS drops it).  The search answers with a pair test
of the whole mesh at each of its advances.  For a sphere centred on its body, against a mesh or height field
that stands still, the centre's path is the motion's parabola

    p(t) = x0 + v t + a t^2 / 2

and the triangle's contact at time t is what the shape's pair test reports for it there: ``sphere_triangle``
(gap ``-depth``), passed by the Voronoi filter of edges and vertices (the mesh's ``feature_is_true``; the height
field's neighbour directions and vertex rings from its grid).  If that gap is 0 or less at some time t in
(0, T] (the sphere touches or overlaps the triangle), the triangle is reached by then, and so the search over
the same horizon cannot end in a MISS: its advances are conservative and stop at the first time a piece comes
within the hit tolerance, before it touches.  (A gap that only comes within the tolerance at the horizon's very
end, closing to it without touching, is left to the search, whose advances aim at touching.)  The times tried
are ``T k / SAMPLES`` for k = 1..SAMPLES; when the sphere touches at none, nothing is decided and the search
runs.
"""
from ..._numba.jit import njit
from ..mesh import mesh_layout as ml
from ..mesh.heightfield_collide import CORNERS, cell_triangle, heightfield_vertex_is_true, neighbour_direction
from ..mesh.mesh_collide import feature_is_true
from ..triangle.triangle_contact import edge_is_true
from ..triangle.triangle_sphere import EDGE_AB, EDGE_CA, VERTEX_A, VERTEX_C, sphere_triangle
from ..vec3 import mat_to_local
from .motion import position_at

#: times tried in the horizon (evenly spaced, the last at its end)
SAMPLES = 4


@njit
def _field_feature_is_true(params, geom_f, off_f, i, j, k, feature, a, b, c, p, q):
    """The height field's Voronoi test (as its pair test makes it) of a contact at point ``q`` on ``feature``
    of triangle ``k`` of cell ``(i, j)`` (corners ``a b c``) for the sphere centred at ``p``."""
    if EDGE_AB <= feature <= EDGE_CA:
        e = feature - EDGE_AB
        u, w = (a, b) if e == 0 else ((b, c) if e == 1 else (c, a))
        return edge_is_true(p, q, neighbour_direction(params, geom_f, off_f, i, j, k, e, u, w))
    if VERTEX_A <= feature <= VERTEX_C:
        corner = CORNERS[k][feature - VERTEX_A]
        return heightfield_vertex_is_true(params, geom_f, off_f, i + corner[0], j + corner[1], p)
    return True


@njit
def sphere_reaches_triangle(motion, radius, pos_s, m_s, field, params, geom_f, geom_i, off_f, off_i, t, horizon):
    """True if the sphere of ``radius`` (m) centred on a body moving on ``motion`` (``toi/motion.py``) touches or
    overlaps triangle ``t`` of the static shape posed at ``pos_s`` (3-tuple, m), ``m_s`` (row-major 9-tuple
    rotation), as the shape's pair test reports that triangle, at one of the times ``horizon k / SAMPLES`` (s),
    k = 1..SAMPLES; False says nothing (module docstring).  The shape: a height field when ``field`` (its kernel
    record ``params``, heights at ``off_f``), else a mesh (blob slices at ``off_f``/``off_i``)."""
    i = j = k = 0
    if field:
        cell = t // 2
        k = t - 2 * cell
        i, j = divmod(cell, int(params[6]) - 1)
        a, b, c, n = cell_triangle(params, geom_f, off_f, i, j, k)
    else:
        a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, t)
        if n[0] == 0.0 and n[1] == 0.0 and n[2] == 0.0:
            return False
    for s in range(1, SAMPLES + 1):
        x = position_at(motion, horizon * s / SAMPLES)
        p = mat_to_local(m_s, (x[0] - pos_s[0], x[1] - pos_s[1], x[2] - pos_s[2]))
        feature, q, normal, depth = sphere_triangle(p, radius, a, b, c, n, 0.0)
        if feature < 0 or depth < 0.0:
            continue
        if field:
            if _field_feature_is_true(params, geom_f, off_f, i, j, k, feature, a, b, c, p, q):
                return True
        elif feature_is_true(geom_f, geom_i, off_f, off_i, t, feature, p, q):
            return True
    return False
