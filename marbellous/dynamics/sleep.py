"""Islands and sleeping: bodies that touch (or are joined) form an island; a resting island sleeps.

A body rests while ``|v| < linear_tol`` and ``|omega| < angular_tol``; an island whose bodies have all
rested for ``time_to_sleep`` seconds falls asleep (velocities zeroed, no integration, no solving).  A
sleeping island wakes when an awake body or a kinematic body in motion touches it, a force or impulse is
applied, or its state is set.  Static and kinematic bodies belong to no island; a body touching a
kinematic body in motion never rests.
Islands are found with union-find (path halving, union by index) over contacts and constraints.
"""

from .._numba.jit import njit, njit_inline
from ..state.layout import (C_BODY_A, C_BODY_B, C_FLAGS, CP_SENSOR, F_SLEEPING, FLAGS, ISLAND, K_BODY_A, K_BODY_B,
                            K_FLAGS, KF_ALIVE, KF_BROKEN, OMEGA, SLEEP_TIME, VEL)
from .forces import is_driven, is_dynamic, is_moving


@njit
def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit
def _union(parent, i, j):
    ri = _find(parent, i)
    rj = _find(parent, j)
    if ri < rj:
        parent[rj] = ri
    elif rj < ri:
        parent[ri] = rj


@njit_inline
def wake_touched_islands(bi, bf, ci, nc, nb):
    """Stage "wake": an awake body touching a sleeping one wakes that body's whole island."""
    for c in range(nc):
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        for sleeper, other in ((a, b), (b, a)):
            if (bi[sleeper, FLAGS] & F_SLEEPING) != 0 and (is_moving(bi, other) or is_driven(bf, bi, other)):
                island = bi[sleeper, ISLAND]
                for i in range(nb):
                    if (bi[i, FLAGS] & F_SLEEPING) != 0 and (i == sleeper or bi[i, ISLAND] == island):
                        bi[i, FLAGS] &= ~F_SLEEPING
                        bf[i, SLEEP_TIME] = 0.0


@njit
def update_sleep(bf, bi, nb, cf, ci, nc, ki, nk, dt, linear_tol, angular_tol, time_to_sleep, parent, least):
    """Stage "islands and sleep": rest timers, islands, and putting resting islands to sleep.

    ``parent`` (int) and ``least`` (float) are scratch of length ``nb`` or more.
    """
    for i in range(nb):
        parent[i] = i
        if not is_moving(bi, i):
            continue
        v2 = bf[i, VEL] ** 2 + bf[i, VEL + 1] ** 2 + bf[i, VEL + 2] ** 2
        w2 = bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2
        if v2 < linear_tol * linear_tol and w2 < angular_tol * angular_tol:
            bf[i, SLEEP_TIME] += dt
        else:
            bf[i, SLEEP_TIME] = 0.0
    for c in range(nc):
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        if is_dynamic(bi, a) and is_dynamic(bi, b):
            _union(parent, a, b)
        elif is_driven(bf, bi, a) or is_driven(bf, bi, b):
            bf[b if is_driven(bf, bi, a) else a, SLEEP_TIME] = 0.0     # carried: it does not rest
    for c in range(nk):
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        if (ki[c, K_FLAGS] & KF_ALIVE) != 0 and (ki[c, K_FLAGS] & KF_BROKEN) == 0 and b >= 0 \
                and is_dynamic(bi, a) and is_dynamic(bi, b):
            _union(parent, a, b)
    # Island rest time = the least rest time of its awake members, kept at the island's root.
    for i in range(nb):
        least[i] = 1e300
    for i in range(nb):
        if is_moving(bi, i):
            r = _find(parent, i)
            if bf[i, SLEEP_TIME] < least[r]:
                least[r] = bf[i, SLEEP_TIME]
    for i in range(nb):
        if not is_dynamic(bi, i):
            bi[i, ISLAND] = -1
            continue
        if not is_moving(bi, i):
            continue  # a sleeping body keeps the island it fell asleep in
        r = _find(parent, i)
        bi[i, ISLAND] = r
        if time_to_sleep > 0.0 and least[r] >= time_to_sleep:
            bi[i, FLAGS] |= F_SLEEPING
            for k in range(3):
                bf[i, VEL + k] = 0.0
                bf[i, OMEGA + k] = 0.0
