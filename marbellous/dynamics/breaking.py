"""Breaking points: a spring (or rod, cable) whose force exceeded its breaking force is broken for good."""
import math

from .._numba.jit import njit
from ..state.layout import K_BREAKING, K_FLAGS, K_FORCE, KF_ALIVE, KF_BROKEN


@njit
def break_overloaded(kf, ki, nk):
    """Mark every live constraint with ``|F| > breaking force`` as broken; it applies no force afterwards."""
    for c in range(nk):
        if (ki[c, K_FLAGS] & KF_ALIVE) == 0 or (ki[c, K_FLAGS] & KF_BROKEN) != 0:
            continue
        fx, fy, fz = kf[c, K_FORCE], kf[c, K_FORCE + 1], kf[c, K_FORCE + 2]
        if math.sqrt(fx * fx + fy * fy + fz * fz) > kf[c, K_BREAKING]:
            ki[c, K_FLAGS] |= KF_BROKEN
