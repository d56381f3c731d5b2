"""Marbellous is y-up, PyBullet and MuJoCo are z-up: a quarter turn about x maps one to the other.

    R = rotation by +90 degrees about x:   (x, y, z)_marbellous  ->  (x, -z, y)_peer
    orientations:  q_peer = q_R q_marbellous,  q_marbellous = q_R* q_peer   (the world frame turns, body frames do not)
"""
import math

import numpy as np

#: the quarter turn as a rotation matrix and as a (w, x, y, z) quaternion
R = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
Q_R = np.array([math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0])


def to_peer(v):
    """A vector (or rows of vectors) in peer axes."""
    return np.asarray(v, dtype=np.float64) @ R.T


def from_peer(v):
    """A vector (or rows of vectors) back in Marbellous axes."""
    return np.asarray(v, dtype=np.float64) @ R


def quat_to_peer(q):
    """A (w, x, y, z) orientation in peer axes: q_R q."""
    w1, x1, y1, z1 = Q_R
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def quat_from_peer(q):
    """A (w, x, y, z) orientation in peer axes (or rows of them) back in Marbellous axes: q_R* q_peer."""
    q = np.asarray(q, dtype=np.float64)
    c, s = Q_R[0], Q_R[1]           # q_R* = (c, -s, 0, 0)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([c * w + s * x, c * x - s * w, c * y + s * z, c * z - s * y], axis=-1)
