"""Contact passes on several threads: contacts split into regions that share no movable body.

At the start of each step the movable (awake, dynamic) bodies are cut into ``R`` slabs of equal width
along the axis on which their centres spread most.  A contact belongs to region ``r`` when each of its
two bodies lies in slab ``r`` or cannot move (static and sleeping bodies: the solver reads them and never
writes them); otherwise it belongs to the boundary.  Each region and then the boundary is laid out in
coloured bundles of its own (dynamics/contact_bundles.py); a pass solves the ``R`` regions' bundles (and
overflow contacts) at the same time, then the boundary's, so no two threads ever write one body.  With
one thread there is one region: all the contacts, and an empty boundary.

Sequential impulses converge whatever order the contacts are visited in; this order differs from the
serial pass (``threads = 1``), so the results differ from it by round-off and iteration order, and they
are the same bit for bit on every run with the same thread count.  Below ``MIN_PARALLEL_CONTACTS``
contacts the serial pass is used, as a thread launch (about 1 us with the OpenMP layer) costs more than
it saves.
"""
import numpy as np
from numba import prange

from .._numba.jit import njit, njit_inline, njit_parallel
from .._numba.wide import LANES
from ..state.layout import C_BODY_A, C_BODY_B, POS
from .contact_bundles import bundle_contacts, push_bundles, solve_bundles
from .contact_solver import push_contacts, solve_contacts
from .forces import is_moving
from .soft import soft_depth

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


@njit_inline
def bundle_regions(cf, ci, order, starts, regions, sb, used, colour_of, colour_fill, wide_f, wide_i, part_bundles,
                   overflow, part_overflow):
    """Coloured bundles (``contact_bundles.bundle_contacts``) of each region and then of the boundary:
    part ``p``'s bundles are ``part_bundles[p]:part_bundles[p + 1]`` and its overflow contacts
    ``overflow[part_overflow[p]:part_overflow[p + 1]]``, for ``p <= regions``.  Returns the bundles in all."""
    part_bundles[0] = 0
    part_overflow[0] = 0
    for part in range(regions + 1):
        bundles, n_over = bundle_contacts(cf, ci, order, starts[part], starts[part + 1], sb, used, colour_of,
                                          colour_fill, wide_f, wide_i, part_bundles[part], overflow,
                                          part_overflow[part])
        part_bundles[part + 1] = part_bundles[part] + bundles
        part_overflow[part + 1] = part_overflow[part] + n_over
    return part_bundles[regions + 1]


@njit
def _solve_part(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, part, sb, pb, lam_p, h, pushing, rate,
                max_push, first_pass, soft, lane_change):
    """One pass over part ``part``: its bundles, then its overflow by the scalar pass; the largest velocity
    change (m/s).  A velocity pass (``solve_bundles``, ``solve_contacts``; ``soft`` = (bias_rate, mass_scale,
    impulse_scale), (0, 1, 0) in the rigid relax pass) or, when ``pushing``, a push pass on the pseudo-velocities ``pb``
    (``push_bundles``, ``push_contacts``; ``lam_p`` the overflow's push impulses).  ``lane_change`` is
    scratch of ``LANES`` floats."""
    lo, hi = part_overflow[part], part_overflow[part + 1]
    if pushing:
        depth = soft_depth(rate, max_push)
        change = push_bundles(wide_f, wide_i, part_bundles[part], part_bundles[part + 1], sb, pb, h, rate, max_push,
                              depth, first_pass, lane_change)
        return max(change, push_contacts(cf, ci, overflow, lo, hi, sb, pb, lam_p, h, rate, max_push, depth,
                                         first_pass))
    change = solve_bundles(wide_f, wide_i, part_bundles[part], part_bundles[part + 1], sb, h, soft, lane_change)
    return max(change, solve_contacts(cf, ci, overflow, lo, hi, sb, h, soft))


@njit_parallel
def _solve_regions(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, regions, sb, pb, lam_p, h, pushing,
                   rate, max_push, first_pass, soft, lane_change, largest):
    """One pass: the regions at the same time, then the boundary; the largest velocity change (m/s)."""
    for r in prange(regions):
        largest[r] = _solve_part(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, r, sb, pb, lam_p, h,
                                 pushing, rate, max_push, first_pass, soft, lane_change[r * LANES:(r + 1) * LANES])
    change = _solve_part(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, regions, sb, pb, lam_p, h,
                         pushing, rate, max_push, first_pass, soft, lane_change[regions * LANES:(regions + 1) * LANES])
    for r in range(regions):
        change = max(change, largest[r])
    return change


@njit_inline
def solve_bundle_pass(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, regions, sb, pb, lam_p, h,
                      pushing, rate, max_push, first_pass, soft, lane_change, largest):
    """One pass of sequential impulses over the bundles and overflow of every part (``bundle_regions``), the
    regions on ``regions`` threads: a velocity pass, or a push pass when ``pushing`` (``_solve_part``);
    returns the largest velocity change (m/s).  Scratch: ``lane_change`` (``LANES`` floats per part),
    ``largest`` (one float per region)."""
    if regions > 1:
        return _solve_regions(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, regions, sb, pb, lam_p,
                              h, pushing, rate, max_push, first_pass, soft, lane_change, largest)
    return _solve_part(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, 0, sb, pb, lam_p, h, pushing,
                       rate, max_push, first_pass, soft, lane_change)
