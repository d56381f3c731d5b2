"""Convex shape (sphere, capsule, box) against a static triangle mesh, through its acceleration.

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

from .._jit import njit, njit_inline
from . import mesh_layout as ml
from .aabb import boxes_overlap, sphere_misses_box
from .bvh_static import bvh_candidates
from .grid2d import grid_candidates
from . import shape_types as st
from .triangle_contact import MAX_ROWS, N_COLS, SEEN_ROWS, edge_is_true, vertex_ring_passes, write_row
from .triangle_convex import convex_local_bounds, convex_triangle, emit_unique, to_static_frame
from .triangle_sphere import EDGE_AB, EDGE_CA, VERTEX_A, VERTEX_B, VERTEX_C, sphere_triangle


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
def keep_row(geom_f, geom_i, off_f, off_i, t, scratch, r):
    """Voronoi test on the whole mesh of scratch row ``r`` (a contact with triangle ``t``): edge rows
    against the neighbour's direction, vertex rows against the vertex's ring; others pass."""
    f = int(scratch[r, 7])
    p = (scratch[r, 8], scratch[r, 9], scratch[r, 10])
    if EDGE_AB <= f <= EDGE_CA:
        return edge_is_true(p, (scratch[r, 0], scratch[r, 1], scratch[r, 2]),
                            ml.neighbour_direction(geom_f, geom_i, off_f, off_i, t, f - EDGE_AB))
    if VERTEX_A <= f <= VERTEX_C:
        ia, ib, ic = ml.corners(geom_f, geom_i, off_f, off_i, t)
        v = ia if f == VERTEX_A else (ib if f == VERTEX_B else ic)
        return vertex_is_true(geom_f, geom_i, off_f, off_i, v, p)
    return True


@njit
def collide_convex_mesh(type_a, pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, geom_i,
                        off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of convex shape a (SPHERE, CAPSULE or BOX) with the static mesh b.

    ``pos_*`` (3,) world positions (m), ``rot_*`` (3, 3) rotations, ``params_*`` kernel records,
    ``geom_f``/``geom_i`` the global geometry blobs with b's slices at ``off_f_b``/``off_i_b``;
    ``prediction`` (m) speculative distance.  Appends rows to ``out_f``/``out_i`` (the buffer
    convention of docs/architecture.md: normal from a to b) and returns the new count.
    """
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    lo, hi = convex_local_bounds(type_a, c, rot, params_a, prediction)
    cand, first, count = mesh_candidates(params_b, geom_f, geom_i, off_f_b, off_i_b, lo, hi)
    scratch = np.empty((MAX_ROWS, N_COLS))
    seen = np.empty((SEEN_ROWS, 7))
    n_seen = 0
    zero = (0.0, 0.0, 0.0)
    reach = params_a[0] + prediction
    for j in range(first, first + count):
        t = cand[j]
        a, b, cc, nrm = ml.triangle(geom_f, geom_i, off_f_b, off_i_b, t)
        if nrm[0] == 0.0 and nrm[1] == 0.0 and nrm[2] == 0.0:
            continue                                  # degenerate
        if type_a == st.SPHERE:
            if sphere_misses_box(c, reach, a, b, cc):
                continue                              # too far
            # convex_triangle's sphere case, by values: a miss costs no call that takes arrays (whose
            # references Numba would count)
            feature, q, normal, depth = sphere_triangle(c, params_a[0], a, b, cc, nrm, prediction)
            if feature < 0:
                continue
            k = write_row(scratch, 0, q, normal, depth, feature, c)
        else:
            if not boxes_overlap(a, b, cc, lo, hi):
                continue                              # too far
            m0 = m1 = m2 = zero
            if type_a == st.BOX:
                m0 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 0)
                m1 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 1)
                m2 = ml.neighbour_direction(geom_f, geom_i, off_f_b, off_i_b, t, 2)
            k = convex_triangle(type_a, c, rot, params_a, a, b, cc, nrm, m0, m1, m2, prediction, scratch)
        for r in range(k):
            if keep_row(geom_f, geom_i, off_f_b, off_i_b, t, scratch, r):
                n, n_seen = emit_unique(scratch, r, pos_b, rot_b, t, seen, n_seen, out_f, out_i, n)
    return n
