"""Convex shape (sphere, capsule, box, hull) against a static triangle mesh, through its acceleration.

1. Move shape a into the mesh's frame: ``c = R_b^T (p_a - p_b)``, ``R = R_b^T R_a``.
2. Its bounding box grown by ``prediction`` selects candidate triangles: all of them
   (``"brute"``, with a per-triangle box test), the 2D grid's cells under its x-z box
   (``"grid2d"``) or the BVH's overlapping leaves (``"bvh"``).  Every structure yields the
   candidates in ascending triangle order without repeats, and the exact test below decides, so
   all three give the same contacts in the same order, bit for bit.
3. Each live candidate triangle whose box overlaps (for a sphere: whose box is within its reach): the
   pair test (``triangle_convex``), then edge contacts filtered by the neighbour directions and vertex
   contacts by the vertex's ring (``triangle_contact``), so there are no ghost contacts on internal
   edges anywhere in the mesh.
4. Contacts go back to world coordinates with feature id ``triangle * 16 + code``; a contact that
   repeats an earlier one bit for bit (a sphere right over a vertex of a flat grid touches six
   coplanar faces at the same point) is reported once.
"""

import numpy as np

from ..._numba.jit import njit, njit_inline
from .. import shape_types as st
from ..aabb import boxes_overlap, sphere_misses_box
from ..triangle.triangle_contact import MAX_ROWS, N_COLS, SEEN_ROWS, edge_is_true, vertex_ring_passes
from ..hull.polytope import hull_polytope, no_polytope
from ..triangle.triangle_convex import convex_local_bounds, convex_triangle, emit_contact, emit_unique, to_static_frame
from ..triangle.triangle_sphere import EDGE_AB, EDGE_CA, VERTEX_A, VERTEX_B, VERTEX_C, sphere_triangle
from ..vec3 import mat_to_local, matrix
from . import mesh_layout as ml
from .bvh_static import bvh_candidates
from .grid2d import grid_candidates


@njit_inline
def vertex_is_true(geom_f, geom_i, off_f, off_i, v, p):
    """Voronoi test of a contact at vertex ``v`` for query point ``p``: ``(P - V).(W - V) <= 0``
    for every welded ring neighbour ``W``."""
    w = geom_i[off_i + geom_i[off_i + ml.I_WELD] + v]
    rs = off_i + geom_i[off_i + ml.I_RING_START]
    ring = off_i + geom_i[off_i + ml.I_RING]
    pv = ml.vertex(geom_f, geom_i, off_f, off_i, v)
    for k in range(geom_i[rs + w], geom_i[rs + w + 1]):
        if not vertex_ring_passes(p, pv, ml.vertex(geom_f, geom_i, off_f, off_i, geom_i[ring + k])):
            return False
    return True


@njit_inline
def mesh_candidates(params_b, geom_f, geom_i, off_f, off_i, lo, hi):
    """Candidate triangles under the box ``lo..hi`` (mesh frame), ascending: ``(array, first, count)``,
    the candidates being ``array[first:first + count]``."""
    accel = int(params_b[2])
    if accel == ml.ACCEL_GRID2D:
        return grid_candidates(params_b, geom_i, off_i, lo, hi)
    if accel == ml.ACCEL_BVH:
        buf, m = bvh_candidates(geom_f, geom_i, off_f, off_i, lo, hi)
        return buf, 0, m
    n_tri = int(params_b[1])
    buf = np.empty(n_tri, np.int64)
    m = 0
    for t in range(n_tri):
        a, b, c, nrm = ml.triangle(geom_f, geom_i, off_f, off_i, t)
        if boxes_overlap(a, b, c, lo, hi):
            buf[m] = t
            m += 1
    return buf, 0, m


@njit_inline
def feature_is_true(geom_f, geom_i, off_f, off_i, t, feature, p, q):
    """Voronoi test on the whole mesh of a contact on ``feature`` of triangle ``t`` at point ``q`` for
    query point ``p``: edge contacts against the neighbour's direction, vertex contacts against the
    vertex's ring; face contacts pass."""
    if EDGE_AB <= feature <= EDGE_CA:
        return edge_is_true(p, q, ml.neighbour_direction(geom_f, geom_i, off_f, off_i, t, feature - EDGE_AB))
    if VERTEX_A <= feature <= VERTEX_C:
        ia, ib, ic = ml.corners(geom_f, geom_i, off_f, off_i, t)
        v = ia if feature == VERTEX_A else (ib if feature == VERTEX_B else ic)
        return vertex_is_true(geom_f, geom_i, off_f, off_i, v, p)
    return True


@njit_inline
def _within_reach(c, reach, triangle):
    """Whether the triangle ``(a, b, c, normal)`` (``ml.triangle``) is not degenerate and its box comes within
    ``reach`` (m) of the point ``c``."""
    a, b, cc, nrm = triangle
    return not sphere_misses_box(c, reach, a, b, cc) and not (nrm[0] == 0.0 and nrm[1] == 0.0 and nrm[2] == 0.0)


