"""Benchmark of the collide stage's own kernels: ``update_aabbs`` and ``narrow_phase``.

Each scene (sphere pile 1k and 8k, the marble on the 131k-triangle mesh, a marble on a 64 x 64 height
field) is built and stepped into a settled state; then the world's own arrays are taken as
``World.step`` sees them and the two kernels are called on them, ``reps`` times inside one
compiled loop (so the Python-to-Numba dispatch, ~1 us, is not counted), best of ``REPEATS`` rounds:
the machine is shared, and other processes only ever add time.  Both kernels only read the bodies, so
every call sees the same input.  Reports us per call, ns per candidate pair, the pair and contact
counts and a digest of the contacts (equal digests: bit-identical contacts), and writes
``bench/results/<date>-<host>-narrow_phase.json``.

Run:  python -m bench.bench_narrow_phase [--quick] [--scenes pile_1k marble_terrain]
      python -m bench.bench_narrow_phase --scenes pyramid_20 --warm-steps 20 --no-write   (box pairs, awake)
"""
import argparse
import hashlib
import os
import time

import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision.broadphase import find_pairs
from marbellous.state.params import write_params
from marbellous.collision.shape_types import COVER_ALL, COVER_GROUND, COVER_MESHES, COVER_SPHERES
from marbellous.pipeline.collide import (narrow_phase_all, narrow_phase_ground, narrow_phase_meshes,
                                         narrow_phase_spheres, pose_tables, update_aabbs)
from marbellous.state import layout as L

from .machine import describe, write_results
from .scenes import DT, SCENES, build_scene

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DEFAULT_SCENES = ("pile_1k", "pile_8k", "marble_terrain", "marble_heightfield")
REPEATS = 7
#: wall time (s) one round of calls should take at least
ROUND_SECONDS = 0.05
#: the compiled narrow phase of each coverage (``shape_types.COVER_*``)
NARROW_PHASES = {COVER_SPHERES: narrow_phase_spheres, COVER_MESHES: narrow_phase_meshes,
                 COVER_GROUND: narrow_phase_ground, COVER_ALL: narrow_phase_all}


@njit
def _repeat_narrow(reps, narrow_phase, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                   raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """``narrow_phase`` (the compiled narrow phase of one coverage, ``NARROW_PHASES[coverage]``: the one the
    world's step has compiled already) called ``reps`` times, every pair tested (``npc`` = 0: no rows of a last
    step to keep); returns the last count."""
    n = 0
    for _ in range(reps):
        n = narrow_phase(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i,
                         ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)
    return n


@njit
def _repeat_aabbs(reps, bf, bi, sf, si, nb, aabbs, sweep, dt, gravity_mag, speculative, pos_t, rot_t, q):
    """``update_aabbs`` called ``reps`` times."""
    for _ in range(reps):
        update_aabbs(bf, bi, sf, si, nb, aabbs, sweep, dt, gravity_mag, speculative, pos_t, rot_t, q)


class CollideInput:
    """The collide stage's input taken from a world at its current state: the arrays ``World.step``
    passes to ``update_aabbs`` and ``narrow_phase``, with the broad phase's pairs and private output
    buffers (the world's own are left alone)."""

    def __init__(self, world, dt):
        w = world
        write_params(world, dt, w._state.params_f, w._state.params_i)
        pf, pi = w._state.params_f, w._state.params_i
        self.bf, self.bi, self.sf, self.si = w._state.bf, w._state.bi, w._state.sf, w._state.si
        self.geom_f, self.geom_i = w._state.geom_f, w._state.geom_i
        self.nb = w._state.bodies.end
        self.dt = dt * pf[L.PF_SWEEP]
        gravity = pf[L.PF_GRAVITY:L.PF_GRAVITY + 3]
        self.g_mag = float(np.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2))
        self.speculative = float(pf[L.PF_SPECULATIVE])
        # the pair tests compiled for the kinds of shape the world has, and no last step's rows to keep
        self.coverage = w._state.step_variant()[0]
        self.previous_f, self.previous_i = np.zeros((0, L.CF_COLS)), np.zeros((0, L.CI_COLS), dtype=np.int64)
        self.aabbs = w._state.aabbs.copy()
        self.sweep = np.empty(self.nb)
        self.poses = pose_tables(self.sf.shape[0])   # the step's scratch (the record's, in a world)
        pos_t, rot_t, _, q = self.poses
        update_aabbs(self.bf, self.bi, self.sf, self.si, self.nb, self.aabbs, self.sweep, self.dt, self.g_mag,
                     self.speculative, pos_t, rot_t, q)
        pairs = np.zeros_like(w._state.pairs)
        while True:
            n_pairs = find_pairs(pi[L.PI_BROADPHASE], self.aabbs, self.bi[:, L.FLAGS], self.bi[:, L.GROUP],
                                 self.bi[:, L.MASK], self.nb, w._state.bp_f.copy(), w._state.bp_i.copy(), pairs)
            if n_pairs <= pairs.shape[0]:
                break
            pairs = np.zeros((n_pairs, 2), dtype=np.int64)
        self.pairs, self.n_pairs = pairs, n_pairs
        cap = max(16, w._state.raw_f.shape[0])
        while True:
            self.raw_f = np.zeros((cap, w._state.raw_f.shape[1]))
            self.raw_i = np.zeros(cap, dtype=np.int64)
            self.ci = np.zeros((cap, L.CI_COLS), dtype=np.int64)
            self.cf = np.zeros((cap, L.CF_COLS))
            self.n_contacts = self.narrow(1)
            if self.n_contacts <= cap:
                break
            cap = self.n_contacts

    def narrow(self, reps):
        """Run the narrow phase ``reps`` times; the number of contact points."""
        return _repeat_narrow(reps, NARROW_PHASES[self.coverage], self.bf, self.bi, self.sf, self.si, self.geom_f,
                              self.geom_i, self.pairs, self.n_pairs, self.sweep, self.speculative, self.raw_f,
                              self.raw_i, self.ci, self.cf, self.previous_f, self.previous_i, 0, *self.poses)

    def aabbs_update(self, reps):
        """Run ``update_aabbs`` ``reps`` times."""
        pos_t, rot_t, _, q = self.poses
        _repeat_aabbs(reps, self.bf, self.bi, self.sf, self.si, self.nb, self.aabbs, self.sweep, self.dt,
                      self.g_mag, self.speculative, pos_t, rot_t, q)

    def contacts(self):
        """``(raw_f, raw_i, ci)`` rows of the last narrow phase."""
        n = self.n_contacts
        return self.raw_f[:n].copy(), self.raw_i[:n].copy(), self.ci[:n].copy()

    def digest(self):
        """SHA-256 (16 hex digits) of the contacts' bytes: equal digests mean bit-identical contacts."""
        h = hashlib.sha256()
        for a in self.contacts():
            h.update(np.ascontiguousarray(a).tobytes())
        return h.hexdigest()[:16]


