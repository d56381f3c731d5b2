"""A small MAC-grid fluid solver in Taichi kernels (CPU backend, float64), for ``bench/bench_fluid.py``.

The same scheme as ``marbellous.Fluid``, written for the benchmark: the velocity on the faces of a staggered grid
(``q[c, i, j, k]``, the lower face of cell ``(i, j, k)`` along axis ``c``; face 0 of a walled axis stored and held at
zero, face ``n`` not stored), pressure and dye at cell centres, a 2D fluid one cell deep.  Walls all round: the
normal velocity is zero on them, a tangential component has the ghost value ``2 U_wall - q`` beyond them (no slip,
or a sliding lid: ``lid`` m/s along x on the y+ side).  A step of ``dt`` s:

1. the dye, then the velocity, advected by MacCormack (Selle et al. 2008) on semi-Lagrangian steps whose points
   are traced by the midpoint rule (second-order Runge-Kutta) through the velocity at the start of the step,
   the corrected value clamped to the range of the grid values the back-traced point was interpolated from;
2. viscosity (when ``viscosity > 0``): the backward-Euler step ``(I - a L) u = u*`` (``a = nu dt / h^2``), solved
   for the correction by conjugate gradients until no face's residual exceeds 1e-8 of the largest speed;
3. the pressure projection: ``A p = -rho h^2 div u / dt`` (``A`` the cells' graph Laplacian, walls Neumann), solved
   by conjugate gradients with a Jacobi (diagonal) preconditioner, warm-started from the last step's pressure,
   until ``max |div u| dt <= tolerance`` after the update; then ``u -= dt / (rho h) grad p``.

Unlike Marbellous (MIC(0)-preconditioned CG, a serial triangular solve), the preconditioner is the diagonal,
which parallelises; Taichi runs each kernel's outer loop on all the CPU's cores.
"""
import numpy as np
import taichi as ti

_STARTED = []


def start():
    """``ti.init`` once per process: the CPU backend, float64, Taichi's warnings only."""
    if not _STARTED:
        ti.init(arch=ti.cpu, default_fp=ti.f64, default_ip=ti.i32, log_level=ti.WARN)
        _STARTED.append(ti.lang.impl.current_cfg().cpu_max_num_threads)
    return _STARTED[0]


