"""KD-tree over the box centres, refitted or rebuilt at every update.

A node holding more than ``leaf_size`` bodies is split at the median of its bodies' centres along one
axis, the axes alternating x, y, z, x, ... with depth (the lecture: "choose the subdividing line, e.g.
the median point of the contained objects, cutting them in half; alternate axes").  Each body goes to
the side of its centre, so the tree has at most 2 m - 1 nodes and depth ``ceil(log2(m / leaf_size))``.
The median is found by quickselect, O(m) per level, O(m log m) per build.  Each node keeps the tight
box around its subtree, which the traversals in ``static_tree`` prune with.

Between updates the partition is kept and only the node boxes are refitted to the moved bodies, until
their summed surface area exceeds ``refit_growth`` (1.5) times its value after the last build, or a body
is added or removed; then the tree is rebuilt.

State: the layout of ``static_tree`` plus ``state_f[F_LEAF_SIZE]`` and ``state_f[F_REFIT_GROWTH]``.
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import alive_indices, select_nth
from marbellous.collision.broadphase.static_tree import F_REFIT_GROWTH, finish_build, tree_views, try_refit

F_LEAF_SIZE = 0


def kd_init_params(state_f, leaf_size=4, refit_growth=1.5):
    """Write the tunables: most bodies in a leaf, and how much the summed node area may grow by
    refitting before the tree is rebuilt (``static_tree.try_refit``)."""
    state_f[F_LEAF_SIZE] = leaf_size
    state_f[F_REFIT_GROWTH] = refit_growth


@njit
def kd_build(aabbs, flags, n_bodies, state_f, state_i):
    """Refit the KD-tree to the moved boxes, or rebuild it over the live bodies among the first
    ``n_bodies`` slots if refitting is not enough."""
    if try_refit(aabbs, flags, n_bodies, state_f, state_i):
        return
    node_i, bounds, items, keys, _ = tree_views(state_f, state_i)
    live = alive_indices(flags, n_bodies)
    m = live.shape[0]
    items[:m] = live
    leaf_size = max(1, int(state_f[F_LEAF_SIZE]))
    n_nodes = 0
    if m > 0:
        node_i[0, 0] = 0
        node_i[0, 1] = 0
        node_i[0, 2] = 0
        node_i[0, 3] = m
        n_nodes = 1
        work = np.empty((node_i.shape[0], 2), np.int64)
        work[0, 0] = 0
        work[0, 1] = 0
        top = 1
        while top > 0:
            top -= 1
            node = work[top, 0]
            depth = work[top, 1]
            s = node_i[node, 2]
            cnt = node_i[node, 3]
            if cnt <= leaf_size:
                continue
            axis = depth % 3
            for p in range(s, s + cnt):
                i = items[p]
                keys[p] = 0.5 * (aabbs[i, axis] + aabbs[i, axis + 3])
            half = cnt // 2
            select_nth(items, keys, s, s + cnt, s + half)
            c = n_nodes
            n_nodes += 2
            node_i[node, 0] = c
            node_i[node, 1] = 2
            node_i[node, 3] = 0
            node_i[c, 0] = 0
            node_i[c, 1] = 0
            node_i[c, 2] = s
            node_i[c, 3] = half
            node_i[c + 1, 0] = 0
            node_i[c + 1, 1] = 0
            node_i[c + 1, 2] = s + half
            node_i[c + 1, 3] = cnt - half
            for child in range(c, c + 2):
                work[top, 0] = child
                work[top, 1] = depth + 1
                top += 1
    finish_build(node_i, bounds, items, aabbs, n_nodes, m, n_bodies, state_f, state_i)
