"""Chains of ball joints, side by side with PyBullet and MuJoCo: cost per step and how well the joints hold.

The scene (``bench/chains.py``, also ``python -m bench --scenes chains``): ``chains`` chains of ``links``
boxes (0.2 kg, 8 cm long, 2 cm apart at their ends, so that neighbours never touch), each hanging from the
world by a ball joint and joined to the next at the middle of the gap, let go at 0.5 rad from the vertical so
that they swing; 60 Hz, gravity 9.81.
- Marbellous: ``add_ball_joint`` (sequential impulses, its defaults: 4 sub-steps, 4 iterations), and again at
  one sub-step and 2 iterations (``marbellous-1-substep``: each chain is a tree of joints, solved exactly
  whatever the budget);
- PyBullet: single-link multibodies (its default) joined by ``JOINT_POINT2POINT`` constraints (10 solver
  iterations, its default; the joined pairs' collisions switched off as Marbellous does);
- MuJoCo: each chain one kinematic tree of ball joints (PGS, 10 iterations, its ``implicitfast``
  integrator: with its default Euler the chains went unstable at 1.17 s, NaN accelerations, and MuJoCo
  reset them; with ``implicitfast`` too, at the same time), the reduced-coordinate way: its joints cannot
  open at all, so its "widest gap" is 0 by construction; a run that MuJoCo flags unstable is reported as
  failed, not timed.
Reported per engine: ms per step (the ``step()`` calls only, best of ``--repeats``) and the widest gap
(m) between a joint's two anchors over the run, computed from the bodies' poses.

    python bench/bench_joints.py [--quick] [--json FILE]
"""
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.chains import HALF, MASS, PITCH, JointGaps, chain_joints, chain_world, layout  # noqa: E402
from bench.peers.axes import from_peer, quat_from_peer, quat_to_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco  # noqa: E402

DT = 1.0 / 60.0


def run_marbellous(chains, links, steps, substeps=None, iterations=None):
    """Marbellous' ms per step and widest gap (m, its joints' own ``separation``, every step), at its defaults
    or the given sub-steps and iterations."""
    w, joints = chain_world(chains, links)
    w.substeps, w.iterations = substeps, iterations
    w.step(DT)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        w.step(DT)
        seconds += time.perf_counter() - t
        worst = max(worst, max(j.separation for j in joints))
    return 1e3 * seconds / steps, worst


def run_pybullet(chains, links, steps):
    """PyBullet's ms per step and widest gap (m, from its bodies' poses, every step)."""
    p, kw = direct_client(DT)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(HALF), **kw)
    ids, centres, orientations = [], [], []
    for chain_centres, q, _ in layout(chains, links):
        qp = quat_to_peer(q)
        for c in chain_centres:
            bid = p.createMultiBody(MASS, shape, basePosition=list(to_peer(c)),
                                    baseOrientation=[qp[1], qp[2], qp[3], qp[0]], **kw)
            p.changeDynamics(bid, -1, linearDamping=0.0, angularDamping=0.0, **kw)
            ids.append(bid)
            centres.append(c)
            orientations.append(q)
    joints = chain_joints(chains, links)
    gaps = JointGaps(joints, centres, orientations)
    for k, (child, parent, anchor) in enumerate(joints):
        if parent < 0:
            # (to the world: the body is the constraint's parent and the world point its child frame)
            c = p.createConstraint(ids[child], -1, -1, -1, p.JOINT_POINT2POINT, [0, 0, 0], list(gaps.local_a[k]),
                                   list(to_peer(anchor)), **kw)
        else:
            c = p.createConstraint(ids[parent], -1, ids[child], -1, p.JOINT_POINT2POINT, [0, 0, 0],
                                   list(gaps.local_b[k]), list(gaps.local_a[k]), **kw)
            p.setCollisionFilterPair(ids[parent], ids[child], -1, -1, 0, **kw)
        p.changeConstraint(c, maxForce=1e9, **kw)
    p.stepSimulation(**kw)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        p.stepSimulation(**kw)
        seconds += time.perf_counter() - t
        poses = [p.getBasePositionAndOrientation(bid, **kw) for bid in ids]
        pos = from_peer(np.array([x for x, _ in poses]))
        orn = quat_from_peer(np.array([[r[3], r[0], r[1], r[2]] for _, r in poses]))
        worst = max(worst, float(gaps(pos, orn).max()))
    p.disconnect(**kw)
    return 1e3 * seconds / steps, worst


def run_mujoco(chains, links, steps):
    """MuJoCo's ms per step and widest gap (0: its tree's joints cannot open)."""
    import mujoco
    parts = []
    for centres, q, _ in layout(chains, links):
        qp = quat_to_peer(q)
        xml = ""
        for k in reversed(range(links)):
            pos = to_peer(centres[k]) if k == 0 else np.array([0.0, 0.0, 0.0])
            body = (f'<body pos="{_f(pos)}" quat="{_f(qp)}">' if k == 0 else
                    f'<body pos="{_f(np.array([0.0, -PITCH, 0.0]))}">')
            xml = (body + f'<joint type="ball" pos="0 {PITCH / 2:.17g} 0"/>'
                   f'<geom type="box" size="{_f(HALF)}" mass="{MASS}"/>' + xml + '</body>')
        parts.append(xml)
    model_xml = (f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -9.81" solver="PGS" iterations="10" '
                 f'integrator="implicitfast"/>'
                 f'<worldbody>{"".join(parts)}</worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_string(model_xml)
    return time_mujoco(model, mujoco.MjData(model), steps, "the chains"), 0.0


def run_marbellous_one_substep(chains, links, steps):
    """:func:`run_marbellous` at one sub-step and 2 iterations."""
    return run_marbellous(chains, links, steps, substeps=1, iterations=2)


RUNS = {"marbellous": run_marbellous, "marbellous-1-substep": run_marbellous_one_substep, "pybullet": run_pybullet,
        "mujoco": run_mujoco}


def main():
    args = bench_arguments(__doc__)
    chains, links, steps = (2, 10, 30) if args.quick else (10, 20, 600)
    results = {name: r if isinstance(r, dict) else {"ms_per_step": r[0], "widest_gap_m": r[1]}
               for name, r in best_results(RUNS, args.repeats, chains, links, steps).items()}
    base = results["marbellous"]["ms_per_step"]
    print(f"{chains} chains x {links} ball-jointed links, {steps} steps at 60 Hz")
    print(f"{'engine':20s} {'ms/step':>9s} {'x marbellous':>13s} {'widest gap (m)':>15s}")
    for name, r in results.items():
        if "failed" in r:
            print(f"{name:20s} {r['failed']}")
        else:
            print(f"{name:20s} {r['ms_per_step']:9.3f} {r['ms_per_step'] / base:13.2f} {r['widest_gap_m']:15.2e}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"chains": chains, "links": links, "steps": steps, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
