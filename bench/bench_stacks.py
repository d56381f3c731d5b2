"""Towers of cubes, side by side with PyBullet and MuJoCo: cost per step, and whether the tower still stands.

The scene: a tower of ``N`` cubes (half extent 0.25 m, density 500 kg/m^3: 62.5 kg each) stacked exactly, face
on face with no gap, on a ground plane, their centres on the vertical axis through the origin, for N = 10, 20
and 30; friction 0.6 on the cubes and the ground, 60 Hz, gravity 9.81, one untimed step and then 300 timed
steps (5 s), every body awake throughout.
- Marbellous: sequential impulses, its defaults (4 sub-steps) but ``sleeping=False``, once as
  ``marbellous-4`` (its default: at most 4 passes per sub-step) and once as ``marbellous-adaptive`` with
  ``adaptive_iterations = True`` (up to two passes per body of the stack's support depth, 4 to 128 per
  sub-step, passes beyond the first 4 only while a velocity still changes by 1e-3 m/s), and once as
  ``marbellous-bottom-up`` with ``solve_order = "bottom_up"`` (4 passes, the contacts one by one from the
  ground up instead of in coloured bundles);
- PyBullet: ``GEOM_BOX`` maximal-coordinate rigid bodies (Bullet's own box inertia), its default solver
  (10 iterations), no damping (its default 0.04 off, as Marbellous has none), sleeping off; Bullet multiplies
  two bodies' friction, so each cube and the ground get ``sqrt(0.6)``;
- MuJoCo: box geoms on free joints, mass and inertia from the density, its defaults (Newton solver, Euler
  integrator, pyramidal friction cones, soft contacts).  A run that MuJoCo flags unstable is reported as
  failed, not timed.
Reported per engine and N: ms per step (the ``step()`` calls only, best of ``--repeats``); the top cube's
sideways drift at the end (m, the horizontal distance of its centre from the tower's axis); how far the top
sank (m, its ideal height 0.25 + 0.5 (N - 1) minus its height at the end; below 0: it rose); whether the tower
still stands (the top within 0.25 m of the axis and above 90% of its ideal height); and for Marbellous the
mean velocity passes per step (``World.profile.iterations``: all 4 sub-steps together, from an untimed,
profiled replay of the same run, which is deterministic).  An engine whose bodies end with non-finite poses is
reported as failed.

    python bench/bench_stacks.py [--quick] [--json FILE]
"""
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

import marbellous as mb  # noqa: E402
from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402
from bench.peers.axes import from_peer, quat_to_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco, time_pybullet  # noqa: E402

DT = 1.0 / 60.0
HALF = 0.25                 # half extent of a cube (m)
DENSITY = 500.0
FRICTION = 0.6
STANDING_DRIFT = 0.25       # a tower stands while its top is within this of the axis (m) ...
STANDING_HEIGHT = 0.9       # ... and above this fraction of its ideal height


def centres(count):
    """The cubes' centres (m, Marbellous axes, y up), from the bottom up: face on face on the ground."""
    return [np.array([0.0, HALF + 2.0 * HALF * k, 0.0]) for k in range(count)]


def ideal_top(count):
    """Height of the top cube's centre in a perfect tower (m)."""
    return HALF + 2.0 * HALF * (count - 1)


def measures(count, top):
    """``(drift (m), sink (m))`` of the top cube's centre ``top`` (m, Marbellous axes); RuntimeError when it
    is not finite (the engine blew up)."""
    if not np.all(np.isfinite(top)):
        raise RuntimeError("non-finite poses at the end (the tower blew up)")
    return float(math.hypot(top[0], top[2])), ideal_top(count) - float(top[1])


def standing(count, drift, sink):
    """Whether the tower still stands: its top near the axis and not far down."""
    return drift < STANDING_DRIFT and ideal_top(count) - sink > STANDING_HEIGHT * ideal_top(count)


def marbellous_tower(count, adaptive, order):
    """``(world, cubes)``: the tower in a Marbellous world, with ``adaptive_iterations`` on or off, the contacts
    solved in ``order`` (``World.solve_order``)."""
    w = mb.World(sleeping=False)
    w.adaptive_iterations = adaptive
    w.solve_order = order
    w.add_static(mb.Plane(), friction=FRICTION)
    cubes = [w.add_body(mb.Box((HALF, HALF, HALF)), position=x, density=DENSITY, friction=FRICTION)
             for x in centres(count)]
    return w, cubes


