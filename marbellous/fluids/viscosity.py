"""Viscosity, ``du/dt = nu laplacian(u)``, by a backward-Euler step (stable at any viscosity and step).

With ``a = nu dt / h^2`` and the grid Laplacian ``L`` (the sum over a face's neighbours of ``q_nb - q``, the
walls' ghost values included), the new velocity solves ``(I - a L) u = u*``.  Writing ``u = u* + d``, the
correction ``d`` is zero on fixed faces, has ghosts ``-d`` at walls (the wall velocities are in ``u*``'s
ghosts), and solves the symmetric positive-definite system

    (I - a L0) d = a L(u*)

by conjugate gradients (``L0``: ``L`` with the walls at rest).  Its condition number is below
``1 + 4 a dims``, so a few tens of iterations reach round-off even when viscosity dominates.
"""
import numpy as np

from .._numba.jit import njit
from .grid_vectors import add_scaled, assign, dot, largest_magnitude, scale_add
from .mac_grid import face_value

#: the correction is accepted when no face's residual exceeds this fraction of the largest speed (of the fluid
#: or a wall)
RELATIVE_TOLERANCE = 1e-8
#: most conjugate-gradient iterations per step
MAX_ITERATIONS = 500


@njit
def laplacian(q, fixed, n, periodic, wall, dims, out):
    """``out`` = ``L q`` (m/s): on each free face the sum of its neighbours minus itself; 0 on fixed faces."""
    nx, ny, nz = n[0], n[1], n[2]
    for c in range(dims):
        for i in range(nx):
            for j in range(ny):
                for k in range(nz):
                    if fixed[c, i, j, k]:
                        out[c, i, j, k] = 0.0
                        continue
                    here = q[c, i, j, k]
                    if 0 < i < nx - 1 and 0 < j < ny - 1:
                        total = q[c, i - 1, j, k] + q[c, i + 1, j, k] + q[c, i, j - 1, k] + q[c, i, j + 1, k]
                    else:
                        total = (face_value(q, c, i - 1, j, k, n, periodic, wall)
                                 + face_value(q, c, i + 1, j, k, n, periodic, wall)
                                 + face_value(q, c, i, j - 1, k, n, periodic, wall)
                                 + face_value(q, c, i, j + 1, k, n, periodic, wall))
                    total -= 4.0 * here
                    if nz > 1:
                        if 0 < k < nz - 1:
                            total += q[c, i, j, k - 1] + q[c, i, j, k + 1] - 2.0 * here
                        else:
                            total += (face_value(q, c, i, j, k - 1, n, periodic, wall)
                                      + face_value(q, c, i, j, k + 1, n, periodic, wall) - 2.0 * here)
                    out[c, i, j, k] = total


@njit
def diffuse(q, fixed, a, n, periodic, wall, dims, work):
    """Replace ``q`` by the backward-Euler viscous step ``(I - a L)^-1 q`` (``a = nu dt / h^2``).  ``work``:
    (4, 3, nx, ny, nz).  Returns the iterations taken."""
    work[:] = 0.0
    r, d, p, ap = work[0, :dims], work[1, :dims], work[2, :dims], work[3, :dims]
    still = np.zeros_like(wall)
    laplacian(q, fixed, n, periodic, wall, dims, ap)
    add_scaled(r, a, ap)
    assign(p, r)
    rr = dot(r, r)
    limit = RELATIVE_TOLERANCE * max(largest_magnitude(q[:dims]), largest_magnitude(wall), 1e-30)
    iterations = 0
    while iterations < MAX_ITERATIONS and largest_magnitude(r) > limit:
        laplacian(p, fixed, n, periodic, still, dims, ap)
        scale_add(ap, -a, p)
        curvature = dot(p, ap)
        if curvature <= 0.0:
            break
        alpha = rr / curvature
        add_scaled(d, alpha, p)
        add_scaled(r, -alpha, ap)
        rr_new = dot(r, r)
        scale_add(p, rr_new / rr, r)
        rr = rr_new
        iterations += 1
    add_scaled(q[:dims], 1.0, d)
    return iterations
