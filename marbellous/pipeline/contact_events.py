"""Contact begin and end events: which pairs of bodies started or stopped touching over a step.

A pair touches when one of its contact points overlaps at detection (``depth > 0``) or carries a normal
impulse over the step (a speculative contact the solver closed: the bodies meet within the step).  A
speculative contact that stays open is not a touch, so a body passing close by begins nothing.  An event is
one per pair of bodies, not per point: a box landing flat on four corners begins once.

The two sets come from the contact tables the world keeps anyway: the step's contacts (the cache) and the
ones it began with (the other table, untouched by a single-interval step, or the copy a multi-interval step
keeps), so a step that nobody asks about costs nothing.
"""
import numpy as np

from ..state import layout as L


def approach_table(cf, ci):
    """Rows ``(body a, body b, approach speed)`` of contacts ``cf``, ``ci``: the speed (m/s, >= 0) at which
    the points closed along the normal before the solver acted, ``max(0, -v_n)``."""
    out = np.empty((cf.shape[0], 3))
    out[:, 0] = ci[:, L.C_BODY_A]
    out[:, 1] = ci[:, L.C_BODY_B]
    out[:, 2] = np.maximum(-cf[:, L.C_VN0], 0.0)
    return out


def _touching(cf, ci, gone):
    """``(pair key, lower body, upper body, row)`` of the touching contacts, pairs with a body in ``gone``
    (rows removed since) left out."""
    touch = (cf[:, L.C_SUM_N] > 0.0) | (cf[:, L.C_DEPTH] > 0.0)
    rows = np.flatnonzero(touch)
    a, b = ci[rows, L.C_BODY_A], ci[rows, L.C_BODY_B]
    if gone:
        keep = ~(np.isin(a, gone) | np.isin(b, gone))
        rows, a, b = rows[keep], a[keep], b[keep]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    return lo * (1 << 32) + hi, lo, hi, rows


def _events(kind, keys, lo, hi, rows, cf, ci, speed_of):
    """One event per pair in ``keys`` (sorted): point and normal of the pair's deepest contact, the normal
    turned to point from the lower body row to the upper."""
    out = []
    if keys.size == 0:
        return out
    order = np.lexsort((-cf[rows, L.C_DEPTH], lo * (1 << 32) + hi))
    sorted_keys = (lo * (1 << 32) + hi)[order]
    first = order[np.searchsorted(sorted_keys, keys)]
    for key, j in zip(keys.tolist(), first.tolist()):
        r = rows[j]
        a, b = int(lo[j]), int(hi[j])
        normal = cf[r, L.C_NORMAL:L.C_NORMAL + 3].copy()
        if ci[r, L.C_BODY_A] != a:
            normal = -normal
        out.append((kind, a, b, cf[r, L.C_POINT:L.C_POINT + 3].copy(), normal, speed_of(key)))
    return out


def contact_events(before, after, approach, gone):
    """The begin and end events between the contact tables ``before`` and ``after`` (each ``(cf, ci)``), as
    tuples ``(kind, body row a, body row b, point, normal, approach speed)``, begins first, each kind
    ordered by body rows.  ``approach``: rows ``(body a, body b, speed)`` from which a begin's approach
    speed is the largest of its pair's (:func:`approach_table`); ``gone``: rows of bodies removed since the
    step."""
    k0, lo0, hi0, r0 = _touching(*before, gone)
    k1, lo1, hi1, r1 = _touching(*after, gone)
    began = np.setdiff1d(k1, k0)
    ended = np.setdiff1d(k0, k1)
    speed = {}
    if began.size:
        a, b = approach[:, 0].astype(np.int64), approach[:, 1].astype(np.int64)
        keys = np.minimum(a, b) * (1 << 32) + np.maximum(a, b)
        for key, v in zip(keys.tolist(), approach[:, 2].tolist()):
            if v > speed.get(key, 0.0):
                speed[key] = v
    return (_events("begin", began, lo1, hi1, r1, *after, lambda key: speed.get(key, 0.0))
            + _events("end", ended, lo0, hi0, r0, *before, lambda key: 0.0))
