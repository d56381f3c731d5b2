"""Stiff cloth at 60 Hz: explicit Euler, backward Euler and XPBD on the same mass-spring sheet, measured.

The scene: a square sheet of ``n`` x ``n`` particles (n = 20 and 40; ``--quick``: 20 only), 1 m x 1 m,
0.5 kg in all (equal masses ``m = 0.5 / n^2``), in the horizontal plane y = 0 at the start (x, z in
[0, 1]), at rest; pinned at two adjacent corners, (0, 0, 0) and (1, 0, 0); gravity 9.81 m/s^2 along -y;
hanging for 300 steps of ``dt = 1/60`` s (5 s).  Springs of one stiffness ``k`` (N/m; k = 1e2, 1e3, 1e4,
1e5, 1e6; ``--quick``: 1e2, 1e4, 1e6), no damping anywhere: structural (each particle to its neighbours
along x and z, rest length ``L = 1 / (n - 1)``) and shear (the two diagonals of each square, ``L sqrt 2``);
no bending springs, no collisions.  A spring pulls its ends together with ``k (l - l0)`` along the edge.

The integrators (all vectorised NumPy / SciPy, the same forces, the same pins):
- ``explicit``: semi-implicit (symplectic) Euler at ``h = dt``: ``v += h f(x) / m``, then ``x += h v``;
  pinned particles never move;
- ``explicit-16``: the same in 16 sub-steps of ``h = dt / 16`` per step;
- ``implicit``: backward Euler as Baraff and Witkin (1998): one linearised Newton step per step,
  ``(M + h^2 K) dv = h (f(x) - h K v)``, then ``v += dv``, ``x += h v``, with ``K = -df/dx`` the springs'
  full stiffness matrix, the transverse term included but clamped at compression (per spring
  ``k [n n^T + max(0, 1 - l0/l) (I - n n^T)]``, so that ``M + h^2 K`` stays positive definite), assembled
  sparse, the pinned coordinates eliminated (the rows and columns of the free ones kept), solved directly
  with ``scipy.sparse.linalg.spsolve`` (SuperLU);
- ``xpbd-16x1``: extended position-based dynamics as the engine steps particle networks
  (``marbellous/deformables``): 16 sub-steps of ``h = dt / 16``, each a prediction ``v += h g``,
  ``x_prev = x``, ``x += h v``, one Gauss-Seidel pass over the springs as compliant distance constraints
  (compliance ``alpha = 1 / k``, ``alpha~ = alpha / h^2``, ``dlambda = (-C - alpha~ lambda) / (w_a + w_b +
  alpha~)``), then ``v = (x - x_prev) / h``.  The pass goes through the springs in 8 colours (no two
  springs of a colour share a particle, so each colour is one exact vectorised Gauss-Seidel update; the
  engine goes through the edges one by one in their order);
- ``xpbd-1x16``: the same with one step of ``h = dt`` and 16 passes (iterations, ``lambda`` accumulated).

Measured for each (integrator, n, k), the timed part being the steps only (one run; the machine is shared):
- stable, or blew up and when: a run blows up at the first step that ends with a non-finite coordinate or
  with its kinetic and gravitational energy above the start's by more than ``BLOWN`` J (the springs' energy is
  >= 0 and nothing adds energy, so this sum stays <= 0 unless the integrator makes energy; the springs'
  energy is left out because an integrator may stretch them more than their k allows, section below, without
  blowing up; the run stops there);
- the largest and the mean edge strain ``l / l0 - 1`` at the end, beside the sheet's static strain: the
  strain at rest found by minimising the potential energy (gravity plus springs) by damped Newton steps, and
  the order of magnitude ``W / k`` (``W = 0.5 g``, the sheet's weight: a column of the sheet carries its
  share ``W / n`` with springs ``k`` of length ``1 / n``); more than the static strain at the end is the
  swing's, or the integrator's softness;
- the energy lost to numerical damping: ``E = kinetic + m g y + sum k (l - l0)^2 / 2`` (0 at the start) after
  1 s and at the end, as the share of the potential energy released by then that is missing,
  ``-E(t) / (m g y(0) - m g y(t))`` (0: conserved; 1: all lost, the sheet at rest; below 0: the springs are
  stretched more than the released energy could stretch springs of stiffness k, i.e. the integrator's springs
  are softer than k); and, free of the springs' energy, the sheet's mean kinetic energy over the last second
  as a share of the potential energy released at the end ("moving": how much swing is left);
- ms per step;
- Lambert's measure of stiffness: ``h omega_max``, the step (or sub-step) ``h`` times the largest magnitude of
  an eigenvalue of the Jacobian of ``(x, v)' = (v, M^-1 f)``, ``omega_max = sqrt(lambda_max(M^-1 K))`` (K at
  rest, flat; eigsh), against 2, the stability limit of symplectic Euler; and ``h sqrt(k / m)`` for one spring.
  Then, per n, a check of that limit: each explicit integrator run at 0.8 and 1.25 times the stiffness at which
  ``h omega_max = 2``.

The static strains come from ``Sheet.static``, continued from each k's rest shape to the next k's (its residual,
the largest net force on a particle over that particle's weight, is in the JSON).  The NumPy XPBD here was
checked against the engine's (``World.add_particles``, ``add_network(kind="spring")``, its 16 sub-steps) on
n = 20: largest strain at the end 0.199 both at k = 1e2, 0.0426 both at k = 1e4.

    python bench/bench_cloth_integrators.py [--quick] [--json FILE]

A full run writes ``bench/results/2026-12-03-vm-cloth-integrators.json`` unless ``--json`` names another file;
a ``--quick`` run writes only where ``--json`` says.
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
import scipy
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh, spsolve

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

from bench.machine import describe  # noqa: E402

DT = 1.0 / 60.0
STEPS = 300                 # 5 s
G = 9.81
SIZE = 1.0                  # side of the sheet (m)
MASS = 0.5                  # the sheet's mass (kg)
SUBSTEPS = 16
PASSES = 16
BLOWN = 1.0                 # energy above the start (J) that counts as blown up
ONE_SECOND = 60             # steps
DEFAULT_JSON = os.path.join(HERE, "results", "2026-12-03-vm-cloth-integrators.json")


# --- the sheet -------------------------------------------------------------------------------------------------
class Sheet:
    """The particles, springs and pins of an ``n`` x ``n`` sheet of stiffness ``k`` (module docstring)."""

    def __init__(self, n, k):
        self.n, self.k = n, k
        spacing = SIZE / (n - 1)
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")      # particle i * n + j at (i L, 0, j L)
        self.x0 = np.column_stack([spacing * i.ravel(), np.zeros(n * n), spacing * j.ravel()])
        self.m = MASS / (n * n)
        idx = lambda a, b: (a * n + b).ravel()
        colours = []
        for parity in (0, 1):
            ii, jj = np.meshgrid(np.arange(parity, n - 1, 2), np.arange(n), indexing="ij")        # along x
            colours.append((idx(ii, jj), idx(ii + 1, jj)))
            ii, jj = np.meshgrid(np.arange(n), np.arange(parity, n - 1, 2), indexing="ij")        # along z
            colours.append((idx(ii, jj), idx(ii, jj + 1)))
            ii, jj = np.meshgrid(np.arange(parity, n - 1, 2), np.arange(n - 1), indexing="ij")    # diagonals
            colours.append((idx(ii, jj), idx(ii + 1, jj + 1)))
            colours.append((idx(ii + 1, jj), idx(ii, jj + 1)))
        self.colours = []
        start = 0
        for a, b in colours:
            assert len(np.unique(np.concatenate([a, b]))) == 2 * len(a), "a colour's springs share a particle"
            self.colours.append(slice(start, start + len(a)))
            start += len(a)
        self.a = np.concatenate([c[0] for c in colours])
        self.b = np.concatenate([c[1] for c in colours])
        self.rest = np.linalg.norm(self.x0[self.a] - self.x0[self.b], axis=1)
        pinned = np.zeros(n * n, bool)
        pinned[[0, (n - 1) * n]] = True                                   # (0, 0, 0) and (1, 0, 0)
        self.pinned = pinned
        self.w = np.where(pinned, 0.0, 1.0 / self.m)                      # inverse masses
        self.free_dof = np.repeat(~pinned, 3)
        e = len(self.a)
        rows = np.concatenate([np.arange(e), np.arange(e)])
        self.incidence = sp.csr_matrix((np.concatenate([np.ones(e), -np.ones(e)]),
                                        (rows, np.concatenate([self.a, self.b]))), shape=(e, n * n))
        self.incidence_t = self.incidence.T.tocsr()

    def forces(self, x):
        """The forces on the particles (N, ``(n^2, 3)``): gravity and the springs."""
        d = x[self.a] - x[self.b]
        length = np.linalg.norm(d, axis=1)
        t = self.k * (length - self.rest) / length
        f = -(self.incidence_t @ (t[:, None] * d))
        f[:, 1] -= self.m * G
        return f

    def potential(self, x):
        """Gravity's and the springs' energy (J), 0 in the flat sheet at rest."""
        stretch = np.linalg.norm(x[self.a] - x[self.b], axis=1) - self.rest
        return self.m * G * float(np.sum(x[:, 1])) + 0.5 * self.k * float(stretch @ stretch)

    def energy(self, x, v):
        """Kinetic plus potential energy (J) at positions ``x`` and velocities ``v``."""
        return 0.5 * self.m * float(np.sum(v * v)) + self.potential(x)

    def strains(self, x):
        """Each spring's strain ``|d| / L - 1`` at positions ``x``."""
        return np.linalg.norm(x[self.a] - x[self.b], axis=1) / self.rest - 1.0

    def stiffness(self, x):
        """``K = -df/dx`` (sparse ``3 n^2`` square), the transverse term clamped at compression."""
        d = x[self.a] - x[self.b]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        c = np.maximum(0.0, 1.0 - self.rest / length)
        outer = u[:, :, None] * u[:, None, :]
        block = self.k * (outer + c[:, None, None] * (np.eye(3) - outer))           # (e, 3, 3)
        ends = [(self.a, self.a, 1.0), (self.b, self.b, 1.0), (self.a, self.b, -1.0), (self.b, self.a, -1.0)]
        r3 = np.arange(3)
        rows, cols, vals = [], [], []
        for p, q, s in ends:
            shape = (p.size, 3, 3)
            rows.append(np.broadcast_to(3 * p[:, None, None] + r3[None, :, None], shape))
            cols.append(np.broadcast_to(3 * q[:, None, None] + r3[None, None, :], shape))
            vals.append(s * block)
        size = 3 * self.n * self.n
        return sp.csr_matrix((np.concatenate(vals).ravel(), (np.concatenate(rows).ravel(),
                                                              np.concatenate(cols).ravel())), shape=(size, size))

    def omega_max(self):
        """The largest angular frequency (rad/s) of the flat sheet at rest, ``sqrt(lambda_max(M^-1 K))``."""
        k = self.stiffness(self.x0)[self.free_dof][:, self.free_dof] / self.m
        return math.sqrt(float(eigsh(k, k=1, which="LA", return_eigenvectors=False)[0]))

    def static(self, start=None, iterations=400):
        """The sheet at rest: the potential energy minimised by Newton steps damped by ``M / h^2`` (the step
        ``h`` grown while the energy falls, shrunk when it would rise), from ``start`` (the sheet at rest with
        softer springs; the flat sheet when None) until no particle's net force exceeds 1e-6 of its weight, or
        for ``iterations`` steps; ``(positions, largest net force on a particle / its weight)``."""
        x = (self.x0 if start is None else start).copy()
        free = self.free_dof
        mass = sp.identity(int(free.sum()), format="csr") * self.m
        h, energy = 0.02, self.potential(x)
        weight = self.m * G
        for _ in range(iterations):
            f = self.forces(x)
            f[self.pinned] = 0.0
            residual = float(np.max(np.abs(f))) / weight
            if residual < 1e-6:
                return x, residual
            k = self.stiffness(x)[free][:, free]
            dx = spsolve((mass / (h * h) + k).tocsc(), f.ravel()[free])
            trial = x.copy()
            trial.ravel()[free] += dx
            e = self.potential(trial)
            if np.all(np.isfinite(trial)) and e <= energy:
                x, energy, h = trial, e, min(h * 3.0, 1e4)
            else:
                h *= 0.2
        f = self.forces(x)
        f[self.pinned] = 0.0
        return x, float(np.max(np.abs(f))) / weight


