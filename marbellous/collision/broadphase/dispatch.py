"""The broad-phase dispatcher: one kernel entry per operation, the method chosen by an integer code.

All entries are Numba kernels that can be called from inside another ``@njit`` function (the step):

``count = find_pairs(method, aabbs, flags, groups, masks, n_bodies, state_f, state_i, pairs_out)``
    Updates the method's structure and writes every pair ``(i, j)``, ``i < j < n_bodies``, that is
    alive, passes the filter, is not static-static and whose boxes overlap (closed intervals), sorted
    lexicographically, into ``pairs_out`` (pair_capacity, 2) int64.  Returns the full count; if it
    exceeds ``pair_capacity`` only the first ``pair_capacity`` pairs are written (grow and call
    again: the same boxes give the same answer).  The list is identical for every method.
``update(method, aabbs, flags, n_bodies, state_f, state_i)``
    Brings the structure up to date with the boxes without listing pairs.
``count = query_aabb(method, aabbs, flags, n_bodies, state_f, state_i, box_min, box_max, out)``
    Live bodies whose box overlaps ``[box_min, box_max]`` (m), ascending.
``count = query_ray(method, aabbs, flags, n_bodies, state_f, state_i, origin, direction,
max_distance, out)``
    Live bodies whose box the ray ``origin + t * direction / |direction|``, ``0 <= t <= max_distance``
    (m) enters, sorted by entry distance, ties by index.

Queries answer over the structure of the last ``find_pairs``/``update`` with the same ``n_bodies``
(the boxes are those of the last step); after changing boxes or flags call ``update`` first.

Inputs: ``aabbs`` (capacity, 6) float64 rows ``[minx, miny, minz, maxx, maxy, maxz]``; ``flags``
(capacity,) int64, bit 0 alive, bit 1 static; ``groups``, ``masks`` (capacity,) int64 filter bits,
pair ``(i, j)`` allowed if ``(groups[i] & masks[j]) != 0 and (groups[j] & masks[i]) != 0``.
``state_f``, ``state_i`` come from ``make_state(method, capacity)``; remake them when the capacity
grows (a fresh state makes the next update rebuild from scratch).
"""
import numpy as np

from marbellous._numba.jit import njit, njit_inline
from marbellous.collision.broadphase._common import (HEADER_F, HEADER_I, I_CAPACITY, I_METHOD, I_N_PREV, keep_alive,
                                                     write_indices, write_pairs, write_ray_hits)
from marbellous.collision.broadphase.brute_force import brute_force_pairs, scan_query_aabb, scan_query_ray
from marbellous.collision.broadphase.bsp_tree import bsp_build, bsp_init_params
from marbellous.collision.broadphase.dynamic_bvh import (bvh_init_params, bvh_pairs, bvh_query_aabb, bvh_query_ray,
                                                         bvh_state_sizes, bvh_update)
from marbellous.collision.broadphase.kd_tree import kd_build, kd_init_params
from marbellous.collision.broadphase.loose_octree import octree_build, octree_init_params
from marbellous.collision.broadphase.static_tree import (F_PLANE_TOLERANCE, I_N_NODES, tree_pairs, tree_query_aabb,
                                                         tree_query_ray, tree_state_sizes, tree_views)
from marbellous.collision.broadphase.sweep_and_prune import (sap_init_params, sap_pairs, sap_query_aabb,
                                                             sap_state_sizes, sap_update)
from marbellous.collision.broadphase.uniform_grid import GRID_MIN_SLOTS, grid_init_params, grid_pairs, grid_state_sizes

BRUTE = 0
SAP = 1
GRID = 2
BVH = 3
OCTREE = 4
KDTREE = 5
BSP = 6

#: Broad-phase names (as accepted by ``World(broadphase=...)``) and their kernel codes.
METHODS = {"brute": BRUTE, "sap": SAP, "grid": GRID, "bvh": BVH, "octree": OCTREE,
           "kdtree": KDTREE, "bsp": BSP}


def state_sizes(method, capacity):
    """Lengths ``(len(state_f), len(state_i))`` of the state of ``method`` for ``capacity`` slots:

    brute ``(8, 8)``; sap ``(8 + c, 8 + c)``; grid ``(8, 8)`` (the grid is rebuilt each update);
    bvh ``(8 + 12 c, 8 + 11 c)``; octree, kdtree, bsp ``(8 + 11 M + c, 8 + 4 M + c)`` with
    ``M = 2 c + 16`` nodes.
    """
    if method in (BRUTE, GRID):
        return grid_state_sizes(capacity)
    if method == SAP:
        return sap_state_sizes(capacity)
    if method == BVH:
        return bvh_state_sizes(capacity)
    return tree_state_sizes(capacity)


