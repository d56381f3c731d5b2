"""The solver's view of the bodies: inverse mass and world inverse inertia, zero for bodies that do not move.

Row ``i`` of the (nb, 10) table ``sb`` holds ``[1/m, (R I_body^-1 R^T) row-major]``; static and sleeping
bodies get zeros, so every constraint treats them as immovable without a branch.
"""
from .._jit import njit
from ..layout import F_ISOTROPIC, FLAGS, INV_I, INV_MASS, QUAT
from .forces import is_moving
from .rigid import body_inverse_inertia_world

SB_COLS = 10


@njit
def prepare_solver_bodies(bf, bi, nb, sb, mats):
    """Fill ``sb`` from the bodies' current orientations (``mats``: at least two 3x3 scratch matrices)."""
    rot = mats[0]
    iw = mats[1]
    for i in range(nb):
        if is_moving(bi, i) and (bi[i, FLAGS] & F_ISOTROPIC) != 0:
            # R (s E) R^T = s E: the body-frame inverse inertia is already the world one.
            sb[i, 0] = bf[i, INV_MASS]
            for k in range(9):
                sb[i, 1 + k] = bf[i, INV_I + k]
        elif is_moving(bi, i):
            sb[i, 0] = bf[i, INV_MASS]
            body_inverse_inertia_world(bf, i, bf[i, QUAT:QUAT + 4], rot, iw)
            for r in range(3):
                for c in range(3):
                    sb[i, 1 + 3 * r + c] = iw[r, c]
        else:
            for k in range(SB_COLS):
                sb[i, k] = 0.0
