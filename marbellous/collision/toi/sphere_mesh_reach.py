"""Whether a sphere reaches one triangle of a static mesh within a horizon, tested at a few times: a sufficient
answer that spares the time-of-impact search (``conservative_advancement``) its usual case.

A marble rolling over a mesh has, most steps, a speculative contact with the next triangle ahead, and the
time-of-impact stage asks whether anything reaches it (a MISS drops it).  The search answers with a pair test
of the whole mesh at each of its advances.  For a sphere centred on its body, against a mesh that stands
still, the centre's path is the motion's parabola

    p(t) = x0 + v t + a t^2 / 2

and the triangle's contact at time t is what the mesh's pair test reports for it there: ``sphere_triangle``
(gap ``-depth``), passed by the mesh's Voronoi filter of edges and vertices (``feature_is_true``).  If that
gap is 0 or less at some time t in (0, T] (the sphere touches or overlaps the triangle), the triangle is reached
by then, and so the search over the same horizon cannot end in a MISS: its advances are conservative and stop
at the first time a piece comes within the hit tolerance, before it touches.  (A gap that only comes within the
tolerance at the horizon's very end, closing to it without touching, is left to the search, whose advances aim
at touching.)  The times tried are ``T k / SAMPLES`` for k = 1..SAMPLES; when the sphere touches at none,
nothing is decided and the search runs.
"""
from ..._numba.jit import njit
from ..mesh import mesh_layout as ml
from ..mesh.mesh_collide import feature_is_true
from ..triangle.triangle_sphere import sphere_triangle
from ..vec3 import mat_to_local
from .motion import position_at

#: times tried in the horizon (evenly spaced, the last at its end)
SAMPLES = 4


@njit
def sphere_reaches_triangle(motion, radius, pos_m, m_m, geom_f, geom_i, off_f, off_i, t, horizon):
    """True if the sphere of ``radius`` (m) centred on a body moving on ``motion`` (``toi/motion.py``) touches or
    overlaps triangle ``t`` of the static mesh posed at ``pos_m`` (3-tuple, m), ``m_m`` (row-major 9-tuple
    rotation), blob slices at ``off_f``/``off_i``, as the mesh's pair test reports that triangle, at one of the
    times ``horizon k / SAMPLES`` (s), k = 1..SAMPLES; False says nothing (module docstring)."""
    a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, t)
    if n[0] == 0.0 and n[1] == 0.0 and n[2] == 0.0:
        return False
    for k in range(1, SAMPLES + 1):
        x = position_at(motion, horizon * k / SAMPLES)
        p = mat_to_local(m_m, (x[0] - pos_m[0], x[1] - pos_m[1], x[2] - pos_m[2]))
        feature, q, normal, depth = sphere_triangle(p, radius, a, b, c, n, 0.0)
        if feature >= 0 and depth >= 0.0 and feature_is_true(geom_f, geom_i, off_f, off_i, t, feature, p, q):
            return True
    return False
