"""How deep the contacts stack: the adaptive iteration count of the sequential-impulse passes.

A pass of sequential impulses hands a contact's impulse on to the next body in the chain, so the weight of the
top of a stack of ``n`` bodies reaches the ground only after passes in proportion to ``n``; with too few, a
tall stack leans and walks (20 cubes at 60 Hz with 4 passes per sub-step: the top moved 26 cm sideways in
5 s; with 16, 1.5 cm).  The lecture's remedy: give scenes with many stacked contacts more iterations and
scenes with few contacts fewer.  The passes already stop once no velocity changes by more than the tolerance
(few contacts: fewer passes); this module gives deep stacks more.  More passes delay a tall tower's fall but
do not stop it: its soft contacts give way as it leans (``bench/bench_stacks.py``); stiffer contacts (more
sub-steps, a higher ``contact_hertz``) do.

The support depth is how many bodies deep the stack goes: over the movable bodies, the most contacts any of
them is from something that cannot move (the ground, a static, kinematic or sleeping body) along its
shortest chain; breadth-first search over the contact graph, level 1 for the bodies touching the ground.
With ``World.adaptive_iterations`` on, a sub-step's passes may run to ``DEPTH_PASSES`` times that depth (at
least the world's ``iterations``, at most ``MAX_ADAPTIVE``); the passes beyond ``iterations`` go on only
while a velocity still changes by ``EXTRA_TOLERANCE``.  It is off by default: converged passes carry a heavy
heap's weight to its lowest contacts, which give in proportion (1000 balls in a heap 3.8 m high: the lowest
5.8 mm into the ground at 4 passes, 15 mm at 8, 24 mm at 32).
"""
from .._numba.jit import njit
from ..state.layout import C_BODY_A, C_BODY_B
from .forces import is_moving

#: passes allowed per body of support depth (20 cubes: top 1.0 cm sideways in 5 s at 40 passes, 0.4 cm at 64)
DEPTH_PASSES = 2
#: most passes per sub-step the depth can ask for
MAX_ADAPTIVE = 128
#: the passes beyond the world's base count go on only while some velocity still changes by this much (m/s):
#: a settled pyramid stops at the base count, a tower falling over does not (20 cubes: 0.9 cm off its axis in
#: 5 s at 1e-3, 13 cm at 1e-2; a lean of a few mm/s gets no extra passes)
EXTRA_TOLERANCE = 1e-3


@njit
def support_depth(bi, ci, nc, nb, level, start, adjacent, queue):
    """The support depth (module docstring) over the contacts ``0 .. nc - 1``: the largest breadth-first
    level of a movable body, level 1 touching a body that cannot move; 0 when none does.

    Scratch: ``level`` and ``queue`` (>= nb ints), ``start`` (>= nb + 1), ``adjacent`` (>= 2 nc).
    """
    for i in range(nb + 1):
        start[i] = 0
    for c in range(nc):
        a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
        start[a + 1] += 1
        start[b + 1] += 1
    for i in range(nb):
        start[i + 1] += start[i]
    for i in range(nb):
        level[i] = start[i]                  # (fill cursor)
    for c in range(nc):
        a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
        adjacent[level[a]] = b
        level[a] += 1
        adjacent[level[b]] = a
        level[b] += 1
    head = 0
    tail = 0
    for i in range(nb):
        level[i] = -1
        if is_moving(bi, i):
            for k in range(start[i], start[i + 1]):
                if not is_moving(bi, adjacent[k]):
                    level[i] = 1
                    queue[tail] = i
                    tail += 1
                    break
    depth = 1 if tail > 0 else 0
    while head < tail:
        i = queue[head]
        head += 1
        for k in range(start[i], start[i + 1]):
            j = adjacent[k]
            if level[j] < 0 and is_moving(bi, j):
                level[j] = level[i] + 1
                depth = max(depth, level[j])
                queue[tail] = j
                tail += 1
    return depth


@njit
def order_bottom_up(bi, ci, nc, level, depth, count, order):
    """Write ``order[0:nc]``: the contacts sorted by their level, the lowest level of their movable bodies
    (``level`` and ``depth`` from ``support_depth``; contacts of bodies out of reach of anything that cannot
    move last), ascending contact index within a level.  Scratch: ``count`` (>= depth + 2 ints)."""
    for k in range(depth + 2):
        count[k] = 0
    for c in range(nc):
        count[_contact_level(bi, ci, c, level, depth)] += 1
    total = 0
    for k in range(depth + 2):
        total, count[k] = total + count[k], total
    for c in range(nc):
        k = _contact_level(bi, ci, c, level, depth)
        order[count[k]] = c
        count[k] += 1


@njit
def _contact_level(bi, ci, c, level, depth):
    """Level of contact ``c``: its movable bodies' lowest level, ``depth + 1`` when neither is reached."""
    lowest = depth + 1
    for body in (ci[c, C_BODY_A], ci[c, C_BODY_B]):
        if is_moving(bi, body) and level[body] > 0:
            lowest = min(lowest, level[body])
    return lowest


@njit
def iteration_cap(base, adaptive, depth):
    """Most velocity passes per sub-step: ``base``, or with ``adaptive`` up to ``DEPTH_PASSES * depth``
    (at most ``MAX_ADAPTIVE``)."""
    if not adaptive:
        return base
    return max(base, min(MAX_ADAPTIVE, DEPTH_PASSES * depth))


@njit
def stop_change(passes, base, tolerance):
    """The velocity change (m/s) below which the passes stop after ``passes`` of them: ``tolerance`` within
    the world's ``base`` count, at least ``EXTRA_TOLERANCE`` past it."""
    return tolerance if passes < base else max(tolerance, EXTRA_TOLERANCE)
