"""Whether a gap closes within a horizon, in closed form, for the pairs whose gap is an exact function of
time: the time-of-impact search (``conservative_advancement``) is not needed for them.

Two spheres centred on bodies with the same acceleration (both moving under gravity, or both still): the
centres' offset moves linearly, ``d(t) = d0 + u t`` with ``u = v_b - v_a``, and the gap is
``|d(t)| - (r_a + r_b)``, smallest at

    t* = clamp(-(d0 . u) / (u . u), 0, T)

A centred sphere against a static plane: the gap along the plane's normal ``n`` is exactly

    g(t) = g0 - c t - a t^2 / 2,   c = -(v_b - v_a) . n,   a = -(a_b - a_a) . n

smallest at an end of ``[0, T]`` or, when ``a < 0`` (accelerating away), at its vertex ``t = -c / a``.
"""
import math

from ..._numba.jit import njit


@njit
def spheres_come_within(d0, u, radius_sum, horizon, tolerance):
    """True if two centres at offset ``d0`` (3-tuple, m) moving apart at ``u`` (3-tuple, m/s) come within
    ``radius_sum + tolerance`` (m) of each other in ``[0, horizon]`` (s)."""
    uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    t = 0.0
    if uu > 0.0:
        t = min(max(-(d0[0] * u[0] + d0[1] * u[1] + d0[2] * u[2]) / uu, 0.0), horizon)
    x, y, z = d0[0] + u[0] * t, d0[1] + u[1] * t, d0[2] + u[2] * t
    return math.sqrt(x * x + y * y + z * z) - radius_sum <= tolerance


@njit
def gap_comes_within(gap, speed, acceleration, horizon, tolerance):
    """True if ``g(t) = gap - speed t - acceleration t^2 / 2`` (m; m/s, m/s^2) comes down to ``tolerance``
    (m) in ``[0, horizon]`` (s)."""
    smallest = min(gap, gap - speed * horizon - 0.5 * acceleration * horizon * horizon)
    if acceleration < 0.0:
        t = -speed / acceleration
        if 0.0 < t < horizon:
            smallest = min(smallest, gap - speed * t - 0.5 * acceleration * t * t)
    return smallest <= tolerance