@njit
def collide_sphere_mesh(centre, radius, pos_b, m_b, params_b, geom_f, geom_i, off_f_b, off_i_b, prediction,
                        out_f, out_i, n):
    """Contacts of a sphere (``centre`` 3-tuple in world coordinates, m; ``radius`` m) with the static
    mesh b (``pos_b`` 3-tuple, m; ``m_b`` its rotation as a row-major 9-tuple; ``params_b`` its kernel
    record, its slices of the blobs at ``off_f_b``/``off_i_b``).  Arguments otherwise, and the result, as
    :func:`collide_convex_mesh`, whose sphere case this is.  The pose comes by value, so the narrow phase
    calls it with the shapes' poses in registers.
    """
    c = mat_to_local(m_b, (centre[0] - pos_b[0], centre[1] - pos_b[1], centre[2] - pos_b[2]))
    lo = (c[0] - radius - prediction, c[1] - radius - prediction, c[2] - radius - prediction)
    hi = (c[0] + radius + prediction, c[1] + radius + prediction, c[2] + radius + prediction)
    cand, first, count = mesh_candidates(params_b, geom_f, geom_i, off_f_b, off_i_b, lo, hi)
    reach = radius + prediction
    # (the first candidate within reach found before the repeats' memory is made: a sphere near none, such as most
    # particles' queries each step, allocates nothing)
    start = first
    while start < first + count and not _within_reach(c, reach, ml.triangle(geom_f, geom_i, off_f_b, off_i_b,
                                                                              cand[start])):
        start += 1
    if start == first + count:
        return n
    seen = np.empty((SEEN_ROWS, 7))
    n_seen = 0
    for j in range(start, first + count):
        t = cand[j]
        a, b, cc, nrm = ml.triangle(geom_f, geom_i, off_f_b, off_i_b, t)
        if not _within_reach(c, reach, (a, b, cc, nrm)):
            continue
        feature, q, normal, depth = sphere_triangle(c, radius, a, b, cc, nrm, prediction)
        if feature >= 0 and feature_is_true(geom_f, geom_i, off_f_b, off_i_b, t, feature, c, q):
            n, n_seen = emit_contact(q, normal, depth, feature, pos_b, m_b, t, seen, n_seen, out_f, out_i, n)
    return n


@njit
def collide_convex_mesh(type_a, pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, geom_i,
                        off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of convex shape a (SPHERE, CAPSULE or BOX) with the static mesh b.

    ``pos_*`` (3,) world positions (m), ``rot_*`` (3, 3) rotations, ``params_*`` kernel records,
    ``geom_f``/``geom_i`` the global geometry blobs with b's slices at ``off_f_b``/``off_i_b``;
    ``prediction`` (m) speculative distance.  Appends rows to ``out_f``/``out_i`` (the buffer
    convention of docs/architecture.md: normal from a to b) and returns the new count.
    """
    if type_a == st.SPHERE:
        return collide_sphere_mesh((pos_a[0], pos_a[1], pos_a[2]), params_a[0], (pos_b[0], pos_b[1], pos_b[2]),
                                   matrix(rot_b), params_b, geom_f, geom_i, off_f_b, off_i_b, prediction, out_f,
                                   out_i, n)
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    return _convex_mesh(type_a, c, rot, params_a, no_polytope(), pos_b, rot_b, params_b, geom_f, geom_i, off_f_b,
                        off_i_b, prediction, out_f, out_i, n)


@njit
def collide_hull_mesh(pos_a, rot_a, params_a, off_f_a, off_i_a, pos_b, rot_b, params_b, geom_f, geom_i,
                      off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of the convex hull a (its blob slices at ``off_f_a``/``off_i_a``) with the static mesh b;
    arguments otherwise as :func:`collide_convex_mesh`."""
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    poly = hull_polytope(c, rot, geom_f, geom_i, off_f_a, off_i_a)
    return _convex_mesh(st.HULL, c, rot, params_a, poly, pos_b, rot_b, params_b, geom_f, geom_i, off_f_b, off_i_b,
                        prediction, out_f, out_i, n)


@njit
def _convex_mesh(type_a, c, rot, params_a, poly, pos_b, rot_b, params_b, geom_f, geom_i, off_f_b, off_i_b,
                 prediction, out_f, out_i, n):
    """Contacts of convex shape a (CAPSULE, BOX or HULL; centre ``c`` and rotation ``rot`` in b's frame, a
    hull placed there as ``poly``) with the static mesh b."""
    pb = (pos_b[0], pos_b[1], pos_b[2])
    m_b = matrix(rot_b)
    lo, hi = convex_local_bounds(type_a, c, rot, params_a, prediction)
    cand, first, count = mesh_candidates(params_b, geom_f, geom_i, off_f_b, off_i_b, lo, hi)
    scratch = np.empty((MAX_ROWS, N_COLS))
    seen = np.empty((SEEN_ROWS, 7))
    n_seen = 0
    zero = (0.0, 0.0, 0.0)
    for j in range(first, first + count):
        t = cand[j]
        a, b, cc, nrm = ml.triangle(geom_f, geom_i, off_f_b, off_i_b, t)
        if nrm[0] == 0.0 and nrm[1] == 0.0 and nrm[2] == 0.0:
            continue                                  # degenerate
        if not boxes_overlap(a, b, cc, lo, hi):
            continue                                  # too far
        m0 = m1 = m2 = zero
        if type_a == st.BOX or type_a == st.HULL:
            m0 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 0)
            m1 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 1)
            m2 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 2)
        k = convex_triangle(type_a, c, rot, params_a, poly, a, b, cc, nrm, m0, m1, m2, prediction, scratch)
        for r in range(k):
            f = int(scratch[r, 7])
            if feature_is_true(geom_f, geom_i, off_f_b, off_i_b, t, f, (scratch[r, 8], scratch[r, 9], scratch[r, 10]),
                               (scratch[r, 0], scratch[r, 1], scratch[r, 2])):
                n, n_seen = emit_unique(scratch, r, pb, m_b, t, seen, n_seen, out_f, out_i, n)
    return n
