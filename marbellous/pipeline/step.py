"""One world step as a list of named stages, compiled as one kernel so its fixed cost stays small.

    for each sub-step of h = dt / substeps:
        integrate velocities   forces (gravity, user, springs) -> velocities
        integrate positions    velocities -> poses, quaternions renormalised
        break constraints      springs over their breaking force snap
    clear force accumulators
"""
import numpy as np

from .._jit import njit
from ..dynamics.breaking import break_overloaded
from ..dynamics.integrators import integrate_positions, integrate_velocities
from ..layout import FORCE, TORQUE, W_PREV_DT, W_TIME

# params_f layout
P_DT = 0
P_GRAVITY = 1      # 3 values
PF_LEN = 4
# params_i layout
P_INTEGRATOR = 0
P_SUBSTEPS = 1
PI_LEN = 2


@njit
def step_world(bf, bi, kf, ki, ws, nb, nk, params_f, params_i):
    """Advance the world by ``params_f[P_DT]`` seconds in ``params_i[P_SUBSTEPS]`` equal sub-steps."""
    substeps = params_i[P_SUBSTEPS]
    method = params_i[P_INTEGRATOR]
    h = params_f[P_DT] / substeps
    gravity = params_f[P_GRAVITY:P_GRAVITY + 3]
    F = np.empty((nb, 3))
    T = np.empty((nb, 3))
    for _ in range(substeps):
        integrate_velocities(method, bf, bi, kf, ki, nb, nk, gravity, F, T, h, ws[W_PREV_DT])
        integrate_positions(method, bf, bi, nb, h)
        break_overloaded(kf, ki, nk)
        ws[W_PREV_DT] = h
    ws[W_TIME] += params_f[P_DT]
    for i in range(nb):
        for k in range(3):
            bf[i, FORCE + k] = 0.0
            bf[i, TORQUE + k] = 0.0
