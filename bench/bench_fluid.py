"""Grid fluids, side by side with PhiFlow, Taichi and Warp: a lid-driven cavity (2D) and a smoke jet (3D).

Units: SI throughout (m, s, m/s; density 1 kg/m^3); times are milliseconds per ``step(dt)`` call, the mean over the
timed steps of a run, the best of ``--repeats`` runs; divergences are reported as ``max |div u| dt``, the largest
fraction of its volume any cell gains or loses over a step (Marbellous' ``Fluid.tolerance``, 1e-6 here).  Every
engine runs in float64 on the CPU, in one process, engine after engine.  The scenes:

- ``cavity_128``: the 2D lid-driven cavity, 128 x 128 cells in the unit square (h = 1/128 m), no-slip walls, the lid
  (y = 1) sliding at 1 m/s along x, kinematic viscosity 0.01 m^2/s (Re = 100), dt = 1/128 s; the fluid starts at
  rest, and after an untimed first step (compilation) and 199 more untimed steps (t = 1.56 s, the main vortex
  formed) 50 steps are timed.  No dye (Marbellous skips a fluid's dye while it is all zero; the peers are told
  there is none).
- ``smoke_64``: 3D smoke, 64^3 cells in the unit cube (h = 1/64 m), walls all round, inviscid (viscosity 0, no
  viscosity solve), dt = 1/64 s.  A jet: before every step (untimed) the dye is set to 1 in the cells whose centres
  lie in a ball of radius 0.08 m around (0.5, 0.15, 0.5) m and the faces of the vertical velocity whose centres
  lie in it to 1 m/s (a CFL number of 1 there), the other faces kept.  Every engine's body force is zero: the jet
  stands for the buoyancy, which Marbellous cannot apply per cell (its ``body_force`` is uniform), so that every
  engine does the same work a step: advect the dye and the velocity, project.  An untimed first step and 19 more
  untimed steps, then 10 timed.
- ``--quick``: ``cavity_64`` (64 x 64, dt = 1/64 s, 50 untimed and 20 timed steps) and ``smoke_32`` (32^3, dt =
  1/32 s, 5 untimed and 5 timed steps).

The engines (the peers' solvers are described fully in their files, ``bench/peers/*_fluid.py``):

- ``marbellous``: ``mb.Fluid(resolution, h, viscosity=nu, density=1.0, boundary="wall")``, the lid by
  ``set_wall_velocity("y+", (1, 0))``, the jet by ``set_velocity`` and ``dye``; ``step(dt)``: MacCormack advection of
  the dye and the velocity (midpoint-rule traces, clamped), backward-Euler viscosity by conjugate gradients, the
  projection by MIC(0)-preconditioned conjugate gradients to ``max |div u| dt <= 1e-6``.  Serial Numba kernels
  (one thread), compiled on first use and cached on disk.
- ``taichi`` (Taichi 1.7.4, ``ti.init(arch=ti.cpu, default_fp=ti.f64)``): a MAC-grid solver written for this
  bench in Taichi kernels (``bench/peers/taichi_fluid.py``), the same scheme as Marbellous (MacCormack with
  midpoint traces and the clamp, the same ghost values at the walls, backward-Euler viscosity by CG to 1e-8 of
  the largest speed) except the pressure solve: conjugate gradients with a Jacobi (diagonal) preconditioner
  (which parallelises; MIC(0) is a serial triangular solve), warm-started from the last step's pressure, to the
  same ``max |div u| dt <= 1e-6``.  Taichi runs each kernel on all the CPU's cores (2 here).
- ``warp`` (Warp 1.19.0, device ``"cpu"``): the same solver in Warp kernels (``bench/peers/warp_fluid.py``),
  float64; Warp runs a CPU kernel on one thread.  (Warp's own ``examples/core/example_fluid.py`` is a 2D
  collocated grid with semi-Lagrangian advection and a fixed number of Jacobi iterations in float32: not the
  same work, so not used.)
- ``phiflow`` (PhiFlow 3.4.0, NumPy backend, ``math.set_global_precision(64)``; ``bench/peers/phiflow_fluid.py``):
  ``StaggeredGrid`` velocity, ``advect.mac_cormack`` with midpoint traces for the dye and the velocity, except the
  cavity's velocity, which is advected by ``advect.semi_lagrangian`` (``mac_cormack`` fails on a grid with a moving
  wall in 3.4.0); the cavity's viscosity by ``math.solve_linear`` (CG) per component (``diffuse.implicit`` fails on
  a walled ``StaggeredGrid`` in 3.4.0); ``fluid.make_incompressible`` with ``Solve('CG', rel_tol=0,
  abs_tol=1e-6 / dt)``, unpreconditioned, from a zero pressure, stopping on the residual's L2 norm (stricter than
  the largest cell's: its divergence ends lower, and it iterates more).  One thread.

Reported per scene and engine: ms per step (best of the runs; ``runs``), the slowest timed step (ms), the setup (s),
the untimed first step (s, the compilation), the pressure solve's iterations (the mean over the timed steps; for
Marbellous its MIC(0)-PCG, for Taichi and Warp their Jacobi-PCG, for PhiFlow its CG) and the viscosity solve's (the
cavity), ``max |div u| dt`` after the last step (each engine's own discrete divergence), the largest face speed
(m/s) and the kinetic energy (J; per metre of depth in 2D); the cavity's smallest u on the vertical centreline
x = 0.5 (m/s; Ghia et al.'s steady value at Re = 100 is -0.21, reached later than t = 1.95 s), the smoke's total dye
(m^3 of dye at 1) and its centre's height (m).  A run whose velocity is not finite or faster than 100 m/s at the end
of the untimed steps or of the run is reported as blown up; a run slower than ``cap_s`` a step (2 s for the cavity,
5 s for the smoke) over its first 3 or more steps after the first is stopped and reported as capped; after a run
longer than 60 s an engine's other repeats are left out.  An engine that is not installed is reported as such.

    python bench/bench_fluid.py [--quick] [--repeats N] [--json FILE] [--engines marbellous,taichi,warp,phiflow]

``--engines`` runs only the engines named (default: all of them).
"""
import json
import math
import os
import sys
import time
from importlib import metadata

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

