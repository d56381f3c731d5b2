"""4x4 camera and model matrices for the renderer (column vectors, OpenGL clip space, y up).

All functions return float64 (4, 4) arrays ``M`` that map column vectors, ``p' = M @ p``.  Upload
``M.T`` (row-major NumPy to column-major GLSL) as ``float32``.
"""
import math

import numpy as np


def perspective(fov_y, aspect, near, far):
    """Perspective projection: vertical field of view ``fov_y`` (rad), ``aspect`` = width / height,
    clip distances ``near`` and ``far`` (m)."""
    f = 1.0 / math.tan(fov_y / 2.0)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = f / aspect, f
    m[2, 2], m[2, 3] = (far + near) / (near - far), 2.0 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def orthographic(half_width, half_height, near, far):
    """Orthographic projection of the box ``|x| <= half_width``, ``|y| <= half_height``, depth in
    ``[near, far]`` (m) in front of the eye."""
    m = np.eye(4)
    m[0, 0], m[1, 1] = 1.0 / half_width, 1.0 / half_height
    m[2, 2], m[2, 3] = -2.0 / (far - near), -(far + near) / (far - near)
    return m


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """View matrix of a camera at ``eye`` looking at ``target`` (m) with ``up`` roughly up.

    Rows of its rotation part are the camera's right, up and backward (``-lookat``) axes.
    """
    # on Python floats: NumPy's calls on 3-vectors cost ten times the arithmetic (0.3 ms a matrix)
    eye, target, up = (tuple(float(c) for c in v) for v in (eye, target, up))
    fwd = _unit(tuple(t - e for t, e in zip(target, eye)))
    right = _cross(fwd, up)
    if math.hypot(*right) < 1e-9:  # looking straight along up: any right vector will do
        right = _cross(fwd, (1.0, 0.0, 0.0) if abs(fwd[0]) < 0.9 else (0.0, 0.0, 1.0))
    right = _unit(right)
    true_up = _cross(right, fwd)
    back = tuple(-c for c in fwd)
    return np.array([[*axis, -sum(a * e for a, e in zip(axis, eye))] for axis in (right, true_up, back)]
                    + [[0.0, 0.0, 0.0, 1.0]])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(v):
    n = math.hypot(*v)
    return tuple(c / n for c in v)


def model_matrix(position, rotation=None, scale=1.0):
    """Model matrix: scale, then rotate by the (3, 3) ``rotation`` (identity if None), then translate."""
    m = np.eye(4)
    m[:3, :3] = (np.eye(3) if rotation is None else np.asarray(rotation, np.float64)) * scale
    m[:3, 3] = position
    return m


def quat_to_matrix(q):
    """Rotation matrix (3, 3) of the unit quaternion ``q = (w, x, y, z)``."""
    w, x, y, z = (float(c) for c in q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def quats_to_matrices(q):
    """Rotation matrices (N, 3, 3) of the unit quaternions ``q`` (N, 4) as rows ``(w, x, y, z)``."""
    w, x, y, z = np.asarray(q, np.float64).reshape(-1, 4).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)
