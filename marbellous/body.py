"""``Body``: a thin handle over one row of the world's body tables.

Reading a property returns a copy; writing validates and stores.  A handle is a body row and the row's
revision when the body was made: once the body is removed (or a restore drops it) the row's revision moves
on, and any use of the handle raises instead of touching whatever body takes the row next.  The same
``Body`` object is handed back wherever the world refers to that body.
"""
from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike

from ._validate import MAX_DT, MAX_FORCE, MAX_SPEED, MIN_DT, as_filter_bits, as_float, as_quat, as_vec3
from .material import validated
from .math3d import quat_conj, quat_product, quat_to_matrix_np
from .state import layout as L

_as_speed = functools.partial(as_vec3, bound=MAX_SPEED, unit="m/s")
_as_angular_speed = functools.partial(as_vec3, bound=MAX_SPEED, unit="rad/s")


class _Material:
    """A material property of a body (``marbellous.material``), read and written at any time: a write is
    validated as ``add_body`` validates it, and wakes the body and the sleepers touching it."""

    def __init__(self, column):
        self.column = column

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, body, owner=None):
        if body is None:
            return self
        return float(body._row()[self.column])

    def __set__(self, body, value):
        v = validated(self.name, value)
        body._row()[self.column] = v
        body._wake_touching()


