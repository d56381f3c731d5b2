"""Particles against particles (``collide_particles=True``): a spatial hash over the step, and the overlaps
of the listed pairs removed in each sub-step with the same friction and restitution as against shapes.

The hash: cubic cells of side ``cell`` (at least the largest diameter plus how far a particle may travel in
the step), keyed ``(73856093 i ^ 19349663 j ^ 83492791 k) mod table`` (Teschner et al. 2003) and sorted by key
with a counting sort, so that the pairs are found in a fixed order.  Two particles whose distance is below
their radii's sum plus the travel margin become a candidate pair for the step, unless an edge of a network
joins them (a rope's neighbours overlap by design) or they are nodes of one soft body.  Two particles of two
different collide-sets and of the same set meet alike.
"""
import math

import numpy as np

from .._numba.jit import njit
from ..collision.adjacency import begin_fill, clear_counts, count_link, end_fill, fill_link, joined
from .particle_contacts import append_pair, hold_or_slip, record_contact, separate
from .particle_layout import (E_A, E_B, KK_PARTICLE, P_FLAGS, P_FRICTION, P_INV_MASS, P_POS, P_RADIUS,
                              P_RESTITUTION, P_SET, P_STATIC_FRICTION, P_VEL0, PP_COLLIDE, PP_SOFT)


@njit
def index_key(i, j, k, table):
    """The hash-table slot (of ``table``) of the cell of integer indices ``(i, j, k)``."""
    return ((i * 73856093) ^ (j * 19349663) ^ (k * 83492791)) % table


@njit
def cell_key(x, y, z, cell, table):
    """The hash-table slot of the cell of side ``cell`` (m) that holds the point ``(x, y, z)``."""
    return index_key(int(math.floor(x / cell)), int(math.floor(y / cell)), int(math.floor(z / cell)), table)


@njit
def add_key(keys, n_keys, key):
    """Append ``key`` to the first ``n_keys`` of ``keys`` unless it is there already; returns the new count."""
    for k in range(n_keys):
        if keys[k] == key:
            return n_keys
    keys[n_keys] = key
    return n_keys + 1


@njit
def edge_adjacency(ei, ne, n_particles, adjacent_start, adjacent):
    """Each particle's neighbours along the edges (broken ones too): ``adjacent[adjacent_start[p]:
    adjacent_start[p + 1]]`` (``collision/adjacency.py``).  Scratch sizes: ``n_particles + 1`` and ``2 ne``."""
    clear_counts(adjacent_start, n_particles)
    for e in range(ne):
        count_link(adjacent_start, ei[e, E_A], ei[e, E_B])
    begin_fill(adjacent_start, n_particles)
    for e in range(ne):
        fill_link(adjacent_start, adjacent, ei[e, E_A], ei[e, E_B])
    end_fill(adjacent_start, n_particles)


@njit
def _same_soft_body(pi, a, b):
    """Whether particle rows ``a`` and ``b`` are nodes of one soft body (its elements keep them apart)."""
    return (pi[a, P_FLAGS] & PP_SOFT) != 0 and pi[a, P_SET] == pi[b, P_SET]


