"""The world's shape cast: the first body a convex shape meets as it slides, without turning, from ``start``
to ``end``.

The shape's motion is ``x(t) = start + t (end - start)`` for ``0 <= t <= 1``; each body whose box meets the
box swept by the shape is a candidate, and for each of its shapes the time-of-impact search
(``collision/toi/conservative_advancement``, the pair test as its distance oracle) finds the first ``t``
the gap closes to ``HIT_TOLERANCE``.  The nearest over all candidates is the hit, at distance
``t |end - start|``; its point and normal come from the pair test at that pose (the point: the middle of
the touching points, the normal turned to point from the body towards the shape, as a ray hit's does).
A shape that already overlaps a body hits it at distance 0.
"""
import math

import numpy as np

from .._numba.jit import njit
from ..collision import shape_types as st
from ..collision.aabb import shape_bounds
from ..collision.broadphase import query_aabb
from ..collision.pairs.dispatch import collide_pair_covering
from ..collision.toi.conservative_advancement import MISS, time_of_impact
from ..math3d import quat_to_matrix
from ..state.layout import (FLAGS, GROUP, POS, QUAT, S_LOCAL_POS, S_LOCAL_QUAT, S_OFF_F, S_OFF_I, S_PARAMS, S_TYPE,
                            SHAPE_COUNT, SHAPE_START)
from .raycast import refresh_boxes

#: the gap (m) at which the cast shape has reached a surface
HIT_TOLERANCE = 1e-7
#: rows of the pair test's contact buffer
CONTACT_ROWS = 64


@njit
def shape_cast_world(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, method, nb, cast_type, cast_params, cast_off_f,
                     cast_off_i, start, end, quat, mask, candidates, hit):
    """First hit of the convex shape (``cast_type``, kernel record ``cast_params``, a hull's geometry at
    ``cast_off_f``/``cast_off_i`` of the blobs) at orientation ``quat``
    moved from ``start`` to ``end`` (m) on the bodies whose ``group & mask`` is nonzero; writes
    ``hit = [distance, body, px, py, pz, nx, ny, nz]`` and returns True.  ``candidates``: scratch of at
    least ``nb`` ints."""
    refresh_boxes(bf, bi, sf, si, aabbs, bp_f, bp_i, method, nb)
    rot = np.empty((3, 3))
    quat_to_matrix(quat, rot)
    lo0, hi0 = shape_bounds(cast_type, start, rot, cast_params)
    lo1, hi1 = shape_bounds(cast_type, end, rot, cast_params)
    lower = np.array([min(lo0[k], lo1[k]) for k in range(3)])
    upper = np.array([max(hi0[k], hi1[k]) for k in range(3)])
    count = query_aabb(method, aabbs, bi[:, FLAGS], nb, bp_f, bp_i, lower, upper, candidates)
    d = (end[0] - start[0], end[1] - start[1], end[2] - start[2])
    length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    zero = (0.0, 0.0, 0.0)
    q = (quat[0], quat[1], quat[2], quat[3])
    cast_motion = ((start[0], start[1], start[2]), d, zero, q, zero)
    identity = (1.0, 0.0, 0.0, 0.0)
    out_f = np.empty((CONTACT_ROWS, 7))
    out_i = np.empty(CONTACT_ROWS, np.int64)
    pos_t = np.empty((2, 3))
    rot_t = np.empty((2, 3, 3))
    q_scratch = np.empty(4)
    touch = np.zeros(CONTACT_ROWS + 1, np.int64)
    best = math.inf
    found = False
    for k in range(min(count, candidates.shape[0])):
        b = candidates[k]
        if (bi[b, GROUP] & mask) == 0:
            continue
        body_motion = ((bf[b, POS], bf[b, POS + 1], bf[b, POS + 2]), zero, zero,
                       (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3]), zero)
        for s in range(bi[b, SHAPE_START], bi[b, SHAPE_START] + bi[b, SHAPE_COUNT]):
            outcome, t = time_of_impact(
                st.COVER_ALL, cast_type, cast_params, cast_off_f, cast_off_i, cast_motion, zero, identity, 0.0,
                si[s, S_TYPE], sf[s, S_PARAMS:S_PARAMS + st.N_SHAPE_PARAMS], si[s, S_OFF_F], si[s, S_OFF_I],
                body_motion, (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]),
                (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2], sf[s, S_LOCAL_QUAT + 3]),
                0.0, geom_f, geom_i, 1.0, 0.0, HIT_TOLERANCE, 0.0, out_f, out_i, pos_t, rot_t, q_scratch, touch)
            if outcome == MISS or (found and t >= best):
                continue
            # the contact at the hit: the pair test at that pose (positions as the search posed them)
            for j in range(3):
                pos_t[0, j] = start[j] + t * d[j]
            n = collide_pair_covering(st.COVER_ALL, cast_type, pos_t[0], rot, cast_params, si[s, S_TYPE], pos_t[1],
                                      rot_t[1], sf[s, S_PARAMS:S_PARAMS + st.N_SHAPE_PARAMS], geom_f, geom_i,
                                      cast_off_f, cast_off_i, si[s, S_OFF_F], si[s, S_OFF_I],
                                      2.0 * HIT_TOLERANCE + 1e-9 * length, out_f, out_i, 0)
            if n == 0:
                continue
            m = min(n, CONTACT_ROWS)
            deepest = 0
            for j in range(1, m):
                if out_f[j, 6] > out_f[deepest, 6]:
                    deepest = j
            found = True
            best = t
            hit[0] = t * length
            hit[1] = b
            # the point: the mean of the contact points as deep as the deepest (a face's patch: its middle)
            hit[2:5] = 0.0
            level = 0
            for j in range(m):
                if out_f[j, 6] >= out_f[deepest, 6] - HIT_TOLERANCE:
                    level += 1
                    for i in range(3):
                        hit[2 + i] += out_f[j, i]
            for j in range(3):
                hit[2 + j] /= level
                hit[5 + j] = -out_f[deepest, 3 + j]
    return found
