"""A small MAC-grid fluid solver in Warp kernels (device "cpu", float64), for ``bench/bench_fluid.py``.

The same scheme, grid and boundaries as ``bench/peers/taichi_fluid.py`` (see its docstring): MacCormack advection
of the dye and the velocity on midpoint-rule (RK2) traces with the clamp, backward-Euler viscosity by conjugate
gradients (faces' residuals within 1e-8 of the largest speed), the pressure by conjugate gradients with a Jacobi
(diagonal) preconditioner, warm-started from the last step's pressure, to ``max |div u| dt <= tolerance``.  Warp
runs a CPU kernel on one thread; each reduction (a dot product, a largest magnitude) is a kernel writing with
atomics into a small array that is read back.
"""
import numpy as np
import warp as wp

DEVICE = "cpu"
_STARTED = []

ZERO = wp.constant(wp.float64(0.0))
HALF = wp.constant(wp.float64(0.5))
ONE = wp.constant(wp.float64(1.0))
TWO = wp.constant(wp.float64(2.0))
FOUR = wp.constant(wp.float64(4.0))
HUGE = wp.constant(wp.float64(1e300))


def start():
    if not _STARTED:
        wp.config.quiet = True
        wp.init()
        _STARTED.append(True)


# --- the grid: values with their ghosts, interpolation -------------------------------------------------------------
@wp.func
def fold(index: int, count: int, low: wp.float64, high: wp.float64, offset: wp.float64, sign: wp.float64):
    """An index across a wall folded into the stored range, with the ghost's bookkeeping (``2 U_wall - q``)."""
    if index < 0:
        return 0, offset + sign * TWO * low, -sign
    if index >= count:
        return count - 1, offset + sign * TWO * high, -sign
    return index, offset, sign


@wp.func
def face(f: wp.array4d(dtype=wp.float64), c: int, i: int, j: int, k: int, nx: int, ny: int, nz: int,
         lid: wp.float64):
    """Component ``c`` at face ``(i, j, k)``: along ``c`` 0..n (n: the far wall, 0), across it -1..n (ghosts);
    the y+ wall slides at ``lid`` along x."""
    offset = ZERO
    sign = ONE
    inside = True
    ii = i
    jj = j
    kk = k
    if c == 0:
        inside = i > 0 and i < nx
        jj, offset, sign = fold(j, ny, ZERO, lid, offset, sign)
        kk, offset, sign = fold(k, nz, ZERO, ZERO, offset, sign)
    elif c == 1:
        inside = j > 0 and j < ny
        ii, offset, sign = fold(i, nx, ZERO, ZERO, offset, sign)
        kk, offset, sign = fold(k, nz, ZERO, ZERO, offset, sign)
    else:
        inside = k > 0 and k < nz
        ii, offset, sign = fold(i, nx, ZERO, ZERO, offset, sign)
        jj, offset, sign = fold(j, ny, ZERO, ZERO, offset, sign)
    value = offset
    if inside:
        value = offset + sign * f[c, ii, jj, kk]
    return value


@wp.kernel
def pad_faces(f: wp.array4d(dtype=wp.float64), padded: wp.array4d(dtype=wp.float64), nx: int, ny: int, nz: int,
              lid: wp.float64):
    c, i, j, k = wp.tid()
    padded[c, i, j, k] = face(f, c, i - 1, j - 1, k - 1, nx, ny, nz, lid)


