"""Dynamic AABB tree (bounding volume hierarchy), incremental, after Box2D's ``b2DynamicTree``.

Each live body owns a leaf whose box is *fattened*: grown by ``margin * (largest edge)`` on every side.
At an update, a leaf is removed and reinserted only when its body's box has left the fat box, or the
fat box has become more than ``looseness`` times the wanted fat size along some axis (the body shrank);
otherwise nothing in the tree changes.  Coherent motion therefore touches only a few leaves per step.
When more than ``rebuild_fraction`` of the bodies need reinsertion (a fresh state, fast motion), the
tree is instead rebuilt top-down: leaves sorted along the Morton curve, each run split in half.

Insertion descends from the root choosing, at each internal node, the cheapest of: pairing with the
node itself, or descending into either child, with the surface-area heuristic
``cost(sibling) = SA(sibling U leaf) + sum over ancestors of the growth SA(ancestor U leaf) - SA(ancestor)``.
Walking back up, every ancestor is refitted (its box becomes the union of its children) and rebalanced
by an AVL-style tree rotation when its children's heights differ by more than one, which keeps the
height O(log n) even when bodies are inserted in sorted order.

Pairs come from one descent of the tree against itself; box and ray queries descend through the fat
boxes.  At a leaf the body's own (unfattened) box is tested, so the pair set equals the brute-force one.

State layout (``M = 2 * capacity`` nodes): ``state_f[HEADER_F:][:6M]`` fat boxes;
``state_i[HEADER_I:][:5M]`` node rows ``[parent, child1, child2, height, body]`` (``child1 == -1`` for
a leaf; a free node's ``parent`` links the free list), then ``leaf_of_body`` (capacity,).
``state_i[I_ROOT]``, ``[I_NODE_COUNT]`` (high-water mark), ``[I_FREE]``; tunables ``state_f[F_MARGIN]``,
``state_f[F_LOOSENESS]``, ``state_f[F_REBUILD_FRACTION]``.
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import (HEADER_F, HEADER_I, I_CAPACITY, I_N_PREV, add_index, add_pair,
                                                     alive_indices, is_alive, pair_allowed, ray_entry, row_overlaps_box,
                                                     rows_overlap)

I_ROOT = 3
I_NODE_COUNT = 4
I_FREE = 5
F_MARGIN = 0
F_LOOSENESS = 1
F_REBUILD_FRACTION = 2
PARENT = 0
CHILD1 = 1
CHILD2 = 2
HEIGHT = 3
BODY = 4


@njit
def bvh_max_nodes(capacity):
    """Nodes a tree over ``capacity`` leaves can need: the leaves and at most ``capacity - 1``
    internal nodes."""
    return 2 * capacity


def bvh_state_sizes(capacity):
    """Lengths ``(len(state_f), len(state_i))`` of the dynamic tree state for ``capacity`` slots."""
    m = bvh_max_nodes(capacity)
    return HEADER_F + 6 * m, HEADER_I + 5 * m + capacity


def bvh_init_params(state_f, margin=0.1, looseness=4.0, rebuild_fraction=0.25):
    """Write the tunables: fattening as a fraction of a box's largest edge, how much larger than
    wanted a fat box may grow before its leaf is reinserted, and the fraction of live bodies needing
    reinsertion above which the whole tree is rebuilt instead."""
    state_f[F_MARGIN] = margin
    state_f[F_LOOSENESS] = looseness
    state_f[F_REBUILD_FRACTION] = rebuild_fraction


@njit
def bvh_views(state_f, state_i):
    """Views ``(node, fat, leaf_of_body)`` into the dynamic tree state."""
    cap = state_i[I_CAPACITY]
    m = bvh_max_nodes(cap)
    node = state_i[HEADER_I:HEADER_I + 5 * m].reshape((m, 5))
    leaf_of = state_i[HEADER_I + 5 * m:HEADER_I + 5 * m + cap]
    fat = state_f[HEADER_F:HEADER_F + 6 * m].reshape((m, 6))
    return node, fat, leaf_of


@njit
def _surface_area(fat, a):
    """Surface area of box row ``fat[a]`` (m^2)."""
    dx = fat[a, 3] - fat[a, 0]
    dy = fat[a, 4] - fat[a, 1]
    dz = fat[a, 5] - fat[a, 2]
    return 2.0 * (dx * dy + dy * dz + dz * dx)


@njit
def _union_area(fat, a, b):
    """Surface area of the union of box rows ``fat[a]`` and ``fat[b]`` (m^2)."""
    dx = max(fat[a, 3], fat[b, 3]) - min(fat[a, 0], fat[b, 0])
    dy = max(fat[a, 4], fat[b, 4]) - min(fat[a, 1], fat[b, 1])
    dz = max(fat[a, 5], fat[b, 5]) - min(fat[a, 2], fat[b, 2])
    return 2.0 * (dx * dy + dy * dz + dz * dx)


@njit
def _set_union(fat, dst, a, b):
    """``fat[dst] = fat[a] U fat[b]``."""
    for k in range(3):
        fat[dst, k] = min(fat[a, k], fat[b, k])
        fat[dst, k + 3] = max(fat[a, k + 3], fat[b, k + 3])


@njit
def _alloc(node, state_i):
    """Take a node from the free list, or the next unused one."""
    free = state_i[I_FREE]
    if free >= 0:
        state_i[I_FREE] = node[free, PARENT]
        return free
    idx = state_i[I_NODE_COUNT]
    state_i[I_NODE_COUNT] = idx + 1
    return idx


@njit
def _release(node, state_i, idx):
    """Return node ``idx`` to the free list."""
    node[idx, PARENT] = state_i[I_FREE]
    node[idx, HEIGHT] = -1
    state_i[I_FREE] = idx


@njit
def _replace_child(node, state_i, parent, old, new):
    """Make ``new`` take ``old``'s place under ``parent`` (or as the root)."""
    if parent >= 0:
        if node[parent, CHILD1] == old:
            node[parent, CHILD1] = new
        else:
            node[parent, CHILD2] = new
    else:
        state_i[I_ROOT] = new


