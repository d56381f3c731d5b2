"""Body forces on the fluid: ``du/dt = g`` on every free face (a channel's pressure drop, a wind)."""
from .._numba.jit import njit


@njit
def add_body_force(q, fixed, force, dt, dims):
    """``q += dt force`` (m/s) on the free faces of each component."""
    for c in range(dims):
        if force[c] == 0.0:
            continue
        change = dt * force[c]
        qc = q[c]
        fc = fixed[c]
        for index in range(qc.size):
            if fc.flat[index] == 0:
                qc.flat[index] += change
