"""Cloth edges against cloth edges: two edges that cross with all four ends clear of the other's triangles,
which the points against triangles (triangle_contacts.py) do not see, kept a thickness apart on the side they
came from.

Once per step (``edge_candidates``), a grid of the edges' swept boxes (swept_boxes.py) lists the pairs of cloth
edges (of two cloths, or of one cloth with ``self_collision``) whose swept boxes overlap and that are no farther
apart than what the two can close in the step, leaving out edges that share an end or that lie within twice the
cloth's thickness of each other in its rest shape, and records the side ``s = +-1``: the sign of
``(x_a - x_c) . (e_1 x e_2)``, ``e_1 = x_b - x_a`` and ``e_2 = x_d - x_c``.  In each sub-step, a pair whose
closest points ``p_1 = x_a + u e_1`` and ``p_2 = x_c + v e_2`` lie inside both edges (``0 < u, v < 1``; at an
end it is a point's contact) and closer than ``g`` (the two edges' radii, half the thickness each) along
``n = s (e_1 x e_2) / |e_1 x e_2|``, or behind by less than that, is pushed apart:

    C = n . (p_1 - p_2) - g >= 0
    grad_a = (1 - u) n,  grad_b = u n,  grad_c = -(1 - v) n,  grad_d = -v n
    dlambda = -C / ((1 - u)^2 w_a + u^2 w_b + (1 - v)^2 w_c + v^2 w_d)

An overlap already there at the sub-step's start is reduced by at most ``PUSH_SPEED h``, as for the
triangles.  Edges that are nearly parallel (``|e_1 x e_2|`` under a thousandth of ``|e_1| |e_2|``) are left to
the points and triangles.
"""
import math

import numpy as np

from .._numba.jit import njit
from .layer_contacts import record_push
from .particle_layout import (CL_SELF, CL_THICKNESS, E_A, E_B, E_FLAGS, EB_BROKEN, P_CLOTH, P_INV_MASS, P_POS,
                              P_PREV, P_RADIUS, P_REST)
from .swept_boxes import (bin_boxes, box_table, closing_reach, empty_boxes, grow_box, overlapping, sweep_point,
                          typical_extent)
from .triangle_contacts import PUSH_SPEED

#: ``|e_1 x e_2| / (|e_1| |e_2|)`` under which two edges count as parallel
PARALLEL = 1e-3


@njit
def _cloth_edge(pi, ei, e):
    """The cloth of edge row ``e`` if it is a live edge between two vertices of one cloth, else -1."""
    a, b = ei[e, E_A], ei[e, E_B]
    if (ei[e, E_FLAGS] & EB_BROKEN) != 0 or pi[a, P_CLOTH] < 0 or pi[a, P_CLOTH] != pi[b, P_CLOTH]:
        return -1
    return pi[a, P_CLOTH]


@njit
def _rest_apart(pf, a, b, c, d, reach):
    """Whether every end of edge ``a b`` is at least ``reach`` (m) from every end of edge ``c d`` at rest."""
    for p in (a, b):
        for q in (c, d):
            if ((pf[p, P_REST] - pf[q, P_REST]) ** 2 + (pf[p, P_REST + 1] - pf[q, P_REST + 1]) ** 2
                    + (pf[p, P_REST + 2] - pf[q, P_REST + 2]) ** 2) < reach * reach:
                return False
    return True


@njit
def _side(pf, a, b, c, d):
    """``+1`` or ``-1``: the side of edge ``c d`` edge ``a b`` is on (module docstring); 0 if parallel."""
    e1 = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
    e2 = (pf[d, P_POS] - pf[c, P_POS], pf[d, P_POS + 1] - pf[c, P_POS + 1], pf[d, P_POS + 2] - pf[c, P_POS + 2])
    m = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    size = math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
    if size <= PARALLEL * math.sqrt((e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2) * (e2[0] ** 2 + e2[1] ** 2 + e2[2] ** 2)):
        return 0
    s = ((pf[a, P_POS] - pf[c, P_POS]) * m[0] + (pf[a, P_POS + 1] - pf[c, P_POS + 1]) * m[1]
         + (pf[a, P_POS + 2] - pf[c, P_POS + 2]) * m[2])
    return 1 if s >= 0.0 else -1


