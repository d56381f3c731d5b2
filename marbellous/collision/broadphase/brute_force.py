"""Brute force: test every pair of boxes, O(n^2).  The reference every other broad phase must match
exactly, and the right choice for a handful of bodies.

Box queries and ray queries over the bodies are a linear scan."""
from marbellous._jit import njit
from marbellous.collision.broadphase._common import (
    is_alive, pair_allowed, push_index, push_pair, ray_entry, row_overlaps_box, rows_overlap)


@njit
def brute_force_pairs(aabbs, flags, groups, masks, n_bodies, keys):
    """All pairs ``i < j < n_bodies`` that pass the filter and whose boxes overlap, appended to the
    key buffer ``keys``.  Returns ``(keys, count)``."""
    count = 0
    for i in range(n_bodies):
        if not is_alive(flags, i):
            continue
        for j in range(i + 1, n_bodies):
            if pair_allowed(i, j, flags, groups, masks) and rows_overlap(aabbs, i, aabbs, j):
                keys = push_pair(keys, count, i, j, n_bodies)
                count += 1
    return keys, count


@njit
def scan_query_aabb(aabbs, flags, n_bodies, box_min, box_max, buf):
    """Live bodies whose box overlaps ``[box_min, box_max]`` (m), by a linear scan.
    Returns ``(buf, count)``."""
    count = 0
    for i in range(n_bodies):
        if is_alive(flags, i) and row_overlaps_box(aabbs, i, box_min, box_max):
            buf = push_index(buf, count, i)
            count += 1
    return buf, count


@njit
def scan_query_ray(aabbs, flags, n_bodies, origin, direction, max_distance, buf):
    """Live bodies whose box the ray (unit ``direction``, length ``max_distance`` m) enters, by a
    linear scan.  Returns ``(buf, count)``."""
    count = 0
    for i in range(n_bodies):
        if is_alive(flags, i) and ray_entry(aabbs, i, origin, direction, max_distance) >= 0.0:
            buf = push_index(buf, count, i)
            count += 1
    return buf, count