@wp.kernel
def pad_cells(f: wp.array3d(dtype=wp.float64), padded: wp.array4d(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    padded[0, i, j, k] = f[wp.clamp(i - 1, 0, nx - 1), wp.clamp(j - 1, 0, ny - 1), wp.clamp(k - 1, 0, nz - 1)]


@wp.func
def interpolate(padded: wp.array4d(dtype=wp.float64), c: int, x: wp.float64, y: wp.float64, z: wp.float64,
                shift_x: wp.float64, shift_y: wp.float64, shift_z: wp.float64, nx: int, ny: int, nz: int):
    """(value, smallest, largest corner) of field ``c`` of a padded grid whose samples sit at index + shift."""
    sx = wp.min(wp.max(x, ZERO), wp.float64(nx)) - shift_x
    sy = wp.min(wp.max(y, ZERO), wp.float64(ny)) - shift_y
    i0 = wp.min(int(wp.floor(sx)), nx - 1)
    j0 = wp.min(int(wp.floor(sy)), ny - 1)
    fx = sx - wp.float64(i0)
    fy = sy - wp.float64(j0)
    k0 = int(0)  # noqa: UP018 (a Warp variable, not a constant)
    fz = ZERO
    layers = int(1)  # noqa: UP018
    if nz > 1:
        sz = wp.min(wp.max(z, ZERO), wp.float64(nz)) - shift_z
        k0 = wp.min(int(wp.floor(sz)), nz - 1)
        fz = sz - wp.float64(k0)
        layers = 2
    value = ZERO
    lo = HUGE
    hi = -HUGE
    for dk in range(layers):
        wz = ONE - fz
        if dk == 1:
            wz = fz
        for dj in range(2):
            wy = ONE - fy
            if dj == 1:
                wy = fy
            for di in range(2):
                wx = ONE - fx
                if di == 1:
                    wx = fx
                corner = padded[c, i0 + 1 + di, j0 + 1 + dj, k0 + 1 + dk]
                value += wx * wy * wz * corner
                lo = wp.min(lo, corner)
                hi = wp.max(hi, corner)
    return wp.vec3d(value, lo, hi)


@wp.func
def interpolate_face(padded: wp.array4d(dtype=wp.float64), c: int, p: wp.vec3d, nx: int, ny: int, nz: int):
    sx = HALF
    sy = HALF
    sz = HALF
    if c == 0:
        sx = ZERO
    elif c == 1:
        sy = ZERO
    else:
        sz = ZERO
    return interpolate(padded, c, p[0], p[1], p[2], sx, sy, sz, nx, ny, nz)


@wp.func
def velocity_at(flow: wp.array4d(dtype=wp.float64), p: wp.vec3d, nx: int, ny: int, nz: int):
    u = interpolate_face(flow, 0, p, nx, ny, nz)[0]
    v = interpolate_face(flow, 1, p, nx, ny, nz)[0]
    w = ZERO
    if nz > 1:
        w = interpolate_face(flow, 2, p, nx, ny, nz)[0]
    return wp.vec3d(u, v, w)


@wp.func
def trace(flow: wp.array4d(dtype=wp.float64), p: wp.vec3d, steps: wp.float64, nx: int, ny: int, nz: int):
    """From ``p`` (cells) along the flow for ``steps`` = dt / h (negative: back), midpoint rule."""
    mid = p + HALF * steps * velocity_at(flow, p, nx, ny, nz)
    return p + steps * velocity_at(flow, mid, nx, ny, nz)


@wp.func
def face_centre(c: int, i: int, j: int, k: int):
    p = wp.vec3d(wp.float64(i) + HALF, wp.float64(j) + HALF, wp.float64(k) + HALF)
    p[c] = p[c] - HALF
    return p


@wp.func
def along(c: int, i: int, j: int, k: int):
    index = i
    if c == 1:
        index = j
    elif c == 2:
        index = k
    return index


# --- advection --------------------------------------------------------------------------------------------------
@wp.kernel
def advect_faces_back(flow: wp.array4d(dtype=wp.float64), steps: wp.float64, hat: wp.array4d(dtype=wp.float64),
                      lo: wp.array4d(dtype=wp.float64), hi: wp.array4d(dtype=wp.float64), nx: int, ny: int, nz: int):
    c, i, j, k = wp.tid()
    if along(c, i, j, k) == 0:
        hat[c, i, j, k] = ZERO
        return
    b = trace(flow, face_centre(c, i, j, k), -steps, nx, ny, nz)
    r = interpolate_face(flow, c, b, nx, ny, nz)
    hat[c, i, j, k] = r[0]
    lo[c, i, j, k] = r[1]
    hi[c, i, j, k] = r[2]


@wp.kernel
def advect_faces_forth(flow: wp.array4d(dtype=wp.float64), q: wp.array4d(dtype=wp.float64),
                       hat: wp.array4d(dtype=wp.float64), padded: wp.array4d(dtype=wp.float64), steps: wp.float64,
                       lo: wp.array4d(dtype=wp.float64), hi: wp.array4d(dtype=wp.float64),
                       out: wp.array4d(dtype=wp.float64), nx: int, ny: int, nz: int):
    c, i, j, k = wp.tid()
    if along(c, i, j, k) == 0:
        out[c, i, j, k] = ZERO
        return
    f = trace(flow, face_centre(c, i, j, k), steps, nx, ny, nz)
    back = interpolate_face(padded, c, f, nx, ny, nz)[0]
    corrected = hat[c, i, j, k] + HALF * (q[c, i, j, k] - back)
    out[c, i, j, k] = wp.min(wp.max(corrected, lo[c, i, j, k]), hi[c, i, j, k])


@wp.kernel
def advect_cells_back(flow: wp.array4d(dtype=wp.float64), padded: wp.array4d(dtype=wp.float64), steps: wp.float64,
                      hat: wp.array3d(dtype=wp.float64), lo: wp.array3d(dtype=wp.float64),
                      hi: wp.array3d(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    p = wp.vec3d(wp.float64(i) + HALF, wp.float64(j) + HALF, wp.float64(k) + HALF)
    b = trace(flow, p, -steps, nx, ny, nz)
    r = interpolate(padded, 0, b[0], b[1], b[2], HALF, HALF, HALF, nx, ny, nz)
    hat[i, j, k] = r[0]
    lo[i, j, k] = r[1]
    hi[i, j, k] = r[2]


@wp.kernel
def advect_cells_forth(flow: wp.array4d(dtype=wp.float64), s: wp.array3d(dtype=wp.float64),
                       hat: wp.array3d(dtype=wp.float64), padded: wp.array4d(dtype=wp.float64), steps: wp.float64,
                       lo: wp.array3d(dtype=wp.float64), hi: wp.array3d(dtype=wp.float64),
                       out: wp.array3d(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    p = wp.vec3d(wp.float64(i) + HALF, wp.float64(j) + HALF, wp.float64(k) + HALF)
    f = trace(flow, p, steps, nx, ny, nz)
    back = interpolate(padded, 0, f[0], f[1], f[2], HALF, HALF, HALF, nx, ny, nz)[0]
    corrected = hat[i, j, k] + HALF * (s[i, j, k] - back)
    out[i, j, k] = wp.min(wp.max(corrected, lo[i, j, k]), hi[i, j, k])


# --- viscosity --------------------------------------------------------------------------------------------------
@wp.func
def laplacian(f: wp.array4d(dtype=wp.float64), c: int, i: int, j: int, k: int, nx: int, ny: int, nz: int,
              lid: wp.float64):
    here = f[c, i, j, k]
    total = (face(f, c, i - 1, j, k, nx, ny, nz, lid) + face(f, c, i + 1, j, k, nx, ny, nz, lid)
             + face(f, c, i, j - 1, k, nx, ny, nz, lid) + face(f, c, i, j + 1, k, nx, ny, nz, lid) - FOUR * here)
    if nz > 1:
        total += face(f, c, i, j, k - 1, nx, ny, nz, lid) + face(f, c, i, j, k + 1, nx, ny, nz, lid) - TWO * here
    return total


@wp.kernel
def viscous_start(q: wp.array4d(dtype=wp.float64), a: wp.float64, r: wp.array4d(dtype=wp.float64),
                  s: wp.array4d(dtype=wp.float64), d: wp.array4d(dtype=wp.float64), sums: wp.array(dtype=wp.float64),
                  nx: int, ny: int, nz: int, lid: wp.float64):
    c, i, j, k = wp.tid()
    value = ZERO
    if along(c, i, j, k) != 0:
        value = a * laplacian(q, c, i, j, k, nx, ny, nz, lid)
    r[c, i, j, k] = value
    s[c, i, j, k] = value
    d[c, i, j, k] = ZERO
    wp.atomic_add(sums, 0, value * value)
    wp.atomic_max(sums, 1, wp.abs(value))
    wp.atomic_max(sums, 2, wp.abs(q[c, i, j, k]))


@wp.kernel
def viscous_apply(s: wp.array4d(dtype=wp.float64), a: wp.float64, As: wp.array4d(dtype=wp.float64),
                  sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int):
    c, i, j, k = wp.tid()
    value = ZERO
    if along(c, i, j, k) != 0:
        value = s[c, i, j, k] - a * laplacian(s, c, i, j, k, nx, ny, nz, ZERO)
    As[c, i, j, k] = value
    wp.atomic_add(sums, 0, value * s[c, i, j, k])


@wp.kernel
def viscous_update(alpha: wp.float64, s: wp.array4d(dtype=wp.float64), As: wp.array4d(dtype=wp.float64),
                   d: wp.array4d(dtype=wp.float64), r: wp.array4d(dtype=wp.float64),
                   sums: wp.array(dtype=wp.float64)):
    c, i, j, k = wp.tid()
    d[c, i, j, k] = d[c, i, j, k] + alpha * s[c, i, j, k]
    value = r[c, i, j, k] - alpha * As[c, i, j, k]
    r[c, i, j, k] = value
    wp.atomic_add(sums, 0, value * value)
    wp.atomic_max(sums, 1, wp.abs(value))


@wp.kernel
def direction4(beta: wp.float64, r: wp.array4d(dtype=wp.float64), s: wp.array4d(dtype=wp.float64)):
    c, i, j, k = wp.tid()
    s[c, i, j, k] = r[c, i, j, k] + beta * s[c, i, j, k]


@wp.kernel
def add4(q: wp.array4d(dtype=wp.float64), d: wp.array4d(dtype=wp.float64)):
    c, i, j, k = wp.tid()
    q[c, i, j, k] = q[c, i, j, k] + d[c, i, j, k]


# --- pressure ---------------------------------------------------------------------------------------------------
@wp.func
def neighbours(i: int, j: int, k: int, nx: int, ny: int, nz: int):
    count = ZERO
    if i > 0:
        count += ONE
    if i < nx - 1:
        count += ONE
    if j > 0:
        count += ONE
    if j < ny - 1:
        count += ONE
    if k > 0:
        count += ONE
    if k < nz - 1:
        count += ONE
    return count


@wp.func
def apply_A(f: wp.array3d(dtype=wp.float64), i: int, j: int, k: int, nx: int, ny: int, nz: int):
    here = f[i, j, k]
    total = ZERO
    if i > 0:
        total += here - f[i - 1, j, k]
    if i < nx - 1:
        total += here - f[i + 1, j, k]
    if j > 0:
        total += here - f[i, j - 1, k]
    if j < ny - 1:
        total += here - f[i, j + 1, k]
    if k > 0:
        total += here - f[i, j, k - 1]
    if k < nz - 1:
        total += here - f[i, j, k + 1]
    return total


@wp.func
def divergence_at(q: wp.array4d(dtype=wp.float64), i: int, j: int, k: int, nx: int, ny: int, nz: int,
                  lid: wp.float64):
    """The net outflow of cell (i, j, k) times h (m/s)."""
    total = (face(q, 0, i + 1, j, k, nx, ny, nz, lid) - q[0, i, j, k]
             + face(q, 1, i, j + 1, k, nx, ny, nz, lid) - q[1, i, j, k])
    if nz > 1:
        total += face(q, 2, i, j, k + 1, nx, ny, nz, lid) - q[2, i, j, k]
    return total


@wp.kernel
def pressure_rhs(q: wp.array4d(dtype=wp.float64), scale: wp.float64, b: wp.array3d(dtype=wp.float64),
                 sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int, lid: wp.float64):
    i, j, k = wp.tid()
    value = scale * divergence_at(q, i, j, k, nx, ny, nz, lid)
    b[i, j, k] = value
    wp.atomic_add(sums, 0, value)


@wp.kernel
def pressure_start(b: wp.array3d(dtype=wp.float64), mean: wp.float64, p: wp.array3d(dtype=wp.float64),
                   r: wp.array3d(dtype=wp.float64), s: wp.array3d(dtype=wp.float64),
                   sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    value = b[i, j, k] - mean - apply_A(p, i, j, k, nx, ny, nz)
    r[i, j, k] = value
    z = value / neighbours(i, j, k, nx, ny, nz)
    s[i, j, k] = z
    wp.atomic_add(sums, 0, z * value)
    wp.atomic_max(sums, 1, wp.abs(value))


@wp.kernel
def pressure_apply(s: wp.array3d(dtype=wp.float64), As: wp.array3d(dtype=wp.float64),
                   sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    value = apply_A(s, i, j, k, nx, ny, nz)
    As[i, j, k] = value
    wp.atomic_add(sums, 0, value * s[i, j, k])


@wp.kernel
def pressure_update(alpha: wp.float64, s: wp.array3d(dtype=wp.float64), As: wp.array3d(dtype=wp.float64),
                    p: wp.array3d(dtype=wp.float64), r: wp.array3d(dtype=wp.float64),
                    z: wp.array3d(dtype=wp.float64), sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int):
    i, j, k = wp.tid()
    p[i, j, k] = p[i, j, k] + alpha * s[i, j, k]
    value = r[i, j, k] - alpha * As[i, j, k]
    r[i, j, k] = value
    zz = value / neighbours(i, j, k, nx, ny, nz)
    z[i, j, k] = zz
    wp.atomic_add(sums, 0, zz * value)
    wp.atomic_max(sums, 1, wp.abs(value))


@wp.kernel
def direction3(beta: wp.float64, z: wp.array3d(dtype=wp.float64), s: wp.array3d(dtype=wp.float64)):
    i, j, k = wp.tid()
    s[i, j, k] = z[i, j, k] + beta * s[i, j, k]


@wp.kernel
def subtract_gradient(p: wp.array3d(dtype=wp.float64), scale: wp.float64, q: wp.array4d(dtype=wp.float64)):
    c, i, j, k = wp.tid()
    if along(c, i, j, k) == 0:
        return
    below = p[i, j, k]
    if c == 0:
        below = p[i - 1, j, k]
    elif c == 1:
        below = p[i, j - 1, k]
    else:
        below = p[i, j, k - 1]
    q[c, i, j, k] = q[c, i, j, k] - scale * (p[i, j, k] - below)


@wp.kernel
def max_divergence(q: wp.array4d(dtype=wp.float64), sums: wp.array(dtype=wp.float64), nx: int, ny: int, nz: int,
                   lid: wp.float64):
    i, j, k = wp.tid()
    wp.atomic_max(sums, 0, wp.abs(divergence_at(q, i, j, k, nx, ny, nz, lid)))


class WarpFluid:
    """An incompressible fluid of ``n = (nx, ny, nz)`` cells of side ``h`` m (``nz = 1``: 2D), walls all round."""

    def __init__(self, n, h, viscosity, density, tolerance, lid=0.0, max_iterations=5000):
        start()
        self.nx, self.ny, self.nz = (int(v) for v in n)
        self.dims = 2 if self.nz == 1 else 3
        self.h, self.nu, self.rho, self.tol, self.lid = float(h), float(viscosity), float(density), tolerance, lid
        self.max_iterations = max_iterations
        faces = (3, self.nx, self.ny, self.nz)
        cells = (self.nx, self.ny, self.nz)
        padded = (3, self.nx + 2, self.ny + 2, self.nz + 2)

        def zeros(shape):
            return wp.zeros(shape, dtype=wp.float64, device=DEVICE)

        self.q, self.hat, self.lo, self.hi, self.out = (zeros(faces) for _ in range(5))
        self.vr, self.vd, self.vs, self.vas = (zeros(faces) for _ in range(4))
        self.dye, self.dye_hat, self.dye_lo, self.dye_hi, self.dye_out = (zeros(cells) for _ in range(5))
        self.p, self.r, self.z, self.s, self.As = (zeros(cells) for _ in range(5))
        self.flow, self.padded = zeros(padded), zeros(padded)
        self.dye_padded = zeros((1,) + padded[1:])
        self.sums = zeros(3)
        self.pressure_iterations = 0
        self.viscosity_iterations = 0

    def _launch(self, kernel, dim, *inputs):
        wp.launch(kernel, dim=dim, inputs=list(inputs), device=DEVICE)

    def _reduce(self, kernel, dim, *inputs):
        """Launch ``kernel`` (which accumulates into ``self.sums``) and read the sums back."""
        self.sums.zero_()
        wp.launch(kernel, dim=dim, inputs=list(inputs), device=DEVICE)
        return self.sums.numpy()

    def step(self, dt):
        n = (self.nx, self.ny, self.nz)
        faces = (self.dims,) + n
        padded = (self.dims, self.nx + 2, self.ny + 2, self.nz + 2)
        steps = dt / self.h
        self._launch(pad_faces, padded, self.q, self.flow, *n, self.lid)
        self._launch(pad_cells, padded[1:], self.dye, self.dye_padded, *n)
        self._launch(advect_cells_back, n, self.flow, self.dye_padded, steps, self.dye_hat, self.dye_lo,
                     self.dye_hi, *n)
        self._launch(pad_cells, padded[1:], self.dye_hat, self.dye_padded, *n)
        self._launch(advect_cells_forth, n, self.flow, self.dye, self.dye_hat, self.dye_padded, steps, self.dye_lo,
                     self.dye_hi, self.dye_out, *n)
        self.dye, self.dye_out = self.dye_out, self.dye
        self._launch(advect_faces_back, faces, self.flow, steps, self.hat, self.lo, self.hi, *n)
        self._launch(pad_faces, padded, self.hat, self.padded, *n, self.lid)
        self._launch(advect_faces_forth, faces, self.flow, self.q, self.hat, self.padded, steps, self.lo, self.hi,
                     self.out, *n)
        self.q, self.out = self.out, self.q
        if self.nu > 0.0:
            self.viscosity_iterations = self.diffuse(dt)
        self.pressure_iterations = self.project(dt)

    def diffuse(self, dt):
        n = (self.nx, self.ny, self.nz)
        faces = (self.dims,) + n
        a = self.nu * dt / self.h ** 2
        rr, worst, speed = self._reduce(viscous_start, faces, self.q, a, self.vr, self.vs, self.vd, self.sums, *n,
                                        self.lid)
        limit = 1e-8 * max(speed, abs(self.lid), 1e-30)
        iterations = 0
        while iterations < 500 and worst > limit:
            curvature = self._reduce(viscous_apply, faces, self.vs, a, self.vas, self.sums, *n)[0]
            if curvature <= 0.0:
                break
            rr_new, worst = self._reduce(viscous_update, faces, rr / curvature, self.vs, self.vas, self.vd, self.vr,
                                         self.sums)[:2]
            self._launch(direction4, faces, rr_new / rr, self.vr, self.vs)
            rr = rr_new
            iterations += 1
        self._launch(add4, faces, self.q, self.vd)
        return iterations

    def project(self, dt):
        n = (self.nx, self.ny, self.nz)
        h, rho = self.h, self.rho
        total = self._reduce(pressure_rhs, n, self.q, -rho * h / dt, self.z, self.sums, *n, self.lid)[0]
        zr, worst = self._reduce(pressure_start, n, self.z, total / (self.nx * self.ny * self.nz), self.p, self.r,
                                 self.s, self.sums, *n)[:2]
        limit = self.tol * rho * h * h / (dt * dt)
        iterations = 0
        while worst > limit and iterations < self.max_iterations:
            alpha = zr / self._reduce(pressure_apply, n, self.s, self.As, self.sums, *n)[0]
            zr_new, worst = self._reduce(pressure_update, n, alpha, self.s, self.As, self.p, self.r, self.z,
                                         self.sums, *n)[:2]
            iterations += 1
            if worst <= limit:
                break
            self._launch(direction3, n, zr_new / zr, self.z, self.s)
            zr = zr_new
        self._launch(subtract_gradient, (self.dims,) + n, self.p, dt / (rho * h), self.q)
        return iterations

    def max_divergence(self):
        n = (self.nx, self.ny, self.nz)
        return self._reduce(max_divergence, n, self.q, self.sums, *n, self.lid)[0] / self.h

    # --- state as NumPy arrays (outside the timed steps) -------------------------------------------------------
    def faces(self):
        return self.q.numpy()

    def set_faces(self, q):
        self.q.assign(np.ascontiguousarray(q, dtype=np.float64))

    def get_dye(self):
        return self.dye.numpy()

    def set_dye(self, d):
        self.dye.assign(np.ascontiguousarray(d, dtype=np.float64))