class Body:
    """A rigid body in a :class:`marbellous.World` (created by ``add_body``, ``add_static`` or
    ``add_kinematic``).

    Setters validate as ``add_body`` does: positions within +-1e12 m, velocities within +-1e9 m/s
    (rad/s), forces, torques and impulses within +-1e20 N (N m, N s) per component.  A handle has no
    other attributes: assigning an unknown one raises AttributeError."""

    __slots__ = ("_world", "_index", "_revision", "_shapes", "__weakref__")

    def __init__(self, world, index, revision, shapes):
        self._world = world
        self._index = index
        self._revision = revision
        self._shapes = tuple((s, _frozen(p), _frozen(q)) for s, p, q in shapes)

    @property
    def shapes(self) -> list[tuple]:
        """The body's shapes as a list of ``(shape, local_position (m), local_orientation (w, x, y, z))``
        tuples in the frame of its centre of mass (new arrays: editing them changes nothing)."""
        return [(s, p.copy(), q.copy()) for s, p, q in self._shapes]

    # --- internals ---------------------------------------------------------------------------
    def _state(self):
        """The world's state, after checking that this handle is still live."""
        w = self._world
        if w is None or w._state.bodies.revision[self._index] != self._revision:
            raise ValueError("this body has been removed from its world")
        return w._state

    def _row(self):
        return self._state().bf[self._index]

    def _set_state(self, col, n, value, name, validate):
        row = self._row()
        v = validate(name, value)
        if self.is_static:
            raise ValueError(f"{name} of a static body cannot be changed")
        row[col:col + n] = v
        if self.is_kinematic:
            self._wake_touching()           # what rested on it may no longer be held, or be in its way
            return
        st = self._world._state
        st.bi[self._index, L.FLAGS] |= L.F_RESTART
        st.wake(self._index)

    def _immovable(self):
        """True for static and kinematic bodies: no force, torque or impulse moves them."""
        return bool(self._state().bi[self._index, L.FLAGS] & (L.F_STATIC | L.F_KINEMATIC))

    # --- state -----------------------------------------------------------------------------------
    @property
    def position(self) -> np.ndarray:
        """Position of the centre of mass, world frame (m)."""
        return self._row()[L.POS:L.POS + 3].copy()

    @position.setter
    def position(self, value: ArrayLike) -> None:
        self._set_state(L.POS, 3, value, "position", as_vec3)

    @property
    def orientation(self) -> np.ndarray:
        """Orientation as a unit quaternion (w, x, y, z)."""
        return self._row()[L.QUAT:L.QUAT + 4].copy()

    @orientation.setter
    def orientation(self, value: ArrayLike) -> None:
        self._set_state(L.QUAT, 4, value, "orientation", as_quat)

    @property
    def velocity(self) -> np.ndarray:
        """Linear velocity of the centre of mass (m/s)."""
        return self._row()[L.VEL:L.VEL + 3].copy()

    @velocity.setter
    def velocity(self, value: ArrayLike) -> None:
        self._set_state(L.VEL, 3, value, "velocity", _as_speed)

    @property
    def angular_velocity(self) -> np.ndarray:
        """Angular velocity, world frame (rad/s)."""
        return self._row()[L.OMEGA:L.OMEGA + 3].copy()

    @angular_velocity.setter
    def angular_velocity(self, value: ArrayLike) -> None:
        self._set_state(L.OMEGA, 3, value, "angular_velocity", _as_angular_speed)

    @property
    def mass(self) -> float:
        """Mass (kg); ``inf`` for a static or kinematic body."""
        return float(self._row()[L.MASS])

    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensor about the centre of mass in world coordinates, ``R I_body R^T`` (kg m^2): the one
        simulated, whose principal moments are within a factor 1e4 of each other (a needle's smallest moment
        is raised to that, ``dynamics.mass_properties.conditioned_inertia``)."""
        row = self._row()
        if self._immovable():
            return np.diag([np.inf, np.inf, np.inf])
        r = quat_to_matrix_np(row[L.QUAT:L.QUAT + 4])
        return r @ row[L.I_BODY:L.I_BODY + 9].reshape(3, 3) @ r.T

    @property
    def is_static(self) -> bool:
        """True for bodies made with ``add_static`` (they never move)."""
        return bool(self._state().bi[self._index, L.FLAGS] & L.F_STATIC)

    @property
    def is_kinematic(self) -> bool:
        """True for bodies made with ``add_kinematic`` (moved by their velocities only)."""
        return bool(self._state().bi[self._index, L.FLAGS] & L.F_KINEMATIC)

    def move_to(self, position: ArrayLike, orientation: ArrayLike, dt: float) -> None:
        """Kinematic bodies: set the velocities that carry the body from its pose now to ``position`` (m)
        and ``orientation`` (w, x, y, z) in ``dt`` seconds (the next step's length):

            v = (x_target - x) / dt,    omega = axis * angle / dt  of the rotation  q_target q^-1

        (the shorter way round).  The pose is reached at the end of a step of ``dt``; the velocities stay
        until changed, so call it every step to follow a path.
        """
        row = self._row()
        p = as_vec3("position", position)
        q = as_quat("orientation", orientation)
        dt = as_float("dt", dt, lo=MIN_DT, hi=MAX_DT, unit="s")
        if not self.is_kinematic:
            raise ValueError("move_to is for kinematic bodies (add_kinematic); set a dynamic body's velocity")
        turn = quat_product(tuple(q), quat_conj(tuple(row[L.QUAT:L.QUAT + 4])))
        if turn[0] < 0.0:
            turn = tuple(-c for c in turn)
        sin_half = math.sqrt(turn[1] ** 2 + turn[2] ** 2 + turn[3] ** 2)
        angle = 2.0 * math.atan2(sin_half, turn[0])
        omega = np.zeros(3) if sin_half == 0.0 else np.array(turn[1:]) * (angle / (sin_half * dt))
        v = _as_speed("position", (p - row[L.POS:L.POS + 3]) / dt)
        omega = _as_angular_speed("orientation", omega)
        row[L.VEL:L.VEL + 3] = v
        row[L.OMEGA:L.OMEGA + 3] = omega
        self._wake_touching()

    @property
    def is_sleeping(self) -> bool:
        """True while the body rests in a sleeping island (it is not integrated until woken)."""
        return bool(self._state().bi[self._index, L.FLAGS] & L.F_SLEEPING)

    @property
    def is_sensor(self) -> bool:
        """True for sensors: they detect overlaps but exert no force."""
        return bool(self._state().bi[self._index, L.FLAGS] & L.F_SENSOR)

    def wake(self) -> None:
        """Wake the body and the rest of its sleeping island (no effect on an awake or static body)."""
        st = self._state()
        if self.is_static or not self.is_sleeping:
            return
        n = st.bodies.end
        island = st.bi[self._index, L.ISLAND]
        same = np.flatnonzero((st.bi[:n, L.ISLAND] == island) & ((st.bi[:n, L.FLAGS] & L.F_SLEEPING) != 0))
        for j in same if island >= 0 else ():
            st.wake(int(j))
        st.wake(self._index)

    # --- collision filter ---------------------------------------------------------------------------
    @property
    def group(self) -> int:
        """The body's collision group bits: it collides with ``other`` only if ``self.group & other.mask``
        and ``other.group & self.mask`` are both nonzero (default 1)."""
        return int(self._state().bi[self._index, L.GROUP])

    @group.setter
    def group(self, value: int) -> None:
        self._set_filter(L.GROUP, as_filter_bits("group", value))

    @property
    def mask(self) -> int:
        """The groups the body collides with, as bits (default -1: all)."""
        return int(self._state().bi[self._index, L.MASK])

    @mask.setter
    def mask(self, value: int) -> None:
        self._set_filter(L.MASK, as_filter_bits("mask", value))

    def _set_filter(self, col, bits):
        """Store filter bits (the next step's broad phase applies them)."""
        self._state().bi[self._index, col] = bits
        self._wake_touching()

    def _wake_touching(self):
        """Wake the body and the sleepers that may rest on it: what holds them up has changed."""
        st = self._state()
        self._world._wake_neighbours(self._index)
        if not self.is_static:
            st.wake(self._index)

    # --- material ---------------------------------------------------------------------------------------
    friction = _Material(L.FRICTION)
    """Dynamic (sliding) Coulomb friction coefficient; contacts use the geometric mean of the two bodies'
    values."""
    static_friction = _Material(L.STATIC_FRICTION)
    """Static (sticking) Coulomb friction coefficient (geometric mean, as ``friction``)."""
    restitution = _Material(L.RESTITUTION)
    """Coefficient of restitution in [0, 1]; contacts use the larger of the two bodies' values."""
    rolling_friction = _Material(L.ROLLING)
    """Rolling resistance as a lever arm (m): the torque against rolling (across the contact normal) is at
    most this times the normal force; contacts use the larger of the two bodies' values."""
    torsional_friction = _Material(L.TORSION)
    """Torsional friction as a lever arm (m): the torque against spinning about the contact normal is at
    most this times the normal force; contacts use the larger of the two bodies' values."""
    linear_damping = _Material(L.LINEAR_DAMPING)
    """Linear damping rate (1/s): ``dv/dt = -c v`` besides the forces."""
    angular_damping = _Material(L.ANGULAR_DAMPING)
    """Angular damping rate (1/s): ``domega/dt = -c omega`` besides the torques."""

    # --- forces ------------------------------------------------------------------------------------
    def apply_force(self, force: ArrayLike, point: ArrayLike | None = None) -> None:
        """Add a world-space ``force`` (N) at world ``point`` (m; None: the centre of mass) for the next step.

        The torque about the centre of mass is ``(point - x) x force``.
        """
        self._state()                   # (a removed body's handle is refused before its arguments)
        f = as_vec3("force", force, bound=MAX_FORCE, unit="N")
        p = None if point is None else as_vec3("point", point)
        self._add_force(f, p)

    def _add_force(self, f, p=None):
        """:meth:`apply_force` of a force ``f`` (N) at ``p`` (m; None: the centre of mass) already checked
        (float64 arrays of 3 finite numbers within the bounds): for the engine's own forces, step after step."""
        st = self._state()
        i = self._index
        if st.bi[i, L.FLAGS] & (L.F_STATIC | L.F_KINEMATIC):
            return
        row = st.bf[i]
        row[L.FORCE:L.FORCE + 3] += f
        if p is not None:
            row[L.TORQUE:L.TORQUE + 3] += np.cross(p - row[L.POS:L.POS + 3], f)
        st.wake(i)

    def apply_torque(self, torque: ArrayLike) -> None:
        """Add a world-space ``torque`` (N m) for the next step."""
        row = self._row()
        t = as_vec3("torque", torque, bound=MAX_FORCE, unit="N m")
        if self._immovable():
            return
        row[L.TORQUE:L.TORQUE + 3] += t
        self._world._state.wake(self._index)

    def apply_impulse(self, impulse: ArrayLike, point: ArrayLike | None = None) -> None:
        """Change the momentum at once by ``impulse`` (N s) at world ``point`` (None: the centre of mass).

        ``dv = J / m``, ``domega = I_w^-1 ((point - x) x J)``.
        """
        row = self._row()
        j = as_vec3("impulse", impulse, bound=MAX_FORCE, unit="N s")
        p = None if point is None else as_vec3("point", point)
        if self._immovable():
            return
        row[L.VEL:L.VEL + 3] += j * row[L.INV_MASS]
        if p is not None:
            r = quat_to_matrix_np(row[L.QUAT:L.QUAT + 4])
            iw_inv = r @ row[L.INV_I:L.INV_I + 9].reshape(3, 3) @ r.T
            row[L.OMEGA:L.OMEGA + 3] += iw_inv @ np.cross(p - row[L.POS:L.POS + 3], j)
        self._world._state.bi[self._index, L.FLAGS] |= L.F_RESTART
        self._world._state.wake(self._index)

    def __repr__(self):
        try:
            kind = "static" if self.is_static else ("kinematic" if self.is_kinematic else "dynamic")
        except ValueError:
            return "<Body removed>"
        x, y, z = (float(v) for v in self.position)
        return f"<Body {kind} #{self._index} at ({x:.4g}, {y:.4g}, {z:.4g})>"


def _frozen(arr):
    """A read-only float64 copy of ``arr``."""
    out = np.array(arr, dtype=np.float64)
    out.flags.writeable = False
    return out