@njit
def _segment_distance(pf, a, b, c, d):
    """The distance (m) between the segments ``a b`` and ``c d``: the lines' closest points clamped into the
    segments, each clamp followed by the other segment's closest point to it (Ericson 2005, 5.1.9)."""
    e1 = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
    e2 = (pf[d, P_POS] - pf[c, P_POS], pf[d, P_POS + 1] - pf[c, P_POS + 1], pf[d, P_POS + 2] - pf[c, P_POS + 2])
    r = (pf[a, P_POS] - pf[c, P_POS], pf[a, P_POS + 1] - pf[c, P_POS + 1], pf[a, P_POS + 2] - pf[c, P_POS + 2])
    l11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]
    l22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]
    l12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]
    r1 = r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2]
    r2 = r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2]
    det = l11 * l22 - l12 * l12
    u = min(max((l12 * r2 - l22 * r1) / det, 0.0), 1.0) if det > 1e-24 else 0.0
    v = (l12 * u + r2) / l22 if l22 > 1e-24 else 0.0
    if v < 0.0 or v > 1.0:
        v = min(max(v, 0.0), 1.0)
        u = min(max((l12 * v - r1) / l11, 0.0), 1.0) if l11 > 1e-24 else 0.0
    gap = (r[0] + u * e1[0] - v * e2[0], r[1] + u * e1[1] - v * e2[1], r[2] + u * e1[2] - v * e2[2])
    return math.sqrt(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2])


@njit
def edge_candidates(pf, pi, ei, ne, cloth_f, mean, dt, slack, out):
    """List the candidate ``(edge, edge, side)`` rows into ``out`` (module docstring); returns how many there
    are (rows past ``out``'s end are not written).  Two edges are looked at when their swept boxes overlap
    (swept_boxes.py; ``mean`` the velocity they sweep relative to, m/s, each grown by half its cloth's
    thickness and half of ``slack``, m), and kept when they are no farther apart than the thickest cloth's
    thickness, ``slack`` and what their ends can close in the step (``swept_boxes.closing_reach``)."""
    if cloth_f.shape[0] == 0 or (cloth_f.shape[0] == 1 and cloth_f[0, CL_SELF] == 0.0):
        return 0
    thickest = 0.0
    for c in range(cloth_f.shape[0]):
        thickest = max(thickest, cloth_f[c, CL_THICKNESS])
    lo, hi = empty_boxes(ne)
    for e in range(ne):
        own = _cloth_edge(pi, ei, e)
        if own >= 0:
            sweep_point(pf, ei[e, E_A], mean, dt, lo, hi, e)
            sweep_point(pf, ei[e, E_B], mean, dt, lo, hi, e)
            grow_box(lo, hi, e, 0.5 * cloth_f[own, CL_THICKNESS] + 0.5 * slack)
    cell = typical_extent(lo, hi, ne)
    cell_start = box_table(ne)
    grid = bin_boxes(lo, hi, ne, cell, cell_start)
    found = np.empty(ne, np.int64)
    n = 0
    for e1 in range(ne):
        own = _cloth_edge(pi, ei, e1)
        if own < 0:
            continue
        a, b = ei[e1, E_A], ei[e1, E_B]
        for f in range(overlapping(lo, hi, ne, cell, cell_start, grid, lo, hi, e1, e1, found)):
            e2 = found[f]
            other = _cloth_edge(pi, ei, e2)
            c, d = ei[e2, E_A], ei[e2, E_B]
            if c == a or c == b or d == a or d == b or (other == own and cloth_f[own, CL_SELF] == 0.0):
                continue
            if other == own and not _rest_apart(pf, a, b, c, d, 2.0 * cloth_f[own, CL_THICKNESS]):
                continue
            closing = max(closing_reach(pf, a, c, dt), closing_reach(pf, a, d, dt), closing_reach(pf, b, c, dt),
                          closing_reach(pf, b, d, dt))
            if _segment_distance(pf, a, b, c, d) > thickest + closing + slack:
                continue
            side = _side(pf, a, b, c, d)
            if side == 0:
                continue
            if n < out.shape[0]:
                out[n, 0] = e1
                out[n, 1] = e2
                out[n, 2] = side
            n += 1
    return n


