"""The contact pass against the solver limit: one velocity pass of sequential impulses over a scene's
contact bundles, by Marbellous (``contact_bundles.solve_bundles``, compiled by Numba) and by the same pass
written in C++ (``bench/contact_pass.cpp``: GCC's vector extensions, ``-O3 -march=native``), on the same
tables, in ns per contact.

Each scene is built and stepped into its measured state; then the step's own bundle tables (``wide_f``,
``wide_i``), solver bodies and parameters are copied out of the world, and both kernels run on copies of
them.  First one pass of each from the same copy: the two must leave bit-identical tables (the C++ pass
does the engine's arithmetic term for term, so equal tables show that it does the same work, no more and no
less).  Then each is timed over ``passes`` passes inside its own compiled loop (no call overhead counted),
best of ``REPEATS`` rounds (``bench_narrow_phase.best_seconds``), as the machine is shared.  The pass's work
does not depend on the values (the only branches are the bundles' flags), so later passes cost what the first
does.  Reports ns per contact (pad lanes not counted as contacts), the ratios, and the largest difference the
single-precision pass makes to the velocities, and writes ``bench/results/<date>-<host>-contact_pass.json``.

The C++ kernel is compiled on first use by ``$CXX`` (else ``c++``) into
``~/.cache/marbellous-bench/contact-pass/<key>/`` (key: the source, the layout and the flags).

Run:  python -m bench.bench_contact_pass [--quick] [--scenes pile_1k pyramid_20_awake] [--no-write]
"""
import argparse
import ctypes
import hashlib
import os
import shutil
import subprocess

import numpy as np

from marbellous._numba.jit import njit
from marbellous._numba.wide import LANES
from marbellous.dynamics.contact_bundles import solve_bundles
from marbellous.pipeline.step import solve_softness
from marbellous.state import layout as L

from .bench_narrow_phase import REPEATS, best_seconds
from .machine import describe, write_results
from .peers.cache import cache_dir, exclusive
from .scenes import DT, SCENES, build_scene

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SOURCE = os.path.join(HERE, "contact_pass.cpp")
#: the compiler's flags: the engine's rounding (no fused multiply-add), the machine's widest vectors
FLAGS = ("-O3", "-march=native", "-ffp-contract=off", "-fno-math-errno", "-std=c++17", "-shared", "-fPIC")
#: the layout's names the kernel is compiled with
LAYOUT_NAMES = ("BUNDLE_FIELDS", "BUNDLE_ROWS", "SB_COLS", "SB_V", "WB_NORMAL", "WB_RA", "WB_RB", "WB_T1", "WB_T2",
                "WB_MASS_N", "WB_MASS_T1", "WB_MASS_T2", "WB_MU", "WB_LAMBDA_N", "WB_LAMBDA_T1", "WB_LAMBDA_T2",
                "WB_MAX_N", "WB_VN0", "WB_NEW", "WB_SEPARATION", "WB_INV_MASS_A", "WB_INV_I_A", "WB_INV_MASS_B",
                "WB_INV_I_B", "WB_ROLL", "WB_TORSION", "WB_LAMBDA_R", "WI_READ_A", "WI_READ_B", "WI_WRITE_A",
                "WI_WRITE_B", "WI_TURNING", "WI_ROLLING")
DEFAULT_SCENES = ("pile_1k", "pile_8k", "pyramid_20_awake")
#: steps before measuring the awake pyramid (it stands; the piles use their bench warm-up)
AWAKE_STEPS = 120


def _defines():
    return [f"-DLANES={LANES}"] + [f"-D{name}={getattr(L, name)}" for name in LAYOUT_NAMES]