@ti.data_oriented
class TaichiFluid:
    """An incompressible fluid of ``n = (nx, ny, nz)`` cells of side ``h`` m (``nz = 1``: 2D), walls all round."""

    def __init__(self, n, h, viscosity, density, tolerance, lid=0.0, max_iterations=5000):
        self.threads = start()
        self.nx, self.ny, self.nz = (int(v) for v in n)
        self.dims = 2 if self.nz == 1 else 3
        self.h, self.nu, self.rho, self.tol, self.lid = float(h), float(viscosity), float(density), tolerance, lid
        self.max_iterations = max_iterations
        faces = (3, self.nx, self.ny, self.nz)
        cells = (self.nx, self.ny, self.nz)
        self.q, self.hat, self.lo, self.hi, self.out = (ti.field(ti.f64, shape=faces) for _ in range(5))
        self.vr, self.vd, self.vs, self.vas = (ti.field(ti.f64, shape=faces) for _ in range(4))
        self.dye, self.dye_hat, self.dye_lo, self.dye_hi, self.dye_out = (ti.field(ti.f64, shape=cells)
                                                                          for _ in range(5))
        self.p, self.r, self.z, self.s, self.As = (ti.field(ti.f64, shape=cells) for _ in range(5))
        padded = (3, self.nx + 2, self.ny + 2, self.nz + 2)
        self.flow, self.padded = ti.field(ti.f64, shape=padded), ti.field(ti.f64, shape=padded)
        self.dye_padded = ti.field(ti.f64, shape=(1,) + padded[1:])
        self.pressure_iterations = 0
        self.viscosity_iterations = 0

    # --- the grid: values with their ghosts, interpolation ---------------------------------------------------
    @ti.func
    def wall(self, side, c, moving: ti.template()):
        """The velocity component ``c`` of wall ``side`` (0..5: x-, x+, y-, y+, z-, z+): the lid is y+ along x."""
        value = 0.0
        if ti.static(moving):
            if side == 3 and c == 0:
                value = self.lid
        return value

    @ti.func
    def face(self, f: ti.template(), c, i, j, k, moving: ti.template()):
        """Component ``c`` of face field ``f`` at face ``(i, j, k)``: along ``c`` the index runs 0..n (n: the far
        wall, 0), across it -1..n (ghosts ``2 U_wall - q``)."""
        n = ti.Vector([self.nx, self.ny, self.nz])
        idx = ti.Vector([i, j, k])
        offset = 0.0
        sign = 1.0
        inside = 0 < idx[c] < n[c]
        for a in ti.static(range(3)):
            if a != c:
                if idx[a] < 0:
                    idx[a] = 0
                    offset += sign * 2.0 * self.wall(2 * a, c, moving)
                    sign = -sign
                elif idx[a] >= n[a]:
                    idx[a] = n[a] - 1
                    offset += sign * 2.0 * self.wall(2 * a + 1, c, moving)
                    sign = -sign
        value = offset
        if inside:
            value += sign * f[c, idx[0], idx[1], idx[2]]
        return value

    @ti.func
    def cell(self, f: ti.template(), i, j, k):
        """A cell-centred value, the nearest cell's beyond a wall."""
        return f[ti.max(ti.min(i, self.nx - 1), 0), ti.max(ti.min(j, self.ny - 1), 0),
                 ti.max(ti.min(k, self.nz - 1), 0)]

    @ti.kernel
    def pad_faces(self, f: ti.template(), padded: ti.template()):
        """``padded[c, i + 1, j + 1, k + 1]`` = :meth:`face` for i in -1..n (likewise j, k)."""
        for c, i, j, k in ti.ndrange(self.dims, self.nx + 2, self.ny + 2, self.nz + 2):
            padded[c, i, j, k] = self.face(f, c, i - 1, j - 1, k - 1, True)

    @ti.kernel
    def pad_cells(self, f: ti.template(), padded: ti.template()):
        for i, j, k in ti.ndrange(self.nx + 2, self.ny + 2, self.nz + 2):
            padded[0, i, j, k] = self.cell(f, i - 1, j - 1, k - 1)

    @ti.func
    def interpolate(self, padded: ti.template(), c, x, y, z, is_face: ti.template()):
        """(value, smallest, largest corner) of field ``c`` of a padded grid (faces if ``is_face``, else cells) at
        ``(x, y, z)`` cells, the point held inside the box."""
        shift = ti.Vector([0.5, 0.5, 0.5])
        if ti.static(is_face):
            shift[c] = 0.0
        sx = ti.min(ti.max(x, 0.0), float(self.nx)) - shift[0]
        sy = ti.min(ti.max(y, 0.0), float(self.ny)) - shift[1]
        i0 = ti.min(int(ti.floor(sx)), self.nx - 1)
        j0 = ti.min(int(ti.floor(sy)), self.ny - 1)
        fx = sx - i0
        fy = sy - j0
        k0 = 0
        fz = 0.0
        if ti.static(self.nz > 1):
            sz = ti.min(ti.max(z, 0.0), float(self.nz)) - shift[2]
            k0 = ti.min(int(ti.floor(sz)), self.nz - 1)
            fz = sz - k0
        value = 0.0
        lo = 1e300
        hi = -1e300
        for dk in ti.static(range(2 if self.nz > 1 else 1)):
            wz = fz if dk == 1 else 1.0 - fz
            for dj in ti.static(range(2)):
                wy = fy if dj == 1 else 1.0 - fy
                for di in ti.static(range(2)):
                    wx = fx if di == 1 else 1.0 - fx
                    corner = padded[c, i0 + 1 + di, j0 + 1 + dj, k0 + 1 + dk]
                    value += wx * wy * wz * corner
                    lo = ti.min(lo, corner)
                    hi = ti.max(hi, corner)
        return ti.Vector([value, lo, hi])

    @ti.func
    def velocity_at(self, x, y, z):
        u = self.interpolate(self.flow, 0, x, y, z, True)[0]
        v = self.interpolate(self.flow, 1, x, y, z, True)[0]
        w = 0.0
        if ti.static(self.dims == 3):
            w = self.interpolate(self.flow, 2, x, y, z, True)[0]
        return ti.Vector([u, v, w])

    @ti.func
    def trace(self, x, steps):
        """From ``x`` (cells) along the flow (the padded velocity at the step's start) for ``steps`` = dt / h
        (negative: back), midpoint rule."""
        mid = x + 0.5 * steps * self.velocity_at(x[0], x[1], x[2])
        return x + steps * self.velocity_at(mid[0], mid[1], mid[2])

    # --- advection ---------------------------------------------------------------------------------------------
    @ti.kernel
    def advect_faces_back(self, steps: ti.f64):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            idx = ti.Vector([i, j, k])
            if idx[c] == 0:
                self.hat[c, i, j, k] = 0.0
            else:
                x = ti.Vector([i + 0.5, j + 0.5, k + 0.5])
                x[c] -= 0.5
                b = self.trace(x, -steps)
                r = self.interpolate(self.flow, c, b[0], b[1], b[2], True)
                self.hat[c, i, j, k] = r[0]
                self.lo[c, i, j, k] = r[1]
                self.hi[c, i, j, k] = r[2]

    @ti.kernel
    def advect_faces_forth(self, steps: ti.f64):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            idx = ti.Vector([i, j, k])
            if idx[c] == 0:
                self.out[c, i, j, k] = 0.0
            else:
                x = ti.Vector([i + 0.5, j + 0.5, k + 0.5])
                x[c] -= 0.5
                f = self.trace(x, steps)
                back = self.interpolate(self.padded, c, f[0], f[1], f[2], True)[0]
                corrected = self.hat[c, i, j, k] + 0.5 * (self.q[c, i, j, k] - back)
                self.out[c, i, j, k] = ti.min(ti.max(corrected, self.lo[c, i, j, k]), self.hi[c, i, j, k])

    @ti.kernel
    def advect_dye_back(self, steps: ti.f64):
        for i, j, k in self.dye:
            b = self.trace(ti.Vector([i + 0.5, j + 0.5, k + 0.5]), -steps)
            r = self.interpolate(self.dye_padded, 0, b[0], b[1], b[2], False)
            self.dye_hat[i, j, k] = r[0]
            self.dye_lo[i, j, k] = r[1]
            self.dye_hi[i, j, k] = r[2]

    @ti.kernel
    def advect_dye_forth(self, steps: ti.f64):
        for i, j, k in self.dye:
            f = self.trace(ti.Vector([i + 0.5, j + 0.5, k + 0.5]), steps)
            back = self.interpolate(self.dye_padded, 0, f[0], f[1], f[2], False)[0]
            corrected = self.dye_hat[i, j, k] + 0.5 * (self.dye[i, j, k] - back)
            self.dye_out[i, j, k] = ti.min(ti.max(corrected, self.dye_lo[i, j, k]), self.dye_hi[i, j, k])

    @ti.kernel
    def copy_faces(self, dst: ti.template(), src: ti.template()):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            dst[c, i, j, k] = src[c, i, j, k]

    @ti.kernel
    def copy_cells(self, dst: ti.template(), src: ti.template()):
        for i, j, k in src:
            dst[i, j, k] = src[i, j, k]

    # --- viscosity ---------------------------------------------------------------------------------------------
    @ti.func
    def laplacian(self, f: ti.template(), c, i, j, k, moving: ti.template()):
        here = f[c, i, j, k]
        total = (self.face(f, c, i - 1, j, k, moving) + self.face(f, c, i + 1, j, k, moving)
                 + self.face(f, c, i, j - 1, k, moving) + self.face(f, c, i, j + 1, k, moving) - 4.0 * here)
        if ti.static(self.nz > 1):
            total += self.face(f, c, i, j, k - 1, moving) + self.face(f, c, i, j, k + 1, moving) - 2.0 * here
        return total

    @ti.kernel
    def viscous_start(self, a: ti.f64) -> ti.types.vector(2, ti.f64):
        """r = s = a L(q) (walls moving), d = 0; returns (r.r, max |r|)."""
        rr = 0.0
        worst = 0.0
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            idx = ti.Vector([i, j, k])
            value = 0.0
            if idx[c] != 0:
                value = a * self.laplacian(self.q, c, i, j, k, True)
            self.vr[c, i, j, k] = value
            self.vs[c, i, j, k] = value
            self.vd[c, i, j, k] = 0.0
            rr += value * value
            ti.atomic_max(worst, ti.abs(value))
        return ti.Vector([rr, worst])

    @ti.kernel
    def viscous_apply(self, a: ti.f64) -> ti.f64:
        """As = (I - a L0) s; returns s.As."""
        total = 0.0
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            idx = ti.Vector([i, j, k])
            value = 0.0
            if idx[c] != 0:
                value = self.vs[c, i, j, k] - a * self.laplacian(self.vs, c, i, j, k, False)
            self.vas[c, i, j, k] = value
            total += value * self.vs[c, i, j, k]
        return total

    @ti.kernel
    def viscous_update(self, alpha: ti.f64) -> ti.types.vector(2, ti.f64):
        rr = 0.0
        worst = 0.0
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            self.vd[c, i, j, k] += alpha * self.vs[c, i, j, k]
            r = self.vr[c, i, j, k] - alpha * self.vas[c, i, j, k]
            self.vr[c, i, j, k] = r
            rr += r * r
            ti.atomic_max(worst, ti.abs(r))
        return ti.Vector([rr, worst])

    @ti.kernel
    def viscous_direction(self, beta: ti.f64):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            self.vs[c, i, j, k] = self.vr[c, i, j, k] + beta * self.vs[c, i, j, k]

    @ti.kernel
    def add_correction(self):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            self.q[c, i, j, k] += self.vd[c, i, j, k]

    @ti.kernel
    def largest_speed(self) -> ti.f64:
        worst = 0.0
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            ti.atomic_max(worst, ti.abs(self.q[c, i, j, k]))
        return worst

    def diffuse(self, dt):
        a = self.nu * dt / self.h ** 2
        rr, worst = self.viscous_start(a)
        limit = 1e-8 * max(self.largest_speed(), abs(self.lid), 1e-30)
        iterations = 0
        while iterations < 500 and worst > limit:
            curvature = self.viscous_apply(a)
            if curvature <= 0.0:
                break
            rr_new, worst = self.viscous_update(rr / curvature)
            self.viscous_direction(rr_new / rr)
            rr = rr_new
            iterations += 1
        self.add_correction()
        return iterations

    # --- pressure ----------------------------------------------------------------------------------------------
    @ti.func
    def neighbours(self, i, j, k):
        count = 0.0
        if i > 0:
            count += 1.0
        if i < self.nx - 1:
            count += 1.0
        if j > 0:
            count += 1.0
        if j < self.ny - 1:
            count += 1.0
        if ti.static(self.nz > 1):
            if k > 0:
                count += 1.0
            if k < self.nz - 1:
                count += 1.0
        return count

    @ti.func
    def apply_A(self, f: ti.template(), i, j, k):
        """(A f)_cell: the sum over the cell's free faces of f_cell - f_neighbour."""
        here = f[i, j, k]
        total = 0.0
        if i > 0:
            total += here - f[i - 1, j, k]
        if i < self.nx - 1:
            total += here - f[i + 1, j, k]
        if j > 0:
            total += here - f[i, j - 1, k]
        if j < self.ny - 1:
            total += here - f[i, j + 1, k]
        if ti.static(self.nz > 1):
            if k > 0:
                total += here - f[i, j, k - 1]
            if k < self.nz - 1:
                total += here - f[i, j, k + 1]
        return total

    @ti.func
    def divergence_at(self, i, j, k):
        """The net outflow of cell (i, j, k) times h (m/s)."""
        total = (self.face(self.q, 0, i + 1, j, k, True) - self.q[0, i, j, k]
                 + self.face(self.q, 1, i, j + 1, k, True) - self.q[1, i, j, k])
        if ti.static(self.dims == 3):
            total += self.face(self.q, 2, i, j, k + 1, True) - self.q[2, i, j, k]
        return total

    @ti.kernel
    def pressure_rhs(self, scale: ti.f64) -> ti.f64:
        """z = -rho h^2 div / dt (scale = -rho h / dt); returns its sum."""
        total = 0.0
        for i, j, k in self.z:
            b = scale * self.divergence_at(i, j, k)
            self.z[i, j, k] = b
            total += b
        return total

    @ti.kernel
    def pressure_start(self, mean: ti.f64) -> ti.types.vector(2, ti.f64):
        """r = b - mean - A p, s = z = r / diag; returns (z.r, max |r|)."""
        zr = 0.0
        worst = 0.0
        for i, j, k in self.p:
            r = self.z[i, j, k] - mean - self.apply_A(self.p, i, j, k)
            self.r[i, j, k] = r
            zz = r / self.neighbours(i, j, k)
            self.s[i, j, k] = zz
            zr += zz * r
            ti.atomic_max(worst, ti.abs(r))
        return ti.Vector([zr, worst])

    @ti.kernel
    def pressure_apply(self) -> ti.f64:
        total = 0.0
        for i, j, k in self.s:
            value = self.apply_A(self.s, i, j, k)
            self.As[i, j, k] = value
            total += value * self.s[i, j, k]
        return total

    @ti.kernel
    def pressure_update(self, alpha: ti.f64) -> ti.types.vector(2, ti.f64):
        zr = 0.0
        worst = 0.0
        for i, j, k in self.p:
            self.p[i, j, k] += alpha * self.s[i, j, k]
            r = self.r[i, j, k] - alpha * self.As[i, j, k]
            self.r[i, j, k] = r
            zz = r / self.neighbours(i, j, k)
            self.z[i, j, k] = zz
            zr += zz * r
            ti.atomic_max(worst, ti.abs(r))
        return ti.Vector([zr, worst])

    @ti.kernel
    def pressure_direction(self, beta: ti.f64):
        for i, j, k in self.s:
            self.s[i, j, k] = self.z[i, j, k] + beta * self.s[i, j, k]

    @ti.kernel
    def subtract_gradient(self, scale: ti.f64):
        for c, i, j, k in ti.ndrange(self.dims, self.nx, self.ny, self.nz):
            idx = ti.Vector([i, j, k])
            if idx[c] > 0:
                below = idx
                below[c] -= 1
                self.q[c, i, j, k] -= scale * (self.p[i, j, k] - self.p[below[0], below[1], below[2]])

    @ti.kernel
    def max_divergence(self) -> ti.f64:
        worst = 0.0
        for i, j, k in self.p:
            ti.atomic_max(worst, ti.abs(self.divergence_at(i, j, k)))
        return worst / self.h

    def project(self, dt):
        h, rho = self.h, self.rho
        total = self.pressure_rhs(-rho * h / dt)
        zr, worst = self.pressure_start(total / (self.nx * self.ny * self.nz))
        limit = self.tol * rho * h * h / (dt * dt)
        iterations = 0
        while worst > limit and iterations < self.max_iterations:
            alpha = zr / self.pressure_apply()
            zr_new, worst = self.pressure_update(alpha)
            iterations += 1
            if worst <= limit:
                break
            self.pressure_direction(zr_new / zr)
            zr = zr_new
        self.subtract_gradient(dt / (rho * h))
        return iterations

    # --- the step ----------------------------------------------------------------------------------------------
    def step(self, dt):
        steps = dt / self.h
        self.pad_faces(self.q, self.flow)
        self.pad_cells(self.dye, self.dye_padded)
        self.advect_dye_back(steps)
        self.pad_cells(self.dye_hat, self.dye_padded)
        self.advect_dye_forth(steps)
        self.advect_faces_back(steps)
        self.pad_faces(self.hat, self.padded)
        self.advect_faces_forth(steps)
        self.copy_cells(self.dye, self.dye_out)
        self.copy_faces(self.q, self.out)
        if self.nu > 0.0:
            self.viscosity_iterations = self.diffuse(dt)
        self.pressure_iterations = self.project(dt)

    # --- state as NumPy arrays (outside the timed steps) -------------------------------------------------------
    def faces(self):
        """The face velocities, (3, nx, ny, nz) m/s, as Marbellous stores them."""
        return self.q.to_numpy()

    def set_faces(self, q):
        self.q.from_numpy(np.ascontiguousarray(q, dtype=np.float64))

    def get_dye(self):
        return self.dye.to_numpy()

    def set_dye(self, d):
        self.dye.from_numpy(np.ascontiguousarray(d, dtype=np.float64))