def marble_on_heightfield(cells=64, spacing=0.1):
    """``(world, meta)``: a marble (r = 0.25 m) rolling on a wavy ``cells`` x ``cells`` height field."""
    import marbellous as mb

    x = np.linspace(0.0, 6.0, cells)
    heights = 0.3 * np.sin(x)[:, None] * np.cos(x)[None, :]
    half = 0.5 * (cells - 1) * spacing
    world = mb.World()
    world.add_static(mb.HeightField(heights, spacing=(spacing, spacing), origin=(-half, 0.0, -half)))
    world.add_body(mb.Sphere(0.25), position=(0.1, 0.6, 0.2), velocity=(1.0, 0.0, 0.5))
    return world, {}


#: scenes of this benchmark only: name -> (builder, warm-up steps)
EXTRA_SCENES = {"marble_heightfield": (marble_on_heightfield, 60)}


def best_seconds(run):
    """Best seconds per call of ``run(reps)`` over ``REPEATS`` rounds of at least ``ROUND_SECONDS``."""
    reps = 1
    while True:
        t0 = time.perf_counter()
        run(reps)
        t = time.perf_counter() - t0
        if t >= ROUND_SECONDS or reps >= 1 << 22:
            break
        reps *= 2
    best = t / reps
    for _ in range(REPEATS - 1):
        t0 = time.perf_counter()
        run(reps)
        best = min(best, (time.perf_counter() - t0) / reps)
    return best


def measure(name, quick=False, warm_steps=None):
    """The collide-stage timings of scene ``name`` after ``warm_steps`` steps (default: the scene's
    warm-up).  Returns a dict of numbers."""
    if name in EXTRA_SCENES:
        build, default_steps = EXTRA_SCENES[name]
        world, _ = build()
    else:
        world, _ = build_scene(name, quick=quick)
        default_steps = SCENES[name].warmup_steps(quick)
    steps = default_steps if warm_steps is None else warm_steps
    for _ in range(steps):
        world.step(DT)
    inp = CollideInput(world, DT)
    narrow = best_seconds(inp.narrow)
    aabbs = best_seconds(inp.aabbs_update)
    return {"scene": name, "bodies": int(inp.nb), "warm_steps": int(steps), "pairs": int(inp.n_pairs),
            "contacts": int(inp.n_contacts), "narrow_us": narrow * 1e6,
            "narrow_ns_per_pair": narrow * 1e9 / max(inp.n_pairs, 1), "aabbs_us": aabbs * 1e6,
            "aabbs_ns_per_body": aabbs * 1e9 / max(inp.nb, 1), "contacts_digest": inp.digest()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller scenes: a check of the harness")
    ap.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES), help="scene names")
    ap.add_argument("--warm-steps", type=int, default=None,
                    help="steps before measuring (default: the scene's warm-up; stacks need few, or they sleep)")
    ap.add_argument("--no-write", action="store_true", help="print only, write no results file")
    args = ap.parse_args(argv)
    rows = []
    print(f"load average {os.getloadavg()[0]:.2f}")
    for name in args.scenes:
        r = measure(name, quick=args.quick, warm_steps=args.warm_steps)
        rows.append(r)
        print(f"{name:16s} pairs {r['pairs']:6d}  contacts {r['contacts']:6d}  narrow {r['narrow_us']:10.2f} us "
              f"({r['narrow_ns_per_pair']:7.1f} ns/pair)  aabbs {r['aabbs_us']:9.2f} us "
              f"({r['aabbs_ns_per_body']:5.1f} ns/body)  digest {r['contacts_digest']}", flush=True)
    if args.no_write:
        return rows
    machine = describe(ROOT, {})
    machine["load_average"] = os.getloadavg()[0]
    out = {"machine": machine, "quick": args.quick, "repeats": REPEATS, "scenes": rows}
    path = write_results(os.path.join(HERE, "results"), "narrow_phase", out)
    print("wrote", path)
    return rows


if __name__ == "__main__":
    main()
