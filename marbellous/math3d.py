"""Small vector, quaternion and matrix kernels shared by every layer.

Quaternions are ``(w, x, y, z)`` with unit length; a quaternion ``q`` rotates a vector ``v`` as
``q v q*``.  Rotation matrices map body (local) coordinates to world coordinates.
All functions are Numba kernels that write into caller-provided arrays where that avoids allocation.
"""
import math

import numpy as np

from ._numba.jit import njit


@njit
def dot3(a, b):
    """Dot product of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def row3(table, i, col):
    """Columns ``col .. col + 2`` of row ``i`` of a 2-D table as a tuple (no array view is made)."""
    return table[i, col], table[i, col + 1], table[i, col + 2]


@njit
def row4(table, i, col):
    """Columns ``col .. col + 3`` of row ``i`` as a tuple (a quaternion)."""
    return table[i, col], table[i, col + 1], table[i, col + 2], table[i, col + 3]


@njit
def row9(table, i, col):
    """Columns ``col .. col + 8`` of row ``i`` as a 9-tuple (a row-major 3x3 tensor)."""
    return (table[i, col], table[i, col + 1], table[i, col + 2], table[i, col + 3], table[i, col + 4],
            table[i, col + 5], table[i, col + 6], table[i, col + 7], table[i, col + 8])


@njit
def cross(a, b):
    """``a x b`` as a tuple."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit
def cross3(a, b, out):
    """``out = a x b``."""
    out[0], out[1], out[2] = cross(a, b)


@njit
def norm3(a):
    """Euclidean length of a 3-vector."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit
def quat_product(a, b):
    """Hamilton product ``a * b`` of (w, x, y, z) quaternions, as a tuple."""
    return (a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0])


@njit
def quat_conj(q):
    """The conjugate ``(w, -x, -y, -z)``: the inverse rotation of a unit quaternion, as a tuple."""
    return q[0], -q[1], -q[2], -q[3]


@njit
def quat_mul(a, b, out):
    """Hamilton product ``out = a * b`` of (w, x, y, z) quaternions (out must not alias a or b)."""
    out[0], out[1], out[2], out[3] = quat_product(a, b)


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
def rotated(q, v):
    """``q v q*``: the vector ``v`` rotated by the unit quaternion ``q``, as a tuple.

    Uses ``v' = v + 2 w (u x v) + 2 u x (u x v)`` with ``u = (x, y, z)``.
    """
    w, ux, uy, uz = q[0], q[1], q[2], q[3]
    tx = 2.0 * (uy * v[2] - uz * v[1])
    ty = 2.0 * (uz * v[0] - ux * v[2])
    tz = 2.0 * (ux * v[1] - uy * v[0])
    return (v[0] + w * tx + (uy * tz - uz * ty),
            v[1] + w * ty + (uz * tx - ux * tz),
            v[2] + w * tz + (ux * ty - uy * tx))


@njit
def quat_rotate(q, v, out):
    """``out = q v q*``: the vector ``v`` rotated by the unit quaternion ``q`` (:func:`rotated`)."""
    out[0], out[1], out[2] = rotated(q, v)


@njit
def quat_step(q, omega, h):
    """``q`` rotated by the world angular velocity ``omega`` (rad/s) held for ``h`` seconds, as a tuple.

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
    r0 = dw * q[0] - dx * q[1] - dy * q[2] - dz * q[3]
    r1 = dw * q[1] + dx * q[0] + dy * q[3] - dz * q[2]
    r2 = dw * q[2] - dx * q[3] + dy * q[0] + dz * q[1]
    r3 = dw * q[3] + dx * q[2] - dy * q[1] + dz * q[0]
    n = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    return r0 / n, r1 / n, r2 / n, r3 / n


@njit
def quat_integrate(q, omega, h, out):
    """As :func:`quat_step`, written into ``out``."""
    r = quat_step(q, omega, h)
    for k in range(4):
        out[k] = r[k]


@njit
def rotation_of(q):
    """Rotation matrix (local to world) of the unit quaternion ``q``, as a row-major 9-tuple."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


@njit
def rotate_tensor(r, m):
    """``R M R^T`` for row-major 9-tuples ``r`` (a rotation) and ``m`` (a body-frame tensor): the tensor in
    world coordinates, as a 9-tuple."""
    # A = M R^T:  A[k][j] = sum_m M[k][m] R[j][m]
    a0 = m[0] * r[0] + m[1] * r[1] + m[2] * r[2]
    a1 = m[0] * r[3] + m[1] * r[4] + m[2] * r[5]
    a2 = m[0] * r[6] + m[1] * r[7] + m[2] * r[8]
    a3 = m[3] * r[0] + m[4] * r[1] + m[5] * r[2]
    a4 = m[3] * r[3] + m[4] * r[4] + m[5] * r[5]
    a5 = m[3] * r[6] + m[4] * r[7] + m[5] * r[8]
    a6 = m[6] * r[0] + m[7] * r[1] + m[8] * r[2]
    a7 = m[6] * r[3] + m[7] * r[4] + m[8] * r[5]
    a8 = m[6] * r[6] + m[7] * r[7] + m[8] * r[8]
    # R A
    return (r[0] * a0 + r[1] * a3 + r[2] * a6, r[0] * a1 + r[1] * a4 + r[2] * a7, r[0] * a2 + r[1] * a5 + r[2] * a8,
            r[3] * a0 + r[4] * a3 + r[5] * a6, r[3] * a1 + r[4] * a4 + r[5] * a7, r[3] * a2 + r[4] * a5 + r[5] * a8,
            r[6] * a0 + r[7] * a3 + r[8] * a6, r[6] * a1 + r[7] * a4 + r[8] * a7, r[6] * a2 + r[7] * a5 + r[8] * a8)


@njit
def tensor_vec(m, v):
    """``M v`` for a row-major 9-tuple ``m``, as a 3-tuple."""
    return (m[0] * v[0] + m[1] * v[1] + m[2] * v[2],
            m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2])


def quat_to_matrix_np(q):
    """Rotation matrix of a (w, x, y, z) quaternion, as a new (3, 3) NumPy array (Python side)."""
    out = np.empty((3, 3))
    quat_to_matrix(np.asarray(q, dtype=np.float64), out)
    return out
