"""The earliest time a gap can close, from a bound on how fast it closes.

A gap ``g > 0`` along a fixed direction whose closing distance is at most ``D(t) = c t + a t^2 / 2``
(``c`` the closing speed bound at the start, m/s; ``a`` the closing acceleration, m/s^2) cannot close
before the smallest ``t > 0`` with ``D(t) = g``::

    t = 2 g / (c + sqrt(c^2 + 2 a g))

(the root of ``a t^2 / 2 + c t - g = 0`` written without cancellation).  No root (the gap never closes)
when ``c^2 + 2 a g < 0``, or when ``c <= 0`` and ``a <= 0``.
"""
import math

from ..._numba.jit import njit


@njit
def time_to_close(gap, speed, acceleration):
    """The earliest time (s) a gap of ``gap`` (m) closes at closing ``speed`` (m/s) and ``acceleration``
    (m/s^2); ``inf`` if it never does, 0 if it is already closed."""
    if gap <= 0.0:
        return 0.0
    disc = speed * speed + 2.0 * acceleration * gap
    if disc < 0.0:
        return math.inf
    den = speed + math.sqrt(disc)
    if den <= 0.0:
        return math.inf
    return 2.0 * gap / den
