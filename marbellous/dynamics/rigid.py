"""Rigid-body kinematics shared by the integrators and solvers.

The velocity of a body point at offset ``r`` from the centre of mass is ``v + omega x r``; the world
inverse inertia is ``I_w^-1 = R I_body^-1 R^T``.
"""
import numpy as np

from .._jit import njit
from ..layout import INV_I, I_BODY
from ..math3d import quat_to_matrix, world_inverse_inertia


@njit
def body_inverse_inertia_world(bf, i, quat, rot, out):
    """World inverse inertia ``R I_body^-1 R^T`` of body row ``i`` at orientation ``quat`` (1/(kg m^2)).

    ``rot`` is scratch (3, 3) that receives the rotation matrix.
    """
    quat_to_matrix(quat, rot)
    world_inverse_inertia(rot, bf[i, INV_I:INV_I + 9].reshape(3, 3), out)


@njit
def body_inertia_world(bf, i, rot, out):
    """World inertia ``R I_body R^T`` (kg m^2) for the rotation matrix ``rot`` of body row ``i``."""
    world_inverse_inertia(rot, bf[i, I_BODY:I_BODY + 9].reshape(3, 3), out)


def inverse_inertia_np(inertia):
    """Inverse of a symmetric positive-definite 3x3 inertia tensor (Python side, for body creation)."""
    return np.linalg.inv(np.asarray(inertia, dtype=np.float64))
