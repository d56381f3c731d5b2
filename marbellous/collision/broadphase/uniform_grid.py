"""Uniform grid (spatial hash), rebuilt from the boxes at every update.

Cell size ``h = cell_factor * median(largest box edge)`` over the live bodies (``cell_factor = 2``
by default), so a typical box covers one or two cells per axis.  The grid starts at the lowest
corner of the boxes it holds (oversized ones, such as an infinite plane, are left out); cell
coordinates along an axis are ``floor((x - origin) / h)``.  ``h`` is raised if needed so that no
axis has more than 2^20 cells (the packed cell key then fits in 63 bits).

A box that would cover more than ``max_cells_per_axis`` cells along some axis is *oversized*: it is
not put in the grid, so one huge body among many small ones costs O(n) tests instead of filling
O(n) cells.  Up to 16 oversized bodies are tested against every gridded body; beyond that the gridded
bodies are sorted by their lower x bound and each oversized body only sweeps the x-window it can reach
(oversized bodies among themselves are swept and pruned along x).

Each box is entered into every cell it covers; the entries are bucketed by a hash of their cell with a
counting sort (O(entries)).  Inside a bucket, two entries of the same cell are a candidate pair, and the
pair is reported only in the lowest cell both boxes cover (cell ``max(lo_i, lo_j)`` per axis), so each
overlapping pair is found exactly once without a dedupe pass.

The grid is transient (rebuilt each update), so box and ray queries for this method are linear scans.
With at most ``GRID_MIN_SLOTS`` body slots the dispatcher skips the grid and tests every pair.
State: only the header; ``state_f[F_CELL_FACTOR]`` and ``state_f[F_MAX_CELLS]`` hold the tunables.
"""
import math

import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import (HEADER_F, HEADER_I, add_pair, alive_indices, pair_allowed,
                                                     rows_overlap)

F_CELL_FACTOR = 0
F_MAX_CELLS = 1
_AXIS_CELLS = 1 << 20
#: Below this many body slots the dispatcher tests every pair instead (same pairs, same order): building
#: the grid costs a few microseconds, testing 32 * 31 / 2 box pairs well under one.
GRID_MIN_SLOTS = 32


def grid_state_sizes(capacity):
    """Lengths ``(len(state_f), len(state_i))`` of the grid state (the grid itself is transient)."""
    return HEADER_F, HEADER_I


def grid_init_params(state_f, cell_factor=2.0, max_cells_per_axis=3):
    """Write the tunables: cell size over median box size, and cells per axis beyond which a box
    is handled as oversized."""
    state_f[F_CELL_FACTOR] = cell_factor
    state_f[F_MAX_CELLS] = max_cells_per_axis


@njit
def _cell_size(aabbs, live, cell_factor, max_cells, oversized):
    """Edge of a grid cell (m) and the grid origin (lowest corner of the boxes that go in the grid).

    The cell edge comes from the median box edge; a box longer than ``max_cells`` cells along some
    axis (an infinite plane, a long wall) is marked in ``oversized`` and left out of the origin and
    span, so it can neither push the grid to infinity nor coarsen it for everyone else.
    """
    m = live.shape[0]
    edge = np.empty(m)
    for a in range(m):
        i = live[a]
        e = 0.0
        for k in range(3):
            e = max(e, aabbs[i, k + 3] - aabbs[i, k])
        edge[a] = e
    finite = edge[np.isfinite(edge)]
    h = cell_factor * np.median(finite) if finite.shape[0] > 0 else 1.0
    if not h > 0.0:
        h = 1.0
    origin = np.full(3, np.inf)
    top = np.full(3, -np.inf)
    for a in range(m):
        i = live[a]
        # longer than max_cells cell edges: covers more than max_cells cells wherever it lies
        oversized[i] = not (edge[a] <= max_cells * h)
        if not oversized[i]:
            for k in range(3):
                origin[k] = min(origin[k], aabbs[i, k])
                top[k] = max(top[k], aabbs[i, k + 3])
    span = 0.0
    for k in range(3):
        if top[k] > origin[k]:
            span = max(span, top[k] - origin[k])
    h = max(h, span / _AXIS_CELLS)
    return h, origin


