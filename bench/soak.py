"""Soak test: a long run with churn, printing memory and step time over time.

    python bench/soak.py [--minutes 5] [--seed 0]

A world with a terrain mesh, a height field, planes and boxes is stepped at 120 Hz for the given wall
time while, every step, bodies are spawned (spheres, boxes, capsules, compounds) and the oldest are
removed beyond a population cap; springs, rods and cables are added and removed; forces and impulses
applied; snapshots taken and restored now and then; raycasts cast; and ``advance`` called with
stalled frames.  Every interval it prints: elapsed time, simulated time, live bodies and constraints,
table capacities (rows), resident memory (MB), Python heap blocks, mean and worst step time (us) of the
interval, and the count of bodies with NaN.  A healthy run has flat memory and step time, and no NaN.
"""
import argparse
import gc
import math
import os
import resource
import sys
import time
import tracemalloc

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import marbellous as mb                      # noqa: E402
from marbellous.scenes.terrain import terrain_mesh   # noqa: E402

DT = 1.0 / 120.0
MAX_BODIES = 150


def rss_mb():
    """Resident memory of this process (MB), from /proc (falls back to the peak)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6
    except OSError:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3


def build(rng):
    w = mb.World()
    w.add_static(mb.Plane(offset=-5.0))
    w.add_static(terrain_mesh(cells=64), position=(-16.0, 0.0, -16.0))
    h = rng.normal(0.0, 0.2, (40, 40))
    w.add_static(mb.HeightField(h, spacing=(0.5, 0.5), origin=(30.0, 0.0, -10.0)))
    for k in range(5):
        w.add_static(mb.Box((1.0, 0.3, 1.0)), position=(-10.0 + 4 * k, 1.0, -12.0))
    return w


def spawn(w, rng):
    kind = rng.integers(4)
    pos = (rng.uniform(-15, 40), rng.uniform(3, 8), rng.uniform(-15, 15))
    vel = tuple(rng.normal(0, 2, 3))
    if kind == 0:
        shape = mb.Sphere(rng.uniform(0.1, 0.5))
    elif kind == 1:
        shape = mb.Box(rng.uniform(0.1, 0.5, 3))
    elif kind == 2:
        shape = mb.Capsule(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.5))
    else:
        shape = [(mb.Sphere(0.2), (0.3, 0.0, 0.0)), (mb.Box((0.2, 0.1, 0.1)), (-0.2, 0.0, 0.0))]
    return w.add_body(shape, position=pos, velocity=vel, restitution=rng.uniform(0, 0.5),
                      friction=rng.uniform(0.1, 1.0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=5.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--interval", type=float, default=20.0, help="seconds between report lines")
    ap.add_argument("--violent-joints", action="store_true",
                    help="join random bodies by 2 m rods whatever their distance (the solver then yanks bodies "
                         "tens of metres apart together: with --seed 0 a pile explodes within two minutes and "
                         "bodies turn NaN, which stops the run); by default joints start at the bodies' current "
                         "distance")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    w = build(rng)
    t0 = time.perf_counter()
    w.step(DT)                                   # compile or load the kernels before timing
    print(f"warm-up (kernels) {time.perf_counter() - t0:.1f} s", flush=True)
    tracemalloc.start()
    live = []
    snap, snap_bodies, restore_at = None, None, 0
    counts = dict(spawned=0, removed=0, constraints=0, snapshots=0, restores=0, refused=0, rays=0)
    times = []
    start = time.perf_counter()
    next_report = start + args.interval
    steps = 0
    print(f"{'wall s':>7s} {'sim s':>8s} {'bodies':>6s} {'cons':>5s} {'rows b/s/k':>14s} {'RSS MB':>7s} "
          f"{'py KB':>7s} {'mean us':>8s} {'max us':>8s} {'NaN':>4s}", flush=True)
    rss0 = rss_mb()
    while True:
        now = time.perf_counter()
        if now - start > args.minutes * 60:
            break
        # churn
        for _ in range(rng.integers(0, 3)):
            live.append(spawn(w, rng))
            counts["spawned"] += 1
        while snap is None and (len(live) > MAX_BODIES or (live and rng.random() < 0.02)):
            b = live.pop(0 if rng.random() < 0.8 else int(rng.integers(len(live))))
            w.remove(b)
            counts["removed"] += 1
        if len(live) >= 2 and rng.random() < 0.05:
            a, b = rng.choice(len(live), 2, replace=False)
            kind = rng.integers(3)
            gap = float(np.linalg.norm(live[a].position - live[b].position))
            if kind == 0:
                w.add_spring(live[a], live[b], rest_length=gap, stiffness=50.0, damping=1.0, breaking_force=500.0)
            elif kind == 1:
                w.add_rod(live[a], live[b], length=2.0 if args.violent_joints else None)
            else:
                w.add_cable(live[a], None, max_length=3.0, anchor_b=tuple(live[a].position + (0, 2, 0)))
            counts["constraints"] += 1
        if w.constraints and snap is None and rng.random() < 0.03:
            w.remove(w.constraints[int(rng.integers(len(w.constraints)))])
        if live and rng.random() < 0.2:
            b = live[int(rng.integers(len(live)))]
            b.apply_force(tuple(rng.normal(0, 20, 3)), point=tuple(b.position + rng.normal(0, 0.1, 3)))
            b.apply_impulse(tuple(rng.normal(0, 0.5, 3)))
        if rng.random() < 0.05:
            w.raycast(tuple(rng.uniform(-20, 40, 3) + (0, 20, 0)), tuple(rng.normal(0, 1, 3)))
            counts["rays"] += 1
        if rng.random() < 0.01:                  # bad input now and then: refused, nothing changes
            try:
                w.add_body(mb.Sphere(1.0), position=(math.nan, 0, 0))
            except ValueError:
                counts["refused"] += 1
        if snap is None and rng.random() < 0.002:
            # a snapshot, restored 1 to 60 steps later (no removals meanwhile: a snapshot holding a body
            # removed since is refused); the bodies spawned meanwhile go with the restore
            snap, snap_bodies, restore_at = w.snapshot(), list(live), steps + int(rng.integers(1, 60))
            counts["snapshots"] += 1
        elif snap is not None and steps >= restore_at:
            w.restore(snap)
            alive = set(w.bodies)
            live = [b for b in snap_bodies if b in alive]
            snap = None
            counts["restores"] += 1
        # step (now and then a stalled frame through advance)
        t = time.perf_counter()
        if rng.random() < 0.01:
            w.advance(rng.uniform(0.0, 5.0), dt=DT)
        else:
            w.step(DT)
        times.append(time.perf_counter() - t)
        steps += 1
        if np.isnan(w._state.bf[:w._state.bodies.end]).any():   # (outside the timed call)
            print(f"NaN in the bodies' state after step {steps} ({w.time:.2f} s simulated): stopping", flush=True)
            break
        # fallen bodies go
        for b in [b for b in live if snap is None and b.position[1] < -50]:
            live.remove(b)
            w.remove(b)
            counts["removed"] += 1
        if time.perf_counter() >= next_report:
            next_report += args.interval
            gc.collect()
            st = w._state
            bf = st.bf[:st.bodies.end]
            nan = int(np.count_nonzero(np.isnan(bf).any(axis=1)))
            cur, _ = tracemalloc.get_traced_memory()
            arr = np.array(times) * 1e6
            print(f"{time.perf_counter() - start:7.0f} {w.time:8.1f} {len(w.bodies):6d} {len(w.constraints):5d} "
                  f"{st.bf.shape[0]:>4d}/{st.sf.shape[0]:>4d}/{st.kf.shape[0]:>3d} {rss_mb():7.1f} {cur / 1e3:7.0f} "
                  f"{arr.mean():8.1f} {arr.max():8.0f} {nan:4d}", flush=True)
            times = []
    print(f"\n{steps} steps, {w.time:.1f} s simulated; {counts}")
    print(f"RSS {rss0:.1f} -> {rss_mb():.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