def build_kernels():
    """The compiled C++ passes in double and in single precision, as ctypes functions ``(wide_f, wide_i, first,
    last, sb, h, soft, passes) -> largest change``; built on first use.  Raises RuntimeError without a C++
    compiler."""
    compiler = os.environ.get("CXX") or "c++"
    if shutil.which(compiler) is None:
        raise RuntimeError(f"no C++ compiler {compiler!r} (set $CXX)")
    command = [compiler, *FLAGS, *_defines()]
    with open(SOURCE, "rb") as f:
        key = hashlib.sha256(f.read() + " ".join(command).encode()).hexdigest()[:16]
    directory = cache_dir("contact-pass", key)
    library = os.path.join(directory, "contact_pass.so")
    with exclusive(os.path.join(directory, "lock")):
        if not os.path.exists(library):
            built = library + ".part"
            done = subprocess.run(command + [SOURCE, "-o", built], capture_output=True, text=True)
            if done.returncode != 0:
                raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr}")
            os.replace(built, library)
    lib = ctypes.CDLL(library)
    int_p = np.ctypeslib.ndpointer(np.int64, flags="C_CONTIGUOUS")
    kernels = []
    for f, dtype, scalar in ((lib.solve_passes_double, np.float64, ctypes.c_double),
                             (lib.solve_passes_float, np.float32, ctypes.c_float)):
        real_p = np.ctypeslib.ndpointer(dtype, flags="C_CONTIGUOUS")
        f.argtypes = [real_p, int_p, ctypes.c_int64, ctypes.c_int64, real_p, scalar, real_p, ctypes.c_int64]
        f.restype = scalar
        kernels.append(f)
    return tuple(kernels)


@njit
def _bundle_tables(ctx):
    """The step's bundle tables, solver bodies, bundle and overflow counts, sub-step and the solve passes'
    soft parameters ``(bias_rate, mass_scale, impulse_scale, max_bias)``, as the last step left them."""
    soft = np.array(solve_softness(ctx))
    return (ctx.wide_f.copy(), ctx.wide_i.copy(), ctx.solver_bodies.copy(), ctx.bundles, ctx.n_overflow, ctx.nc,
            ctx.h, soft)


@njit
def _repeat_solve(passes, wide_f, wide_i, bundles, sb, h, soft, largest):
    """``solve_bundles`` over every bundle ``passes`` times; the last pass's largest change."""
    change = 0.0
    s = (soft[0], soft[1], soft[2], soft[3])
    for _ in range(passes):
        change = solve_bundles(wide_f, wide_i, 0, bundles, sb, h, s, largest)
    return change


class ContactPass:
    """A scene's contact bundles as the world's last step solved them, and the kernels on copies of them."""

    def __init__(self, world, kernels):
        state = world._state
        if state.context is None:
            raise ValueError("the world has not stepped since its tables last changed")
        (self.wide_f, self.wide_i, self.sb, self.bundles, self.overflow, self.contacts, self.h,
         self.soft) = _bundle_tables(state.context)
        if self.bundles == 0:
            raise ValueError("the scene's last step solved no bundles")
        used = self.bundles * L.BUNDLE_ROWS * LANES
        lanes = self.wide_i[:used].reshape(self.bundles, L.BUNDLE_ROWS, LANES)[:, L.WI_CONTACT]
        self.bundled = int(np.count_nonzero(lanes >= 0))
        self.double, self.single = kernels
        self.largest = np.zeros(LANES)

    def engine(self, passes, wide_f, sb):
        """``passes`` passes of Marbellous' kernel on the tables ``wide_f``, ``sb``."""
        return _repeat_solve(passes, wide_f, self.wide_i, self.bundles, sb, self.h, self.soft, self.largest)

    def limit(self, passes, wide_f, sb):
        """``passes`` passes of the C++ kernel in double precision on the tables ``wide_f``, ``sb``."""
        return self.double(wide_f, self.wide_i, 0, self.bundles, sb, self.h, self.soft, passes)

    def limit_single(self, passes, wide_f, sb):
        """``passes`` passes of the C++ kernel in single precision on float32 tables ``wide_f``, ``sb``."""
        return self.single(wide_f, self.wide_i, 0, self.bundles, sb, self.h, self.soft.astype(np.float32), passes)

    def one_pass(self, run, dtype=np.float64):
        """``(wide_f, sb, change)`` after one pass of ``run`` from copies of the tables in ``dtype``."""
        wide_f, sb = self.wide_f.astype(dtype), self.sb.astype(dtype)
        change = run(1, wide_f, sb)
        return wide_f, sb, change

    def same_result(self):
        """True if one pass of the engine's kernel and one of the C++ kernel in double precision, from the same
        tables, leave bit-identical tables and report the same change."""
        (f1, s1, c1), (f2, s2, c2) = self.one_pass(self.engine), self.one_pass(self.limit)
        return (np.array_equal(f1, f2, equal_nan=True) and np.array_equal(s1, s2, equal_nan=True)
                and (c1 == c2 or (np.isnan(c1) and np.isnan(c2))))

    def single_difference(self):
        """Largest difference (m/s, rad/s) between the bodies' velocities after one pass in single precision
        and after one in double precision."""
        _, double_sb, _ = self.one_pass(self.engine)
        _, single_sb, _ = self.one_pass(self.limit_single, np.float32)
        velocities = slice(L.SB_V, L.SB_W + 3)
        return float(np.max(np.abs(single_sb[:, velocities] - double_sb[:, velocities])))

    def seconds_per_pass(self, run, dtype=np.float64):
        """Best seconds per pass of ``run`` on copies of the tables in ``dtype`` (``bench_narrow_phase.best_seconds``:
        best of its rounds)."""
        wide_f, sb = self.wide_f.astype(dtype), self.sb.astype(dtype)
        return best_seconds(lambda passes: run(passes, wide_f, sb))


