"""Swept boxes and the hash grid that pairs them: the broad phase of the cloths' contacts with themselves
(triangle_contacts.py, edge_contacts.py).

A point's swept box holds where it goes in the step if it keeps the direction of its velocity ``v`` relative
to a common velocity ``m`` (any will do: two points that meet at time ``s`` meet at one place in every frame
moving at a constant velocity) at up to twice its speed, or turns by up to half its speed, and its user force
``F`` (of inverse mass ``w``) acts on it:

    box(p) = box{ x_p,  x_p + 2 (v_p - m) dt + w_p F_p dt^2 } grown by |v_p - m| dt / 2 and its pad

(``m`` the mean velocity of the particles, so a sheet falling as a whole has boxes no larger than at rest; the
turn: a bag's vertices pushed about by the ball in it, boxed along their velocities alone, missed folds of the
bag they were pushed into, which then snagged: its edges ended stretched by 18 % instead of 12 %).
A triangle's or an edge's box holds its corners' boxes.  Where two primitives meet within the step, the
meeting place lies in both boxes, so only pairs whose boxes overlap are candidates: the boxes follow the
direction each one moves in, so a sheet that has stopped on a sphere in its middle while its rim still falls
pairs each edge with the few it can reach, not with every edge within its speed's reach in all directions.

The pairing: a hash grid (``particle_pairs.index_key``) of cells whose width along each axis is ``cell 2^l``
for that axis' level ``l`` (``cell`` the boxes' median largest extent).  Each box is binned once, into the cell
of its low corner among the cells as narrow as it is along each axis (so a box long in one direction, the sweep
of a fast point, sits in cells long in that direction only), with a counting sort so the candidates come in a
fixed order.  A box that overlaps a query box then has its low corner at most one cell below the query's along
each axis, so a query looks at those few cells of each shape of cell in use, and skips a shape whose boxes all
lie away from it.  The table has at least four slots a box, so the cells a query looks at seldom share a slot
with other cells' boxes.  A sheet at rest has every box in the finest cells; the fast rim of a sheet landing on
a sphere moves its own boxes to longer cells, not everyone's.
"""
import math

import numpy as np

from .._numba.jit import njit
from .particle_layout import P_FORCE, P_INV_MASS, P_POS, P_VEL
from .particle_pairs import index_key

#: levels along an axis (a box wider along some axis than 2^15 cell is looked at by every query)
LEVELS = 16


@njit
def empty_boxes(count):
    """``(lo, hi)``: ``count`` empty boxes (lo above hi on every axis)."""
    return np.full((count, 3), np.inf), np.full((count, 3), -np.inf)


@njit
def sweep_point(pf, p, mean, dt, lo, hi, row):
    """Widen box ``row`` of ``lo``/``hi`` (m) to hold particle row ``p``'s sweep over the step of ``dt`` s,
    ``x_p`` to ``x_p + 2 (v_p - mean) dt + w_p F_p dt^2`` and the turn ``|v_p - mean| dt / 2`` around it (module
    docstring)."""
    turn = 0.5 * math.sqrt((pf[p, P_VEL] - mean[0]) ** 2 + (pf[p, P_VEL + 1] - mean[1]) ** 2
                           + (pf[p, P_VEL + 2] - mean[2]) ** 2)
    for k in range(3):
        x = pf[p, P_POS + k]
        y = x + 2.0 * (pf[p, P_VEL + k] - mean[k]) * dt + pf[p, P_INV_MASS] * pf[p, P_FORCE + k] * dt * dt
        lo[row, k] = min(lo[row, k], min(x, y) - turn * dt)
        hi[row, k] = max(hi[row, k], max(x, y) + turn * dt)


@njit
def closing_reach(pf, p, q, dt):
    """How far (m) particle rows ``p`` and ``q`` may close in the step of ``dt`` s: twice their relative speed
    times ``dt`` and what their user forces add, ``2 |v_p - v_q| dt + |w_p F_p - w_q F_q| dt^2``."""
    dv = dF = 0.0
    for k in range(3):
        dv += (pf[p, P_VEL + k] - pf[q, P_VEL + k]) ** 2
        dF += (pf[p, P_INV_MASS] * pf[p, P_FORCE + k] - pf[q, P_INV_MASS] * pf[q, P_FORCE + k]) ** 2
    return 2.0 * math.sqrt(dv) * dt + math.sqrt(dF) * dt * dt


@njit
def grow_box(lo, hi, row, pad):
    """Grow box ``row`` of ``lo``/``hi`` by ``pad`` (m) on every side."""
    for k in range(3):
        lo[row, k] -= pad
        hi[row, k] += pad