# --- the integrators: each advances ``(x, v)`` in place by one step of DT --------------------------------------
def explicit(sheet, substeps):
    h = DT / substeps
    moving = ~sheet.pinned

    def step(x, v):
        for _ in range(substeps):
            v[moving] += (h / sheet.m) * sheet.forces(x)[moving]
            x += h * v
    return step


def implicit(sheet):
    h = DT
    free = sheet.free_dof
    mass = sp.identity(int(free.sum()), format="csr") * sheet.m

    def step(x, v):
        k = sheet.stiffness(x)[free][:, free]
        vf = v.ravel()[free]
        rhs = h * (sheet.forces(x).ravel()[free] - h * (k @ vf))
        v.ravel()[free] += spsolve((mass + (h * h) * k).tocsc(), rhs)
        x += h * v
    return step


def xpbd(sheet, substeps, passes):
    h = DT / substeps
    alpha = 1.0 / (sheet.k * h * h)
    a, b, rest, w = sheet.a, sheet.b, sheet.rest, sheet.w
    lam = np.zeros(len(a))
    gravity = np.where(sheet.pinned, 0.0, -G * h)

    def step(x, v):
        for _ in range(substeps):
            v[:, 1] += gravity
            prev = x.copy()
            x += h * v
            lam[:] = 0.0
            for _ in range(passes):
                for c in sheet.colours:
                    ca, cb = a[c], b[c]
                    d = x[ca] - x[cb]
                    length = np.linalg.norm(d, axis=1)
                    n = d / length[:, None]
                    wa, wb = w[ca], w[cb]
                    dl = (-(length - rest[c]) - alpha * lam[c]) / (wa + wb + alpha)
                    lam[c] += dl
                    x[ca] += (wa * dl)[:, None] * n
                    x[cb] -= (wb * dl)[:, None] * n
            v[:] = (x - prev) / h
    return step