def measure(name, kernels, quick=False):
    """The kernels' ns per contact on scene ``name``; a dict of numbers."""
    world, _ = build_scene(name, quick=quick)
    steps = AWAKE_STEPS if name.endswith("_awake") else SCENES[name].warmup_steps(quick)
    for _ in range(steps):
        world.step(DT)
    run = ContactPass(world, kernels)
    identical = run.same_result()
    difference = run.single_difference()
    engine = run.seconds_per_pass(run.engine)
    limit = run.seconds_per_pass(run.limit)
    single = run.seconds_per_pass(run.limit_single, np.float32)
    per = 1e9 / run.bundled
    return {"scene": name, "steps": steps, "contacts": int(run.contacts), "bundled": run.bundled,
            "lanes": int(run.bundles * LANES), "overflow": int(run.overflow), "identical": bool(identical),
            "single_velocity_difference": difference, "engine_ns_per_contact": engine * per,
            "limit_ns_per_contact": limit * per, "single_ns_per_contact": single * per,
            "ratio": engine / limit, "ratio_single": engine / single}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller scenes: a check of the harness")
    ap.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES), help="scene names")
    ap.add_argument("--no-write", action="store_true", help="print only, write no results file")
    args = ap.parse_args(argv)
    kernels = build_kernels()
    rows = []
    print(f"load average {os.getloadavg()[0]:.2f}")
    for name in args.scenes:
        r = measure(name, kernels, quick=args.quick)
        rows.append(r)
        print(f"{name:18s} contacts {r['bundled']:6d} in {r['lanes']:6d} lanes (+{r['overflow']} overflow), "
              f"ns per contact: Marbellous {r['engine_ns_per_contact']:6.2f}, C++ {r['limit_ns_per_contact']:6.2f} "
              f"(ratio {r['ratio']:4.2f}, identical {r['identical']}), C++ float {r['single_ns_per_contact']:6.2f} "
              f"(ratio {r['ratio_single']:4.2f}, velocities within {r['single_velocity_difference']:.1e})",
              flush=True)
    if args.no_write:
        return rows
    machine = describe(ROOT, {})
    machine["load_average"] = os.getloadavg()[0]
    machine["compiler"] = subprocess.run([os.environ.get("CXX") or "c++", "--version"], capture_output=True,
                                         text=True).stdout.splitlines()[0]
    out = {"machine": machine, "quick": args.quick, "repeats": REPEATS, "flags": list(FLAGS), "scenes": rows}
    path = write_results(os.path.join(HERE, "results"), "contact_pass", out)
    print("wrote", path)
    return rows


if __name__ == "__main__":
    main()
