"""Advection, ``dq/dt + (u . grad) q = 0``, by the MacCormack scheme on semi-Lagrangian steps.

A semi-Lagrangian step traces each sample point back along the flow (second-order Runge-Kutta) and reads the
field there: unconditionally stable, but first-order diffusive.  MacCormack (Selle et al. 2008, "An
unconditionally stable MacCormack method") removes the leading error: advect forwards, ``q^ = A(q)``, advect
the result backwards in time, ``q~ = A^R(q^)``, and correct by half the round trip's error,

    q^{n+1} = q^ + (q - q~) / 2

which is second order in space and time where the field is smooth.  Where the corrected value leaves the
range of the grid values the back-traced point was interpolated from (at a front), the sample falls back to
the plain semi-Lagrangian value, which keeps the scheme stable at any time step.
"""
from .._numba.jit import borrow, njit
from .mac_grid import face_centre, interpolate_cell, interpolate_face, pad_cells, pad_faces, velocity_at


@njit
def trace(flow, x, y, z, steps, n, periodic, dims):
    """Follow the flow (padded faces, :func:`pad_faces`) from ``(x, y, z)`` (cells) for ``steps`` = dt / h
    (s/m; negative goes back in time) by the midpoint rule: the point reached."""
    u, v, w = velocity_at(flow, x, y, z, n, periodic, dims)
    mx = x + 0.5 * steps * u
    my = y + 0.5 * steps * v
    mz = z + 0.5 * steps * w
    u, v, w = velocity_at(flow, mx, my, mz, n, periodic, dims)
    return x + steps * u, y + steps * v, z + steps * w


@njit
def advect_velocity(flow, q, fixed, steps, n, periodic, wall, dims, out, work, padded):
    """``out`` = the velocity field ``q`` carried by the flow ``flow`` (padded faces) over one step
    (``steps`` = dt / h, s/m); faces marked in ``fixed`` keep their values.  ``work``: (3,) + ``q.shape``;
    ``padded``: like ``flow``."""
    hat, lo, hi = work[0], work[1], work[2]
    hat[:] = q
    out[:] = q
    flow, q, hat, n, periodic = borrow(flow), borrow(q), borrow(hat), borrow(n), borrow(periodic)
    padded, fixed, lo, hi = borrow(padded), borrow(fixed), borrow(lo), borrow(hi)
    pad_faces(q, n, periodic, wall, dims, padded)
    for c in range(dims):
        for i in range(n[0]):
            for j in range(n[1]):
                for k in range(n[2]):
                    if fixed[c, i, j, k]:
                        continue
                    x, y, z = face_centre(c, i, j, k)
                    bx, by, bz = trace(flow, x, y, z, -steps, n, periodic, dims)
                    hat[c, i, j, k], lo[c, i, j, k], hi[c, i, j, k] = interpolate_face(padded, c, bx, by, bz, n,
                                                                                       periodic)
    pad_faces(hat, n, periodic, wall, dims, padded)
    for c in range(dims):
        for i in range(n[0]):
            for j in range(n[1]):
                for k in range(n[2]):
                    if fixed[c, i, j, k]:
                        continue
                    x, y, z = face_centre(c, i, j, k)
                    fx, fy, fz = trace(flow, x, y, z, steps, n, periodic, dims)
                    back = interpolate_face(padded, c, fx, fy, fz, n, periodic)[0]
                    corrected = hat[c, i, j, k] + 0.5 * (q[c, i, j, k] - back)
                    out[c, i, j, k] = min(max(corrected, lo[c, i, j, k]), hi[c, i, j, k])


@njit
def advect_scalar(s, flow, n, periodic, dims, steps, out, work, padded):
    """``out`` = the cell-centred field ``s`` carried by the flow ``flow`` (padded faces) over one step
    (``steps`` = dt / h); ``work``: (3,) + ``s.shape``; ``padded``: (1,) + ``s.shape`` + 2 along each axis."""
    hat, lo, hi = work[0], work[1], work[2]
    s, flow, hat, n, periodic = borrow(s), borrow(flow), borrow(hat), borrow(n), borrow(periodic)
    padded, lo, hi = borrow(padded), borrow(lo), borrow(hi)
    pad_cells(s, n, periodic, padded)
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                bx, by, bz = trace(flow, i + 0.5, j + 0.5, k + 0.5, -steps, n, periodic, dims)
                hat[i, j, k], lo[i, j, k], hi[i, j, k] = interpolate_cell(padded, bx, by, bz, n, periodic)
    pad_cells(hat, n, periodic, padded)
    for i in range(n[0]):
        for j in range(n[1]):
            for k in range(n[2]):
                fx, fy, fz = trace(flow, i + 0.5, j + 0.5, k + 0.5, steps, n, periodic, dims)
                back = interpolate_cell(padded, fx, fy, fz, n, periodic)[0]
                corrected = hat[i, j, k] + 0.5 * (s[i, j, k] - back)
                out[i, j, k] = min(max(corrected, lo[i, j, k]), hi[i, j, k])
