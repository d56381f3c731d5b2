"""Player controls: keys push the marble in the ground plane relative to where the camera looks.

A control input ``move = (forward, right)``, each in [-1, 1] and together clipped to the unit disc,
becomes a force in the x-z plane

    F = m a_push (forward * f + right * r),   f = (cos psi, 0, sin psi),   r = (-sin psi, 0, cos psi)

for a camera heading ``psi`` (rad).  The force acts at the marble's centre; friction with the ground
turns it into rolling, as in the lecture ("apply forces when keys are pressed").
"""
import math

import numpy as np

#: Keys (pyglet key names) for each direction of the control input.
FORWARD_KEYS = ("W", "UP")
BACK_KEYS = ("S", "DOWN")
LEFT_KEYS = ("A", "LEFT")
RIGHT_KEYS = ("D", "RIGHT")


def clip_to_disc(move):
    """``move`` (2,) scaled down onto the unit disc if it lies outside it; NaN raises ValueError."""
    return np.array(_clipped(move))


def _clipped(move):
    """:func:`clip_to_disc` as two floats.  ``np.hypot`` (the C library's, as the arrays' ``_clip_to_disc``
    uses) only where the move may leave the disc: inside ``a^2 + b^2 <= 1/2`` it is left as it is."""
    m = np.asarray(move, np.float64).reshape(2)
    a, b = float(m[0]), float(m[1])
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ValueError(f"move must be 2 finite numbers, got {move!r}")
    if a * a + b * b <= 0.5:
        return a, b
    n = float(np.hypot(a, b))
    return (a / n, b / n) if n > 1.0 else (a, b)


def heading_axes(heading):
    """``(forward, right)`` unit vectors in the ground plane for a camera heading (rad)."""
    c, s = math.cos(heading), math.sin(heading)
    return np.array([c, 0.0, s]), np.array([-s, 0.0, c])


def control_force(move, heading, mass, push):
    """World-space force (N) for a control input ``move = (forward, right)`` seen from a camera with
    ``heading`` (rad) on a marble of ``mass`` (kg) pushed with ``push`` (m/s^2) at full input."""
    c, s = math.cos(heading), math.sin(heading)
    forward, right = _clipped(move)
    mp = mass * push
    # m_f f + m_r r with f = (c, 0, s), r = (-s, 0, c) (heading_axes), element by element as the arrays would
    return np.array([mp * (forward * c + right * -s), mp * (forward * 0.0 + right * 0.0),
                     mp * (forward * s + right * c)])


def move_for_direction(direction, heading):
    """The control input that pushes along the world-space ``direction`` (its x-z part; length up to
    1 is full input) for a camera ``heading``: the inverse of :func:`control_force`.

        forward = d . f = d_x cos psi + d_z sin psi,   right = d . r = d_z cos psi - d_x sin psi
    """
    c, s = math.cos(heading), math.sin(heading)
    d = np.asarray(direction, np.float64).reshape(3)
    x, z = float(d[0]), float(d[2])
    return clip_to_disc((x * c + z * s, z * c - x * s))


def control_forces(actions, headings, mass, push):
    """:func:`control_force` of :func:`move_for_direction` for many marbles at once: ``actions`` (N, 2), each
    row the push direction's x and z parts (finite numbers), seen from cameras with ``headings`` (N,) rad, on
    marbles of ``mass`` (kg) pushed with ``push`` (m/s^2): (N, 3) N, each row bit for bit the one-marble
    answer (the same operations in the same order, element by element)."""
    c = np.array([math.cos(h) for h in headings])
    s = np.array([math.sin(h) for h in headings])
    x, z = actions[:, 0].astype(np.float64), actions[:, 1].astype(np.float64)
    forward, right = _clip_to_disc(x * c + z * s, z * c - x * s)     # the move (move_for_direction)
    forward, right = _clip_to_disc(forward, right)                   # clipped again, as control_force does
    mp = mass * push
    return np.stack([mp * (forward * c + right * -s), mp * (forward * 0.0 + right * 0.0),
                     mp * (forward * s + right * c)], axis=1)


def _clip_to_disc(a, b):
    """:func:`clip_to_disc` of the pairs ``(a[k], b[k])`` (arrays of finite numbers)."""
    n = np.hypot(a, b)
    over = n > 1.0
    return np.divide(a, n, out=a.copy(), where=over), np.divide(b, n, out=b.copy(), where=over)


def move_from_keys(pressed):
    """Control input from the set of pressed key names (e.g. ``{"W", "LEFT"}``)."""
    fwd = any(k in pressed for k in FORWARD_KEYS) - any(k in pressed for k in BACK_KEYS)
    right = any(k in pressed for k in RIGHT_KEYS) - any(k in pressed for k in LEFT_KEYS)
    return clip_to_disc((fwd, right))
