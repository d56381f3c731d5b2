"""Bounding-volume hierarchy over a static mesh's triangles, for levels with overhangs.

A flat array of nodes, built top-down: a node's triangles are split at the median of their
centroids along the longest axis of the centroids' box, until at most ``LEAF_SIZE`` remain.
A node is one record of 8 floats (one cache line), ``[min xyz, max xyz, first, count]``: a leaf
(``count > 0``) holds ``order[first:first + count]`` (triangle indices in leaf order), an inner
node (``count = 0``) has its two children next to each other at ``first`` and ``first + 1``.
Queries walk it with an explicit stack, no recursion.
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..ray.triangle_ray import ray_triangle
from . import mesh_layout as ml
from .grid2d import sorted_unique

#: Most triangles in a leaf.
LEAF_SIZE = 4
#: Depth bound of the explicit stacks (a median split halves the triangles at every level).
STACK_SIZE = 128


@njit
def build_bvh(verts, tris, degenerate):
    """``(nodes (N, 8) float64, order (T,) int64)`` over the live triangles."""
    live = np.nonzero(~degenerate)[0]
    n = live.shape[0]
    tri_lo = np.empty((tris.shape[0], 3))
    tri_hi = np.empty((tris.shape[0], 3))
    centroid = np.empty((tris.shape[0], 3))
    for t in range(tris.shape[0]):
        for ax in range(3):
            a, b, c = verts[tris[t, 0], ax], verts[tris[t, 1], ax], verts[tris[t, 2], ax]
            tri_lo[t, ax] = min(a, min(b, c))
            tri_hi[t, ax] = max(a, max(b, c))
            centroid[t, ax] = (a + b + c) / 3.0
    order = live.copy()
    if n == 0:
        return np.zeros((0, 8)), order
    nodes = np.zeros((2 * n, 8))
    stack = np.empty((STACK_SIZE, 3), np.int64)    # node, first, count
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, 0, n
    top = 1
    used = 1
    while top > 0:
        top -= 1
        node, first, count = stack[top, 0], stack[top, 1], stack[top, 2]
        clo = np.full(3, math.inf)
        chi = np.full(3, -math.inf)
        for ax in range(3):
            nodes[node, ax] = math.inf
            nodes[node, 3 + ax] = -math.inf
        for i in range(first, first + count):
            t = order[i]
            for ax in range(3):
                nodes[node, ax] = min(nodes[node, ax], tri_lo[t, ax])
                nodes[node, 3 + ax] = max(nodes[node, 3 + ax], tri_hi[t, ax])
                clo[ax] = min(clo[ax], centroid[t, ax])
                chi[ax] = max(chi[ax], centroid[t, ax])
        if count <= LEAF_SIZE or top + 2 > STACK_SIZE:
            nodes[node, 6] = first
            nodes[node, 7] = count
            continue
        axis = int(np.argmax(chi - clo))
        seg = order[first:first + count]
        keys = centroid[seg, axis]
        idx = np.argsort(keys, kind="mergesort")
        order[first:first + count] = seg[idx]
        half = count // 2
        left = used
        used += 2
        nodes[node, 6] = left
        nodes[node, 7] = 0
        stack[top, 0], stack[top, 1], stack[top, 2] = left, first, half
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = left + 1, first + half, count - half
        top += 2
    return nodes[:used].copy(), order


@njit
def _box_overlaps(geom_f, base, node, lo, hi):
    o = base + ml.NODE_RECORD * node
    return not (lo[0] > geom_f[o + 3] or hi[0] < geom_f[o] or lo[1] > geom_f[o + 4] or
                hi[1] < geom_f[o + 1] or lo[2] > geom_f[o + 5] or hi[2] < geom_f[o + 2])


@njit
def bvh_candidates(geom_f, geom_i, off_f, off_i, lo, hi):
    """Ascending, duplicate-free indices of triangles in leaves whose boxes overlap ``lo..hi``.

    Returns ``(array, count)``; only ``array[:count]`` is meaningful.
    """
    n_nodes = geom_i[off_i + ml.I_N_NODES]
    if n_nodes == 0:
        return np.empty(0, np.int64), 0
    order = off_i + geom_i[off_i + ml.I_ORDER]
    base = off_f + geom_i[off_i + ml.F_NODES]
    stack = np.empty(STACK_SIZE, np.int64)
    buf = np.empty(64, np.int64)
    m = 0
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if not _box_overlaps(geom_f, base, node, lo, hi):
            continue
        first = int(geom_f[base + ml.NODE_RECORD * node + 6])
        count = int(geom_f[base + ml.NODE_RECORD * node + 7])
        if count == 0:
            stack[top] = first + 1
            stack[top + 1] = first
            top += 2
            continue
        if m + count > buf.shape[0]:
            bigger = np.empty(2 * buf.shape[0] + count, np.int64)
            bigger[:m] = buf[:m]
            buf = bigger
        for i in range(first, first + count):
            buf[m] = geom_i[order + i]
            m += 1
    return buf, sorted_unique(buf, m)


@njit
def _slab(geom_f, base, node, o, inv, t_max):
    """Entry distance of the ray into node's box, or inf if it misses within ``t_max``."""
    b = base + ml.NODE_RECORD * node
    t0, t1 = 0.0, t_max
    for ax in range(3):
        if inv[ax] == math.inf or inv[ax] == -math.inf:
            if o[ax] < geom_f[b + ax] or o[ax] > geom_f[b + 3 + ax]:
                return math.inf
            continue
        ta = (geom_f[b + ax] - o[ax]) * inv[ax]
        tb = (geom_f[b + 3 + ax] - o[ax]) * inv[ax]
        t0 = max(t0, min(ta, tb))
        t1 = min(t1, max(ta, tb))
    return t0 if t0 <= t1 else math.inf


@njit
def bvh_raycast(geom_f, geom_i, off_f, off_i, o, d, t_max):
    """Nearest triangle hit by the ray ``o + t d``: ``(t, triangle)`` or ``(inf, -1)``; ties go to
    the lower triangle index."""
    best_t, best_tri = math.inf, -1
    n_nodes = geom_i[off_i + ml.I_N_NODES]
    if n_nodes == 0:
        return best_t, best_tri
    order = off_i + geom_i[off_i + ml.I_ORDER]
    base = off_f + geom_i[off_i + ml.F_NODES]
    inv = (1.0 / d[0] if d[0] != 0.0 else math.inf, 1.0 / d[1] if d[1] != 0.0 else math.inf,
           1.0 / d[2] if d[2] != 0.0 else math.inf)
    stack = np.empty(STACK_SIZE, np.int64)
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if _slab(geom_f, base, node, o, inv, min(t_max, best_t)) == math.inf:
            continue
        first = int(geom_f[base + ml.NODE_RECORD * node + 6])
        count = int(geom_f[base + ml.NODE_RECORD * node + 7])
        if count == 0:
            stack[top] = first + 1
            stack[top + 1] = first
            top += 2
            continue
        for i in range(first, first + count):
            t = geom_i[order + i]
            a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, t)
            h = ray_triangle(o, d, a, b, c, t_max)
            if h < best_t or (h == best_t and h < math.inf and t < best_tri):
                best_t = h
                best_tri = t
    return best_t, best_tri
