"""The pressure projection: the velocity made divergence-free, ``u <- u - (dt / rho) grad p`` with ``p`` such
that ``div u = 0`` in every fluid cell.

On the staggered grid the divergence of cell ``c`` is the net outflow through its faces,
``div_c = sum_faces +-q / h``, and the pressure gradient on a free face between cells ``c-`` and ``c+`` is
``(p+ - p-) / h``; fixed faces (walls, bodies) keep their velocity, so pressure does not act across them (a
zero normal gradient).  Subtracting the gradient changes ``div_c`` by ``(dt / (rho h^2)) (A p)_c`` with

    (A p)_c = sum over the free faces of c of (p_c - p_neighbour)

the graph Laplacian of the fluid cells (symmetric, positive semi-definite: constant pressures are its null
space, since the fluid fills its box).  The projection solves ``A p = -rho h^2 div / dt`` by conjugate
gradients preconditioned with the modified incomplete Cholesky factor MIC(0) (Bridson, "Fluid Simulation for
Computer Graphics", ch. 5), the constants projected out.  The solve stops when no cell's volume changes by
more than ``tolerance`` (a fraction of the cell) over the step: ``max |div| dt <= tolerance``.
"""
import math

from .._numba.jit import njit
from .grid_vectors import add_scaled, assign, dot, largest_magnitude, scale_add
from .mac_grid import face_value

#: MIC(0)'s share of the dropped fill-in moved to the diagonal, and the safety floor of a pivot (Bridson)
MIC_TUNING = 0.97
MIC_SAFETY = 0.25


@njit
def divergence(q, n, periodic, wall, dims, h, out):
    """``out`` (1/s) = the net outflow of each cell per unit volume (0 in solid cells is the caller's
    business)."""
    nx, ny, nz = n[0], n[1], n[2]
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                if i + 1 < nx and j + 1 < ny and (dims == 2 or k + 1 < nz):
                    total = q[0, i + 1, j, k] - q[0, i, j, k] + q[1, i, j + 1, k] - q[1, i, j, k]
                    if dims == 3:
                        total += q[2, i, j, k + 1] - q[2, i, j, k]
                else:
                    total = (face_value(q, 0, i + 1, j, k, n, periodic, wall) - q[0, i, j, k]
                             + face_value(q, 1, i, j + 1, k, n, periodic, wall) - q[1, i, j, k])
                    if dims == 3:
                        total += face_value(q, 2, i, j, k + 1, n, periodic, wall) - q[2, i, j, k]
                out[i, j, k] = total / h


@njit
def upper_face(axis, i, j, k, n, periodic, fixed, solid):
    """Whether the face above cell ``(i, j, k)`` along ``axis`` lets pressure act (both cells fluid, the face
    not fixed), whether it wraps around a periodic box, and the cell above."""
    count = n[axis]
    index = (i, j, k)[axis] + 1
    if count == 1 or (index == count and not periodic[axis]):
        return False, False, i, j, k
    wraps = index == count
    index = index % count
    if axis == 0:
        a, b, c = index, j, k
    elif axis == 1:
        a, b, c = i, index, k
    else:
        a, b, c = i, j, index
    free = fixed[axis, a, b, c] == 0 and solid[i, j, k] == 0 and solid[a, b, c] == 0
    return free, wraps, a, b, c


@njit
def prepare(n, periodic, fixed, solid, coefficients, precon):
    """Fill ``coefficients`` (7, nx, ny, nz) with ``A``'s diagonal [0], whether each cell is coupled to its
    upper neighbour along x, y, z [1..3] (1 or 0, around a periodic box too) and MIC(0)'s couplings [4..6]
    (-1 or 0, the wrapped ones left out: the factor cannot hold them), and ``precon`` with MIC(0)'s inverse
    pivots."""
    coefficients[:] = 0.0
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                for axis in range(3):
                    free, wraps, a, b, c = upper_face(axis, i, j, k, n, periodic, fixed, solid)
                    if free:
                        coefficients[0, i, j, k] += 1.0
                        coefficients[0, a, b, c] += 1.0
                        coefficients[1 + axis, i, j, k] = 1.0
                        if not wraps:
                            coefficients[4 + axis, i, j, k] = -1.0
    diag, ax, ay, az = coefficients[0], coefficients[4], coefficients[5], coefficients[6]
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                precon[i, j, k] = 0.0
                if solid[i, j, k] or diag[i, j, k] == 0.0:
                    continue
                e = diag[i, j, k]
                if i > 0:
                    t = ax[i - 1, j, k] * precon[i - 1, j, k]
                    e -= t * t + MIC_TUNING * ax[i - 1, j, k] * (ay[i - 1, j, k] + az[i - 1, j, k]) \
                        * precon[i - 1, j, k] ** 2
                if j > 0:
                    t = ay[i, j - 1, k] * precon[i, j - 1, k]
                    e -= t * t + MIC_TUNING * ay[i, j - 1, k] * (ax[i, j - 1, k] + az[i, j - 1, k]) \
                        * precon[i, j - 1, k] ** 2
                if k > 0:
                    t = az[i, j, k - 1] * precon[i, j, k - 1]
                    e -= t * t + MIC_TUNING * az[i, j, k - 1] * (ax[i, j, k - 1] + ay[i, j, k - 1]) \
                        * precon[i, j, k - 1] ** 2
                if e < MIC_SAFETY * diag[i, j, k]:
                    e = diag[i, j, k]
                precon[i, j, k] = 1.0 / math.sqrt(e)