def make_state(method, capacity):
    """Fresh state arrays ``(state_f, state_i)`` for ``method`` (a code from ``METHODS``) and
    ``capacity`` body slots, with the method's default tunables; the next update rebuilds."""
    if isinstance(method, bool) or not isinstance(method, (int, np.integer)) \
            or method not in METHODS.values():
        raise ValueError(f"method must be one of the codes {sorted(METHODS.values())}, got {method!r}")
    if isinstance(capacity, bool) or not isinstance(capacity, (int, np.integer)) or capacity < 0:
        raise ValueError(f"capacity must be an integer >= 0, got {capacity!r}")
    nf, ni = state_sizes(method, int(capacity))
    state_f = np.zeros(max(nf, HEADER_F), np.float64)
    state_i = np.zeros(max(ni, HEADER_I), np.int64)
    state_i[I_METHOD] = method
    state_i[I_CAPACITY] = capacity
    state_i[I_N_PREV] = -1
    if method == SAP:
        sap_init_params(state_f)
    elif method == GRID:
        grid_init_params(state_f)
    elif method == BVH:
        bvh_init_params(state_f)
    elif method == OCTREE:
        octree_init_params(state_f)
    elif method == KDTREE:
        kd_init_params(state_f)
    elif method == BSP:
        bsp_init_params(state_f)
    return state_f, state_i


@njit_inline
def _check(method, aabbs, flags, n_bodies, state_i):
    """Reject a state made for another method or too small, and arrays shorter than ``n_bodies``."""
    if state_i[I_METHOD] != method:
        raise ValueError("broad phase: state was made for another method")
    if n_bodies < 0 or n_bodies > state_i[I_CAPACITY]:
        raise ValueError("broad phase: n_bodies exceeds the state's capacity")
    if aabbs.shape[0] < n_bodies or flags.shape[0] < n_bodies:
        raise ValueError("broad phase: aabbs/flags shorter than n_bodies")


@njit
def _build_tree(method, aabbs, flags, n_bodies, state_f, state_i):
    """Rebuild the octree, KD-tree or BSP tree."""
    if method == OCTREE:
        octree_build(aabbs, flags, n_bodies, state_f, state_i)
    elif method == KDTREE:
        kd_build(aabbs, flags, n_bodies, state_f, state_i)
    else:
        bsp_build(aabbs, flags, n_bodies, state_f, state_i)


@njit_inline
def update(method, aabbs, flags, n_bodies, state_f, state_i):
    """Bring ``method``'s structure up to date with the first ``n_bodies`` boxes."""
    _check(method, aabbs, flags, n_bodies, state_i)
    if method == SAP:
        sap_update(aabbs, flags, n_bodies, state_f, state_i)
    elif method == BVH:
        bvh_update(aabbs, flags, n_bodies, state_f, state_i)
    elif method >= OCTREE:
        _build_tree(method, aabbs, flags, n_bodies, state_f, state_i)
    else:
        state_i[I_N_PREV] = n_bodies


@njit_inline
def _collect_pairs(method, aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys):
    """Pair keys of the up-to-date structure into ``keys`` (while it has room); returns the count."""
    if method == BRUTE or (method == GRID and n_bodies <= GRID_MIN_SLOTS):
        return brute_force_pairs(aabbs, flags, groups, masks, n_bodies, keys)
    if method == SAP:
        return sap_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys)
    if method == GRID:
        return grid_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys)
    if method == BVH:
        return bvh_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys)
    node_i, bounds, items, _, planes = tree_views(state_f, state_i)
    return tree_pairs(node_i, bounds, planes, state_f[F_PLANE_TOLERANCE], items, state_i[I_N_NODES],
                      aabbs, flags, groups, masks, n_bodies, keys)


