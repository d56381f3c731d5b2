"""Binary space partition with arbitrary splitting planes, rebuilt at every update (not refitted: the
plane tests rely on every box lying on its side of its parent's plane, which motion breaks).

The lecture's generalisation of the KD-tree: space is cut into half-spaces by planes of any
orientation.  A node holding more than ``leaf_size`` bodies is cut by the plane ``n . x = d`` whose
normal ``n`` is the principal direction of its bodies' centres (the eigenvector of the largest
eigenvalue of their covariance, by power iteration from the axis of largest variance) and whose offset
``d`` is the median of ``n . c`` over the centres, so the plane halves the node across its longest
spread, whatever its orientation.

A box projects onto ``n`` as ``[n.c - r, n.c + r]`` with ``r = sum_k |n_k| h_k`` (``h`` the half
extents).  Boxes entirely behind (``n.c + r < d``) go to the back child, boxes entirely in front
(``n.c - r > d``) to the front child.  Boxes the plane cuts go to a third, *on-plane* child: they lie
in a thin slab around the plane, so that child's own principal direction lies along the plane and its
split separates them there (keeping them all at the node would make every query test every box the
root plane cuts: a percent of the scene).  The body whose centre is the median is always cut, and at
least half of the centres lie on each closed side, so every child holds fewer bodies than its parent
unless the plane cuts every box, and then the node is a leaf.  Every internal node has two or three
children, so there are at most 2 m - 1 nodes.  Pruning uses the tight subtree boxes
(``static_tree``) and, for the back and front children, the parent's plane: a query box entirely in
front of the plane skips the back child (with a rounding allowance, so the pair set stays exact).

State: the layout of ``static_tree`` plus ``state_f[F_LEAF_SIZE]`` and ``state_f[F_POWER_ITERATIONS]``.
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import alive_indices, select_nth
from marbellous.collision.broadphase.static_tree import (F_PLANE_TOLERANCE, SIDE, finish_build, plane_key_radius,
                                                         tree_views)

F_LEAF_SIZE = 0
F_POWER_ITERATIONS = 1


def bsp_init_params(state_f, leaf_size=4, power_iterations=8):
    """Write the tunables: most bodies in a leaf, power-iteration steps for the plane normal."""
    state_f[F_LEAF_SIZE] = leaf_size
    state_f[F_POWER_ITERATIONS] = power_iterations


@njit
def principal_direction(aabbs, items, s, e, iterations):
    """Unit principal direction of the centres of bodies ``items[s:e]``: power iteration
    ``v <- C v / |C v|`` on their covariance ``C``, started from the axis of largest variance."""
    mean = np.zeros(3)
    for p in range(s, e):
        i = items[p]
        for k in range(3):
            mean[k] += 0.5 * (aabbs[i, k] + aabbs[i, k + 3])
    mean /= e - s
    cov = np.zeros((3, 3))
    for p in range(s, e):
        i = items[p]
        dx = np.empty(3)
        for k in range(3):
            dx[k] = 0.5 * (aabbs[i, k] + aabbs[i, k + 3]) - mean[k]
        for a in range(3):
            for b in range(3):
                cov[a, b] += dx[a] * dx[b]
    best = 0
    for k in range(1, 3):
        if cov[k, k] > cov[best, best]:
            best = k
    v = np.zeros(3)
    v[best] = 1.0
    w = np.empty(3)
    for _ in range(iterations):
        # w = cov v, written out: a matrix product in a kernel would need BLAS (SciPy) at run time
        for a in range(3):
            w[a] = cov[a, 0] * v[0] + cov[a, 1] * v[1] + cov[a, 2] * v[2]
        norm = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        if not norm > 0.0:
            break
        v = w / norm
    return v


@njit
def bsp_build(aabbs, flags, n_bodies, state_f, state_i):
    """Rebuild the BSP tree over the live bodies among the first ``n_bodies`` slots."""
    node_i, bounds, items, keys, planes = tree_views(state_f, state_i)
    live = alive_indices(flags, n_bodies)
    m = live.shape[0]
    items[:m] = live
    leaf_size = max(1, int(state_f[F_LEAF_SIZE]))
    iterations = int(state_f[F_POWER_ITERATIONS])
    side = np.empty(max(m, 1), np.int64)
    n_nodes = 0
    if m > 0:
        node_i[0, 0] = 0
        node_i[0, 1] = 0
        node_i[0, 2] = 0
        node_i[0, 3] = m
        planes[0, SIDE] = 0.0
        n_nodes = 1
        scale = 0.0
        for i in live:
            for k in range(6):
                scale = max(scale, abs(aabbs[i, k]))
        state_f[F_PLANE_TOLERANCE] = 1e-10 * scale
        work = np.empty(node_i.shape[0], np.int64)
        work[0] = 0
        top = 1
        while top > 0:
            top -= 1
            node = work[top]
            s = node_i[node, 2]
            cnt = node_i[node, 3]
            if cnt <= leaf_size:
                continue
            n = principal_direction(aabbs, items, s, s + cnt, iterations)
            for p in range(s, s + cnt):
                keys[p], _ = plane_key_radius(n, aabbs, items[p])
            select_nth(items, keys, s, s + cnt, s + cnt // 2)
            d = keys[s + cnt // 2]
            n_back = 0
            n_front = 0
            for p in range(s, s + cnt):
                _, r = plane_key_radius(n, aabbs, items[p])
                if keys[p] + r < d:
                    side[p - s] = 1
                    n_back += 1
                elif keys[p] - r > d:
                    side[p - s] = 2
                    n_front += 1
                else:
                    side[p - s] = 0
            if n_back == 0 and n_front == 0:
                continue
            # stable three-way partition: [cut by the plane | back | front], one child each
            n_cut = cnt - n_back - n_front
            fill = np.array([s, s + n_cut, s + n_cut + n_back])
            moved = items[s:s + cnt].copy()
            for p in range(cnt):
                g = side[p]
                items[fill[g]] = moved[p]
                fill[g] += 1
            c = n_nodes
            node_i[node, 0] = c
            node_i[node, 3] = 0
            child_start = s
            for g in range(3):
                size = n_cut if g == 0 else (n_back if g == 1 else n_front)
                if size == 0:
                    continue
                node_i[n_nodes, 0] = 0
                node_i[n_nodes, 1] = 0
                node_i[n_nodes, 2] = child_start
                node_i[n_nodes, 3] = size
                planes[n_nodes, :3] = n
                planes[n_nodes, 3] = d
                planes[n_nodes, SIDE] = g
                child_start += size
                work[top] = n_nodes
                top += 1
                n_nodes += 1
            node_i[node, 1] = n_nodes - c
    finish_build(node_i, bounds, items, aabbs, n_nodes, m, n_bodies, state_f, state_i)