@njit
def boxes_overlap(lo, hi, a, lo2, hi2, b):
    """Whether box ``a`` of ``lo``/``hi`` and box ``b`` of ``lo2``/``hi2`` overlap."""
    return (lo[a, 0] <= hi2[b, 0] and lo2[b, 0] <= hi[a, 0] and lo[a, 1] <= hi2[b, 1] and lo2[b, 1] <= hi[a, 1]
            and lo[a, 2] <= hi2[b, 2] and lo2[b, 2] <= hi[a, 2])


@njit
def typical_extent(lo, hi, count):
    """The median largest extent (m) of the non-empty boxes among the first ``count`` of ``lo``/``hi``, a
    millionth over (boxes as wide as it but for rounding share its level), at least a micrometre."""
    extents = np.empty(count)
    used = 0
    for b in range(count):
        if lo[b, 0] <= hi[b, 0]:
            extents[used] = max(hi[b, 0] - lo[b, 0], hi[b, 1] - lo[b, 1], hi[b, 2] - lo[b, 2])
            used += 1
    return max(1.000001 * np.median(extents[:used]), 1e-6) if used > 0 else 1e-6


@njit
def shape_key(i, j, k, shape, table):
    """The hash-table slot (of ``table``) of cell ``(i, j, k)`` among the cells of shape ``shape``."""
    return index_key(i ^ (shape * 2654435761), j, k, table)


@njit
def box_table(count):
    """Zeroed slot starts of a hash table for ``count`` boxes (:func:`bin_boxes`): at least four slots a box, so
    that a query's cells seldom share a slot with other cells' boxes (a power of two)."""
    table = 16
    while table < 4 * count:
        table *= 2
    return np.zeros(table + 1, np.int64)


@njit
def _shape(lo, hi, b, cell):
    """The shape of cell that box ``b`` is binned in, ``l_x + LEVELS (l_y + LEVELS l_z)``, each ``l`` the finest
    level whose width ``cell 2^l`` holds the box's extent along that axis; -1 if some extent needs more than
    ``LEVELS``."""
    shape = 0
    for k in (2, 1, 0):
        extent = hi[b, k] - lo[b, k]
        size = cell
        level = 0
        while level < LEVELS and extent > size:
            size *= 2.0
            level += 1
        if level == LEVELS:
            return -1
        shape = shape * LEVELS + level
    return shape


