"""Rigid-body kinematics shared by the integrators and solvers.

The velocity of a body point at offset ``r`` from the centre of mass is ``v + omega x r``; the world
inverse inertia is ``I_w^-1 = R I_body^-1 R^T``.  Small tensors travel as tuples (no arrays in hot loops).
"""
import numpy as np

from .._numba.jit import njit
from ..math3d import rotate_tensor, rotation_of, row9
from ..state.layout import I_BODY, INV_I, OMEGA, VEL


@njit
def inverse_inertia_world(bf, i, q):
    """World inverse inertia ``R I_body^-1 R^T`` (1/(kg m^2)) of body row ``i`` at orientation ``q``, 9-tuple."""
    return rotate_tensor(rotation_of(q), row9(bf, i, INV_I))


@njit
def inertia_world(bf, i, q):
    """World inertia ``R I_body R^T`` (kg m^2) of body row ``i`` at orientation ``q``, 9-tuple."""
    return rotate_tensor(rotation_of(q), row9(bf, i, I_BODY))


def inverse_inertia_np(inertia):
    """Inverse of a symmetric positive-definite 3x3 inertia tensor (Python side, for body creation)."""
    return np.linalg.inv(np.asarray(inertia, dtype=np.float64))


@njit
def point_velocity(bf, i, r, out):
    """Velocity of the point at offset ``r`` from body ``i``'s centre of mass: ``v + omega x r`` (m/s)."""
    w0, w1, w2 = bf[i, OMEGA], bf[i, OMEGA + 1], bf[i, OMEGA + 2]
    out[0] = bf[i, VEL] + w1 * r[2] - w2 * r[1]
    out[1] = bf[i, VEL + 1] + w2 * r[0] - w0 * r[2]
    out[2] = bf[i, VEL + 2] + w0 * r[1] - w1 * r[0]


@njit
def relative_velocity(bf, a, ra, b, rb, out):
    """Velocity of b's point ``rb`` relative to a's point ``ra`` (m/s); ``b < 0`` is the fixed world."""
    if b >= 0:
        point_velocity(bf, b, rb, out)
    else:
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
    w0, w1, w2 = bf[a, OMEGA], bf[a, OMEGA + 1], bf[a, OMEGA + 2]
    out[0] -= bf[a, VEL] + w1 * ra[2] - w2 * ra[1]
    out[1] -= bf[a, VEL + 1] + w2 * ra[0] - w0 * ra[2]
    out[2] -= bf[a, VEL + 2] + w0 * ra[1] - w1 * ra[0]