@njit
def _balance(node, fat, state_i, a):
    """Rotate the taller grandchild up if ``a``'s children differ in height by more than one.
    Returns the node now at ``a``'s place."""
    if node[a, CHILD1] < 0 or node[a, HEIGHT] < 2:
        return a
    b = node[a, CHILD1]
    c = node[a, CHILD2]
    balance = node[c, HEIGHT] - node[b, HEIGHT]
    if balance > 1 or balance < -1:
        # up: the taller child (it takes a's place); keep: the other child of a
        up = c if balance > 1 else b
        keep = b if balance > 1 else c
        f = node[up, CHILD1]
        g = node[up, CHILD2]
        node[up, CHILD1] = a
        node[up, PARENT] = node[a, PARENT]
        node[a, PARENT] = up
        _replace_child(node, state_i, node[up, PARENT], a, up)
        # the taller grandchild stays under up, the shorter one moves under a
        tall, short = (f, g) if node[f, HEIGHT] > node[g, HEIGHT] else (g, f)
        node[up, CHILD2] = tall
        if balance > 1:
            node[a, CHILD2] = short
        else:
            node[a, CHILD1] = short
        node[short, PARENT] = a
        _set_union(fat, a, keep, short)
        _set_union(fat, up, a, tall)
        node[a, HEIGHT] = 1 + max(node[keep, HEIGHT], node[short, HEIGHT])
        node[up, HEIGHT] = 1 + max(node[a, HEIGHT], node[tall, HEIGHT])
        return up
    return a


