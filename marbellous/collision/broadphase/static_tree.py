"""The node layout shared by the rebuilt trees (loose octree, KD-tree, BSP tree) and the traversals
that answer pair, box and ray queries over it.

A tree over ``m`` live bodies is stored in four arrays:

``node_i`` (max_nodes, 4) int64 rows ``[child_start, child_count, item_start, item_count]``: a node's
children are the consecutive nodes ``child_start .. child_start + child_count - 1`` (always numbered
after their parent), and the bodies stored *at* the node are ``items[item_start : item_start +
item_count]`` (leaves hold their bodies; an octree node also the boxes too big for its children);
``bounds`` (max_nodes, 6) float64: the tight box around every body in the node's subtree;
``items`` (capacity,) int64: the live body indices, permuted by the build;
``planes`` (max_nodes, 5) float64 rows ``[nx, ny, nz, d, side]``: for BSP children, the parent's plane and
which side of it the node's boxes lie on (side 0: no plane test; kd-tree and octree leave it 0).

Pruning uses the tight bounds, which are unions (min/max, no arithmetic) of the bodies' own boxes, and
for BSP nodes the parent's plane with a rounding allowance; so pruning never drops an overlap and every
method reports exactly the brute-force pairs.  Node 0 is the root.  Traversals use an explicit stack
(no recursion).
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import (HEADER_F, HEADER_I, I_CAPACITY, I_N_PREV, STATIC, add_index,
                                                     add_pair, is_alive, pair_allowed, ray_entry, row_overlaps_box,
                                                     rows_overlap)


@njit
def tree_max_nodes(capacity):
    """Node capacity of a rebuilt tree for ``capacity`` body slots (every tree here has at most
    2 m - 1 nodes for m bodies; the octree stops splitting when it would exceed this)."""
    return 2 * capacity + 16


#: ``state_i[I_N_NODES]``: number of nodes of the tree built by the last update.
I_N_NODES = 3
#: ``state_i[I_N_ITEMS]``: number of bodies in the tree built by the last full build.
I_N_ITEMS = 4
#: ``state_f[F_REFIT_GROWTH]``: tunable of the trees that may refit instead of rebuilding (see
#: ``try_refit``); 0 means rebuild at every update.
F_REFIT_GROWTH = 2
#: ``state_f[F_PLANE_TOLERANCE]``: rounding allowance of the plane tests (m), written by the build.
F_PLANE_TOLERANCE = 4
#: ``state_f[F_BUILT_AREA]``: summed surface area of the node bounds right after the last full build.
F_BUILT_AREA = 5
#: ``planes[node, SIDE]``: 0 no plane test, 1 the node holds only boxes behind its parent's plane
#: ``planes[node, :4] = (n, d)``, 2 only boxes in front of it.
SIDE = 4


def tree_state_sizes(capacity):
    """Lengths ``(len(state_f), len(state_i))`` of a rebuilt tree's state: node bounds, parent
    planes and one float scratch key per slot; node rows and the item permutation."""
    m = tree_max_nodes(capacity)
    return HEADER_F + 11 * m + capacity, HEADER_I + 4 * m + capacity


@njit
def tree_views(state_f, state_i):
    """Views ``(node_i, bounds, items, keys, planes)`` into a rebuilt tree's state arrays."""
    cap = state_i[I_CAPACITY]
    m = tree_max_nodes(cap)
    node_i = state_i[HEADER_I:HEADER_I + 4 * m].reshape((m, 4))
    items = state_i[HEADER_I + 4 * m:HEADER_I + 4 * m + cap]
    bounds = state_f[HEADER_F:HEADER_F + 6 * m].reshape((m, 6))
    keys = state_f[HEADER_F + 6 * m:HEADER_F + 6 * m + cap]
    planes = state_f[HEADER_F + 6 * m + cap:HEADER_F + 11 * m + cap].reshape((m, 5))
    return node_i, bounds, items, keys, planes


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
def _total_area(bounds, n_nodes):
    """Sum of the surface areas of the node bounds (m^2): the expected cost of a query is
    proportional to it (the surface-area heuristic)."""
    total = 0.0
    for node in range(n_nodes):
        dx = bounds[node, 3] - bounds[node, 0]
        dy = bounds[node, 4] - bounds[node, 1]
        dz = bounds[node, 5] - bounds[node, 2]
        total += 2.0 * (dx * dy + dy * dz + dz * dx)
    return total


@njit
def finish_build(node_i, bounds, items, aabbs, n_nodes, n_items, n_bodies, state_f, state_i):
    """Fit the node bounds of a fresh build and record what ``try_refit`` compares against."""
    refit_bounds(node_i, bounds, items, aabbs, n_nodes)
    state_i[I_N_NODES] = n_nodes
    state_i[I_N_ITEMS] = n_items
    state_f[F_BUILT_AREA] = _total_area(bounds, n_nodes)
    state_i[I_N_PREV] = n_bodies