def run_marbellous(count, steps, adaptive, order="coloured"):
    w, cubes = marbellous_tower(count, adaptive, order)
    w.step(DT)
    seconds = 0.0
    for _ in range(steps):
        t = time.perf_counter()
        w.step(DT)
        seconds += time.perf_counter() - t
    top = cubes[-1].position
    # The passes from a profiled replay, so that the timed steps carry no profiling at all.
    w, cubes = marbellous_tower(count, adaptive, order)
    w.step(DT)
    w.profiling = True
    for _ in range(steps):
        w.step(DT)
    if not np.array_equal(cubes[-1].position, top):
        raise AssertionError("the profiled replay of the tower differs from the timed run")
    return 1e3 * seconds / steps, *measures(count, top), w.profile.iterations


def run_marbellous_4(count, steps):
    return run_marbellous(count, steps, False)


def run_marbellous_adaptive(count, steps):
    return run_marbellous(count, steps, True)


def run_marbellous_bottom_up(count, steps):
    return run_marbellous(count, steps, False, "bottom_up")


def run_pybullet(count, steps):
    mu = math.sqrt(FRICTION)        # Bullet multiplies the two coefficients
    p, kw = direct_client(DT, ground_friction=mu)
    box = p.createCollisionShape(p.GEOM_BOX, halfExtents=[HALF] * 3, **kw)
    mass = DENSITY * (2.0 * HALF) ** 3
    qp = quat_to_peer((1.0, 0.0, 0.0, 0.0))
    ids = []
    for x in centres(count):
        bid = p.createMultiBody(mass, box, basePosition=list(to_peer(x)), baseOrientation=[qp[1], qp[2], qp[3], qp[0]],
                                useMaximalCoordinates=True, **kw)
        p.changeDynamics(bid, -1, lateralFriction=mu, linearDamping=0.0, angularDamping=0.0,
                         activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING, **kw)
        ids.append(bid)
    ms = time_pybullet(p, kw, steps)
    top = from_peer(p.getBasePositionAndOrientation(ids[-1], **kw)[0])
    p.disconnect(**kw)
    return ms, *measures(count, top), None


def run_mujoco(count, steps):
    import mujoco
    qp = quat_to_peer((1.0, 0.0, 0.0, 0.0))
    bodies = "".join(f'<body pos="{_f(to_peer(x))}" quat="{_f(qp)}"><freejoint/>'
                     f'<geom type="box" size="{_f([HALF] * 3)}"/></body>' for x in centres(count))
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -9.81"/>'
        f'<default><geom friction="{FRICTION:.17g} 0.005 0.0001" density="{DENSITY:.17g}"/></default>'
        f'<worldbody><geom type="plane" size="50 50 1"/>{bodies}</worldbody></mujoco>')
    data = mujoco.MjData(model)
    ms = time_mujoco(model, data, steps, f"the tower of {count} cubes")
    a = model.jnt_qposadr[count - 1]         # qpos, not xpos, which lags a step behind mj_step
    return ms, *measures(count, from_peer(data.qpos[a:a + 3])), None


RUNS = {"marbellous-4": run_marbellous_4, "marbellous-adaptive": run_marbellous_adaptive,
        "marbellous-bottom-up": run_marbellous_bottom_up, "pybullet": run_pybullet, "mujoco": run_mujoco}


def main():
    args = bench_arguments(__doc__)
    heights, steps = ((10, 20), 120) if args.quick else ((10, 20, 30), 300)
    results = {}
    for count in heights:
        for name, r in best_results(RUNS, args.repeats, count, steps).items():
            if not isinstance(r, dict):
                r = {"ms_per_step": r[0], "top_drift_m": r[1], "top_sink_m": r[2],
                     "standing": standing(count, r[1], r[2]), "passes_per_step": r[3]}
            results.setdefault(str(count), {})[name] = r
    print(f"towers of cubes (half extent {HALF} m, {DENSITY * (2.0 * HALF) ** 3:.1f} kg each) on the ground, "
          f"{steps} steps at 60 Hz, every body awake")
    print(f"{'N':>3s} {'engine':20s} {'ms/step':>9s} {'drift (m)':>10s} {'sank (m)':>10s} {'stands':>7s} "
          f"{'passes/step':>12s}")
    for count, by_engine in results.items():
        for name, r in by_engine.items():
            if "failed" in r:
                print(f"{count:>3s} {name:20s} failed: {r['failed']}")
                continue
            passes = f"{r['passes_per_step']:12.1f}" if r["passes_per_step"] is not None else f"{'-':>12s}"
            print(f"{count:>3s} {name:20s} {r['ms_per_step']:9.3f} {r['top_drift_m']:10.4f} {r['top_sink_m']:10.4f} "
                  f"{'yes' if r['standing'] else 'NO':>7s} {passes}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco")})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "stacks", "machine": machine, "quick": args.quick, "heights": list(heights),
                       "steps": steps, "dt": DT, "repeats": args.repeats, "half_extent_m": HALF,
                       "density": DENSITY, "friction": FRICTION, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