@njit_inline
def find_pairs(method, aabbs, flags, groups, masks, n_bodies, state_f, state_i, pairs_out):
    """Every overlapping, filter-passing pair among the first ``n_bodies`` slots, in canonical order,
    into ``pairs_out``; returns the full number of pairs (see the module docstring)."""
    update(method, aabbs, flags, n_bodies, state_f, state_i)
    # as many keys as the caller's pair buffer holds (a world keeps it as large as its busiest step), so
    # the pairs are collected once, not once to count and again to write
    keys = np.empty(max(64, 4 * n_bodies, pairs_out.shape[0]), np.int64)
    count = _collect_pairs(method, aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys)
    if count > keys.shape[0]:
        keys = np.empty(count, np.int64)
        count = _collect_pairs(method, aabbs, flags, groups, masks, n_bodies, state_f, state_i,
                               keys)
    return write_pairs(keys, count, n_bodies, pairs_out)


@njit
def _collect_box_query(method, aabbs, flags, n_bodies, state_f, state_i, box_min, box_max, buf):
    """Bodies overlapping ``[box_min, box_max]`` into ``buf`` (while it has room); returns the count."""
    if method == BRUTE or method == GRID:
        return scan_query_aabb(aabbs, flags, n_bodies, box_min, box_max, buf)
    if method == SAP:
        return sap_query_aabb(aabbs, flags, n_bodies, state_f, state_i, box_min, box_max, buf)
    if method == BVH:
        return bvh_query_aabb(aabbs, state_f, state_i, box_min, box_max, buf)
    node_i, bounds, items, _, planes = tree_views(state_f, state_i)
    return tree_query_aabb(node_i, bounds, planes, state_f[F_PLANE_TOLERANCE], items,
                           state_i[I_N_NODES], aabbs, box_min, box_max, buf)


@njit_inline
def _collect_ray_query(method, aabbs, flags, n_bodies, state_f, state_i, origin, unit,
                       max_distance, buf):
    """Bodies whose box the ray enters into ``buf`` (while it has room); returns the count."""
    if method == BVH:
        return bvh_query_ray(aabbs, state_f, state_i, origin, unit, max_distance, buf)
    if method >= OCTREE:
        node_i, bounds, items, _, _ = tree_views(state_f, state_i)
        return tree_query_ray(node_i, bounds, items, state_i[I_N_NODES], aabbs, origin, unit,
                              max_distance, buf)
    return scan_query_ray(aabbs, flags, n_bodies, origin, unit, max_distance, buf)


@njit
def query_aabb(method, aabbs, flags, n_bodies, state_f, state_i, box_min, box_max, out):
    """Live bodies whose box overlaps ``[box_min, box_max]`` (m), ascending, into ``out``; returns
    the full count (at most ``len(out)`` are written)."""
    _check(method, aabbs, flags, n_bodies, state_i)
    if state_i[I_N_PREV] != n_bodies:
        update(method, aabbs, flags, n_bodies, state_f, state_i)
    buf = np.empty(64, np.int64)
    count = _collect_box_query(method, aabbs, flags, n_bodies, state_f, state_i, box_min, box_max,
                               buf)
    if count > buf.shape[0]:
        buf = np.empty(count, np.int64)
        count = _collect_box_query(method, aabbs, flags, n_bodies, state_f, state_i, box_min,
                                   box_max, buf)
    count = keep_alive(buf, count, flags)
    return write_indices(buf, count, out)


@njit_inline
def query_ray(method, aabbs, flags, n_bodies, state_f, state_i, origin, direction, max_distance,
              out):
    """Live bodies whose box the ray from ``origin`` along ``direction`` (any non-zero length) enters
    within ``max_distance`` (m), sorted by entry distance then index, into ``out``; returns the full
    count (at most ``len(out)`` are written).  Inlined: where ``method`` is a constant, only its broad
    phase is compiled."""
    _check(method, aabbs, flags, n_bodies, state_i)
    if state_i[I_N_PREV] != n_bodies:
        update(method, aabbs, flags, n_bodies, state_f, state_i)
    length = np.sqrt(direction[0] ** 2 + direction[1] ** 2 + direction[2] ** 2)
    unit = direction / length
    buf = np.empty(64, np.int64)
    count = _collect_ray_query(method, aabbs, flags, n_bodies, state_f, state_i, origin, unit,
                               max_distance, buf)
    if count > buf.shape[0]:
        buf = np.empty(count, np.int64)
        count = _collect_ray_query(method, aabbs, flags, n_bodies, state_f, state_i, origin, unit,
                                   max_distance, buf)
    count = keep_alive(buf, count, flags)
    return write_ray_hits(buf, count, aabbs, origin, unit, max_distance, out)
