"""A body's motion over an interval, as the time-of-impact search extrapolates it, and a shape's pose on it.

Over ``0 <= t <= T`` a body is taken to move with its velocities at the interval's start and a constant
acceleration (gravity for a moving body, none for a static or sleeping one), turning at its angular
velocity::

    x(t) = x0 + v t + a t^2 / 2
    q(t) = exp(omega t / 2) q0                      (world angular velocity omega, rad/s)
    shape position   x_s(t) = x(t) + R(q(t)) p_local
    shape rotation   R_s(t) = R(q(t) q_local)

A motion travels as one tuple ``(x0, v, a, q0, omega)`` of 3- and 4-tuples (m, m/s, m/s^2, unit
quaternion (w, x, y, z), rad/s).  The search only needs bounds on how fast a surface point moves:

    |d/dt (surface point)| <= |v + a t| + |omega| r_reach

with ``r_reach`` how far the shape reaches from its body's centre of mass (``rotation_reach``: a sphere
centred on its body turns in place and reaches 0).
"""
import math

from ..._numba.jit import njit
from ...math3d import quat_mul, quat_rotate, quat_step, quat_to_matrix
from .. import shape_types as st


@njit
def position_at(motion, t):
    """``x(t) = x0 + v t + a t^2 / 2`` (3-tuple, m) of ``motion`` at ``t`` (s)."""
    x, v, a = motion[0], motion[1], motion[2]
    h = 0.5 * t * t
    return (x[0] + v[0] * t + a[0] * h, x[1] + v[1] * t + a[1] * h, x[2] + v[2] * t + a[2] * h)


@njit
def velocity_at(motion, t):
    """``v + a t`` (3-tuple, m/s) of ``motion`` at ``t`` (s)."""
    v, a = motion[1], motion[2]
    return (v[0] + a[0] * t, v[1] + a[1] * t, v[2] + a[2] * t)


@njit
def pose_shape_at(motion, t, p_local, q_local, pos_out, rot_out, q_scratch):
    """World pose of a shape at ``t`` (s) on ``motion``: position into ``pos_out`` (3,) (m), rotation matrix
    into ``rot_out`` (3, 3); ``p_local`` (3-tuple, m) and ``q_local`` (4-tuple) place the shape in its body."""
    w = motion[4]
    q = quat_step(motion[3], w, t) if (w[0] != 0.0 or w[1] != 0.0 or w[2] != 0.0) else motion[3]
    quat_mul(q, q_local, q_scratch)
    quat_to_matrix(q_scratch, rot_out)
    quat_rotate(q, p_local, pos_out)
    x = position_at(motion, t)
    for k in range(3):
        pos_out[k] += x[k]


@njit
def rotation_reach(shape_type, p_local, bounding_radius):
    """How far (m) the shape's surface reaches from its body's centre of mass, as far as turning moves it:
    ``|p_local|`` for a sphere (its centre moves, its surface only with it), ``|p_local| + r_bound``
    otherwise (``r_bound`` the bounding radius about the shape's origin)."""
    offset = math.sqrt(p_local[0] ** 2 + p_local[1] ** 2 + p_local[2] ** 2)
    return offset if shape_type == st.SPHERE else offset + bounding_radius


@njit
def turning_speed(motion, reach):
    """``|omega| r_reach`` (m/s): the fastest a surface point moves by turning (0 for a body that does not
    turn, whatever its reach, which is infinite for planes)."""
    w = motion[4]
    s = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    return s * reach if s > 0.0 else 0.0