@njit
def edge_contacts(pf, ei, pairs, n_pairs, h, lf, li, n_rec):
    """The position pass over the candidate pairs (module docstring) in a sub-step of ``h`` seconds; each push is
    recorded into ``lf``/``li`` after the ``n_rec`` there (``layer_contacts.record_push``); returns their new
    count."""
    push = PUSH_SPEED * h
    for k in range(n_pairs):
        e1, e2, s = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        a, b, c, d = ei[e1, E_A], ei[e1, E_B], ei[e2, E_A], ei[e2, E_B]
        e_1 = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
        e_2 = (pf[d, P_POS] - pf[c, P_POS], pf[d, P_POS + 1] - pf[c, P_POS + 1], pf[d, P_POS + 2] - pf[c, P_POS + 2])
        r = (pf[a, P_POS] - pf[c, P_POS], pf[a, P_POS + 1] - pf[c, P_POS + 1], pf[a, P_POS + 2] - pf[c, P_POS + 2])
        m = (e_1[1] * e_2[2] - e_1[2] * e_2[1], e_1[2] * e_2[0] - e_1[0] * e_2[2], e_1[0] * e_2[1] - e_1[1] * e_2[0])
        size = math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        l11 = e_1[0] * e_1[0] + e_1[1] * e_1[1] + e_1[2] * e_1[2]
        l22 = e_2[0] * e_2[0] + e_2[1] * e_2[1] + e_2[2] * e_2[2]
        if size <= PARALLEL * math.sqrt(l11 * l22):
            continue
        # the closest points of the two lines: u, v from d/du = d/dv = 0 of |r + u e_1 - v e_2|^2
        l12 = e_1[0] * e_2[0] + e_1[1] * e_2[1] + e_1[2] * e_2[2]
        r1 = r[0] * e_1[0] + r[1] * e_1[1] + r[2] * e_1[2]
        r2 = r[0] * e_2[0] + r[1] * e_2[1] + r[2] * e_2[2]
        det = l11 * l22 - l12 * l12
        u = (l12 * r2 - l22 * r1) / det
        v = (l11 * r2 - l12 * r1) / det
        if u <= 0.0 or u >= 1.0 or v <= 0.0 or v >= 1.0:
            continue
        n = (s * m[0] / size, s * m[1] / size, s * m[2] / size)
        gap = 0.5 * (pf[a, P_RADIUS] + pf[b, P_RADIUS] + pf[c, P_RADIUS] + pf[d, P_RADIUS])
        dist = n[0] * r[0] + n[1] * r[1] + n[2] * r[2]        # (p_1 - p_2 lies along n for the lines' closest)
        if dist >= gap or dist < -gap:
            continue
        dist_start = 0.0
        for j in range(3):
            dist_start += n[j] * ((1.0 - u) * pf[a, P_PREV + j] + u * pf[b, P_PREV + j]
                                  - (1.0 - v) * pf[c, P_PREV + j] - v * pf[d, P_PREV + j])
        target = gap if dist_start >= gap else min(gap, dist_start + push)
        if dist >= target:
            continue
        wa, wb, wc, wd = pf[a, P_INV_MASS], pf[b, P_INV_MASS], pf[c, P_INV_MASS], pf[d, P_INV_MASS]
        denominator = (1.0 - u) ** 2 * wa + u * u * wb + (1.0 - v) ** 2 * wc + v * v * wd
        if denominator <= 0.0:
            continue
        dlambda = (target - dist) / denominator
        for j in range(3):
            pf[a, P_POS + j] += wa * (1.0 - u) * dlambda * n[j]
            pf[b, P_POS + j] += wb * u * dlambda * n[j]
            pf[c, P_POS + j] -= wc * (1.0 - v) * dlambda * n[j]
            pf[d, P_POS + j] -= wd * v * dlambda * n[j]
        n_rec = record_push(lf, li, n_rec, (a, b, c, d), (1.0 - u, u, -(1.0 - v), -v), n, dlambda, target)
    return n_rec