@njit
def _refit_upwards(node, fat, state_i, index):
    """From ``index`` to the root: rebalance, then set each node's box and height from its children."""
    while index >= 0:
        index = _balance(node, fat, state_i, index)
        c1 = node[index, CHILD1]
        c2 = node[index, CHILD2]
        node[index, HEIGHT] = 1 + max(node[c1, HEIGHT], node[c2, HEIGHT])
        _set_union(fat, index, c1, c2)
        index = node[index, PARENT]


@njit
def _best_sibling(node, fat, root, leaf):
    """The node to pair ``leaf`` with: least ``SA(sibling U leaf) + sum of the ancestors' growth``,
    by Box2D v3's branch and bound descent (stop when no child's lower bound beats the best so far;
    when both children contain the leaf, descend into the one whose centre is nearer)."""
    area_leaf = _surface_area(fat, leaf)
    area_base = _surface_area(fat, root)
    direct = _union_area(fat, root, leaf)
    inherited = 0.0
    best = root
    best_cost = direct
    index = root
    while node[index, CHILD1] >= 0:
        cost = direct + inherited
        if cost < best_cost:
            best = index
            best_cost = cost
        inherited += direct - area_base
        c1 = node[index, CHILD1]
        c2 = node[index, CHILD2]
        leaf1 = node[c1, CHILD1] < 0
        leaf2 = node[c2, CHILD1] < 0
        direct1 = _union_area(fat, c1, leaf)
        direct2 = _union_area(fat, c2, leaf)
        area1 = _surface_area(fat, c1)
        area2 = _surface_area(fat, c2)
        lower1 = np.inf
        lower2 = np.inf
        if leaf1:
            if direct1 + inherited < best_cost:
                best = c1
                best_cost = direct1 + inherited
        else:
            lower1 = inherited + direct1 + min(area_leaf - area1, 0.0)
        if leaf2:
            if direct2 + inherited < best_cost:
                best = c2
                best_cost = direct2 + inherited
        else:
            lower2 = inherited + direct2 + min(area_leaf - area2, 0.0)
        if leaf1 and leaf2:
            break
        if best_cost <= lower1 and best_cost <= lower2:
            break
        if lower1 == lower2 and not leaf1:
            lower1 = 0.0
            lower2 = 0.0
            for k in range(3):
                centre_leaf = fat[leaf, k] + fat[leaf, k + 3]
                lower1 += (fat[c1, k] + fat[c1, k + 3] - centre_leaf) ** 2
                lower2 += (fat[c2, k] + fat[c2, k + 3] - centre_leaf) ** 2
        if lower1 < lower2 and not leaf1:
            index = c1
            area_base = area1
            direct = direct1
        else:
            index = c2
            area_base = area2
            direct = direct2
    return best


@njit
def _insert_leaf(node, fat, state_i, leaf):
    """Insert ``leaf`` (its fat box already set) by the surface-area heuristic, then refit."""
    root = state_i[I_ROOT]
    if root < 0:
        state_i[I_ROOT] = leaf
        node[leaf, PARENT] = -1
        return
    sibling = _best_sibling(node, fat, root, leaf)
    old_parent = node[sibling, PARENT]
    new_parent = _alloc(node, state_i)
    node[new_parent, PARENT] = old_parent
    node[new_parent, BODY] = -1
    node[new_parent, HEIGHT] = node[sibling, HEIGHT] + 1
    node[new_parent, CHILD1] = sibling
    node[new_parent, CHILD2] = leaf
    _set_union(fat, new_parent, sibling, leaf)
    _replace_child(node, state_i, old_parent, sibling, new_parent)
    node[sibling, PARENT] = new_parent
    node[leaf, PARENT] = new_parent
    _refit_upwards(node, fat, state_i, node[leaf, PARENT])


@njit
def _remove_leaf(node, fat, state_i, leaf):
    """Take ``leaf`` out of the tree (the leaf node itself stays allocated), then refit."""
    if leaf == state_i[I_ROOT]:
        state_i[I_ROOT] = -1
        return
    parent = node[leaf, PARENT]
    grand = node[parent, PARENT]
    sibling = node[parent, CHILD2] if node[parent, CHILD1] == leaf else node[parent, CHILD1]
    _replace_child(node, state_i, grand, parent, sibling)
    node[sibling, PARENT] = grand
    _release(node, state_i, parent)
    if grand >= 0:
        _refit_upwards(node, fat, state_i, grand)


