"""Brute force: test every pair of boxes, O(n^2).  The reference every other broad phase must match
exactly, and the right choice for a handful of bodies.

Box queries and ray queries over the bodies are a linear scan."""
from marbellous._numba.jit import njit
from marbellous.collision.broadphase._common import (add_index, add_pair, is_alive, pair_allowed, ray_entry,
                                                     row_overlaps_box, rows_overlap)


@njit
def brute_force_pairs(aabbs, flags, groups, masks, n_bodies, keys):
    """All pairs ``i < j < n_bodies`` that pass the filter and whose boxes overlap, appended to the
    key buffer ``keys``.  Returns the number of pairs (written while ``keys`` has room)."""
    count = 0
    for i in range(n_bodies):
        if not is_alive(flags, i):
            continue
        for j in range(i + 1, n_bodies):
            if rows_overlap(aabbs, i, aabbs, j) and pair_allowed(i, j, flags, groups, masks):
                count = add_pair(keys, count, i, j, n_bodies)
    return count


@njit
def scan_query_aabb(aabbs, flags, n_bodies, box_min, box_max, buf):
    """Live bodies whose box overlaps ``[box_min, box_max]`` (m), by a linear scan.
    Returns the number found (written while ``buf`` has room)."""
    count = 0
    for i in range(n_bodies):
        if is_alive(flags, i) and row_overlaps_box(aabbs, i, box_min, box_max):
            count = add_index(buf, count, i)
    return count


@njit
def scan_query_ray(aabbs, flags, n_bodies, origin, direction, max_distance, buf):
    """Live bodies whose box the ray (unit ``direction``, length ``max_distance`` m) enters, by a
    linear scan.
    Returns the number found (written while ``buf`` has room)."""
    count = 0
    for i in range(n_bodies):
        if is_alive(flags, i) and ray_entry(aabbs, i, origin, direction, max_distance) >= 0.0:
            count = add_index(buf, count, i)
    return count
