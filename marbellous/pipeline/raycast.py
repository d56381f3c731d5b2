"""The world's queries on the broad phase: the ray cast and the box query.

Both first bring the bodies' boxes and the broad phase up to the bodies' poses now (a pose set by hand
since the last step counts).  Ray candidates come from the broad phase's ray query over the bodies'
boxes, sorted by where the ray enters each box; the search stops once a box is entered beyond the
nearest exact hit found so far.
"""
import numpy as np

from .._numba.jit import njit, njit_inline
from ..collision.broadphase import GRID, query_aabb, query_ray, update
from ..collision.ray.raycast import raycast_shape
from ..state.layout import FLAGS, GROUP, S_OFF_F, S_OFF_I, S_PARAMS, S_TYPE, SHAPE_COUNT, SHAPE_START
from .collide import pose_tables, shape_pose, update_aabbs


@njit_inline
def refresh_boxes(bf, bi, sf, si, aabbs, bp_f, bp_i, method, nb):
    """The bodies' boxes (no sweep) and the broad phase ``method`` (a constant where this is inlined: only
    its broad phase compiled) at the bodies' current poses."""
    sweep = np.empty(nb)
    pos_t, rot_t, _, q = pose_tables(sf.shape[0])
    update_aabbs(bf, bi, sf, si, nb, aabbs, sweep, 0.0, 0.0, 0.0, pos_t, rot_t, q)
    update(method, aabbs, bi[:, FLAGS], nb, bp_f, bp_i)


@njit
def query_box_world(bf, bi, sf, si, aabbs, bp_f, bp_i, method, nb, lower, upper, out):
    """The bodies whose boxes overlap ``[lower, upper]`` (m), ascending rows, into ``out`` (at least ``nb``
    ints); returns their count."""
    refresh_boxes(bf, bi, sf, si, aabbs, bp_f, bp_i, method, nb)
    return query_aabb(method, aabbs, bi[:, FLAGS], nb, bp_f, bp_i, lower, upper, out)


@njit
def raycast_world(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, method, nb, origin, direction,
                  max_distance, mask, candidates, hit):
    """Nearest hit of the ray on the bodies whose ``group & mask`` is nonzero; writes
    ``hit = [distance, body, px, py, pz, nx, ny, nz]`` and returns True.

    ``candidates`` is scratch of at least ``nb`` ints; ``direction`` is a unit vector.  ``method``: the
    world's broad phase (for the grid, :func:`raycast_world_grid` compiles no other).
    """
    return _raycast_world(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, method, nb, origin, direction,
                          max_distance, mask, candidates, hit)


@njit
def raycast_world_grid(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, nb, origin, direction, max_distance, mask,
                       candidates, hit):
    """:func:`raycast_world` in a world of the grid broad phase (the default)."""
    return _raycast_world(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, GRID, nb, origin, direction,
                          max_distance, mask, candidates, hit)


@njit_inline
def _raycast_world(bf, bi, sf, si, geom_f, geom_i, aabbs, bp_f, bp_i, method, nb, origin, direction,
                   max_distance, mask, candidates, hit):
    """:func:`raycast_world`, inlined."""
    refresh_boxes(bf, bi, sf, si, aabbs, bp_f, bp_i, method, nb)
    count = query_ray(method, aabbs, bi[:, FLAGS], nb, bp_f, bp_i, origin, direction, max_distance, candidates)
    best = max_distance
    found = False
    pos = np.empty(3)
    rot = np.empty((3, 3))
    normal = np.empty(3)
    for k in range(min(count, candidates.shape[0])):
        b = candidates[k]
        if (bi[b, GROUP] & mask) == 0:
            continue
        # Entry distance of b's box: no shape inside can be nearer.
        lo = aabbs[b]
        entry = 0.0
        for d in range(3):
            if direction[d] != 0.0:
                t1 = (lo[d] - origin[d]) / direction[d]
                t2 = (lo[3 + d] - origin[d]) / direction[d]
                entry = max(entry, min(t1, t2))
        if found and entry > best:
            break
        for s in range(bi[b, SHAPE_START], bi[b, SHAPE_START] + bi[b, SHAPE_COUNT]):
            shape_pose(bf, sf, s, b, pos, rot)
            t = raycast_shape(si[s, S_TYPE], pos, rot, sf[s, S_PARAMS:S_PARAMS + 8], geom_f, geom_i,
                              si[s, S_OFF_F], si[s, S_OFF_I], origin, direction, best, normal)
            if t >= 0.0 and (not found or t < best):
                found = True
                best = t
                hit[0] = t
                hit[1] = b
                for d in range(3):
                    hit[2 + d] = origin[d] + t * direction[d]
                    hit[5 + d] = normal[d]
    return found
