"""Contact passes on several threads: contacts split into regions that share no movable body.

At the start of each step the movable (awake, dynamic) bodies are cut into ``R`` slabs of equal width
along the axis on which their centres spread most.  A contact belongs to region ``r`` when each of its
two bodies lies in slab ``r`` or cannot move (static and sleeping bodies: the solver reads them and never
writes them); otherwise it belongs to the boundary.  A pass solves the ``R`` regions at the same time,
each in the step's contact order, then the boundary contacts, so no two threads ever write one body.

Sequential impulses converge whatever order the contacts are visited in; this order differs from the
serial pass (``threads = 1``), so the results differ from it by round-off and iteration order, and they
are the same bit for bit on every run with the same thread count.  Below ``MIN_PARALLEL_CONTACTS``
contacts the serial pass is used, as a thread launch (about 1 us with the OpenMP layer) costs more than
it saves.
"""
import numpy as np
from numba import prange

from .._jit import njit, njit_inline, njit_parallel
from ..layout import C_BODY_A, C_BODY_B, POS
from .contact_solver import solve_contacts
from .forces import is_moving

#: fewest contacts for which a pass runs in regions
MIN_PARALLEL_CONTACTS = 256


@njit_inline
def order_contacts(bf, bi, ci, nc, nb, regions, slab, order, starts):
    """Contact order for the step's passes: ``order[starts[r]:starts[r + 1]]`` are region ``r``'s contacts
    (ascending) for ``r < R``, ``order[starts[R]:starts[R + 1]]`` the boundary's.  ``regions`` is the thread
    count asked for; returns ``R`` (1 when the serial pass is to be used: then ``order`` is ``0..nc-1``).
    ``slab`` is scratch of ``nb`` ints, ``starts`` of ``regions + 2``."""
    if regions < 2 or nc < MIN_PARALLEL_CONTACTS:
        for c in range(nc):
            order[c] = c
        starts[0], starts[1], starts[2] = 0, nc, nc
        return 1
    # the slabs: equal widths along the axis of largest spread of the movable bodies
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(nb):
        if is_moving(bi, i):
            for k in range(3):
                lo[k] = min(lo[k], bf[i, POS + k])
                hi[k] = max(hi[k], bf[i, POS + k])
    axis = 0
    for k in range(1, 3):
        if hi[k] - lo[k] > hi[axis] - lo[axis]:
            axis = k
    width = (hi[axis] - lo[axis]) / regions
    for i in range(nb):
        if not is_moving(bi, i):
            slab[i] = -1                     # cannot move: shared by every region
        elif width > 0.0:
            slab[i] = min(regions - 1, max(0, int((bf[i, POS + axis] - lo[axis]) / width)))
        else:
            slab[i] = 0
    # counting sort of the contacts by region (boundary last), stable
    for r in range(regions + 2):
        starts[r] = 0
    for c in range(nc):
        starts[_region(slab, ci, c, regions) + 1] += 1
    for r in range(regions + 1):
        starts[r + 1] += starts[r]
    for c in range(nc):
        r = _region(slab, ci, c, regions)
        order[starts[r]] = c
        starts[r] += 1
    for r in range(regions, 0, -1):          # starts[r] now ends region r: shift back to the starts
        starts[r] = starts[r - 1]
    starts[0] = 0
    return regions


@njit
def _region(slab, ci, c, regions):
    """Region of contact ``c``: its movable bodies' common slab, or ``regions`` (the boundary)."""
    sa = slab[ci[c, C_BODY_A]]
    sb = slab[ci[c, C_BODY_B]]
    if sa < 0:
        return max(sb, 0)
    if sb < 0 or sb == sa:
        return sa
    return regions


@njit_parallel
def _solve_regions(cf, ci, order, starts, regions, sb, h, use_bias, soft, max_push, largest):
    """One pass: the regions at the same time, then the boundary; the largest velocity change (m/s)."""
    for r in prange(regions):
        largest[r] = solve_contacts(cf, ci, order, starts[r], starts[r + 1], sb, h, use_bias, soft, max_push)
    change = solve_contacts(cf, ci, order, starts[regions], starts[regions + 1], sb, h, use_bias, soft, max_push)
    for r in range(regions):
        change = max(change, largest[r])
    return change


@njit_inline
def solve_contact_pass(cf, ci, order, starts, regions, sb, h, use_bias, soft, max_push, largest):
    """One pass of sequential impulses over the contacts in the step's order (``order_contacts``), on
    ``regions`` threads; returns the largest velocity change (m/s).  ``largest`` is scratch of
    ``regions`` floats."""
    if regions > 1:
        return _solve_regions(cf, ci, order, starts, regions, sb, h, use_bias, soft, max_push, largest)
    return solve_contacts(cf, ci, order, starts[0], starts[1], sb, h, use_bias, soft, max_push)
