"""Handles of constraints between bodies: ``Spring`` (Hooke), ``Rod`` (fixed distance), ``Cable`` (at most a
length), and the joints ``BallJoint``, ``Hinge``, ``Slider`` and ``FixedJoint``."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ._validate import MAX_COORD, MAX_FORCE, as_float, as_limits, as_motor_speed
from .dynamics.joint_rows import hinge_or_slider_state
from .math3d import quat_to_matrix_np
from .state import layout as L

if TYPE_CHECKING:
    from .body import Body


class Constraint:
    """Base of the constraint handles: a thin view over one row of the world's constraint table."""

    __slots__ = ("_world", "_index", "_revision", "_body_a", "_body_b", "__weakref__")

    def __init__(self, world, index, revision, body_a, body_b):
        self._world = world
        self._index = index
        self._revision = revision
        self._body_a = body_a
        self._body_b = body_b

    @property
    def body_a(self) -> Body:
        """The first body (``Body``)."""
        return self._body_a

    @property
    def body_b(self) -> Body | None:
        """The second body (``Body``), or None when the constraint is attached to the world."""
        return self._body_b

    def _rows(self):
        w = self._world
        if w is None or w._state.constraints.revision[self._index] != self._revision:
            raise ValueError("this constraint has been removed from its world")
        return w._state.kf[self._index], w._state.ki[self._index]

    @property
    def broken(self) -> bool:
        """True once the force exceeded the breaking force; a broken constraint applies no force."""
        return bool(self._rows()[1][L.K_FLAGS] & L.KF_BROKEN)

    @property
    def force(self) -> np.ndarray:
        """Force (N) the constraint applied to body_a in the last step (body_b got the opposite)."""
        return np.array(self._rows()[0][L.K_FORCE:L.K_FORCE + 3])

    @property
    def anchor_a(self) -> np.ndarray:
        """Where the constraint holds ``body_a``: a point in body_a's frame (m)."""
        return np.array(self._rows()[0][L.K_ANCHOR_A:L.K_ANCHOR_A + 3])

    @property
    def anchor_b(self) -> np.ndarray:
        """Where the constraint holds ``body_b``: a point in body_b's frame, or a fixed world point when
        ``body_b`` is None (m)."""
        return np.array(self._rows()[0][L.K_ANCHOR_B:L.K_ANCHOR_B + 3])

    @property
    def length(self) -> float:
        """Rest length (spring), length (rod) or maximum length (cable), m."""
        return float(self._rows()[0][L.K_LENGTH])

    def __repr__(self):
        return f"<{type(self).__name__} #{self._index} length={self.length:.4g}>"


class Spring(Constraint):
    """Hooke spring with damping: ``F = -k (l - l0) - c dl/dt`` along the line between the anchors."""

    __slots__ = ()

    @property
    def stiffness(self) -> float:
        """Spring constant k (N/m)."""
        return float(self._rows()[0][L.K_STIFFNESS])

    @property
    def damping(self) -> float:
        """Damping coefficient c (N s/m)."""
        return float(self._rows()[0][L.K_DAMPING])


class Rod(Constraint):
    """A massless rigid rod: the distance between the anchors stays ``length``."""

    __slots__ = ()


class Cable(Constraint):
    """A massless inextensible cable: the distance between the anchors is at most ``length``; slack below."""

    __slots__ = ()


class Joint(Constraint):
    """Base of the ball, hinge, slider and fixed joints.  The bodies a joint joins do not collide with each
    other.  :attr:`force` is the force (N) the joint applied to ``body_a`` in the last step and
    :attr:`torque` the torque (N m) about the joint's anchor on ``body_a`` (``body_b`` got the opposite of
    both); past ``breaking_force`` (on the force) the joint breaks for good."""

    __slots__ = ()

    @property
    def torque(self) -> np.ndarray:
        """Torque (N m) the joint applied to body_a about its anchor in the last step."""
        return np.array(self._rows()[0][L.K_TORQUE:L.K_TORQUE + 3])

    @property
    def anchor(self) -> np.ndarray:
        """Where the joint holds ``body_a`` now, in the world frame (m)."""
        w = self._world
        kf, ki = self._rows()
        bf = w._state.bf
        a = ki[L.K_BODY_A]
        return bf[a, L.POS:L.POS + 3] + quat_to_matrix_np(bf[a, L.QUAT:L.QUAT + 4]) @ kf[L.K_ANCHOR_A:L.K_ANCHOR_A + 3]

    @property
    def separation(self) -> float:
        """How far the joint is from holding (m): the distance between its anchors on ``body_a`` and
        ``body_b`` (or the world point), for a slider the distance of ``body_a``'s anchor from its line."""
        kf, ki = self._rows()
        b = ki[L.K_BODY_B]
        other = kf[L.K_ANCHOR_B:L.K_ANCHOR_B + 3]
        if b >= 0:
            bf = self._world._state.bf
            other = bf[b, L.POS:L.POS + 3] + quat_to_matrix_np(bf[b, L.QUAT:L.QUAT + 4]) @ other
        d = self.anchor - other
        if isinstance(self, Slider):
            d = d - (d @ self.axis) * self.axis
        return float(np.linalg.norm(d))

    def __repr__(self):
        return f"<{type(self).__name__} #{self._index}{' broken' if self.broken else ''}>"


