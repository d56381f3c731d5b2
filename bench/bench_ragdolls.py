"""A pile of ragdolls, side by side with PyBullet and MuJoCo: cost per step and how well the joints hold.

The scene: ``count`` ragdolls of ``marbellous.scenes.ragdoll`` (ten capsules and a sphere, 67 kg, 1.9 m),
standing in two layers of a 2 x ``count / 4`` grid 0.7 m apart, the upper layer 2.2 m up, dropped onto a
ground plane so that they fall and tangle into a pile; 60 Hz, gravity 9.81.
- Marbellous: ball joints at the neck, shoulders and hips, limited hinges at the elbows and knees
  (sequential impulses, its defaults: 4 sub-steps, 4 iterations);
- PyBullet: one single-link multibody per part (its default) joined by ``JOINT_POINT2POINT`` constraints
  (10 solver iterations, its default; the joined pairs' collisions switched off as Marbellous does).  Its
  constraints between free bodies have no revolute kind, so elbows and knees are ball joints there, without
  limits: a simpler scene than Marbellous'.
- MuJoCo: each ragdoll one kinematic tree rooted at its torso (a free joint), ball joints and limited
  hinges as Marbellous has them, with MuJoCo's defaults (Newton solver, Euler integrator: with PGS at 10
  iterations and ``implicitfast``, as in ``bench_joints.py``, the pile went unstable at 1.03 s); its
  joints cannot open (reduced coordinates), so its widest gap is 0 by construction.  A run that MuJoCo
  flags unstable is reported as failed, not timed.
Reported per engine: ms per step (the ``step()`` calls only, best of ``--repeats``), the widest gap (m)
between a joint's two anchors over the run, and the lowest body centre at the end (m; below 0: through the
ground).

    python bench/bench_ragdolls.py [--quick] [--json FILE]
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
from bench.peers.axes import quat_to_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco  # noqa: E402
from marbellous.scenes.articulated import RAGDOLL_JOINTS, RAGDOLL_PARTS, ragdoll  # noqa: E402

DT = 1.0 / 60.0
SPACING = 0.7
LAYER = 2.2


def feet(count):
    """Where each ragdoll stands (m): two layers of a 2 x (count / 4) grid."""
    per_layer = max(1, count // 2)
    out = []
    for k in range(count):
        layer, slot = divmod(k, per_layer)
        row, col = divmod(slot, 2)
        out.append(np.array([SPACING * (col - 0.5) + 0.1 * layer, LAYER * layer + 0.01, SPACING * row]))
    return out


def run_marbellous(count, steps):
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane(), friction=0.6)
    bodies, joints = [], []
    for at in feet(count):
        parts, js = ragdoll(w, position=at)
        bodies += list(parts.values())
        joints += js
    w.step(DT)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        w.step(DT)
        seconds += time.perf_counter() - t
        worst = max(worst, max(j.separation for j in joints))
    return 1e3 * seconds / steps, worst, min(float(b.position[1]) for b in bodies)


#: a PyBullet capsule lies along its local z; the parts' capsules along their local y
_Z_TO_Y = [-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)]


def run_pybullet(count, steps):
    p, kw = direct_client(DT, ground_friction=0.6)
    shapes = {}
    for name, (shape, _, _) in RAGDOLL_PARTS.items():
        if isinstance(shape, mb.Sphere):
            shapes[name] = p.createCollisionShape(p.GEOM_SPHERE, radius=shape.radius, **kw)
        else:
            shapes[name] = p.createCollisionShape(p.GEOM_CAPSULE, radius=shape.radius,
                                                  height=2.0 * shape.half_height, collisionFrameOrientation=_Z_TO_Y,
                                                  **kw)
    qp = quat_to_peer((1.0, 0.0, 0.0, 0.0))
    orientation = [qp[1], qp[2], qp[3], qp[0]]
    ids, joints = [], []
    for at in feet(count):
        part = {}
        for name, (_, centre, mass) in RAGDOLL_PARTS.items():
            bid = p.createMultiBody(mass, shapes[name], basePosition=list(to_peer(at + np.array(centre))),
                                    baseOrientation=orientation, **kw)
            p.changeDynamics(bid, -1, lateralFriction=0.6, linearDamping=0.0, angularDamping=0.0, **kw)
            part[name] = bid
            ids.append(bid)
        for _, a, b, anchor, _, _ in RAGDOLL_JOINTS:
            ra = np.array(anchor) - np.array(RAGDOLL_PARTS[a][1])      # body frames are Marbellous' own
            rb = np.array(anchor) - np.array(RAGDOLL_PARTS[b][1])
            c = p.createConstraint(part[a], -1, part[b], -1, p.JOINT_POINT2POINT, [0, 0, 0], list(ra), list(rb),
                                   **kw)
            p.changeConstraint(c, maxForce=1e9, **kw)
            p.setCollisionFilterPair(part[a], part[b], -1, -1, 0, **kw)
            joints.append((part[a], ra, part[b], rb))
    p.stepSimulation(**kw)
    worst, seconds = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        p.stepSimulation(**kw)
        seconds += time.perf_counter() - t
        for a, ra, b, rb in joints:
            worst = max(worst, float(np.linalg.norm(_world(p, a, ra, kw) - _world(p, b, rb, kw))))
    lowest = min(float(p.getBasePositionAndOrientation(i, **kw)[0][2]) for i in ids)
    p.disconnect(**kw)
    return 1e3 * seconds / steps, worst, lowest


def _world(p, body, local, kw):
    """A body-local point (in the body's own frame) in peer world coordinates (m)."""
    x, r = p.getBasePositionAndOrientation(body, **kw)
    return np.array(x) + np.array(p.getMatrixFromQuaternion(r)).reshape(3, 3) @ local


#: the ragdoll as a tree: each part's parent (the joint that holds it is the one between them)
_PARENT = {a: b for _, a, b, _, _, _ in RAGDOLL_JOINTS}


def _mjcf_part(name, at):
    """The MJCF of part ``name`` and the parts it carries, its frame at the part's centre (peer axes, no
    rotation: the parts stand as Marbellous builds them); ``at`` is the parent frame's origin in the
    ragdoll's own coordinates (m, Marbellous axes; for the torso, minus where the ragdoll stands)."""
    shape, centre, mass = RAGDOLL_PARTS[name]
    centre = np.array(centre)
    if name in _PARENT:
        kind, _, _, anchor, axis, limits = next(j for j in RAGDOLL_JOINTS if j[1] == name)
        joint = (f'<joint type="ball" pos="{_f(to_peer(np.array(anchor) - centre))}"/>' if kind == "ball" else
                 f'<joint type="hinge" pos="{_f(to_peer(np.array(anchor) - centre))}" axis="{_f(to_peer(axis))}" '
                 f'limited="true" range="{limits[0]:.17g} {limits[1]:.17g}"/>')
    else:
        joint = '<freejoint/>'
    if isinstance(shape, mb.Sphere):
        geom = f'<geom type="sphere" size="{shape.radius:.17g}" mass="{mass:.17g}"/>'
    else:
        hh = shape.half_height
        geom = (f'<geom type="capsule" size="{shape.radius:.17g}" fromto="0 0 {-hh:.17g} 0 0 {hh:.17g}" '
                f'mass="{mass:.17g}"/>')
    children = "".join(_mjcf_part(child, centre) for child, parent in _PARENT.items() if parent == name)
    return f'<body pos="{_f(to_peer(centre - at))}">{joint}{geom}{children}</body>'


def run_mujoco(count, steps):
    import mujoco
    figures = "".join(_mjcf_part("torso", -at) for at in feet(count))      # the torso at its feet + centre
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><compiler angle="radian"/><option timestep="{DT:.17g}" gravity="0 0 -9.81"/>'
        f'<default><geom friction="0.6 0.005 0.0001"/></default>'
        f'<worldbody><geom type="plane" size="50 50 1"/>{figures}</worldbody></mujoco>')
    data = mujoco.MjData(model)
    ms = time_mujoco(model, data, steps, "the ragdolls")
    return ms, 0.0, float(np.min(data.xpos[1:, 2]))


RUNS = {"marbellous": run_marbellous, "pybullet": run_pybullet, "mujoco": run_mujoco}


def main():
    args = bench_arguments(__doc__)
    count, steps = (2, 30) if args.quick else (16, 300)
    results = {name: r if isinstance(r, dict) else {"ms_per_step": r[0], "widest_gap_m": r[1],
                                                     "lowest_centre_m": r[2]}
               for name, r in best_results(RUNS, args.repeats, count, steps).items()}
    base = results["marbellous"]["ms_per_step"]
    print(f"{count} ragdolls ({count * len(RAGDOLL_PARTS)} bodies, {count * len(RAGDOLL_JOINTS)} joints) dropped "
          f"into a pile, {steps} steps at 60 Hz")
    print(f"{'engine':12s} {'ms/step':>9s} {'x marbellous':>13s} {'widest gap (m)':>15s} {'lowest centre (m)':>18s}")
    for name, r in results.items():
        if "failed" in r:
            print(f"{name:12s} {r['failed']}")
            continue
        print(f"{name:12s} {r['ms_per_step']:9.3f} {r['ms_per_step'] / base:13.2f} {r['widest_gap_m']:15.2e} "
              f"{r['lowest_centre_m']:18.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"ragdolls": count, "steps": steps, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
