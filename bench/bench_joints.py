"""Chains of ball joints, side by side with PyBullet and MuJoCo: cost per step and how well the joints hold.

The scene: ``chains`` chains of ``links`` boxes (0.2 kg, 8 cm long, 2 cm apart at their ends, so that
neighbours never touch), each hanging from the world by a ball joint and joined to the next at the middle
of the gap, let go at 0.5 rad from the vertical so that they swing; 60 Hz, gravity 9.81.
- Marbellous: ``add_ball_joint`` (sequential impulses, its defaults: 4 sub-steps, 4 iterations);
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
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import marbellous as mb  # noqa: E402
from bench.peers.axes import from_peer, quat_to_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco  # noqa: E402

DT = 1.0 / 60.0
HALF = (0.02, 0.04, 0.02)       # a link's half extents (m): 8 cm along the chain
PITCH = 0.1                     # link centres 10 cm apart; the joints halfway between the ends
MASS = 0.2
TILT = 0.5


def layout(chains, links):
    """For each chain and link: (centre, orientation) in Marbellous axes, and each joint's world anchor
    (the first on the world)."""
    s, c = math.sin(TILT), math.cos(TILT)
    q = (math.cos(TILT / 2), 0.0, 0.0, math.sin(TILT / 2))
    out = []
    for n in range(chains):
        top = np.array([0.0, 3.0, 0.5 * n])
        down = np.array([s, -c, 0.0])
        centres = [top + down * PITCH * (k + 0.5) for k in range(links)]
        anchors = [top + down * PITCH * k for k in range(links)]
        out.append((centres, q, anchors))
    return out


def gap_of(positions, orientations, anchors_local):
    """Widest distance (m) between the two sides' anchors: ``anchors_local`` holds, per joint, (parent or -1,
    parent-local anchor or world point, child, child-local anchor)."""
    worst = 0.0
    for parent, pa, child, ca in anchors_local:
        world_c = positions[child] + _rot(orientations[child]) @ ca
        world_p = pa if parent < 0 else positions[parent] + _rot(orientations[parent]) @ pa
        worst = max(worst, float(np.linalg.norm(world_c - world_p)))
    return worst


def _rot(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _local_anchors(chains, links):
    """(parent or -1, parent-local anchor (None for the world: filled in later), child, child-local anchor)
    per joint: a link's local +y points up the chain, its joints at +-PITCH/2 along it."""
    out = []
    for n in range(chains):
        for k in range(links):
            child = n * links + k
            top = np.array([0.0, PITCH / 2, 0.0])
            if k == 0:
                out.append((-1, None, child, top))
            else:
                out.append((child - 1, np.array([0.0, -PITCH / 2, 0.0]), child, top))
    return out


def run_marbellous(chains, links, steps):
    w = mb.World(sleeping=False)
    bodies, joints = [], []
    for centres, q, anchors in layout(chains, links):
        prev = None
        for k in range(links):
            b = w.add_body(mb.Box(HALF), mass=MASS, position=centres[k], orientation=q)
            joints.append(w.add_ball_joint(b, prev, anchor=anchors[k]))
            bodies.append(b)
            prev = b
    w.step(DT)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        w.step(DT)
        seconds += time.perf_counter() - t
        worst = max(worst, max(j.separation for j in joints))
    return 1e3 * seconds / steps, worst


def run_pybullet(chains, links, steps):
    p, kw = direct_client(DT)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(HALF), **kw)
    ids, worlds = [], []
    anchors = _local_anchors(chains, links)
    for centres, q, world_anchors in layout(chains, links):
        for k in range(links):
            qp = quat_to_peer(q)
            bid = p.createMultiBody(MASS, shape, basePosition=list(to_peer(centres[k])),
                                    baseOrientation=[qp[1], qp[2], qp[3], qp[0]], **kw)
            p.changeDynamics(bid, -1, linearDamping=0.0, angularDamping=0.0, **kw)
            ids.append(bid)
        worlds += [to_peer(world_anchors[0])]
    n_world = 0
    for parent, pa, child, ca in anchors:
        if parent < 0:
            # (to the world: the body is the constraint's parent and the world point its child frame)
            c = p.createConstraint(ids[child], -1, -1, -1, p.JOINT_POINT2POINT, [0, 0, 0], list(ca),
                                   list(worlds[n_world]), **kw)
            n_world += 1
        else:
            c = p.createConstraint(ids[parent], -1, ids[child], -1, p.JOINT_POINT2POINT, [0, 0, 0], list(pa),
                                   list(ca), **kw)
            p.setCollisionFilterPair(ids[parent], ids[child], -1, -1, 0, **kw)
        p.changeConstraint(c, maxForce=1e9, **kw)
    world_points = [from_peer(wp) for wp in worlds]
    p.stepSimulation(**kw)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        p.stepSimulation(**kw)
        seconds += time.perf_counter() - t
        pos, orn = [], []
        for bid in ids:
            x, r = p.getBasePositionAndOrientation(bid, **kw)
            pos.append(from_peer(np.array(x)))
            orn.append(_quat_from_peer(np.array([r[3], r[0], r[1], r[2]])))
        worst = max(worst, _gaps(pos, orn, anchors, world_points))
    p.disconnect(**kw)
    return 1e3 * seconds / steps, worst


def _quat_from_peer(qp):
    """A peer (w, x, y, z) orientation back in Marbellous axes: q = q_R* q_peer."""
    w1, x1, y1, z1 = math.sqrt(0.5), -math.sqrt(0.5), 0.0, 0.0
    w2, x2, y2, z2 = qp
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _gaps(pos, orn, anchors, world_points):
    filled, n = [], 0
    for parent, pa, child, ca in anchors:
        if parent < 0:
            filled.append((parent, world_points[n], child, ca))
            n += 1
        else:
            filled.append((parent, pa, child, ca))
    return gap_of(pos, orn, filled)


def run_mujoco(chains, links, steps):
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


RUNS = {"marbellous": run_marbellous, "pybullet": run_pybullet, "mujoco": run_mujoco}


def main():
    args = bench_arguments(__doc__)
    chains, links, steps = (2, 10, 30) if args.quick else (10, 20, 600)
    results = {name: r if isinstance(r, dict) else {"ms_per_step": r[0], "widest_gap_m": r[1]}
               for name, r in best_results(RUNS, args.repeats, chains, links, steps).items()}
    base = results["marbellous"]["ms_per_step"]
    print(f"{chains} chains x {links} ball-jointed links, {steps} steps at 60 Hz")
    print(f"{'engine':12s} {'ms/step':>9s} {'x marbellous':>13s} {'widest gap (m)':>15s}")
    for name, r in results.items():
        if "failed" in r:
            print(f"{name:12s} {r['failed']}")
        else:
            print(f"{name:12s} {r['ms_per_step']:9.3f} {r['ms_per_step'] / base:13.2f} {r['widest_gap_m']:15.2e}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"chains": chains, "links": links, "steps": steps, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