import marbellous as mb  # noqa: E402
from bench.machine import describe  # noqa: E402
from bench.peers.timing import BlewUp, Capped, NotAvailable, bench_arguments, best_of  # noqa: E402

DENSITY = 1.0               # (kg/m^3)
TOLERANCE = 1e-6            # max |div u| dt after the projection
JET_CENTRE = np.array([0.5, 0.15, 0.5])     # the smoke's source ball (m)
JET_RADIUS = 0.08           # (m)
JET_SPEED = 1.0             # upward, in the ball (m/s)

SCENES = {
    "cavity_128": {"cells": (128, 128, 1), "nu": 0.01, "lid": 1.0, "warmup": 200, "steps": 50, "cap_s": 2.0},
    "smoke_64": {"cells": (64, 64, 64), "nu": 0.0, "lid": 0.0, "warmup": 20, "steps": 10, "cap_s": 5.0},
}
QUICK_SCENES = {
    "cavity_64": {"cells": (64, 64, 1), "nu": 0.01, "lid": 1.0, "warmup": 50, "steps": 20, "cap_s": 2.0},
    "smoke_32": {"cells": (32, 32, 32), "nu": 0.0, "lid": 0.0, "warmup": 5, "steps": 5, "cap_s": 5.0},
}
for _scene in (*SCENES.values(), *QUICK_SCENES.values()):
    _scene["h"] = 1.0 / _scene["cells"][0]          # the unit box
    _scene["dt"] = _scene["h"]                      # a CFL number of 1 at 1 m/s
    _scene["dims"] = 2 if _scene["cells"][2] == 1 else 3

MAX_SPEED = 100.0           # a face faster than this (m/s) means the run blew up
CAP_AFTER = 3               # a run is capped when its steps average over the scene's cap_s after this many steps
LONG_RUN_S = 60.0           # after a run this long (s), no more repeats of that engine in that scene
PEERS = {"phiflow": "phiflow", "taichi": "taichi", "warp": "warp-lang"}


