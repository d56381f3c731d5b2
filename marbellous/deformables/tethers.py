"""Tethers (long-range attachments, Kim, Chentanez and Mueller 2012): no particle of an inextensible network
or of a cloth gets farther from its nearest world pin than the network's rods and cables (the cloth's edges)
allow (a cloth that can tear, ``tear_strain``, has none: they would hold it back from its tear; nor do the
vertices of the whole-cloth solve, stretch_solve.py, which hands a load to the pins by itself, and whose contacts
with bodies a tether pulling back each sub-step would feed with energy).

One position pass per sub-step hands a load up a chain of rods one link per pass: a 50 kg box hanging from
a rope of ten 50 g beads, 1 m long, sank 58 mm (5.8 %) below the rope's length at 16 sub-steps (a 5 kg box:
8 mm).  A particle joined to a world-pinned particle by a path of rods and cables of total rest length ``L``
can never be farther than ``L`` from it (the straight line is never longer than the path), so each such
particle gets a tether to its nearest pin (nearest along the path):

    C = |x_p - x_pin| - (1 + s) L <= 0,     solved as a cable with the pin immovable: x_p moves the whole way

which holds the chain's length in one pass, however heavy the load (the 50 kg box: 20 mm, the slack), and does
nothing while the rope is not straight.  The slack ``s`` (``TETHER_SLACK``, 2 %) leaves the load to the rods as long
as they hold it that well, so that their forces (``Network.forces``) report it; where a tether holds instead, the
rods report only their part (the 50 kg box: 93 N of its 495 N).  A body-pinned particle's tether pulls its body
(through the particle's place on it).  A network's springs do not count: they are meant to stretch; a cloth's
edges do (cloth is meant not to), and they need it: one pass per sub-step cannot hand a sheet's weight up to two
pinned corners through 50 rows of stiff springs (a 50 x 50 sheet of 0.5 kg hung by two corners, 16 sub-steps,
no bending: its most stretched edge at 2.2 times its length untethered, 1.35 times tethered).  The tethers follow
from the
networks and pins, and are found again (by Dijkstra's shortest paths over the rods and cables,
``scipy.sparse.csgraph``) whenever these change.
"""
import math

import numpy as np

from .._numba.jit import njit
from .edge_constraints import end_mass, move_end
from .particle_layout import (E_A, E_B, E_FLAGS, E_KIND, E_REST, E_TEAR, EB_BROKEN, EK_CABLE, EK_ROD, P_CLOTH, P_FLAGS,
                              P_PIN_BODY, P_POS, PP_PINNED)

#: how far past its path's rest length a tether lets a particle go, as a fraction of it
TETHER_SLACK = 0.02


def find_tethers(pf, pi, n, ef, ei, ne):
    """``(particle rows, pin rows, lengths)`` of the tethers of the particles ``0 .. n - 1`` over the live
    rods, cables and cloth edges among ``0 .. ne - 1`` (module docstring; the cloth vertices' ``P_CLOTH`` set)."""
    from scipy.sparse import coo_matrix              # (imported here: only worlds with networks need it)
    from scipy.sparse.csgraph import dijkstra
    none = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
    pinned = (pi[:n, P_FLAGS] & PP_PINNED) != 0
    anchors = np.flatnonzero(pinned & (pi[:n, P_PIN_BODY] < 0))
    # (a cloth that can tear must be free to stretch to its tear)
    cloth = (pi[ei[:ne, E_A], P_CLOTH] >= 0) & (pi[ei[:ne, E_B], P_CLOTH] >= 0) & np.isinf(ef[:ne, E_TEAR])
    inextensible = np.isin(ei[:ne, E_KIND], (EK_ROD, EK_CABLE)) | cloth
    keep = np.flatnonzero(inextensible & ((ei[:ne, E_FLAGS] & EB_BROKEN) == 0))
    if anchors.size == 0 or keep.size == 0:
        return none
    a, b, length = ei[keep, E_A], ei[keep, E_B], np.maximum(ef[keep, E_REST], 1e-12)
    graph = coo_matrix((np.concatenate([length, length]), (np.concatenate([a, b]), np.concatenate([b, a]))),
                       shape=(n, n)).tocsr()
    distance, _, source = dijkstra(graph, indices=anchors, min_only=True, return_predecessors=True)
    free = np.flatnonzero(np.isfinite(distance) & (source >= 0) & ~(pinned & (pi[:n, P_PIN_BODY] < 0)))
    # (a tether is only needed past the first link: the rod itself holds a pin's neighbour)
    free = free[distance[free] > 0.0]
    return free.astype(np.int64), source[free].astype(np.int64), (1.0 + TETHER_SLACK) * distance[free]


@njit
def solve_tethers(pf, pi, bf, bi, bx, particles, pins, lengths, slot, back, h):
    """Pull every particle farther from its pin than its tether's length back onto the tether's sphere (not
    the unknowns of the whole-cloth solve, ``slot >= 0``: it hands the load to the pins itself)."""
    for t in range(particles.shape[0]):
        p, q = particles[t], pins[t]
        if slot[p] >= 0:
            continue
        d0 = pf[p, P_POS] - pf[q, P_POS]
        d1 = pf[p, P_POS + 1] - pf[q, P_POS + 1]
        d2 = pf[p, P_POS + 2] - pf[q, P_POS + 2]
        distance = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        c = distance - lengths[t]
        if c <= 0.0:
            continue
        n = (-d0 / distance, -d1 / distance, -d2 / distance)
        on_body = (pi[p, P_FLAGS] & PP_PINNED) != 0 and pi[p, P_PIN_BODY] >= 0
        w = end_mass(pf, pi, bf, bi, bx, p, back, n) if on_body else 1.0
        if w <= 0.0:
            continue
        if on_body:
            move_end(pf, pi, bf, bi, bx, p, back, w, c / w, n, h)
        else:
            for k in range(3):
                pf[p, P_POS + k] += c * n[k]