INTEGRATORS = {
    "explicit": (lambda s: explicit(s, 1), DT),
    "explicit-16": (lambda s: explicit(s, SUBSTEPS), DT / SUBSTEPS),
    "implicit": (implicit, DT),
    "xpbd-16x1": (lambda s: xpbd(s, SUBSTEPS, 1), DT / SUBSTEPS),
    "xpbd-1x16": (lambda s: xpbd(s, 1, PASSES), DT),
}


def run(sheet, name):
    """One run of 300 steps of integrator ``name``: a dict of the measures (module docstring)."""
    step = INTEGRATORS[name][0](sheet)
    x, v = sheet.x0.copy(), np.zeros_like(sheet.x0)
    seconds, blew_up, lost, late = 0.0, None, {}, []
    for s in range(1, STEPS + 1):
        t = time.perf_counter()
        with np.errstate(all="ignore"):
            step(x, v)
        seconds += time.perf_counter() - t
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            blew_up = s * DT
            break
        kinetic = 0.5 * sheet.m * float(np.sum(v * v))
        if kinetic + sheet.m * G * float(np.sum(x[:, 1])) > BLOWN:
            blew_up = s * DT
            break
        if s > STEPS - ONE_SECOND:
            late.append(kinetic)
        if s in (ONE_SECOND, STEPS):
            e = sheet.energy(x, v)
            released = -sheet.m * G * float(np.sum(x[:, 1]))
            lost["1s" if s == ONE_SECOND else "end"] = -e / released
    r = {"ms_per_step": 1e3 * seconds / s, "stable": blew_up is None}
    if blew_up is not None:
        r["blew_up_at_s"] = round(blew_up, 4)
        return r
    strain = sheet.strains(x)
    r.update({"max_strain": float(strain.max()), "mean_strain": float(strain.mean()),
              "energy_lost_1s": lost["1s"], "energy_lost_end": lost["end"],
              "moving_last_s": float(np.mean(late)) / released, "lowest_y_m": float(x[:, 1].min())})
    return r


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n = 20 only, k = 1e2, 1e4, 1e6")
    parser.add_argument("--json", default=None, help="write the results to this file (a full run: by default "
                        "bench/results/2026-12-03-vm-cloth-integrators.json)")
    args = parser.parse_args()
    sizes = (20,) if args.quick else (20, 40)
    stiffnesses = (1e2, 1e4, 1e6) if args.quick else (1e2, 1e3, 1e4, 1e5, 1e6)
    weight = MASS * G
    results, lambert = [], []
    print(f"sheet 1 m x 1 m, {MASS} kg, pinned at two adjacent corners, structural + shear springs, released "
          f"flat, {STEPS} steps at 60 Hz; strain l/l0 - 1; energy lost: share of the released energy missing")
    print(f"{'n':>3s} {'k N/m':>7s} {'W/k':>8s} {'static max/mean':>17s} {'integrator':12s} {'h w_max':>8s} "
          f"{'h sqrt(k/m)':>11s} {'ms/step':>8s} {'result':>14s} {'max strain':>10s} {'mean strain':>11s} "
          f"{'lost 1 s':>8s} {'lost 5 s':>8s} {'moving':>7s}")
    for n in sizes:
        omega1 = Sheet(n, 1.0).omega_max()                     # omega_max grows as sqrt(k)
        rest = None
        for k in stiffnesses:
            sheet = Sheet(n, k)
            rest, residual = sheet.static(rest)
            static = sheet.strains(rest)
            case = {"n": n, "k": k, "particle_mass_kg": sheet.m, "springs": len(sheet.a),
                    "weight_over_k": weight / k, "static_max_strain": float(static.max()),
                    "static_mean_strain": float(static.mean()), "static_residual": residual,
                    "omega_max_rad_s": omega1 * math.sqrt(k), "integrators": {}}
            for name, (_, h) in INTEGRATORS.items():
                r = run(sheet, name)
                r["h_s"] = h
                r["h_omega_max"] = h * omega1 * math.sqrt(k)
                r["h_sqrt_k_over_m"] = h * math.sqrt(k / sheet.m)
                case["integrators"][name] = r
                outcome = "stable" if r["stable"] else f"blew up {r['blew_up_at_s']:.2f} s"
                tail = ""
                if r["stable"]:
                    tail = (f"{r['max_strain']:10.2e} {r['mean_strain']:11.2e} {r['energy_lost_1s']:8.3f} "
                            f"{r['energy_lost_end']:8.3f} {r['moving_last_s']:7.3f}")
                print(f"{n:3d} {k:7.0e} {weight / k:8.1e} {static.max():8.1e}/{static.mean():8.1e} {name:12s} "
                      f"{r['h_omega_max']:8.3g} {r['h_sqrt_k_over_m']:11.3g} {r['ms_per_step']:8.2f} "
                      f"{outcome:>14s} {tail}", flush=True)
            results.append(case)
        for name, (_, h) in INTEGRATORS.items():
            if not name.startswith("explicit"):
                continue
            limit = (2.0 / (h * omega1)) ** 2                 # h omega_max = 2
            for factor in (0.8, 1.25):
                r = run(Sheet(n, factor * limit), name)
                check = {"n": n, "integrator": name, "k_limit": limit, "k": factor * limit,
                         "h_omega_max": 2.0 * math.sqrt(factor), "stable": r["stable"],
                         "blew_up_at_s": r.get("blew_up_at_s")}
                lambert.append(check)
                print(f"Lambert: n = {n} {name:12s} stable while h w_max < 2, k < {limit:7.4g} N/m; at "
                      f"k = {factor * limit:7.4g} (h w_max {check['h_omega_max']:.2f}): "
                      f"{'stable' if r['stable'] else 'blew up at ' + format(r['blew_up_at_s'], '.2f') + ' s'}",
                      flush=True)
    out = args.json or (None if args.quick else DEFAULT_JSON)
    if out is None:
        return
    machine = describe(ROOT, {"scipy": scipy.__version__})
    with open(out, "w") as f:
        json.dump({"benchmark": "cloth-integrators", "machine": machine, "quick": args.quick, "dt": DT,
                   "steps": STEPS, "gravity": G, "size_m": SIZE, "mass_kg": MASS, "substeps": SUBSTEPS,
                   "passes": PASSES, "blown_up_above_j": BLOWN, "results": results,
                   "lambert_check": lambert}, f, indent=1)
    print(f"wrote {os.path.relpath(out)}")


if __name__ == "__main__":
    main()