class BallJoint(Joint):
    """A ball-and-socket joint: the anchor on ``body_a`` stays on the anchor on ``body_b`` (three rows); the
    bodies turn freely about it."""

    __slots__ = ()


class FixedJoint(Joint):
    """A weld: ``body_a`` keeps the pose relative to ``body_b`` it had when the joint was made (its anchor is
    ``body_a``'s centre of mass then)."""

    __slots__ = ()


class _AxisJoint(Joint):
    """A joint with an axis, a limited range, and a motor (hinge, slider)."""

    __slots__ = ()

    def _state_now(self):
        self._rows()
        st = self._world._state
        return hinge_or_slider_state(st.bf, st.kf, st.ki, self._index)

    @property
    def axis(self) -> np.ndarray:
        """The joint's axis now, a unit vector in the world frame (it turns with ``body_b``)."""
        kf, ki = self._rows()
        axis = kf[L.K_AXIS_B:L.K_AXIS_B + 3]
        b = ki[L.K_BODY_B]
        if b < 0:
            return np.array(axis)
        return quat_to_matrix_np(self._world._state.bf[b, L.QUAT:L.QUAT + 4]) @ axis

    @property
    def limits(self) -> tuple[float, float] | None:
        """``(lower, upper)`` of the angle (rad) or position (m), or None when unlimited."""
        kf, ki = self._rows()
        if not ki[L.K_FLAGS] & L.KF_LIMITS:
            return None
        return float(kf[L.K_LOWER]), float(kf[L.K_UPPER])

    @limits.setter
    def limits(self, value) -> None:
        kf, ki = self._rows()
        if value is None:
            ki[L.K_FLAGS] &= ~L.KF_LIMITS
        else:
            kf[L.K_LOWER], kf[L.K_UPPER] = as_limits("limits", value, self._LIMIT_RANGE, self._UNIT)
            ki[L.K_FLAGS] |= L.KF_LIMITS
        self._wake()

    @property
    def motor_speed(self) -> float | None:
        """The speed the motor drives the joint at (rad/s or m/s), or None without a motor."""
        kf, ki = self._rows()
        return float(kf[L.K_MOTOR_SPEED]) if ki[L.K_FLAGS] & L.KF_MOTOR else None

    @motor_speed.setter
    def motor_speed(self, value: float | None) -> None:
        kf, ki = self._rows()
        if value is None:
            ki[L.K_FLAGS] &= ~L.KF_MOTOR
        else:
            kf[L.K_MOTOR_SPEED] = as_motor_speed(value, self._UNIT)
            ki[L.K_FLAGS] |= L.KF_MOTOR
        self._wake()

    def _set_most(self, name, value):
        kf, _ = self._rows()
        kf[L.K_MOTOR_MAX] = as_float(name, value, nonnegative=True, hi=MAX_FORCE)
        self._wake()

    def _wake(self):
        st = self._world._state
        _, ki = self._rows()
        for i in (ki[L.K_BODY_A], ki[L.K_BODY_B]):
            if i >= 0:
                st.wake(i)


class Hinge(_AxisJoint):
    """A revolute joint: the anchors coincide and ``body_a`` turns relative to ``body_b`` about the axis only.
    :attr:`angle` is that rotation (right-handed about :attr:`axis`, 0 when the hinge was made, in
    [-pi, pi]); ``limits`` bound it, and a motor drives :attr:`angular_speed` towards ``motor_speed`` with at
    most ``max_motor_torque``."""

    __slots__ = ()
    _LIMIT_RANGE = (-math.pi, math.pi)
    _UNIT = "rad"

    @property
    def angle(self) -> float:
        """Rotation of body_a relative to body_b about the axis since the hinge was made (rad, in [-pi, pi])."""
        return float(self._state_now()[0])

    @property
    def angular_speed(self) -> float:
        """Rate of :attr:`angle` (rad/s)."""
        return float(self._state_now()[1])

    @property
    def max_motor_torque(self) -> float:
        """The most torque the motor applies (N m)."""
        return float(self._rows()[0][L.K_MOTOR_MAX])

    @max_motor_torque.setter
    def max_motor_torque(self, value: float) -> None:
        self._set_most("max_motor_torque", value)


class Slider(_AxisJoint):
    """A prismatic joint: ``body_a`` moves relative to ``body_b`` along the axis only, without turning.
    :attr:`position` is that displacement (m, 0 when the slider was made); ``limits`` bound it, and a motor
    drives :attr:`speed` towards ``motor_speed`` with at most ``max_motor_force``."""

    __slots__ = ()
    _LIMIT_RANGE = (-2 * MAX_COORD, 2 * MAX_COORD)
    _UNIT = "m"

    @property
    def position(self) -> float:
        """Displacement of body_a's anchor from body_b's along the axis (m)."""
        return float(self._state_now()[0])

    @property
    def speed(self) -> float:
        """Rate of :attr:`position` (m/s)."""
        return float(self._state_now()[1])

    @property
    def max_motor_force(self) -> float:
        """The most force the motor applies (N)."""
        return float(self._rows()[0][L.K_MOTOR_MAX])

    @max_motor_force.setter
    def max_motor_force(self, value: float) -> None:
        self._set_most("max_motor_force", value)