@njit
def _set_fat_box(fat, leaf, aabbs, i, margin):
    """``fat[leaf] = aabbs[i]`` grown by ``margin * (largest edge)`` on every side."""
    edge = 0.0
    for k in range(3):
        edge = max(edge, aabbs[i, k + 3] - aabbs[i, k])
    grow = margin * edge
    for k in range(3):
        fat[leaf, k] = aabbs[i, k] - grow
        fat[leaf, k + 3] = aabbs[i, k + 3] + grow


@njit
def _needs_reinsert(fat, leaf, aabbs, i, margin, looseness):
    """True if body ``i``'s box left its fat box, or the fat box is more than ``looseness`` times
    the wanted fat size along some axis."""
    edge = 0.0
    for k in range(3):
        edge = max(edge, aabbs[i, k + 3] - aabbs[i, k])
    grow = margin * edge
    for k in range(3):
        if aabbs[i, k] < fat[leaf, k] or aabbs[i, k + 3] > fat[leaf, k + 3]:
            return True
        wanted = aabbs[i, k + 3] - aabbs[i, k] + 2.0 * grow
        if fat[leaf, k + 3] - fat[leaf, k] > looseness * wanted:
            return True
    return False


@njit
def _spread_bits(v):
    """Spread the low 21 bits of ``v`` so that two zero bits follow each one (Morton interleave)."""
    v &= 0x1FFFFF
    v = (v | (v << 32)) & 0x1F00000000FFFF
    v = (v | (v << 16)) & 0x1F0000FF0000FF
    v = (v | (v << 8)) & 0x100F00F00F00F00F
    v = (v | (v << 4)) & 0x10C30C30C30C30C3
    v = (v | (v << 2)) & 0x1249249249249249
    return v


@njit
def _morton_order(aabbs, bodies):
    """``bodies`` sorted along the Morton (Z-order) curve of their box centres.  Inserting many
    bodies in this order allocates neighbouring nodes next to each other in memory, so traversals
    stay in cache; the insertion cost and rotations still decide the tree's shape."""
    m = bodies.shape[0]
    if m < 2:
        return bodies
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in bodies:
        for k in range(3):
            c = 0.5 * (aabbs[i, k] + aabbs[i, k + 3])
            lo[k] = min(lo[k], c)
            hi[k] = max(hi[k], c)
    code = np.zeros(m, np.int64)
    for a in range(m):
        i = bodies[a]
        for k in range(3):
            span = hi[k] - lo[k]
            q = 0
            if span > 0.0:
                q = int((0.5 * (aabbs[i, k] + aabbs[i, k + 3]) - lo[k]) / span * 2097151.0)
            code[a] |= _spread_bits(q) << k
    return bodies[np.argsort(code, kind="mergesort")]


@njit
def _new_leaf(node, fat, leaf_of, state_i, aabbs, i, margin):
    """Allocate a leaf for body ``i`` with its fat box (not yet linked into the tree)."""
    leaf = _alloc(node, state_i)
    node[leaf, CHILD1] = -1
    node[leaf, CHILD2] = -1
    node[leaf, HEIGHT] = 0
    node[leaf, BODY] = i
    leaf_of[i] = leaf
    _set_fat_box(fat, leaf, aabbs, i, margin)
    return leaf


