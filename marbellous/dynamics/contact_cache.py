"""Persistent contacts: match this step's contact points with last step's and warm-start their impulses.

A contact point is identified by ``(body_a, body_b, shape_a, shape_b, feature)``.  Both lists come in
the broad phase's canonical pair order, so one merge pass over the pairs finds every match; within a
pair the few candidates are compared directly.  Matched points inherit the accumulated normal,
friction (re-projected onto the new tangents) and rolling impulses and the sliding state.
"""
from .._numba.jit import njit, njit_inline
from ..state.layout import (C_BODY_A, C_BODY_B, C_FEATURE, C_FLAGS, C_LAMBDA_N, C_LAMBDA_R, C_LAMBDA_T1, C_LAMBDA_T2,
                            C_MASS_N, C_MASS_T1, C_MASS_T2, C_NORMAL, C_PAIR_SLIP, C_SHAPE_A, C_SHAPE_B, C_T1, C_T2,
                            CF_COLS, CI_COLS, CP_MATCHED, CP_RESTING, CP_SENSOR, CP_SLIDING, F_ALIVE, F_SLEEPING, FLAGS)
from .forces import is_driven, is_moving
from .contact_basis import contact_basis


@njit
def _pair_key_less(ci_x, x, ci_y, y):
    """True if row x's body pair sorts before row y's."""
    if ci_x[x, C_BODY_A] != ci_y[y, C_BODY_A]:
        return ci_x[x, C_BODY_A] < ci_y[y, C_BODY_A]
    return ci_x[x, C_BODY_B] < ci_y[y, C_BODY_B]


@njit_inline
def solved_rows(pci, npc):
    """How many of the cache's ``npc`` rows were solved last step: those before the resting contacts kept at
    its end."""
    while npc > 0 and (pci[npc - 1, C_FLAGS] & CP_RESTING) != 0:
        npc -= 1
    return npc


@njit_inline
def match_contacts(cf, ci, nc, pcf, pci, npc):
    """Stage "match": copy last step's impulses into this step's contacts with the same features (the
    cache's resting contacts, at its end, are not matched: they were not solved)."""
    npc = solved_rows(pci, npc)
    start = 0
    for c in range(nc):
        ci[c, C_FLAGS] &= ~(CP_MATCHED | CP_SLIDING)
        cf[c, C_LAMBDA_N] = 0.0
        cf[c, C_LAMBDA_T1] = 0.0
        cf[c, C_LAMBDA_T2] = 0.0
        for k in range(3):
            cf[c, C_LAMBDA_R + k] = 0.0
        while start < npc and _pair_key_less(pci, start, ci, c):
            start += 1
        q = start
        while q < npc and pci[q, C_BODY_A] == ci[c, C_BODY_A] and pci[q, C_BODY_B] == ci[c, C_BODY_B]:
            if (pci[q, C_SHAPE_A] == ci[c, C_SHAPE_A] and pci[q, C_SHAPE_B] == ci[c, C_SHAPE_B]
                    and pci[q, C_FEATURE] == ci[c, C_FEATURE]):
                cf[c, C_LAMBDA_N] = pcf[q, C_LAMBDA_N]
                # Friction impulse as a world vector, projected onto the new contact basis.
                t1, t2 = contact_basis((cf[c, C_NORMAL], cf[c, C_NORMAL + 1], cf[c, C_NORMAL + 2]))
                p1 = 0.0
                p2 = 0.0
                for k in range(3):
                    f = pcf[q, C_LAMBDA_T1] * pcf[q, C_T1 + k] + pcf[q, C_LAMBDA_T2] * pcf[q, C_T2 + k]
                    p1 += f * t1[k]
                    p2 += f * t2[k]
                    cf[c, C_LAMBDA_R + k] = pcf[q, C_LAMBDA_R + k]
                cf[c, C_LAMBDA_T1] = p1
                cf[c, C_LAMBDA_T2] = p2
                # (the effective masses they were applied with: prepare_contacts scales them, see there)
                cf[c, C_MASS_N] = pcf[q, C_MASS_N]
                cf[c, C_MASS_T1] = pcf[q, C_MASS_T1]
                cf[c, C_MASS_T2] = pcf[q, C_MASS_T2]
                cf[c, C_PAIR_SLIP] = pcf[q, C_PAIR_SLIP]
                ci[c, C_FLAGS] |= CP_MATCHED | (pci[q, C_FLAGS] & CP_SLIDING)
                break
            q += 1


@njit
def mark_resting(pci, npc):
    """Flag the cache's ``npc`` contacts ``CP_RESTING`` in place: the step found no new contact and every
    cached one rests (:func:`keep_resting_contacts` counted them all), so the cache is the step's table as
    it stands, and copying it row by row into the other table (a sleeping pyramid's 2,360 rows, 50 us a
    step) would change nothing."""
    for r in range(npc):
        pci[r, C_FLAGS] |= CP_RESTING


@njit
def keep_resting_contacts(cf, ci, nc, pcf, pci, npc, bf, bi, write):
    """Copy (when ``write``; else only count) the cache's contacts of resting pairs (neither body moves, one
    sleeps, and no kinematic body in motion is one of them) after this step's ``nc`` contacts, flagged
    ``CP_RESTING``: the narrow phase skips such pairs,
    and these rows keep reporting them (``World.contacts``), with the impulses that held them when they
    were last solved, for as long as they rest.  Returns how many there are (rows past the table's
    capacity are counted, not written)."""
    cap = cf.shape[0]
    k = nc
    for r in range(npc):
        a = pci[r, C_BODY_A]
        b = pci[r, C_BODY_B]
        if is_moving(bi, a) or is_moving(bi, b) or (pci[r, C_FLAGS] & CP_SENSOR) != 0:
            continue
        if is_driven(bf, bi, a) or is_driven(bf, bi, b):
            continue                     # the narrow phase meets this pair afresh (and wakes the sleeper)
        fa, fb = bi[a, FLAGS], bi[b, FLAGS]
        if (fa & F_ALIVE) == 0 or (fb & F_ALIVE) == 0 or ((fa | fb) & F_SLEEPING) == 0:
            continue
        if write and k < cap:
            for j in range(CF_COLS):
                cf[k, j] = pcf[r, j]
            for j in range(CI_COLS):
                ci[k, j] = pci[r, j]
            ci[k, C_FLAGS] |= CP_RESTING
        k += 1
    return k - nc