@njit
def grid_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys):
    """Build the grid over the live boxes and collect every overlapping, filter-passing pair.
    Returns the number of pairs (written while ``keys`` has room)."""
    live = alive_indices(flags, n_bodies)
    m = live.shape[0]
    count = 0
    if m < 2:
        return count
    max_cells = int(state_f[F_MAX_CELLS])
    oversized = np.zeros(n_bodies, np.bool_)
    h, origin = _cell_size(aabbs, live, state_f[F_CELL_FACTOR], max_cells, oversized)
    lo = np.empty((n_bodies, 3), np.int64)
    hi = np.empty((n_bodies, 3), np.int64)
    n_entries = 0
    for a in range(m):
        i = live[a]
        if oversized[i]:
            continue
        cells = 1
        for k in range(3):
            lo[i, k] = int(math.floor((aabbs[i, k] - origin[k]) / h))
            hi[i, k] = int(math.floor((aabbs[i, k + 3] - origin[k]) / h))
            c = hi[i, k] - lo[i, k] + 1
            if c > max_cells:
                oversized[i] = True
            cells *= c
        if not oversized[i]:
            n_entries += cells
    stride = _AXIS_CELLS + 2
    table = 1
    while table < 2 * n_entries:
        table *= 2
    start = np.zeros(table + 1, np.int64)
    entry_body = np.empty(n_entries, np.int64)
    entry_cell = np.empty(n_entries, np.int64)
    for pass_ in range(2):
        for a in range(m):
            i = live[a]
            if oversized[i]:
                continue
            for cx in range(lo[i, 0], hi[i, 0] + 1):
                for cy in range(lo[i, 1], hi[i, 1] + 1):
                    for cz in range(lo[i, 2], hi[i, 2] + 1):
                        bucket = ((cx * 73856093) ^ (cy * 19349663) ^ (cz * 83492791)) & (table - 1)
                        if pass_ == 0:
                            start[bucket + 1] += 1
                        else:
                            slot = start[bucket]
                            start[bucket] += 1
                            entry_body[slot] = i
                            entry_cell[slot] = (cx * stride + cy) * stride + cz
        if pass_ == 0:
            for b in range(table):
                start[b + 1] += start[b]
    # after the scatter, start[b] is the end of bucket b, which is the start of bucket b + 1
    begin = 0
    for b in range(table):
        end = start[b]
        for p in range(begin, end):
            i = entry_body[p]
            for q in range(p + 1, end):
                if entry_cell[q] != entry_cell[p]:
                    continue
                j = entry_body[q]
                lowest = ((max(lo[i, 0], lo[j, 0]) * stride + max(lo[i, 1], lo[j, 1])) * stride
                          + max(lo[i, 2], lo[j, 2]))
                if lowest == entry_cell[p] and rows_overlap(aabbs, i, aabbs, j) \
                        and pair_allowed(i, j, flags, groups, masks):
                    count = add_pair(keys, count, i, j, n_bodies)
        begin = end
    return _oversized_pairs(aabbs, flags, groups, masks, n_bodies, live, oversized,
                            (max_cells + 1) * h, keys, count)


@njit
def _oversized_pairs(aabbs, flags, groups, masks, n_bodies, live, oversized, reach, keys, count):
    """Pairs with at least one oversized body.  Oversized bodies among themselves: sweep and prune
    along x.  Against the gridded bodies: with few oversized bodies, a scan of all of them; with
    more, the gridded bodies are sorted by their lower x bound once, and each oversized body ``i``
    only tests those whose lower x bound lies in ``[min_x_i - reach, max_x_i]`` (a gridded box spans
    fewer than ``max_cells`` cells, so it is shorter than ``reach = (max_cells + 1) h``)."""
    big = np.empty(live.shape[0], np.int64)
    small = np.empty(live.shape[0], np.int64)
    n_big = 0
    n_small = 0
    for i in live:
        if oversized[i]:
            big[n_big] = i
            n_big += 1
        else:
            small[n_small] = i
            n_small += 1
    if n_big == 0:
        return count
    # oversized against oversized: sweep and prune along x
    big = big[:n_big]
    big_low_x = np.empty(n_big)
    for a in range(n_big):
        big_low_x[a] = aabbs[big[a], 0]
    big = big[np.argsort(big_low_x, kind="mergesort")]
    for a in range(n_big):
        i = big[a]
        for b in range(a + 1, n_big):
            j = big[b]
            if aabbs[j, 0] > aabbs[i, 3]:
                break
            if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                count = add_pair(keys, count, i, j, n_bodies)
    small = small[:n_small]
    if n_big <= 16:
        for a in range(n_big):
            i = big[a]
            for j in small:
                if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                    count = add_pair(keys, count, i, j, n_bodies)
        return count
    low_x = np.empty(n_small)
    for b in range(n_small):
        low_x[b] = aabbs[small[b], 0]
    by_x = np.argsort(low_x, kind="mergesort")
    sorted_x = low_x[by_x]
    # the sorted boxes copied side by side, so each window is swept through contiguous memory
    sorted_boxes = np.empty((n_small, 6))
    for b in range(n_small):
        sorted_boxes[b] = aabbs[small[by_x[b]]]
    for a in range(n_big):
        i = big[a]
        first = np.searchsorted(sorted_x, aabbs[i, 0] - reach, side="left")
        for b in range(first, n_small):
            if sorted_x[b] > aabbs[i, 3]:
                break
            if rows_overlap(aabbs, i, sorted_boxes, b):
                j = small[by_x[b]]
                if pair_allowed(i, j, flags, groups, masks):
                    count = add_pair(keys, count, i, j, n_bodies)
    return count
