"""Loose octree, refitted or rebuilt at every update.

The root is the cube around all live box centres.  A node holding more than ``leaf_size`` bodies is
subdivided into its eight octants (the lecture: "subdivide into 8 subdivisions of equal size if the
number of contained objects is too large").  In a *loose* octree each cell's region is its cube grown
by half its edge on every side, so a body whose centre lies in an octant of edge ``a`` moves down into
it when its largest half extent is at most ``a / 2``; bodies too big for the octants stay at the node.
Only octants that receive bodies are created.  Subdivision stops at ``max_depth`` or when the node
array is full (``static_tree.tree_max_nodes``); those nodes simply keep their bodies.

The placement follows the loose cells; pruning uses each node's tight subtree box (``static_tree``),
which is never larger than its loose cell and keeps the pair set exact.

Moving bodies stay in their nodes and only the node boxes are refitted, until the summed node area
exceeds ``refit_growth`` (1.5) times its value after the last build (bodies have wandered out of their
cells) or a body is added or removed; then the octree is rebuilt.

State: the layout of ``static_tree`` plus ``state_f[F_LEAF_SIZE]``, ``state_f[F_MAX_DEPTH]`` and
``state_f[F_REFIT_GROWTH]``.
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import alive_indices
from marbellous.collision.broadphase.static_tree import F_REFIT_GROWTH, finish_build, tree_views, try_refit

F_LEAF_SIZE = 0
F_MAX_DEPTH = 1


def octree_init_params(state_f, leaf_size=8, max_depth=20, refit_growth=1.5):
    """Write the tunables: bodies a node may hold before it is subdivided, the deepest level, and
    how much the summed node area may grow by refitting before the tree is rebuilt."""
    state_f[F_LEAF_SIZE] = leaf_size
    state_f[F_MAX_DEPTH] = max_depth
    state_f[F_REFIT_GROWTH] = refit_growth


@njit
def octree_build(aabbs, flags, n_bodies, state_f, state_i):
    """Refit the loose octree to the moved boxes, or rebuild it over the live bodies among the first
    ``n_bodies`` slots if refitting is not enough."""
    if try_refit(aabbs, flags, n_bodies, state_f, state_i):
        return
    node_i, bounds, items, _, _ = tree_views(state_f, state_i)
    live = alive_indices(flags, n_bodies)
    m = live.shape[0]
    items[:m] = live
    leaf_size = max(1, int(state_f[F_LEAF_SIZE]))
    max_depth = int(state_f[F_MAX_DEPTH])
    max_nodes = node_i.shape[0]
    n_nodes = 0
    if m > 0:
        # cube of each node: lower corner and edge
        cube = np.empty((max_nodes, 4))
        lo = np.full(3, np.inf)
        top_corner = np.full(3, -np.inf)
        for i in live:
            for k in range(3):
                c = 0.5 * (aabbs[i, k] + aabbs[i, k + 3])
                lo[k] = min(lo[k], c)
                top_corner[k] = max(top_corner[k], c)
        edge = 0.0
        for k in range(3):
            edge = max(edge, top_corner[k] - lo[k])
        if not edge > 0.0:
            edge = 1.0
        cube[0, :3] = lo
        cube[0, 3] = edge
        node_i[0, 0] = 0
        node_i[0, 1] = 0
        node_i[0, 2] = 0
        node_i[0, 3] = m
        n_nodes = 1
        octant = np.empty(m, np.int64)
        work = np.empty((max_nodes, 2), np.int64)
        work[0, 0] = 0
        work[0, 1] = 0
        top = 1
        while top > 0:
            top -= 1
            node = work[top, 0]
            depth = work[top, 1]
            s = node_i[node, 2]
            cnt = node_i[node, 3]
            if cnt <= leaf_size or depth >= max_depth or n_nodes + 8 > max_nodes:
                continue
            half = 0.5 * cube[node, 3]
            per_octant = np.zeros(9, np.int64)
            for p in range(s, s + cnt):
                i = items[p]
                g = 0
                for k in range(3):
                    if 0.5 * (aabbs[i, k + 3] - aabbs[i, k]) > 0.5 * half:
                        g = -1
                        break
                    if 0.5 * (aabbs[i, k] + aabbs[i, k + 3]) >= cube[node, k] + half:
                        g |= 1 << k
                octant[p - s] = g + 1
                per_octant[g + 1] += 1
            if per_octant[0] == cnt:
                continue
            # stable partition: [stays here | octant 0 | ... | octant 7]
            fill = np.empty(9, np.int64)
            fill[0] = s
            for g in range(1, 9):
                fill[g] = fill[g - 1] + per_octant[g - 1]
            moved = items[s:s + cnt].copy()
            for p in range(cnt):
                g = octant[p]
                items[fill[g]] = moved[p]
                fill[g] += 1
            c = n_nodes
            node_i[node, 0] = c
            node_i[node, 3] = per_octant[0]
            child_start = s + per_octant[0]
            for g in range(8):
                size = per_octant[g + 1]
                if size == 0:
                    continue
                node_i[n_nodes, 0] = 0
                node_i[n_nodes, 1] = 0
                node_i[n_nodes, 2] = child_start
                node_i[n_nodes, 3] = size
                for k in range(3):
                    cube[n_nodes, k] = cube[node, k] + (half if (g >> k) & 1 else 0.0)
                cube[n_nodes, 3] = half
                child_start += size
                work[top, 0] = n_nodes
                work[top, 1] = depth + 1
                top += 1
                n_nodes += 1
            node_i[node, 1] = n_nodes - c
    finish_build(node_i, bounds, items, aabbs, n_nodes, m, n_bodies, state_f, state_i)