# --- the scenes' fields, in Marbellous' face layout --------------------------------------------------------------
def face_centres(scene, c):
    """The centres (m) of the faces of velocity component ``c``: ``(3, nx, ny, nz)`` per axis, face ``(i, j, k)``
    being the lower face of cell ``(i, j, k)`` along ``c``."""
    n, h = scene["cells"], scene["h"]
    grids = np.meshgrid(*(np.arange(m, dtype=np.float64) for m in n), indexing="ij")
    return [(g + (0.0 if a == c else 0.5)) * h for a, g in enumerate(grids)]


def in_jet(x, y, z, scene):
    """Whether points are in the source ball (in 2D, z is ignored)."""
    r2 = (x - JET_CENTRE[0]) ** 2 + (y - JET_CENTRE[1]) ** 2
    if scene["dims"] == 3:
        r2 = r2 + (z - JET_CENTRE[2]) ** 2
    return r2 < JET_RADIUS ** 2


def jet_faces(scene):
    """The vertical faces whose centres are in the source ball: a mask (nx, ny, nz)."""
    return in_jet(*face_centres(scene, 1), scene)


def jet_cells(scene):
    """The cells whose centres are in the source ball: a mask (nx, ny, nz)."""
    n, h = scene["cells"], scene["h"]
    grids = np.meshgrid(*((np.arange(m) + 0.5) * h for m in n), indexing="ij")
    return in_jet(*grids, scene)


# --- the engines, behind one small interface ----------------------------------------------------------------------
class MarbellousRun:
    """``mb.Fluid`` with the peers' interface: faces and dye as (3, nx, ny, nz) and (nx, ny, nz) arrays."""

    threads = 1

    def __init__(self, scene):
        n, dims = scene["cells"], scene["dims"]
        self.dims = dims
        self.f = mb.Fluid(n[:dims], scene["h"], viscosity=scene["nu"], density=DENSITY, boundary="wall",
                          tolerance=TOLERANCE)
        if scene["lid"]:
            self.f.set_wall_velocity("y+", (scene["lid"], 0.0))

    def step(self, dt):
        self.f.step(dt)

    @property
    def pressure_iterations(self):
        return self.f.pressure_iterations

    @property
    def viscosity_iterations(self):
        return self.f.viscosity_iterations

    def max_divergence(self):
        return float(np.max(np.abs(self.f.divergence())))

    def faces(self):
        return np.array(self.f._q)              # (3, nx, ny, nz), read only for the measures

    def start_jet(self):
        """Set the vertical faces whose centres are in the source ball to the jet's speed, keeping every other face:
        ``set_velocity`` asks for each component at its faces' centres, where ``velocity_at`` reads the face's own
        value back."""
        h = self.f.cell_size

        def velocity(points):
            out = self.f.velocity_at(points)
            y = points[:, 1] / h
            on_y_faces = np.abs(y - np.round(y)) < 1e-6          # the vertical component's faces (y = j h)
            z = points[:, 2] if self.dims == 3 else 0.0
            out[:, 1] = np.where(on_y_faces & in_jet(points[:, 0], points[:, 1], z, {"dims": self.dims}), JET_SPEED,
                                 out[:, 1])
            return out

        self.f.set_velocity(velocity)

    def get_dye(self):
        d = self.f.dye
        return d[..., None] if self.dims == 2 else d

    def set_dye(self, d):
        self.f.dye = d[..., 0] if self.dims == 2 else d


def make_engine(name, scene):
    """A fluid of ``scene`` in engine ``name`` (ImportError when a peer is not installed)."""
    args = (scene["cells"], scene["h"], scene["nu"], DENSITY, TOLERANCE, scene["lid"])
    if name == "marbellous":
        if not hasattr(mb, "Fluid"):
            raise NotAvailable("not available: this Marbellous has no mb.Fluid")
        return MarbellousRun(scene)
    if name == "taichi":
        from bench.peers.taichi_fluid import TaichiFluid
        return TaichiFluid(*args)
    if name == "warp":
        from bench.peers.warp_fluid import WarpFluid
        return WarpFluid(*args)
    if name == "phiflow":
        from bench.peers.phiflow_fluid import PhiFlowFluid
        fluid = PhiFlowFluid(*args)
        fluid.record = True                     # iterations from PhiML's SolveTape (timed too: negligible)
        return fluid
    raise ValueError(f"unknown engine {name!r}")


