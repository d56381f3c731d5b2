"""Small vector, quaternion and matrix kernels shared by every layer.

Quaternions are ``(w, x, y, z)`` with unit length; a quaternion ``q`` rotates a vector ``v`` as
``q v q*``.  Rotation matrices map body (local) coordinates to world coordinates.
All functions are Numba kernels that write into caller-provided arrays where that avoids allocation.
"""
import math

import numpy as np

from ._jit import njit


@njit
def dot3(a, b):
    """Dot product of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def cross3(a, b, out):
    """``out = a x b`` (out must not alias a or b)."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit
def norm3(a):
    """Euclidean length of a 3-vector."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit
def quat_mul(a, b, out):
    """Hamilton product ``out = a * b`` of (w, x, y, z) quaternions (out must not alias a or b)."""
    out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3]
    out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2]
    out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1]
    out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]


@njit
def quat_normalize(q):
    """Scale ``q`` in place to unit length (identity if it is zero)."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if n == 0.0:
        q[0] = 1.0
        q[1] = 0.0
        q[2] = 0.0
        q[3] = 0.0
    else:
        q[0] /= n
        q[1] /= n
        q[2] /= n
        q[3] /= n


@njit
def quat_to_matrix(q, out):
    """Rotation matrix (3x3, local to world) of the unit quaternion ``q``."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    out[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    out[0, 1] = 2.0 * (x * y - w * z)
    out[0, 2] = 2.0 * (x * z + w * y)
    out[1, 0] = 2.0 * (x * y + w * z)
    out[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    out[1, 2] = 2.0 * (y * z - w * x)
    out[2, 0] = 2.0 * (x * z - w * y)
    out[2, 1] = 2.0 * (y * z + w * x)
    out[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit
def quat_rotate(q, v, out):
    """``out = q v q*``: the vector ``v`` rotated by the unit quaternion ``q``.

    Uses ``v' = v + 2 w (u x v) + 2 u x (u x v)`` with ``u = (x, y, z)``.
    """
    w, ux, uy, uz = q[0], q[1], q[2], q[3]
    tx = 2.0 * (uy * v[2] - uz * v[1])
    ty = 2.0 * (uz * v[0] - ux * v[2])
    tz = 2.0 * (ux * v[1] - uy * v[0])
    out[0] = v[0] + w * tx + (uy * tz - uz * ty)
    out[1] = v[1] + w * ty + (uz * tx - ux * tz)
    out[2] = v[2] + w * tz + (ux * ty - uy * tx)


@njit
def quat_integrate(q, omega, h, out):
    """Rotate ``q`` by the world angular velocity ``omega`` (rad/s) held for ``h`` seconds.

    Exact exponential map: ``q' = exp(omega h / 2) * q``, renormalised.
    """
    wx, wy, wz = omega[0] * h, omega[1] * h, omega[2] * h
    angle = math.sqrt(wx * wx + wy * wy + wz * wz)
    if angle < 1e-12:
        # exp(x) ~ (1, x/2) to first order; renormalised below.
        c = 1.0
        s = 0.5
    else:
        c = math.cos(0.5 * angle)
        s = math.sin(0.5 * angle) / angle
    dw, dx, dy, dz = c, s * wx, s * wy, s * wz
    out[0] = dw * q[0] - dx * q[1] - dy * q[2] - dz * q[3]
    out[1] = dw * q[1] + dx * q[0] + dy * q[3] - dz * q[2]
    out[2] = dw * q[2] - dx * q[3] + dy * q[0] + dz * q[1]
    out[3] = dw * q[3] + dx * q[2] - dy * q[1] + dz * q[0]
    quat_normalize(out)


@njit
def world_inverse_inertia(rot, inv_inertia_body, out):
    """``out = R I_body^-1 R^T``: the inverse inertia tensor in world coordinates (1/(kg m^2))."""
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                rk = rot[i, k]
                for m in range(3):
                    s += rk * inv_inertia_body[k, m] * rot[j, m]
            out[i, j] = s


@njit
def mat3_vec(m, v, out):
    """``out = M v`` for a 3x3 matrix (out must not alias v)."""
    out[0] = m[0, 0] * v[0] + m[0, 1] * v[1] + m[0, 2] * v[2]
    out[1] = m[1, 0] * v[0] + m[1, 1] * v[1] + m[1, 2] * v[2]
    out[2] = m[2, 0] * v[0] + m[2, 1] * v[1] + m[2, 2] * v[2]


def quat_to_matrix_np(q):
    """Rotation matrix of a (w, x, y, z) quaternion, as a new (3, 3) NumPy array (Python side)."""
    out = np.empty((3, 3))
    quat_to_matrix(np.asarray(q, dtype=np.float64), out)
    return out