@njit
def apply_laplacian(p, n, coefficients, out):
    """``out = A p``: each cell's pressure times its free faces, less its coupled neighbours' pressures."""
    nx, ny, nz = n[0], n[1], n[2]
    diag, upx, upy, upz = coefficients[0], coefficients[1], coefficients[2], coefficients[3]
    for i in range(nx):
        ip = i + 1 if i + 1 < nx else 0
        im = i - 1 if i > 0 else nx - 1
        for j in range(ny):
            jp = j + 1 if j + 1 < ny else 0
            jm = j - 1 if j > 0 else ny - 1
            for k in range(nz):
                kp = k + 1 if k + 1 < nz else 0
                km = k - 1 if k > 0 else nz - 1
                out[i, j, k] = (diag[i, j, k] * p[i, j, k]
                                - upx[i, j, k] * p[ip, j, k] - upx[im, j, k] * p[im, j, k]
                                - upy[i, j, k] * p[i, jp, k] - upy[i, jm, k] * p[i, jm, k]
                                - upz[i, j, k] * p[i, j, kp] - upz[i, j, km] * p[i, j, km])


@njit
def apply_preconditioner(r, n, solid, coefficients, precon, scratch, out):
    """``out = (L L^T)^-1 r`` with MIC(0)'s factor ``L`` (forward, then backward substitution)."""
    ax, ay, az = coefficients[4], coefficients[5], coefficients[6]
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                if solid[i, j, k]:
                    scratch[i, j, k] = 0.0
                    continue
                t = r[i, j, k]
                if i > 0:
                    t -= ax[i - 1, j, k] * precon[i - 1, j, k] * scratch[i - 1, j, k]
                if j > 0:
                    t -= ay[i, j - 1, k] * precon[i, j - 1, k] * scratch[i, j - 1, k]
                if k > 0:
                    t -= az[i, j, k - 1] * precon[i, j, k - 1] * scratch[i, j, k - 1]
                scratch[i, j, k] = t * precon[i, j, k]
    for i in range(n[0] - 1, -1, -1):
        for j in range(n[1] - 1, -1, -1):
            for k in range(n[2] - 1, -1, -1):
                if solid[i, j, k]:
                    out[i, j, k] = 0.0
                    continue
                t = scratch[i, j, k]
                if i + 1 < n[0]:
                    t -= ax[i, j, k] * precon[i, j, k] * out[i + 1, j, k]
                if j + 1 < n[1]:
                    t -= ay[i, j, k] * precon[i, j, k] * out[i, j + 1, k]
                if k + 1 < n[2]:
                    t -= az[i, j, k] * precon[i, j, k] * out[i, j, k + 1]
                out[i, j, k] = t * precon[i, j, k]


@njit
def remove_mean(x, solid):
    """Subtract the mean over the fluid cells (the null space of ``A``) from ``x``'s fluid cells."""
    xf = x.reshape(x.size)
    sf = solid.reshape(solid.size)
    total = 0.0
    count = 0
    for index in range(xf.size):
        if sf[index] == 0:
            total += xf[index]
            count += 1
    if count == 0:
        return
    mean = total / count
    for index in range(xf.size):
        if sf[index] == 0:
            xf[index] -= mean


@njit
def solve_pressure(p, b, n, solid, coefficients, precon, limit, max_iterations, work):
    """Improve ``p`` (warm start) until ``A p = b`` holds to ``limit`` in every cell (or ``max_iterations``);
    ``work``: (4, nx, ny, nz).  Returns the iterations and the largest residual left."""
    r, z, s, scratch = work[0], work[1], work[2], work[3]
    apply_laplacian(p, n, coefficients, r)
    scale_add(r, -1.0, b)
    remove_mean(r, solid)
    worst = largest_magnitude(r)
    if worst <= limit:
        return 0, worst
    apply_preconditioner(r, n, solid, coefficients, precon, scratch, z)
    remove_mean(z, solid)
    assign(s, z)
    sigma = dot(z, r)
    for iteration in range(1, max_iterations + 1):
        apply_laplacian(s, n, coefficients, z)
        alpha = sigma / dot(z, s)
        add_scaled(p, alpha, s)
        add_scaled(r, -alpha, z)
        worst = largest_magnitude(r)
        if worst <= limit:
            return iteration, worst
        apply_preconditioner(r, n, solid, coefficients, precon, scratch, z)
        remove_mean(z, solid)
        sigma_new = dot(z, r)
        scale_add(s, sigma_new / sigma, z)
        sigma = sigma_new
    return max_iterations, worst


@njit
def subtract_gradient(q, p, scale, n, coefficients):
    """``q -= scale (p+ - p-)`` on every free face (``scale = dt / (rho h)``)."""
    nx, ny, nz = n[0], n[1], n[2]
    for i in range(nx):
        ip = i + 1 if i + 1 < nx else 0
        for j in range(ny):
            jp = j + 1 if j + 1 < ny else 0
            for k in range(nz):
                kp = k + 1 if k + 1 < nz else 0
                here = p[i, j, k]
                if coefficients[1, i, j, k] != 0.0:
                    q[0, ip, j, k] -= scale * (p[ip, j, k] - here)
                if coefficients[2, i, j, k] != 0.0:
                    q[1, i, jp, k] -= scale * (p[i, jp, k] - here)
                if coefficients[3, i, j, k] != 0.0:
                    q[2, i, j, kp] -= scale * (p[i, j, kp] - here)
