"""Many worlds stepped together: :func:`step_worlds`.

Stepping a thousand small worlds one ``World.step`` at a time pays Python's overhead a thousand times per
step, which for a marble on a level is more than its physics.  :func:`step_worlds` steps them with one call
of the compiled step per kind of step (worlds of the same layout share one: same solver, the same kinds of
shapes, and, for the lean step, no joints and a few bodies), so the overhead is paid once per kind, and
splits the worlds across threads when asked (the compiled step runs without Python's lock).

Each world takes exactly the step it would take alone, bit for bit: the same compiled step on the same
arrays.  What a world needs beyond the rigid bodies' step is taken for it around the batched call, as
``World.step`` takes it: a time-of-impact interval, grown tables, particles, cloth, soft bodies, fluids;
a world in the retroactive time-stepping mode is stepped alone.
"""
from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ._numba.record import array_address
from ._validate import as_int
from .world import World

#: the most threads :func:`step_worlds` splits a batch over
MAX_THREADS = 256
#: the threads of :func:`_run` (started when first needed, then kept)
_POOL = None


def step_worlds(worlds: Sequence[World], dt: float, *, threads: int = 1) -> None:
    """Advance each of ``worlds`` (distinct ``World`` objects) by ``dt`` seconds (in [1e-6, 1] s), as
    ``world.step(dt)`` would, world by world, but with one compiled call for all the worlds that share a
    step.  ``threads`` (1 .. 256): how many threads share each such call (the worlds are split into that
    many runs of about equal length; a world's step is never split); more than the machine's cores does not
    help.  Nothing is stepped when an argument is bad (TypeError or ValueError naming it)."""
    if isinstance(worlds, World) or not isinstance(worlds, Sequence):
        raise TypeError(f"worlds must be a sequence of World objects, got {type(worlds).__name__}")
    for k, w in enumerate(worlds):
        if not isinstance(w, World):
            raise TypeError(f"worlds[{k}] must be a World, got {type(w).__name__}")
    if len({id(w) for w in worlds}) != len(worlds):
        raise ValueError("worlds must be distinct (a world listed twice would be stepped twice)")
    threads = as_int("threads", threads, lo=1, hi=MAX_THREADS)
    if len(worlds) < 2:
        if worlds:
            worlds[0].step(dt)                  # (the same step: nothing to share a call with)
        return
    step_checked(worlds, dt, threads)


def step_checked(worlds, dt, threads):
    """:func:`step_worlds` of two or more distinct worlds and ``threads`` already checked (``dt`` is checked
    here, by the first world, before any world changes): for a caller that steps the same worlds step after
    step.  Returns the worlds' step-context addresses after the step (``packed_addresses``)."""
    dt, body_start = worlds[0]._begin_step(dt)
    starts = [body_start] + [w._begin_step(dt)[1] for w in worlds[1:]]
    addresses = packed_addresses(worlds)
    # the worlds that share a compiled step share a call (a world whose own step runs on Numba's threads is not
    # stepped beside another on a second thread: its threading layer takes one parallel step at a time); a
    # world in the retroactive mode (key None) is stepped alone, by its _end_step
    keys = [None if w._retroactive else (w._state.entry, w._state.threads > 1) for w in worlds]
    if keys.count(keys[0]) == len(keys):
        groups = {keys[0]: slice(None)}                       # (the common case: one layout, one call)
    else:
        groups = {}
        for k, key in enumerate(keys):
            groups.setdefault(key, []).append(k)
    statuses = np.zeros(len(worlds), dtype=np.int64)
    for key, group in groups.items():
        if key is not None:
            entry, threaded = key
            out = np.zeros(len(worlds) if isinstance(group, slice) else len(group), dtype=np.int64)
            _run(entry, addresses[group], out, 1 if threaded else threads)
            statuses[group] = out
    for w, start, status, key in zip(worlds, starts, statuses.tolist(), keys):
        w._end_step(dt, -1 if key is None else w._state.settle(status) if status else 0, start)
    # (a step that returned a status other than OK may have grown a table, and so packed a new context)
    return addresses if None not in keys and not statuses.any() else packed_addresses(worlds)


def plain_entry(worlds, dt):
    """The compiled step that all of ``worlds`` take, if each is *plain* for steps of ``dt`` s, else None.
    A plain world has its parameters written for ``dt`` and its context packed, steps in the fixed mode on one
    thread, has no particles, cloth, soft bodies or fluids to step around its bodies, and has nothing left from
    its last step for ``World._end_step`` to do (it has stepped, no body was removed since, its last step was
    one interval): ``World._begin_step`` and ``_end_step`` would do nothing for it, so :func:`step_plain` can
    step it again and again with no Python of its own."""
    entry = worlds[0]._state.entry if worlds else None
    for w in worlds:
        st = w._state
        if st.context is None or st.entry is not entry or st.threads != 1 or w._retroactive \
                or w._params_dt != dt or not w._stepped or w._gone or w._last is not None \
                or w._living_particles or w._living_cloths or w._living_softs or w._living_fluids:
            return None
    return entry


def step_plain(worlds, addresses, entry, dt, threads):
    """One step of ``dt`` s of ``worlds``, plain for it (:func:`plain_entry` gave ``entry``), their contexts at
    ``addresses``: one call of ``entry`` (split over ``threads``), each world's state after it, bit for bit,
    what ``World.step`` gives.  A world whose step asks for more (a buffer to grow, an interval up to a time of
    impact) is finished as ``World.step`` finishes it, and is then no longer plain.  Returns ``(the addresses
    after the step, whether every world is still plain)``."""
    statuses = np.zeros(len(worlds), dtype=np.int64)
    _run(entry, addresses, statuses, threads)
    if not statuses.any():
        return addresses, True
    for k in np.flatnonzero(statuses).tolist():
        w = worlds[k]
        w._end_step(dt, w._state.settle(int(statuses[k])), None)
    return packed_addresses(worlds), False


def packed_addresses(worlds):
    """The address of each world's step context (``_numba/record.py``), packed first where a table was
    replaced since its last step: an int64 array, valid until one of the worlds replaces a table."""
    for w in worlds:
        if w._state.context is None:
            w._state.pack()
    return np.concatenate([w._state.addresses for w in worlds])


def _run(entry, addresses, statuses, threads):
    """One call of ``entry`` over ``addresses``, or ``threads`` calls over runs of them, on as many threads."""
    n = addresses.shape[0]
    runs = min(threads, n)
    if runs == 1:
        entry(array_address(addresses), array_address(statuses), n)
        return
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=MAX_THREADS, thread_name_prefix="marbellous-batch")
    bounds = np.linspace(0, n, runs + 1).astype(int)
    # (the calling thread takes the first run itself rather than wait idle: one hand-over fewer)
    others = [_POOL.submit(entry, array_address(addresses[a:b]), array_address(statuses[a:b]), b - a)
              for a, b in zip(bounds[1:-1], bounds[2:])]
    entry(array_address(addresses[:bounds[1]]), array_address(statuses[:bounds[1]]), int(bounds[1]))
    for f in others:
        f.result()

