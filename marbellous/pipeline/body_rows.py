"""One body row in each of many worlds, read or pushed by one kernel call: what a batch of worlds stepped
together (``marbellous/batch.py``) needs between its steps without a Python call per world.

Each world is named by the address of its step context (``_numba/record.py``: ``record_address``; valid while
its state keeps that context, that is, until a table is replaced) and the body by its row.
"""
from .._numba.jit import njit
from ..state.layout import F_KINEMATIC, F_SLEEPING, F_STATIC, FLAGS, FORCE, POS, SLEEP_TIME, VEL
from .context import context_at, view


@njit
def add_forces_at(addresses, rows, forces):
    """Add ``forces[k]`` (N, at the centre of mass) to the force accumulator of body ``rows[k]`` of the world
    at ``addresses[k]`` and wake it, as ``Body.apply_force`` does (nothing for a static or kinematic body)::

        F_k <- F_k + forces[k]
    """
    for k in range(addresses.shape[0]):
        record = context_at(addresses[k])
        ctx = view(record)
        i = rows[k]
        if ctx.bi[i, FLAGS] & (F_STATIC | F_KINEMATIC):
            continue
        for j in range(3):
            ctx.bf[i, FORCE + j] += forces[k, j]
        ctx.bi[i, FLAGS] &= ~F_SLEEPING
        ctx.bf[i, SLEEP_TIME] = 0.0


@njit
def motions_at(addresses, rows, out):
    """Into ``out[k]``: the position (m) and velocity (m/s) of body ``rows[k]`` of the world at
    ``addresses[k]`` (``out`` (n, 6))."""
    for k in range(addresses.shape[0]):
        record = context_at(addresses[k])
        ctx = view(record)
        i = rows[k]
        for j in range(3):
            out[k, j] = ctx.bf[i, POS + j]
            out[k, 3 + j] = ctx.bf[i, VEL + j]
