"""One convex shape (sphere, capsule, box or hull) against one triangle: picks the pair test by type code.

Everything is in the static shape's local frame.  Candidate contacts go to ``scratch`` rows (layout
in ``triangle_contact``).  The Voronoi tests of edge and vertex rows on the whole surface are left
to the caller (``mesh_collide.feature_is_true``), which fetches the neighbour data only for those
rows; the box uses the neighbour directions in its axis test and needs them up front.
"""
import numpy as np

from ..._numba.jit import njit_inline
from ..shape_types import CAPSULE, HULL, SPHERE
from ..aabb import hull_bounds
from ..pairs.contact_output import add_contact
from ..vec3 import column, madd, mat_to_world, to_local
from .triangle_box import box_triangle
from .triangle_capsule import capsule_triangle
from .triangle_hull import hull_triangle
from .triangle_contact import FEATURE_STRIDE, write_row
from .triangle_sphere import sphere_triangle


@njit_inline
def convex_triangle(type_a, c, rot, params_a, poly, a, b, cc, n, m2ab, m2bc, m2ca, prediction, scratch):
    """Candidate contacts of shape ``type_a`` (centre ``c``, rotation ``rot``, ``params_a``; a hull placed
    as ``poly``, ``hull/polytope``) with the triangle ``a b cc`` (unit normal ``n``; neighbour directions
    ``m2*``, read by boxes and hulls only); returns their number.  Inlined: where ``type_a`` is a constant,
    only its test is compiled.
    """
    if type_a == SPHERE:
        feature, q, normal, depth = sphere_triangle(c, params_a[0], a, b, cc, n, prediction)
        if feature < 0:
            return 0
        return write_row(scratch, 0, q, normal, depth, feature, c)
    if type_a == CAPSULE:
        axis = column(rot, 1)
        hh = params_a[1]
        return capsule_triangle(madd(c, -hh, axis), madd(c, hh, axis), params_a[0], a, b, cc, n, prediction,
                                scratch)
    if type_a == HULL:
        return hull_triangle(poly, params_a[6], a, b, cc, n, m2ab, m2bc, m2ca, prediction, scratch)
    return box_triangle(c, rot, params_a, a, b, cc, n, m2ab, m2bc, m2ca, prediction, scratch)


@njit_inline
def convex_local_bounds(type_a, c, rot, params_a, margin):
    """Axis-aligned box ``(lo, hi)`` (3-tuples, m) of the shape in the static shape's frame,
    grown by ``margin`` (m) on every side."""
    if type_a == SPHERE:
        e = (params_a[0], params_a[0], params_a[0])
    elif type_a == CAPSULE:
        r, hh = params_a[0], params_a[1]
        e = (abs(rot[0, 1]) * hh + r, abs(rot[1, 1]) * hh + r, abs(rot[2, 1]) * hh + r)
    elif type_a == HULL:
        return hull_bounds(c, rot, params_a, margin)
    else:
        h = params_a
        e = (abs(rot[0, 0]) * h[0] + abs(rot[0, 1]) * h[1] + abs(rot[0, 2]) * h[2],
             abs(rot[1, 0]) * h[0] + abs(rot[1, 1]) * h[1] + abs(rot[1, 2]) * h[2],
             abs(rot[2, 0]) * h[0] + abs(rot[2, 1]) * h[1] + abs(rot[2, 2]) * h[2])
    return ((c[0] - e[0] - margin, c[1] - e[1] - margin, c[2] - e[2] - margin),
            (c[0] + e[0] + margin, c[1] + e[1] + margin, c[2] + e[2] + margin))


@njit_inline
def to_static_frame(pos_a, rot_a, pos_b, rot_b):
    """Centre (3-tuple) and rotation matrix (new (3, 3) array) of shape a in b's frame:
    ``c = R_b^T (p_a - p_b)``, ``R = R_b^T R_a``."""
    rel = (pos_a[0] - pos_b[0], pos_a[1] - pos_b[1], pos_a[2] - pos_b[2])
    c = to_local(rot_b, rel)
    rot = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            rot[i, j] = rot_b[0, i] * rot_a[0, j] + rot_b[1, i] * rot_a[1, j] + rot_b[2, i] * rot_a[2, j]
    return c, rot


@njit_inline
def emit_contact(q, normal, depth, code, pos_b, m_b, triangle, seen, n_seen, out_f, out_i, n):
    """Append a contact found in the static frame (``q`` the point on the triangle, ``normal`` unit from
    the convex shape to the triangle, ``depth`` m, ``code`` the feature code) to the contact buffer, in
    world coordinates (``pos_b`` the static shape's position, ``m_b`` its rotation as a row-major
    9-tuple) with feature id ``triangle * FEATURE_STRIDE + code`` -- unless it repeats (bit for bit:
    point, normal, depth) a contact already emitted in this query, as happens where triangles of one
    plane meet right under a sphere.

    ``seen`` (m, 7) remembers the first ``m`` emitted contacts; returns ``(n, n_seen)``.
    """
    for s in range(min(n_seen, seen.shape[0])):
        if ((seen[s, 0] == q[0]) & (seen[s, 1] == q[1]) & (seen[s, 2] == q[2]) & (seen[s, 3] == normal[0])
                & (seen[s, 4] == normal[1]) & (seen[s, 5] == normal[2]) & (seen[s, 6] == depth)):
            return n, n_seen
    if n_seen < seen.shape[0]:
        for k in range(3):
            seen[n_seen, k] = q[k]
            seen[n_seen, 3 + k] = normal[k]
        seen[n_seen, 6] = depth
    qw = mat_to_world(m_b, q)
    nw = mat_to_world(m_b, normal)
    p_on_a = (qw[0] + pos_b[0] + nw[0] * depth, qw[1] + pos_b[1] + nw[1] * depth, qw[2] + pos_b[2] + nw[2] * depth)
    return add_contact(out_f, out_i, n, p_on_a, nw, depth, triangle * FEATURE_STRIDE + code), n_seen + 1


@njit_inline
def emit_unique(scratch, k, pos_b, m_b, triangle, seen, n_seen, out_f, out_i, n):
    """:func:`emit_contact` of scratch row ``k`` (layout in ``triangle_contact``)."""
    return emit_contact((scratch[k, 0], scratch[k, 1], scratch[k, 2]), (scratch[k, 3], scratch[k, 4], scratch[k, 5]),
                        scratch[k, 6], int(scratch[k, 7]), pos_b, m_b, triangle, seen, n_seen, out_f, out_i, n)