@njit
def _sizes(shape, cell):
    """The widths (m) along x, y and z of the cells of shape ``shape``."""
    return (cell * 2.0 ** (shape % LEVELS), cell * 2.0 ** ((shape // LEVELS) % LEVELS),
            cell * 2.0 ** (shape // (LEVELS * LEVELS)))


@njit
def bin_boxes(lo, hi, count, cell, cell_start):
    """Bin the non-empty boxes ``0 .. count - 1`` of ``lo``/``hi`` into the grid of finest cell ``cell`` (m)
    (module docstring); returns ``(box, home, glo, ghi, shapes, wide, shape_lo, shape_hi)``: the binned boxes'
    rows, cells ``(i, j, k, shape)`` and corners in the order of their slots (box ``box[s]`` for ``s`` in
    ``cell_start[key] .. cell_start[key + 1]`` lies in cell ``home[s]``, of slot ``key``; ``cell_start``: table + 1
    ints, filled here, :func:`box_table`; a cell's boxes are read one after another), the shapes of cell in use
    (ascending), the boxes too wide for any, and the box around each shape's boxes (rows as ``shapes``)."""
    table = cell_start.shape[0] - 1
    for k in range(table + 1):
        cell_start[k] = 0
    cells = np.empty((count, 4), np.int64)
    slot = np.full(count, -1, np.int64)
    used = np.zeros(LEVELS ** 3, np.bool_)
    n_wide = 0
    for b in range(count):
        if lo[b, 0] > hi[b, 0]:
            continue
        shape = _shape(lo, hi, b, cell)
        if shape < 0:
            n_wide += 1
            continue
        sizes = _sizes(shape, cell)
        for k in range(3):
            cells[b, k] = math.floor(lo[b, k] / sizes[k])
        cells[b, 3] = shape
        used[shape] = True
        slot[b] = shape_key(cells[b, 0], cells[b, 1], cells[b, 2], shape, table)
        cell_start[slot[b] + 1] += 1
    for k in range(table):
        cell_start[k + 1] += cell_start[k]
    m = cell_start[table]
    box, home, glo, ghi = np.empty(m, np.int64), np.empty((m, 4), np.int64), np.empty((m, 3)), np.empty((m, 3))
    wide = np.empty(n_wide, np.int64)
    fill = cell_start[:table].copy()
    n_wide = 0
    for b in range(count):
        if slot[b] >= 0:
            s = fill[slot[b]]
            fill[slot[b]] += 1
            box[s] = b
            # (element by element: a row copied whole is a view made, counted and freed for every box)
            for k in range(4):
                home[s, k] = cells[b, k]
            for k in range(3):
                glo[s, k] = lo[b, k]
                ghi[s, k] = hi[b, k]
        elif lo[b, 0] <= hi[b, 0]:
            wide[n_wide] = b
            n_wide += 1
    shapes = np.flatnonzero(used)
    index_of = np.empty(LEVELS ** 3, np.int64)       # (read at the shapes in use only)
    for u in range(shapes.shape[0]):
        index_of[shapes[u]] = u
    shape_lo, shape_hi = empty_boxes(shapes.shape[0])
    for s in range(m):
        u = index_of[home[s, 3]]
        for k in range(3):
            shape_lo[u, k] = min(shape_lo[u, k], glo[s, k])
            shape_hi[u, k] = max(shape_hi[u, k], ghi[s, k])
    return box, home, glo, ghi, shapes, wide, shape_lo, shape_hi


@njit
def overlapping(lo, hi, count, cell, cell_start, grid, qlo, qhi, q, after, found):
    """The boxes ``b > after`` of ``lo``/``hi`` (``grid`` from :func:`bin_boxes` with ``cell`` and
    ``cell_start``) that overlap query box ``q`` of ``qlo``/``qhi``, each once, into ``found`` (``count`` ints);
    returns how many."""
    box, home, glo, ghi, shapes, wide, shape_lo, shape_hi = grid
    table = cell_start.shape[0] - 1
    # (the query's corners read once, and each box's corners tested before its cell, written out: the edge and
    # triangle candidates of a 128 x 128 sheet in free fall, which find none, took 2.3 and 2.9 times as long the
    # other way, and 2.5 and 2 times as long with the tests below through a helper like ``boxes_overlap``, inlined
    # or not)
    x0, y0, z0, x1, y1, z1 = qlo[q, 0], qlo[q, 1], qlo[q, 2], qhi[q, 0], qhi[q, 1], qhi[q, 2]
    n = 0
    for u in range(shapes.shape[0]):
        # (a shape none of whose boxes comes near the query: a sheet landing on a sphere binned its edges in up
        # to 28 shapes, and the 27 or more cells of each held boxes of other cells in their slots)
        if not (shape_lo[u, 0] <= x1 and x0 <= shape_hi[u, 0] and shape_lo[u, 1] <= y1 and y0 <= shape_hi[u, 1]
                and shape_lo[u, 2] <= z1 and z0 <= shape_hi[u, 2]):
            continue
        shape = shapes[u]
        sizes = _sizes(shape, cell)
        first = (math.floor(x0 / sizes[0]) - 1, math.floor(y0 / sizes[1]) - 1, math.floor(z0 / sizes[2]) - 1)
        last = (math.floor(x1 / sizes[0]), math.floor(y1 / sizes[1]), math.floor(z1 / sizes[2]))
        if (last[0] - first[0] + 1) * (last[1] - first[1] + 1) * (last[2] - first[2] + 1) > count:
            # (a query wider than these cells by far: every box in them instead)
            for s in range(box.shape[0]):
                if home[s, 3] == shape and box[s] > after and boxes_overlap(glo, ghi, s, qlo, qhi, q):
                    found[n] = box[s]
                    n += 1
            continue
        for i in range(first[0], last[0] + 1):
            for j in range(first[1], last[1] + 1):
                for k in range(first[2], last[2] + 1):
                    key = shape_key(i, j, k, shape, table)
                    for s in range(cell_start[key], cell_start[key + 1]):
                        # (another cell of the same slot: its boxes are not this cell's)
                        if glo[s, 0] <= x1 and x0 <= ghi[s, 0] and glo[s, 1] <= y1 and y0 <= ghi[s, 1] \
                                and glo[s, 2] <= z1 and z0 <= ghi[s, 2] and box[s] > after and home[s, 0] == i \
                                and home[s, 1] == j and home[s, 2] == k and home[s, 3] == shape:
                            found[n] = box[s]
                            n += 1
    for b in wide:
        if b > after and boxes_overlap(lo, hi, b, qlo, qhi, q):
            found[n] = b
            n += 1
    return n
