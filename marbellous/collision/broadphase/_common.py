"""Pieces every broad phase shares: the pair filter, box overlap, the pair and index buffers,
the canonical output order, the ray-versus-box slab test and a selection (nth element) kernel.

State arrays.  Every method keeps its persistent data in two flat arrays, ``state_f`` (float64)
and ``state_i`` (int64).  Their first entries are a common header:

``state_i[I_METHOD]``   method code the state was made for,
``state_i[I_CAPACITY]`` largest number of body slots the state can hold,
``state_i[I_N_PREV]``   ``n_bodies`` of the last update, or -1 for a freshly made state (rebuild),
``state_i[3:HEADER_I]`` method-specific counters;
``state_f[:4]``         the method's tunables (cell factor, margins, leaf sizes), written by
``make_state`` so that kernels never read tunables from globals;
``state_f[4:HEADER_F]`` values a build computes for later updates (plane tolerance, tree area).
"""
import numpy as np

from marbellous._numba.jit import njit

#: Bit 0 of a body's flags: the slot holds a live body.
ALIVE = 1
#: Bit 1 of a body's flags: the body is static (static-static pairs are never reported).
STATIC = 2

HEADER_I = 8
HEADER_F = 8
I_METHOD = 0
I_CAPACITY = 1
I_N_PREV = 2


@njit
def is_alive(flags, i):
    """True if slot ``i`` holds a live body."""
    return (flags[i] & ALIVE) != 0


@njit
def pair_allowed(i, j, flags, groups, masks):
    """True if bodies ``i`` and ``j`` may collide: both alive, not both static, and each one's
    group bits meet the other's mask bits: ``(g_i & m_j) != 0 and (g_j & m_i) != 0``."""
    fi = flags[i]
    fj = flags[j]
    if (fi & ALIVE) == 0 or (fj & ALIVE) == 0:
        return False
    if (fi & STATIC) != 0 and (fj & STATIC) != 0:
        return False
    return (groups[i] & masks[j]) != 0 and (groups[j] & masks[i]) != 0


@njit
def rows_overlap(a, ia, b, ib):
    """Closed-interval overlap of box row ``a[ia]`` and box row ``b[ib]`` (rows are
    ``[minx, miny, minz, maxx, maxy, maxz]``); touching boxes overlap."""
    return (a[ia, 0] <= b[ib, 3] and b[ib, 0] <= a[ia, 3]
            and a[ia, 1] <= b[ib, 4] and b[ib, 1] <= a[ia, 4]
            and a[ia, 2] <= b[ib, 5] and b[ib, 2] <= a[ia, 5])


@njit
def row_overlaps_box(a, ia, box_min, box_max):
    """Closed-interval overlap of box row ``a[ia]`` with the box ``[box_min, box_max]``."""
    return (a[ia, 0] <= box_max[0] and box_min[0] <= a[ia, 3]
            and a[ia, 1] <= box_max[1] and box_min[1] <= a[ia, 4]
            and a[ia, 2] <= box_max[2] and box_min[2] <= a[ia, 5])


@njit
def add_pair(keys, count, i, j, n_bodies):
    """Record the pair ``{i, j}`` as the key ``min * n_bodies + max`` at ``keys[count]`` if there is
    room, and return ``count + 1``.  Callers that find ``count > len(keys)`` at the end run again
    with a buffer of ``count`` keys (growing in place would slow the hot loops several times)."""
    if count < keys.shape[0]:
        if i < j:
            keys[count] = i * n_bodies + j
        else:
            keys[count] = j * n_bodies + i
    return count + 1


@njit
def add_index(buf, count, value):
    """Record ``value`` at ``buf[count]`` if there is room, and return ``count + 1``."""
    if count < buf.shape[0]:
        buf[count] = value
    return count + 1


@njit
def sort_keys(keys):
    """The non-negative int64 ``keys`` in ascending order, as a new array.

    LSD radix sort on 11-bit digits: one counting pass and one scatter per digit, O(n) per digit and as
    many digits as the largest key needs (pair keys below 2^33 take three).  Stable, and unlike a
    comparison sort it does not slow down on the partly ordered key runs the broad phases emit.
    """
    n = keys.shape[0]
    out = keys.copy()
    if n < 64:
        out.sort()
        return out
    top = 0
    for k in range(n):
        top = max(top, keys[k])
    tmp = np.empty(n, np.int64)
    start = np.empty(2049, np.int64)
    shift = 0
    while (top >> shift) > 0:
        start[:] = 0
        for k in range(n):
            start[((out[k] >> shift) & 2047) + 1] += 1
        for d in range(2048):
            start[d + 1] += start[d]
        for k in range(n):
            d = (out[k] >> shift) & 2047
            tmp[start[d]] = out[k]
            start[d] += 1
        out, tmp = tmp, out
        shift += 11
    return out


