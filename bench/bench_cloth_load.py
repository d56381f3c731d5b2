"""A heavy box on a light sheet, side by side with PyBullet and MuJoCo: which sheet carries it, and at what cost.

The scene, 60 Hz, gravity 9.81, 360 steps (6 s): a square sheet of 21 x 21 vertices, 1 m x 1 m, 0.2 kg in all, held
at its four corners 1 m above a static ground plane (y up in Marbellous, z up in the peers, ``bench/peers/axes.py``),
and a box of 0.3 x 0.1 x 0.3 m dropped from 0.5 m above it, of 1, 3, 10 and 30 kg (5 to 150 times the sheet's
mass); friction 0.5, the sheet's thickness 0.01 m.
- Marbellous (``marbellous``): ``mb.cloth_grid`` and ``w.add_cloth(..., mass=0.2, damping=1.0)`` pinned at the
  corners, its defaults otherwise: the particles' sub-steps automatic (``w.particle_substeps`` None: 16, more for a
  heavy load, ``deformables/load_substeps.py``); again with 16 fixed (``marbellous-16``).
- PyBullet (``pybullet``): its deformable world, the sheet loaded as in ``bench/bench_cloth.py`` (mass-spring
  cloth, springs of 100 N/m, 10 sub-steps a step; stiffer springs blew up there), its corners anchored to the
  world (``createSoftBodyAnchor``), the box a rigid body of the same mass.
- MuJoCo (``mujoco``): a ``flexcomp`` grid as in ``bench/bench_cloth.py`` (edges held by equality constraints)
  with its corners pinned (``<pin id=.../>``), the box a free body (``implicitfast``).  Seen here: the sheet alone
  sags to 0.74 m, and the box falls through it as through air (MuJoCo 4.0.1: no contact between the box and the flex
  while it crosses the sheet, 162 once both are near the ground); not resolved, so its rows say what its defaults
  do with this model, not what a tuned flex can.
Reported per engine and mass: ms per step (mean over the run), where the box ends (its centre's height, m),
whether the sheet carries it (``held``: the box's underside above the ground by more than 0.3 m at the end, over
the sheet's square), its motion over the last second (peak to peak, mm) and the lowest the sheet's vertices are
(m).  A run whose positions end non-finite fails.

Run:  python bench/bench_cloth_load.py [--engines ...] [--json out.json]
"""
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

import marbellous as mb  # noqa: E402
from bench.bench_cloth import FRICTION, pb_cloth, pb_deformable_world  # noqa: E402
from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402
from bench.peers.axes import from_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.timing import bench_arguments  # noqa: E402

DT = 1.0 / 60.0
G = 9.81
STEPS = 360                 # 6 s
N, SIZE, SHEET_MASS, HEIGHT = 21, 1.0, 0.2, 1.0
HALF, DROP = (0.15, 0.05, 0.15), 0.5
MASSES = (1.0, 3.0, 10.0, 30.0)
THICKNESS = 0.01
CORNERS = (0, N - 1, N * (N - 1), N * N - 1)
START = np.array([0.0, HEIGHT + HALF[1] + DROP, 0.0])


def _run(step, box_position, sheet_positions):
    """``STEPS`` calls of ``step``, timed; returns ``(ms per step, box heights (m) after each step, the sheet's
    final vertices)``."""
    heights, seconds = [], 0.0
    for _ in range(STEPS):
        t = time.perf_counter()
        step()
        seconds += time.perf_counter() - t
        heights.append(float(box_position()[1]))
    x = sheet_positions()
    if not (np.all(np.isfinite(heights)) and np.all(np.isfinite(x))):
        raise RuntimeError("positions not finite")
    return 1e3 * seconds / STEPS, np.array(heights), x


def run_marbellous(mass, substeps=None):
    w = mb.World()
    w.particle_substeps = substeps
    w.add_static(mb.Plane(), friction=FRICTION)
    v, t = mb.cloth_grid(SIZE, SIZE, N, N)
    c = w.add_cloth(v, t, mass=SHEET_MASS, position=(0.0, HEIGHT, 0.0), damping=1.0, friction=FRICTION,
                    thickness=THICKNESS)
    c.pin(list(CORNERS))
    box = w.add_body(mb.Box(HALF), position=START, mass=mass, friction=FRICTION)
    most = [0]

    def step():
        w.step(DT)
        most[0] = max(most[0], w.particle_substeps_taken)
    ms, heights, x = _run(step, lambda: box.position, lambda: c.positions)
    return ms, heights, x, {"most_substeps": most[0]}


def run_marbellous_16(mass):
    return run_marbellous(mass, 16)


