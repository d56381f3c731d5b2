"""The renderer's reads of a World's internals: the broad phase's boxes, and the particle and edge tables.

The World has no public view of its broad phase, so :func:`broadphase_boxes` reads the box table
directly (``World._state.aabbs``, one row ``(lo x, y, z, hi x, y, z)`` per body row ``Body._index``).
Particles and networks have public handles, but each property read copies one set's rows; a frame of a
16k-particle net reads every set and network at once from the particle tables (``World._state.particles``,
columns in ``deformables/particle_layout.py``) with :func:`particle_table` and :func:`network_edges`.  The
vertices and edges of cloths live in the same tables (each cloth one set and one network, listed in
``World._state.particles.cloths``, :func:`cloth_rows`); they are drawn as the cloth's surface
(``cloth_drawing.py``), so these two leave them out.  When the World's tables change shape, these are the
only functions to adapt.
"""
import numpy as np

from ..deformables import particle_layout as P

#: Edge kinds by their code in the edge table (``particle_layout.EK_*``), as ``Network.kind`` names them.
EDGE_KIND_NAMES = {P.EK_SPRING: "spring", P.EK_ROD: "rod", P.EK_CABLE: "cable"}


def broadphase_boxes(world, bodies):
    """``(lo, hi)``: the broad-phase box corners (len(bodies), 3) (m) of ``bodies`` of ``world``, as the
    last step computed them (swept over the step's motion and grown by the speculative distance).

    A static body's box is set when it is added (infinite for a plane); a dynamic body has no box
    before its first step (both corners zero).
    """
    rows = np.array([b._index for b in bodies], np.int64)
    boxes = world._state.aabbs[rows] if len(rows) else np.zeros((0, 6))
    return boxes[:, :3].copy(), boxes[:, 3:].copy()


def cloth_rows(world):
    """Whether each row of ``world``'s particle table (N,) is a cloth's vertex or a soft body's node (each
    cloth's vertices and each soft body's nodes are the contiguous rows of its set)."""
    ps = world._state.particles
    rows = np.zeros(ps.n, dtype=bool)
    for record in (*ps.cloths, *ps.softs):
        rows[record.set.start:record.set.start + record.set.count] = True
    return rows


def particle_table(world):
    """``(positions (N, 3) m, radii (N,) m, pinned (N,) bool)`` of every particle of every set of ``world``
    that is not a cloth's vertex, sets in creation order.  In a world without cloth, ``positions`` and
    ``radii`` are views of the live table (valid until the next step or change): copy them to keep them.  (A
    soft body's nodes are left out as well: it is drawn as its surface.)"""
    ps = world._state.particles
    f = ps.pf[:ps.n]
    table = f[:, P.P_POS:P.P_POS + 3], f[:, P.P_RADIUS], (ps.pi[:ps.n, P.P_FLAGS] & P.PP_PINNED) != 0
    if not ps.cloths and not ps.softs:
        return table
    keep = ~cloth_rows(world)
    return tuple(column[keep] for column in table)


def network_edges(world):
    """``(ends (E, 2, 3) m, kinds (E,) int)`` of every edge of every network of ``world`` that is not broken
    and not a cloth's: the positions of its two particles now, and its kind (a key of
    :data:`EDGE_KIND_NAMES`)."""
    ps = world._state.particles
    ei = ps.ei[:ps.ne]
    keep = (ei[:, P.E_FLAGS] & P.EB_BROKEN) == 0
    if ps.cloths or ps.softs:
        keep &= ~cloth_rows(world)[ei[:, P.E_A]]
    ends = ei[keep][:, P.E_A:P.E_B + 1]
    x = ps.pf[:ps.n, P.P_POS:P.P_POS + 3]
    return x[ends], ei[keep, P.E_KIND]
