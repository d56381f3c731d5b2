"""The node layout shared by the rebuilt trees (loose octree, KD-tree, BSP tree) and the traversals
that answer pair, box and ray queries over it.

A tree over ``m`` live bodies is stored in three arrays:

``node_i`` (max_nodes, 4) int64 rows ``[child_start, child_count, item_start, item_count]``: a node's
children are the consecutive nodes ``child_start .. child_start + child_count - 1`` (always numbered
after their parent), and the bodies stored *at* the node are ``items[item_start : item_start +
item_count]`` (leaves hold their bodies; a BSP node keeps the boxes its plane cuts; an octree node the
boxes too big for its children);
``bounds`` (max_nodes, 6) float64: the tight box around every body in the node's subtree;
``items`` (capacity,) int64: the live body indices, permuted by the build.

Pruning uses only the tight bounds, which are unions (min/max, no arithmetic) of the bodies' own boxes,
so pruning never drops an overlap and every method reports exactly the brute-force pairs.  Node 0 is
the root.  Traversals use an explicit stack (no recursion).
"""
import numpy as np

from marbellous._jit import njit
from marbellous.collision.broadphase._common import (
    HEADER_F, HEADER_I, I_CAPACITY, STATIC, add_index, add_pair, is_alive, pair_allowed, ray_entry,
    row_overlaps_box, rows_overlap)


def tree_max_nodes(capacity):
    """Node capacity of a rebuilt tree for ``capacity`` body slots (every tree here has at most
    2 m - 1 nodes for m bodies; the octree stops splitting when it would exceed this)."""
    return 2 * capacity + 16


#: ``state_i[I_N_NODES]``: number of nodes of the tree built by the last update.
I_N_NODES = 3


def tree_state_sizes(capacity):
    """Lengths ``(len(state_f), len(state_i))`` of a rebuilt tree's state: node bounds and one
    float scratch key per slot; node rows and the item permutation."""
    m = tree_max_nodes(capacity)
    return HEADER_F + 6 * m + capacity, HEADER_I + 4 * m + capacity


@njit
def tree_views(state_f, state_i):
    """Views ``(node_i, bounds, items, keys)`` into a rebuilt tree's state arrays."""
    cap = state_i[I_CAPACITY]
    m = 2 * cap + 16
    node_i = state_i[HEADER_I:HEADER_I + 4 * m].reshape((m, 4))
    items = state_i[HEADER_I + 4 * m:HEADER_I + 4 * m + cap]
    bounds = state_f[HEADER_F:HEADER_F + 6 * m].reshape((m, 6))
    keys = state_f[HEADER_F + 6 * m:HEADER_F + 6 * m + cap]
    return node_i, bounds, items, keys


@njit
def refit_bounds(node_i, bounds, items, aabbs, n_nodes):
    """Tight bounds of every node, children first (children are numbered after their parents)."""
    for node in range(n_nodes - 1, -1, -1):
        for k in range(3):
            bounds[node, k] = np.inf
            bounds[node, k + 3] = -np.inf
        s = node_i[node, 2]
        for p in range(s, s + node_i[node, 3]):
            i = items[p]
            for k in range(3):
                bounds[node, k] = min(bounds[node, k], aabbs[i, k])
                bounds[node, k + 3] = max(bounds[node, k + 3], aabbs[i, k + 3])
        c = node_i[node, 0]
        for child in range(c, c + node_i[node, 1]):
            for k in range(3):
                bounds[node, k] = min(bounds[node, k], bounds[child, k])
                bounds[node, k + 3] = max(bounds[node, k + 3], bounds[child, k + 3])


@njit
def tree_pairs(node_i, bounds, items, n_nodes, aabbs, flags, groups, masks, n_bodies, keys):
    """Every overlapping, filter-passing pair, by querying the tree with each live dynamic body's box.
    A pair ``(i, j)`` is recorded from ``i``'s query if ``j`` is static or ``j > i``, so it is recorded
    exactly once.  Returns the number of pairs (written while ``keys`` has room)."""
    count = 0
    if n_nodes == 0:
        return count
    stack = np.empty(n_nodes, np.int64)
    for i in range(n_bodies):
        if not is_alive(flags, i) or (flags[i] & STATIC) != 0:
            continue
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            node = stack[top]
            if not rows_overlap(bounds, node, aabbs, i):
                continue
            s = node_i[node, 2]
            for p in range(s, s + node_i[node, 3]):
                j = items[p]
                if j == i or (j < i and (flags[j] & STATIC) == 0):
                    continue
                if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                    count = add_pair(keys, count, i, j, n_bodies)
            c = node_i[node, 0]
            for child in range(c, c + node_i[node, 1]):
                stack[top] = child
                top += 1
    return count


@njit
def tree_query_aabb(node_i, bounds, items, n_nodes, aabbs, box_min, box_max, buf):
    """Bodies in the tree whose box overlaps ``[box_min, box_max]``.  Returns the number found (written while ``buf`` has room)."""
    count = 0
    if n_nodes == 0:
        return count
    stack = np.empty(n_nodes, np.int64)
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if not row_overlaps_box(bounds, node, box_min, box_max):
            continue
        s = node_i[node, 2]
        for p in range(s, s + node_i[node, 3]):
            j = items[p]
            if row_overlaps_box(aabbs, j, box_min, box_max):
                count = add_index(buf, count, j)
        c = node_i[node, 0]
        for child in range(c, c + node_i[node, 1]):
            stack[top] = child
            top += 1
    return count


@njit
def tree_query_ray(node_i, bounds, items, n_nodes, aabbs, origin, direction, max_distance, buf):
    """Bodies in the tree whose box the ray enters within ``max_distance``.  Returns the number found (written while ``buf`` has room)."""
    count = 0
    if n_nodes == 0:
        return count
    stack = np.empty(n_nodes, np.int64)
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if ray_entry(bounds, node, origin, direction, max_distance) < 0.0:
            continue
        s = node_i[node, 2]
        for p in range(s, s + node_i[node, 3]):
            j = items[p]
            if ray_entry(aabbs, j, origin, direction, max_distance) >= 0.0:
                count = add_index(buf, count, j)
        c = node_i[node, 0]
        for child in range(c, c + node_i[node, 1]):
            stack[top] = child
            top += 1
    return count