def run_pybullet(mass):
    import pybullet as p
    kw = {"physicsClientId": p.connect(p.DIRECT)}
    try:
        pb_deformable_world(p, kw)
        box = p.createMultiBody(mass, p.createCollisionShape(p.GEOM_BOX, halfExtents=list(np.abs(to_peer(HALF))),
                                                             **kw),
                                basePosition=list(to_peer(START)), **kw)
        p.changeDynamics(box, -1, lateralFriction=FRICTION, **kw)
        cloth = pb_cloth(p, kw, N, (0.0, HEIGHT, 0.0), SHEET_MASS)
        for k in CORNERS:
            p.createSoftBodyAnchor(cloth, k, -1, -1, **kw)

        def box_position():
            return from_peer(np.array([p.getBasePositionAndOrientation(box, **kw)[0]]))[0]

        ms, heights, x = _run(lambda: p.stepSimulation(**kw), box_position,
                              lambda: from_peer(p.getMeshData(cloth, -1, flags=p.MESH_DATA_SIMULATION_MESH,
                                                              **kw)[1]))
        return ms, heights, x, {}
    finally:
        p.disconnect(**kw)


def run_mujoco(mass):
    import mujoco
    h = SIZE / (N - 1)
    half = np.abs(to_peer(HALF))
    xml = (
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -{G:.17g}" integrator="implicitfast"/>'
        f'<worldbody><geom type="plane" size="50 50 1" friction="{FRICTION:.17g} 0.005 0.0001"/>'
        f'<body name="box" pos="{_f(to_peer(START))}"><freejoint/>'
        f'<geom type="box" size="{_f(half)}" mass="{mass:.17g}" friction="{FRICTION:.17g} 0.005 0.0001"/></body>'
        f'<flexcomp name="cloth" type="grid" dim="2" count="{N} {N} 1" spacing="{h:.17g} {h:.17g} {h:.17g}" '
        f'pos="{_f(to_peer((0.0, HEIGHT, 0.0)))}" radius="{0.5 * THICKNESS:.17g}" mass="{SHEET_MASS:.17g}">'
        f'<contact condim="3" friction="{FRICTION:.17g} 0.005 0.0001" selfcollide="auto"/>'
        f'<edge equality="true"/><pin id="{" ".join(str(k) for k in CORNERS)}"/></flexcomp></worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body = model.body("box").id
    ms, heights, x = _run(lambda: mujoco.mj_step(model, data), lambda: from_peer(data.xpos[body:body + 1])[0],
                          lambda: from_peer(data.flexvert_xpos))
    if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
        raise RuntimeError("MuJoCo flagged the run unstable (NaN or huge accelerations) and reset the state")
    return ms, heights, x, {}


RUNS = {"marbellous": run_marbellous, "marbellous-16": run_marbellous_16, "pybullet": run_pybullet,
        "mujoco": run_mujoco}


def _as_result(measured):
    """A run's ``(ms, heights, sheet, extra)`` as the results dict (module docstring)."""
    ms, heights, x, extra = measured
    return {"ms_per_step": ms, "box_height_m": float(heights[-1]),
            "held": bool(heights[-1] - HALF[1] > 0.3),
            "last_second_mm": float(1e3 * np.ptp(heights[-60:])), "sheet_lowest_m": float(x[:, 1].min()), **extra}


def main():
    args = bench_arguments(__doc__, list(RUNS))
    results = {}
    for mass in MASSES:
        for name, run in RUNS.items():
            if name not in args.engines:
                continue
            try:
                r = _as_result(run(mass))
            except ImportError:
                continue
            except RuntimeError as e:
                r = {"failed": str(e)}
            results.setdefault(f"{mass:g}", {})[name] = r
            print(f"  {mass:g} kg {name}: {r}", file=sys.stderr, flush=True)
    print(f"a {HALF[0] * 2:g} x {HALF[1] * 2:g} x {HALF[2] * 2:g} m box dropped {DROP} m onto a {SIZE:g} m sheet of "
          f"{N} x {N} ({SHEET_MASS} kg) held by its corners, {STEPS} steps at 60 Hz")
    print(f"{'kg':>4s} {'engine':16s} {'ms/step':>8s} {'held':>5s} {'box y (m)':>10s} {'last s (mm)':>12s} "
          f"{'sheet low (m)':>14s}")
    for mass, by_engine in results.items():
        for name, r in by_engine.items():
            if "failed" in r:
                print(f"{mass:>4s} {name:16s} failed: {r['failed']}")
                continue
            print(f"{mass:>4s} {name:16s} {r['ms_per_step']:8.2f} {str(r['held']):>5s} {r['box_height_m']:10.3f} "
                  f"{r['last_second_mm']:12.2f} {r['sheet_lowest_m']:14.3f}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco") if e in args.engines})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "cloth_load", "machine": machine, "engines": args.engines, "steps": STEPS,
                       "dt": DT, "sheet": {"n": N, "side_m": SIZE, "mass_kg": SHEET_MASS, "height_m": HEIGHT},
                       "box_half_m": HALF, "drop_m": DROP, "friction": FRICTION, "thickness_m": THICKNESS,
                       "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