@njit
def particle_candidates(pf, pi, n_particles, margin, cell_start, cell_entries, adjacent_start, adjacent, out):
    """List the candidate pairs ``(a, b)``, ``a < b``, of the colliding particles into ``out``; returns how
    many there are (rows past ``out``'s end are not written).  ``margin`` (m): how far two particles may close
    in the step.  Scratch: ``cell_start`` (table + 1 ints; the table size is its length - 1) and
    ``cell_entries`` (n_particles ints)."""
    table = cell_start.shape[0] - 1
    largest = 0.0
    for p in range(n_particles):
        if (pi[p, P_FLAGS] & PP_COLLIDE) != 0:
            largest = max(largest, pf[p, P_RADIUS])
    cell = 2.0 * largest + margin
    if cell <= 0.0:
        return 0
    for k in range(table + 1):
        cell_start[k] = 0
    for p in range(n_particles):
        if (pi[p, P_FLAGS] & PP_COLLIDE) != 0:
            cell_start[cell_key(pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2], cell, table) + 1] += 1
    for k in range(table):
        cell_start[k + 1] += cell_start[k]
    fill = cell_start[:table].copy()
    for p in range(n_particles):
        if (pi[p, P_FLAGS] & PP_COLLIDE) != 0:
            key = cell_key(pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2], cell, table)
            cell_entries[fill[key]] = p
            fill[key] += 1
    n = 0
    keys = np.empty(27, np.int64)
    for a in range(n_particles):
        if (pi[a, P_FLAGS] & PP_COLLIDE) == 0:
            continue
        xa, ya, za = pf[a, P_POS], pf[a, P_POS + 1], pf[a, P_POS + 2]
        # the 27 cells around a's, each key once (two cells may share a key: their particles are seen once)
        n_keys = 0
        for di in range(-1, 2):
            for dj in range(-1, 2):
                for dk in range(-1, 2):
                    n_keys = add_key(keys, n_keys, cell_key(xa + di * cell, ya + dj * cell, za + dk * cell, cell,
                                                             table))
        for k in range(n_keys):
            for slot in range(cell_start[keys[k]], cell_start[keys[k] + 1]):
                b = cell_entries[slot]
                if b <= a:
                    continue
                d0, d1, d2 = pf[b, P_POS] - xa, pf[b, P_POS + 1] - ya, pf[b, P_POS + 2] - za
                reach = pf[a, P_RADIUS] + pf[b, P_RADIUS] + margin
                if d0 * d0 + d1 * d1 + d2 * d2 <= reach * reach and not joined(adjacent_start, adjacent, a, b) \
                        and not _same_soft_body(pi, a, b):
                    n = append_pair(out, n, a, b)
    return n


@njit
def particle_contacts(pf, bf, bi, bx, pairs, n_pairs, h, kf, ki, nk):
    """The position pass over the candidate pairs: overlaps removed (split by the inverse masses), static
    friction; the contacts appended to ``kf`` / ``ki`` from row ``nk``; returns the new count.  (The body
    tables ``bf``, ``bi``, ``bx`` are passed through to the pair code shared with the shapes' contacts, which
    reads no body for a pair of particles.)"""
    none = (0.0, 0.0, 0.0)
    for c in range(n_pairs):
        a, b = pairs[c, 0], pairs[c, 1]
        d0 = pf[a, P_POS] - pf[b, P_POS]
        d1 = pf[a, P_POS + 1] - pf[b, P_POS + 1]
        d2 = pf[a, P_POS + 2] - pf[b, P_POS + 2]
        distance = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        depth = pf[a, P_RADIUS] + pf[b, P_RADIUS] - distance
        if depth <= 0.0 or distance < 1e-12 or pf[a, P_INV_MASS] + pf[b, P_INV_MASS] <= 0.0:
            continue
        n = (d0 / distance, d1 / distance, d2 / distance)
        # the point on b's surface towards a
        point = (pf[b, P_POS] + n[0] * pf[b, P_RADIUS], pf[b, P_POS + 1] + n[1] * pf[b, P_RADIUS],
                 pf[b, P_POS + 2] + n[2] * pf[b, P_RADIUS])
        vn0 = ((pf[a, P_VEL0] - pf[b, P_VEL0]) * n[0] + (pf[a, P_VEL0 + 1] - pf[b, P_VEL0 + 1]) * n[1]
               + (pf[a, P_VEL0 + 2] - pf[b, P_VEL0 + 2]) * n[2])
        separate(pf, bf, bi, bx, KK_PARTICLE, a, b, none, (1.0, 0.0, 0.0, 0.0), point, n, depth, h, True, False, 1.0,
                 -1, 0.0)
        mu_s = math.sqrt(pf[a, P_STATIC_FRICTION] * pf[b, P_STATIC_FRICTION])
        stuck = hold_or_slip(pf, bf, bi, bx, KK_PARTICLE, a, b, none, (1.0, 0.0, 0.0, 0.0), point, n, depth,
                             mu_s, h, False, -1, 0.0)
        nk = record_contact(kf, ki, nk, a, b, KK_PARTICLE, n, point, depth, vn0,
                            math.sqrt(pf[a, P_FRICTION] * pf[b, P_FRICTION]),
                            max(pf[a, P_RESTITUTION], pf[b, P_RESTITUTION]), stuck)
    return nk