@njit
def try_refit(aabbs, flags, n_bodies, state_f, state_i):
    """Keep the last build's partition and only refit the node bounds to the moved boxes, if the same
    bodies are alive in the same slots and the summed node area has not grown beyond
    ``refit_growth`` times its value after the build (motion has not spoiled the partition).
    Returns True if the refitted tree was kept; False means the caller must rebuild.  The bounds are
    tight either way, so a refitted tree answers exactly like a fresh one, only more slowly."""
    if state_f[F_REFIT_GROWTH] <= 0.0 or state_i[I_N_PREV] != n_bodies:
        return False
    node_i, bounds, items, _, _ = tree_views(state_f, state_i)
    m = state_i[I_N_ITEMS]
    for p in range(m):
        if not is_alive(flags, items[p]):
            return False
    live = 0
    for i in range(n_bodies):
        if is_alive(flags, i):
            live += 1
    if live != m:
        return False
    n_nodes = state_i[I_N_NODES]
    refit_bounds(node_i, bounds, items, aabbs, n_nodes)
    return _total_area(bounds, n_nodes) <= state_f[F_REFIT_GROWTH] * state_f[F_BUILT_AREA]


@njit
def plane_key_radius(n, box, r):
    """Projection of box row ``box[r]`` onto the unit normal ``n``: centre ``n . c`` and radius
    ``sum_k |n_k| h_k`` (m).  Builds and queries use this one function, so their roundings agree."""
    key = 0.0
    radius = 0.0
    for k in range(3):
        key += n[k] * 0.5 * (box[r, k] + box[r, k + 3])
        radius += abs(n[k]) * 0.5 * (box[r, k + 3] - box[r, k])
    return key, radius


@njit
def outside_parent_plane(planes, node, box, r, tolerance):
    """True if box row ``box[r]`` lies strictly on the other side of the plane that put ``node``'s
    boxes behind (side 1) or in front of it (side 2), by more than ``tolerance``.

    Sound despite rounding: a body in the back child has computed ``key + radius < d``, so a box
    that touches it has computed ``key - radius <= d + (both rounding errors)``, and ``tolerance``
    (1e-10 of the largest coordinate) exceeds that sum by orders of magnitude."""
    side = planes[node, SIDE]
    if side == 0.0:
        return False
    key, radius = plane_key_radius(planes[node, :3], box, r)
    if side == 1.0:
        return key - radius > planes[node, 3] + tolerance
    return key + radius < planes[node, 3] - tolerance


@njit
def _tree_body_count(node_i, n_nodes):
    """Number of bodies in the tree: ``items[:count]`` (every node's items are a slice of it)."""
    total = 0
    for node in range(n_nodes):
        total += node_i[node, 3]
    return total


@njit
def tree_pairs(node_i, bounds, planes, tolerance, items, n_nodes, aabbs, flags, groups, masks,
               n_bodies, keys):
    """Every overlapping, filter-passing pair, by querying the tree with each dynamic body's box.
    A pair ``(i, j)`` is recorded from ``i``'s query if ``j`` is static or ``j > i``, so it is recorded
    exactly once.  Returns the number of pairs (written while ``keys`` has room)."""
    count = 0
    if n_nodes == 0:
        return count
    stack = np.empty(n_nodes, np.int64)
    # query in tree order: consecutive queries walk the same nodes, which stay in cache
    for p_query in range(_tree_body_count(node_i, n_nodes)):
        i = items[p_query]
        if (flags[i] & STATIC) != 0:
            continue
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            node = stack[top]
            if not rows_overlap(bounds, node, aabbs, i) \
                    or outside_parent_plane(planes, node, aabbs, i, tolerance):
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
def tree_query_aabb(node_i, bounds, planes, tolerance, items, n_nodes, aabbs, box_min, box_max,
                    buf):
    """Bodies in the tree whose box overlaps ``[box_min, box_max]``.
    Returns the number found (written while ``buf`` has room)."""
    count = 0
    if n_nodes == 0:
        return count
    query = np.empty((1, 6))
    query[0, :3] = box_min
    query[0, 3:] = box_max
    stack = np.empty(n_nodes, np.int64)
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if not row_overlaps_box(bounds, node, box_min, box_max) \
                or outside_parent_plane(planes, node, query, 0, tolerance):
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
    """Bodies in the tree whose box the ray enters within ``max_distance``.
    Returns the number found (written while ``buf`` has room)."""
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