def threads_of(name, fluid):
    return {"marbellous": 1, "warp": 1, "phiflow": 1}.get(name, getattr(fluid, "threads", None))


# --- one run ------------------------------------------------------------------------------------------------------
def make_run(name, scenes):
    """``run(scene name)``: one run of engine ``name``, a results dict."""

    def run(key):
        scene = scenes[key]
        start = time.perf_counter()
        fluid = make_engine(name, scene)
        smoke = scene["dims"] == 3
        if smoke:
            faces, cells = jet_faces(scene), jet_cells(scene)

            def inject():
                if name == "marbellous":
                    fluid.start_jet()
                else:
                    q = fluid.faces()
                    q[1][faces] = JET_SPEED
                    fluid.set_faces(q)
                fluid.set_dye(np.maximum(fluid.get_dye(), cells))
        else:
            def inject():
                pass
        setup = time.perf_counter() - start
        what = f"{name}'s {key}"
        dt = scene["dt"]

        def stepped(count, seconds, took):
            if count >= CAP_AFTER and seconds / count > scene["cap_s"]:
                raise Capped(f"capped: {what} took {seconds / count:.2f} s a step over its first {count} steps "
                             f"(slowest {took:.2f} s); stopped")

        inject()
        t = time.perf_counter()
        fluid.step(dt)
        first = time.perf_counter() - t
        seconds = 0.0                           # the first step (compilation) left out
        for k in range(1, scene["warmup"]):
            inject()
            t = time.perf_counter()
            fluid.step(dt)
            took = time.perf_counter() - t
            seconds += took
            stepped(k, seconds, took)
        check_speed(fluid, what, "after the untimed steps")
        times, pressure, viscosity = [], [], []
        for k in range(scene["steps"]):
            inject()
            t = time.perf_counter()
            fluid.step(dt)
            took = time.perf_counter() - t
            times.append(took)
            seconds += took
            stepped(scene["warmup"] + k, seconds, took)
            pressure.append(fluid.pressure_iterations)
            viscosity.append(fluid.viscosity_iterations)
        q = check_speed(fluid, what, "at the end")
        r = {"ms_per_step": 1e3 * float(np.mean(times)), "slowest_step_ms": 1e3 * max(times), "setup_s": setup,
             "first_step_s": first, "threads": threads_of(name, fluid),
             "pressure_iterations": float(np.mean(pressure)),
             "max_div_dt": fluid.max_divergence() * dt, "max_speed_m_s": float(np.max(np.abs(q))),
             "kinetic_energy_j": 0.5 * DENSITY * scene["h"] ** scene["dims"] * float(np.sum(q ** 2))}
        if scene["nu"] > 0.0:
            r["viscosity_iterations"] = float(np.mean([np.sum(v) for v in viscosity if v is not None]))
        if smoke:
            dye = fluid.get_dye()
            heights = (np.arange(scene["cells"][1]) + 0.5) * scene["h"]
            r["dye_m3"] = float(np.sum(dye)) * scene["h"] ** 3
            r["dye_height_m"] = float(np.sum(dye.sum(axis=(0, 2)) * heights) / max(np.sum(dye), 1e-300))
        else:
            r["u_min_centreline_m_s"] = float(np.min(q[0, scene["cells"][0] // 2, :, 0]))
        return r

    return run


def check_speed(fluid, what, when):
    """The faces (3, nx, ny, nz); BlewUp when they are not finite or faster than ``MAX_SPEED``."""
    q = fluid.faces()
    speed = float(np.max(np.abs(q))) if np.all(np.isfinite(q)) else math.inf
    if not speed <= MAX_SPEED:
        raise BlewUp(f"blew up: {what}, a face at {speed:.3g} m/s {when}")
    return q


# --- the run ------------------------------------------------------------------------------------------------------
def peer_version(name):
    try:
        return metadata.version(PEERS[name])
    except metadata.PackageNotFoundError:
        return None


def main():
    engines = ["marbellous", "taichi", "warp", "phiflow"]
    args = bench_arguments(__doc__, engines)
    scenes = QUICK_SCENES if args.quick else SCENES
    load_start = os.getloadavg()
    results = {}
    for key in scenes:
        for name in args.engines:
            try:
                r = best_of(make_run(name, scenes), args.repeats, key, LONG_RUN_S)
            except ImportError as e:
                r = {"not_installed": f"not installed: {e}"}
            except Exception as e:            # a peer's own error (PhiFlow's, Taichi's, Warp's): reported, not fatal
                r = {"failed": f"{type(e).__name__}: {' '.join(str(e).split())[:300]}"}
            results.setdefault(key, {})[name] = r
            print(f"  {key} {name}: " + (", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                                                 for k, v in r.items())), file=sys.stderr, flush=True)
    print(f"grid fluids: ms per step (best of {args.repeats}), max |div u| dt after the last step "
          f"(tolerance {TOLERANCE:g})")
    print(f"{'scene':11s} {'engine':11s} {'ms/step':>9s} {'slowest':>8s} {'thr':>3s} {'p-its':>6s} {'v-its':>6s} "
          f"{'div dt':>8s} {'speed':>6s} {'check':>10s}")
    for key, by_engine in results.items():
        for name, r in by_engine.items():
            if "ms_per_step" not in r:
                what = next(iter(r))
                print(f"{key:11s} {name:11s} {what}: {r[what]}")
                continue
            check = r.get("u_min_centreline_m_s", r.get("dye_height_m"))
            vits = f"{r['viscosity_iterations']:6.1f}" if "viscosity_iterations" in r else f"{'':6s}"
            print(f"{key:11s} {name:11s} {r['ms_per_step']:9.2f} {r['slowest_step_ms']:8.1f} {r['threads']!s:>3s} "
                  f"{r['pressure_iterations']:6.1f} {vits} {r['max_div_dt']:8.2g} {r['max_speed_m_s']:6.3f} "
                  f"{check:10.4f}")
    if args.json:
        machine = describe(ROOT, {name: peer_version(name) for name in args.engines if name in PEERS})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "fluid", "machine": machine, "engines": args.engines, "quick": args.quick,
                       "repeats": args.repeats, "density_kg_m3": DENSITY, "tolerance_div_dt": TOLERANCE,
                       "scenes": {key: {**scene, "cells": list(scene["cells"])} for key, scene in scenes.items()},
                       "jet": {"centre_m": JET_CENTRE.tolist(), "radius_m": JET_RADIUS, "speed_m_s": JET_SPEED},
                       "cap_after_steps": CAP_AFTER, "long_run_s": LONG_RUN_S,
                       "load_average_1_5_15_min": {"start": load_start, "end": os.getloadavg()},
                       "schemes": SCHEMES, "results": results}, f, indent=1)


SCHEMES = {
    "marbellous": "MacCormack advection (midpoint traces, clamped), backward-Euler viscosity by CG, projection by "
                  "MIC(0)-PCG to max|div u| dt <= 1e-6; serial Numba",
    "taichi": "the same scheme in Taichi kernels (bench/peers/taichi_fluid.py), except the projection: Jacobi-PCG, "
              "warm-started, to max|div u| dt <= 1e-6; all cores",
    "warp": "the same solver as taichi in Warp kernels (bench/peers/warp_fluid.py), device cpu, one thread",
    "phiflow": "PhiFlow 3.4.0 (NumPy): advect.mac_cormack (midpoint traces) for the dye and the smoke's velocity, "
               "advect.semi_lagrangian for the cavity's velocity (mac_cormack fails with a moving wall), viscosity "
               "by math.solve_linear CG per component (diffuse.implicit fails on a walled StaggeredGrid), "
               "fluid.make_incompressible with CG (no preconditioner, from zero) to an L2 residual <= 1e-6 / dt",
}


if __name__ == "__main__":
    main()