@njit
def _rebuild(node, fat, leaf_of, state_i, aabbs, flags, n_bodies, margin):
    """Build the whole tree top-down from the live bodies: leaves in Morton order, each internal node
    splitting its run of leaves in half (a linear BVH), boxes and heights filled in bottom-up."""
    state_i[I_ROOT] = -1
    state_i[I_NODE_COUNT] = 0
    state_i[I_FREE] = -1
    leaf_of[:] = -1
    order = _morton_order(aabbs, alive_indices(flags, n_bodies))
    m = order.shape[0]
    for a in range(m):
        _new_leaf(node, fat, leaf_of, state_i, aabbs, order[a], margin)   # leaf a is node a
    if m == 0:
        return
    if m == 1:
        state_i[I_ROOT] = 0
        node[0, PARENT] = -1
        return
    root = _alloc(node, state_i)
    node[root, PARENT] = -1
    state_i[I_ROOT] = root
    work = np.empty((m, 3), np.int64)
    work[0, 0] = root
    work[0, 1] = 0
    work[0, 2] = m
    top = 1
    while top > 0:
        top -= 1
        parent = work[top, 0]
        lo = work[top, 1]
        hi = work[top, 2]
        mid = (lo + hi) // 2
        node[parent, BODY] = -1
        for half in range(2):
            a = lo if half == 0 else mid
            b = mid if half == 0 else hi
            if b - a == 1:
                child = a
            else:
                child = _alloc(node, state_i)
                work[top, 0] = child
                work[top, 1] = a
                work[top, 2] = b
                top += 1
            node[child, PARENT] = parent
            node[parent, CHILD1 + half] = child
    for idx in range(state_i[I_NODE_COUNT] - 1, m - 1, -1):
        c1 = node[idx, CHILD1]
        c2 = node[idx, CHILD2]
        node[idx, HEIGHT] = 1 + max(node[c1, HEIGHT], node[c2, HEIGHT])
        _set_union(fat, idx, c1, c2)


@njit
def bvh_update(aabbs, flags, n_bodies, state_f, state_i):
    """Remove dead bodies, then insert new bodies and reinsert leaves whose body left its fat box, in
    Morton order.  If more than ``rebuild_fraction`` of the live bodies need it (a fresh state, a
    teleport of everything, fast motion), rebuild the whole tree top-down instead."""
    node, fat, leaf_of = bvh_views(state_f, state_i)
    n_prev = state_i[I_N_PREV]
    margin = state_f[F_MARGIN]
    looseness = state_f[F_LOOSENESS]
    if n_prev < 0:
        _rebuild(node, fat, leaf_of, state_i, aabbs, flags, n_bodies, margin)
        state_i[I_N_PREV] = n_bodies
        return
    for i in range(max(n_bodies, n_prev)):
        leaf = leaf_of[i]
        if leaf >= 0 and (i >= n_bodies or not is_alive(flags, i)):
            _remove_leaf(node, fat, state_i, leaf)
            _release(node, state_i, leaf)
            leaf_of[i] = -1
    changed = np.empty(n_bodies, np.int64)
    n_changed = 0
    n_live = 0
    for i in range(n_bodies):
        if not is_alive(flags, i):
            continue
        n_live += 1
        leaf = leaf_of[i]
        if leaf < 0 or _needs_reinsert(fat, leaf, aabbs, i, margin, looseness):
            changed[n_changed] = i
            n_changed += 1
    if n_changed > state_f[F_REBUILD_FRACTION] * n_live:
        _rebuild(node, fat, leaf_of, state_i, aabbs, flags, n_bodies, margin)
    else:
        for i in _morton_order(aabbs, changed[:n_changed]):
            leaf = leaf_of[i]
            if leaf < 0:
                leaf = _new_leaf(node, fat, leaf_of, state_i, aabbs, i, margin)
            else:
                _remove_leaf(node, fat, state_i, leaf)
                _set_fat_box(fat, leaf, aabbs, i, margin)
            _insert_leaf(node, fat, state_i, leaf)
    state_i[I_N_PREV] = n_bodies


@njit
def _stack_for(node, state_i):
    """A traversal stack deep enough for the current tree (depth-first: height + 1 entries)."""
    root = state_i[I_ROOT]
    height = node[root, HEIGHT] if root >= 0 else 0
    return np.empty(height + 2, np.int64)


