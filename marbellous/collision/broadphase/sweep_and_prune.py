"""Sweep and prune (sort and sweep) on one axis, incremental.

The bodies are kept sorted by the lower bound of their box on the sweep axis.  A sweep walks the sorted
list; for body ``i`` it visits the following bodies while their lower bound is ``<= max_i`` and tests
the other two axes.  Between steps the order from the previous step is kept and repaired by insertion
sort, which costs O(n + swaps): nearly O(n) when motion is coherent.  If the repair needs more than
``swap_budget * n`` swaps (teleports, a fresh scene), the list is re-sorted from scratch (O(n log n)).

The axis is the one along which the box centres vary most.  To avoid re-sorting every step when two
axes are close, the axis only changes when another axis' variance exceeds ``axis_hysteresis`` times
the current one.

State layout: ``state_i[HEADER_I : HEADER_I + capacity]`` the sorted order,
``state_f[HEADER_F : HEADER_F + capacity]`` the sorted lower bounds (dead slots sort last as +inf);
``state_i[I_AXIS]`` the axis; ``state_f[F_SWAP_BUDGET]``, ``state_f[F_AXIS_HYSTERESIS]`` the tunables.
"""
import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import (HEADER_F, HEADER_I, I_N_PREV, add_index, add_pair, is_alive,
                                                     pair_allowed, row_overlaps_box, rows_overlap)

I_AXIS = 3
F_SWAP_BUDGET = 0
F_AXIS_HYSTERESIS = 1


def sap_state_sizes(capacity):
    """Lengths ``(len(state_f), len(state_i))`` of the sweep-and-prune state for ``capacity`` slots."""
    return HEADER_F + capacity, HEADER_I + capacity


def sap_init_params(state_f, swap_budget=8.0, axis_hysteresis=2.0):
    """Write the tunables into a fresh state: swaps allowed per body before a full re-sort, and the
    variance ratio needed to change the sweep axis."""
    state_f[F_SWAP_BUDGET] = swap_budget
    state_f[F_AXIS_HYSTERESIS] = axis_hysteresis


@njit
def _centre_variances(aabbs, flags, n_bodies):
    """Variance of the box centres along x, y, z over the live bodies (m^2)."""
    s = np.zeros(3)
    s2 = np.zeros(3)
    m = 0
    for i in range(n_bodies):
        if is_alive(flags, i):
            m += 1
            for k in range(3):
                c = 0.5 * (aabbs[i, k] + aabbs[i, k + 3])
                s[k] += c
                s2[k] += c * c
    var = np.zeros(3)
    if m > 0:
        for k in range(3):
            mean = s[k] / m
            var[k] = s2[k] / m - mean * mean
    return var


@njit
def sap_update(aabbs, flags, n_bodies, state_f, state_i):
    """Bring the sorted order up to date with the current boxes (insertion sort from last step's
    order, or a full sort on a fresh state, a changed axis, fewer slots or too many swaps)."""
    order = state_i[HEADER_I:HEADER_I + n_bodies]
    lows = state_f[HEADER_F:HEADER_F + n_bodies]
    var = _centre_variances(aabbs, flags, n_bodies)
    n_prev = state_i[I_N_PREV]
    axis = state_i[I_AXIS]
    best = 0
    for k in range(1, 3):
        if var[k] > var[best]:
            best = k
    rebuild = n_prev < 0 or n_prev > n_bodies
    if rebuild or var[best] > state_f[F_AXIS_HYSTERESIS] * var[axis]:
        if axis != best:
            rebuild = True
        axis = best
    if not rebuild:
        for k in range(n_prev, n_bodies):
            order[k] = k
        for k in range(n_bodies):
            i = order[k]
            lows[k] = aabbs[i, axis] if is_alive(flags, i) else np.inf
        budget = state_f[F_SWAP_BUDGET] * n_bodies + 64.0
        swaps = 0
        for k in range(1, n_bodies):
            v = lows[k]
            i = order[k]
            p = k - 1
            while p >= 0 and lows[p] > v:
                lows[p + 1] = lows[p]
                order[p + 1] = order[p]
                p -= 1
            swaps += k - 1 - p
            lows[p + 1] = v
            order[p + 1] = i
            if swaps > budget:
                rebuild = True
                break
    if rebuild:
        for i in range(n_bodies):
            lows[i] = aabbs[i, axis] if is_alive(flags, i) else np.inf
        perm = np.argsort(lows, kind="mergesort")
        for k in range(n_bodies):
            order[k] = perm[k]
        for k in range(n_bodies):
            i = order[k]
            lows[k] = aabbs[i, axis] if is_alive(flags, i) else np.inf
    state_i[I_AXIS] = axis
    state_i[I_N_PREV] = n_bodies


@njit
def sap_pairs(aabbs, flags, groups, masks, n_bodies, state_f, state_i, keys):
    """Sweep the sorted order (``sap_update`` first): every overlapping, filter-passing pair into
    ``keys``.  Returns the number of pairs (written while ``keys`` has room)."""
    order = state_i[HEADER_I:HEADER_I + n_bodies]
    lows = state_f[HEADER_F:HEADER_F + n_bodies]
    axis = state_i[I_AXIS]
    count = 0
    for a in range(n_bodies):
        if lows[a] == np.inf:
            break
        i = order[a]
        hi = aabbs[i, axis + 3]
        for b in range(a + 1, n_bodies):
            if lows[b] > hi:
                break
            j = order[b]
            if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                count = add_pair(keys, count, i, j, n_bodies)
    return count


@njit
def sap_query_aabb(aabbs, flags, n_bodies, state_f, state_i, box_min, box_max, buf):
    """Live bodies overlapping ``[box_min, box_max]``: only the prefix of the sorted list whose lower
    bound is ``<= box_max`` on the sweep axis is tested.
    Returns the number found (written while ``buf`` has room)."""
    order = state_i[HEADER_I:HEADER_I + n_bodies]
    lows = state_f[HEADER_F:HEADER_F + n_bodies]
    axis = state_i[I_AXIS]
    count = 0
    for a in range(n_bodies):
        if lows[a] > box_max[axis]:
            break
        i = order[a]
        if is_alive(flags, i) and row_overlaps_box(aabbs, i, box_min, box_max):
            count = add_index(buf, count, i)
    return count
