"""Projected Gauss-Seidel with over-relaxation on an assembled, bounded linear complementarity problem.

Find impulses ``lambda`` with ``lo <= lambda <= hi`` such that, for ``w = (A + diag(shift)) lambda + b``,

    lambda_i = lo_i       =>  w_i >= 0
    lambda_i = hi_i       =>  w_i <= 0
    lo_i < lambda_i < hi_i  =>  w_i = 0

(the mixed LCP of contacts and joints; ``lo = 0, hi = inf`` is the plain LCP ``lambda >= 0, w >= 0,
lambda . w = 0``).  A friction row ``i`` has bounds that follow the normal impulse of its contact,
``hi_i = mu_i lambda_{link_i} = -lo_i``; when two friction rows are ``partner`` rows, their pair is
stepped together and projected onto the disc ``|(lambda_i, lambda_partner)| <= mu_i lambda_link`` (the
friction cone; the projection is radial, exact for the isotropic tangent block of a sphere or a
centred contact and an approximation otherwise, as in the sequential-impulse solver).

``A = J M^-1 J^T`` is symmetric positive semi-definite, stored in compressed sparse rows
(``ptr``, ``col``, ``val``).  One sweep visits every row in order:

    lambda_i <- project(lambda_i - omega w_i / (A_ii + shift_i))

For 0 < omega < 2 and bounds that do not move (no friction links) this is a descent method on the
quadratic ``1/2 lambda.(A + shift) lambda + b.lambda`` over the box, and converges to the LCP solution
(Cottle, Pang and Stone, "The Linear Complementarity Problem", 5.2).  Each sweep costs one pass over
the non-zeros of A.
"""
import math

from .._numba.jit import njit


@njit
def solve_bounded_lcp(ptr, col, val, shift, b, lo, hi, link, mu, partner, lam, m, sweeps, omega, tolerance):
    """Solve the bounded LCP of the first ``m`` rows in place in ``lam`` (warm start: its contents).

    ``lo``, ``hi`` are the fixed bounds of rows without a ``link`` (-1).  A pair of ``partner`` rows
    (i < j) is updated together when row i is visited: both steps, then the projection onto the disc.
    ``tolerance`` stops the sweeps once no row's ``|delta lambda_i| (A_ii + shift_i)`` (a velocity,
    m/s) exceeds it.  Rows with a zero diagonal move nothing and keep their value.  Returns the number
    of sweeps made (at most ``sweeps``).
    """
    diag = _diagonal(ptr, col, val, shift, m)
    for sweep in range(sweeps):
        largest = 0.0
        for i in range(m):
            j = partner[i]
            if diag[i] <= 0.0 or 0 <= j < i:
                continue            # moves nothing, or updated with its partner
            old = lam[i]
            new = old - omega * _residual(ptr, col, val, shift, b, lam, i) / diag[i]
            if link[i] < 0:
                new = min(max(new, lo[i]), hi[i])
            elif j < 0:
                bound = mu[i] * lam[link[i]]
                new = min(max(new, -bound), bound)
            else:
                # The friction disc: step both tangents, then scale back onto |lambda_t| <= mu lambda_n.
                old_j = lam[j]
                new_j = old_j
                if diag[j] > 0.0:
                    new_j = old_j - omega * _residual(ptr, col, val, shift, b, lam, j) / diag[j]
                bound = mu[i] * lam[link[i]]
                length = math.sqrt(new * new + new_j * new_j)
                if length > bound:
                    scale = bound / length if length > 0.0 else 0.0
                    new *= scale
                    new_j *= scale
                lam[j] = new_j
                largest = max(largest, abs(new_j - old_j) * diag[j])
            lam[i] = new
            largest = max(largest, abs(new - old) * diag[i])
        if largest <= tolerance:
            return sweep + 1
    return sweeps


@njit
def _residual(ptr, col, val, shift, b, lam, i):
    """``w_i = ((A + diag(shift)) lambda + b)_i``, the constrained velocity of row i."""
    w = b[i] + shift[i] * lam[i]
    for p in range(ptr[i], ptr[i + 1]):
        w += val[p] * lam[col[p]]
    return w


@njit
def _diagonal(ptr, col, val, shift, m):
    """``A_ii + shift_i`` for each of the first ``m`` rows."""
    diag = shift[:m].copy()
    for i in range(m):
        for p in range(ptr[i], ptr[i + 1]):
            if col[p] == i:
                diag[i] += val[p]
    return diag