@njit
def bvh_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys):
    """Every overlapping, filter-passing pair, by one descent of the tree against itself
    (``bvh_update`` first).  A work item is a pair of nodes whose fat boxes overlap: ``(a, a)``
    splits into ``(c1, c1)``, ``(c2, c2)``, ``(c1, c2)``; ``(a, b)`` splits the taller node against
    the other; two leaves are an exact test of their bodies' own boxes.  Each pair of leaves is met
    at most once, and only subtrees whose fat boxes overlap are entered.  Returns the number of pairs
    (written while ``keys`` has room)."""
    node, fat, _ = bvh_views(state_f, state_i)
    root = state_i[I_ROOT]
    count = 0
    if root < 0:
        return count
    # at most two pending items per level of the descent, which is at most 2 * height deep
    work = np.empty((4 * node[root, HEIGHT] + 8, 2), np.int64)
    work[0, 0] = root
    work[0, 1] = root
    top = 1
    while top > 0:
        top -= 1
        a = work[top, 0]
        b = work[top, 1]
        if a == b:
            if node[a, CHILD1] >= 0:
                c1 = node[a, CHILD1]
                c2 = node[a, CHILD2]
                work[top, 0] = c1
                work[top, 1] = c1
                work[top + 1, 0] = c2
                work[top + 1, 1] = c2
                top += 2
                if rows_overlap(fat, c1, fat, c2):
                    work[top, 0] = c1
                    work[top, 1] = c2
                    top += 1
            continue
        if node[a, CHILD1] < 0 and node[b, CHILD1] < 0:
            i = node[a, BODY]
            j = node[b, BODY]
            if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                count = add_pair(keys, count, i, j, n_bodies)
            continue
        if node[b, CHILD1] >= 0 and (node[a, CHILD1] < 0 or node[b, HEIGHT] > node[a, HEIGHT]):
            a, b = b, a
        for c in (node[a, CHILD1], node[a, CHILD2]):
            if rows_overlap(fat, c, fat, b):
                work[top, 0] = c
                work[top, 1] = b
                top += 1
    return count


@njit
def bvh_query_aabb(aabbs, state_f, state_i, box_min, box_max, buf):
    """Bodies in the tree whose own box overlaps ``[box_min, box_max]``.
    Returns the number found (written while ``buf`` has room)."""
    node, fat, _ = bvh_views(state_f, state_i)
    root = state_i[I_ROOT]
    count = 0
    if root < 0:
        return count
    stack = _stack_for(node, state_i)
    stack[0] = root
    top = 1
    while top > 0:
        top -= 1
        idx = stack[top]
        if not row_overlaps_box(fat, idx, box_min, box_max):
            continue
        if node[idx, CHILD1] >= 0:
            stack[top] = node[idx, CHILD1]
            stack[top + 1] = node[idx, CHILD2]
            top += 2
        elif row_overlaps_box(aabbs, node[idx, BODY], box_min, box_max):
            count = add_index(buf, count, node[idx, BODY])
    return count


@njit
def bvh_query_ray(aabbs, state_f, state_i, origin, direction, max_distance, buf):
    """Bodies in the tree whose own box the ray enters within ``max_distance``.
    Returns the number found (written while ``buf`` has room)."""
    node, fat, _ = bvh_views(state_f, state_i)
    root = state_i[I_ROOT]
    count = 0
    if root < 0:
        return count
    stack = _stack_for(node, state_i)
    stack[0] = root
    top = 1
    while top > 0:
        top -= 1
        idx = stack[top]
        if ray_entry(fat, idx, origin, direction, max_distance) < 0.0:
            continue
        if node[idx, CHILD1] >= 0:
            stack[top] = node[idx, CHILD1]
            stack[top + 1] = node[idx, CHILD2]
            top += 2
        elif ray_entry(aabbs, node[idx, BODY], origin, direction, max_distance) >= 0.0:
            count = add_index(buf, count, node[idx, BODY])
    return count