@njit
def _ascending(keys, count):
    """True if ``keys[:count]`` is in ascending order."""
    for k in range(1, count):
        if keys[k] < keys[k - 1]:
            return False
    return True


@njit
def write_pairs(keys, count, n_bodies, pairs_out):
    """Sort the pair keys and write them as rows ``(i, j)``, ``i < j``, in lexicographic order into
    ``pairs_out`` (at most its length).  Returns the full number of pairs."""
    # (brute force and small worlds emit their keys in order already: then nothing is copied or sorted)
    ordered = keys[:count] if _ascending(keys, count) else sort_keys(keys[:count])
    m = min(count, pairs_out.shape[0])
    # key = i n + j with i non-decreasing along the sorted keys: step i up instead of dividing
    i = 0
    row = 0
    for k in range(m):
        while ordered[k] >= row + n_bodies:
            i += 1
            row += n_bodies
        pairs_out[k, 0] = i
        pairs_out[k, 1] = ordered[k] - row
    return count


@njit
def keep_alive(buf, count, flags):
    """Drop the bodies of ``buf[:count]`` that are no longer alive; returns the new count."""
    kept = 0
    for k in range(count):
        if (flags[buf[k]] & ALIVE) != 0:
            buf[kept] = buf[k]
            kept += 1
    return kept


@njit
def write_indices(buf, count, out):
    """Sort the body indices and write at most ``len(out)`` of them; returns the full count."""
    ordered = np.sort(buf[:count])
    m = min(count, out.shape[0])
    out[:m] = ordered[:m]
    return count


@njit
def ray_entry(boxes, r, origin, direction, max_distance):
    """Slab test of the ray ``origin + t * direction``, ``0 <= t <= max_distance``, against box row
    ``boxes[r]``.  Returns the entry parameter ``t`` (0 if the origin is inside) or -1 on a miss.

    Per axis ``t = (lo - o) / d`` and ``(hi - o) / d``; the hit interval is the intersection of the
    three slabs with ``[0, max_distance]``.  Both divisions are monotone in the bound, so a box that
    contains another is entered no later and left no earlier: tree pruning never drops a hit.
    """
    t_near = 0.0
    t_far = max_distance
    for k in range(3):
        lo = boxes[r, k]
        hi = boxes[r, k + 3]
        o = origin[k]
        d = direction[k]
        if d == 0.0:
            if o < lo or o > hi:
                return -1.0
        else:
            t1 = (lo - o) / d
            t2 = (hi - o) / d
            if t1 > t2:
                t1, t2 = t2, t1
            if t1 > t_near:
                t_near = t1
            if t2 < t_far:
                t_far = t2
            if t_near > t_far:
                return -1.0
    return t_near


@njit
def write_ray_hits(buf, count, aabbs, origin, direction, max_distance, out):
    """Write the candidate bodies ``buf[:count]`` sorted by entry distance, ties by index, into
    ``out`` (at most its length).  Returns the full count."""
    ordered = np.sort(buf[:count])
    t = np.empty(count)
    for k in range(count):
        t[k] = ray_entry(aabbs, ordered[k], origin, direction, max_distance)
    by_t = np.argsort(t, kind="mergesort")
    m = min(count, out.shape[0])
    for k in range(m):
        out[k] = ordered[by_t[k]]
    return count


@njit
def select_nth(items, keys, lo, hi, k):
    """Reorder ``items[lo:hi]`` and ``keys[lo:hi]`` together so that ``keys[k]`` is the value it would
    have if the range were sorted, with no larger key before ``k`` and no smaller key after it.

    Three-way (Dutch flag) quickselect with a median-of-three pivot: expected O(hi - lo), and runs of
    equal keys (bodies in a plane) end the search at once instead of degrading it."""
    while hi - lo > 1:
        a = keys[lo]
        b = keys[(lo + hi - 1) // 2]
        c = keys[hi - 1]
        pivot = max(min(a, b), min(max(a, b), c))
        lt = lo
        i = lo
        gt = hi
        while i < gt:
            v = keys[i]
            if v < pivot:
                keys[i], keys[lt] = keys[lt], keys[i]
                items[i], items[lt] = items[lt], items[i]
                lt += 1
                i += 1
            elif v > pivot:
                gt -= 1
                keys[i], keys[gt] = keys[gt], keys[i]
                items[i], items[gt] = items[gt], items[i]
            else:
                i += 1
        if k < lt:
            hi = lt
        elif k >= gt:
            lo = gt
        else:
            return


@njit
def alive_indices(flags, n_bodies):
    """Indices of the live bodies among the first ``n_bodies`` slots, ascending."""
    m = 0
    for i in range(n_bodies):
        if (flags[i] & ALIVE) != 0:
            m += 1
    out = np.empty(m, np.int64)
    m = 0
    for i in range(n_bodies):
        if (flags[i] & ALIVE) != 0:
            out[m] = i
            m += 1
    return out
