"""A pile of convex hulls, side by side with PyBullet and MuJoCo: cost per step and how the pile comes to rest.

The scene: ``count`` random convex hulls (``numpy.random.default_rng(SEED)``), each ``mb.ConvexHull`` of 12
normal samples scaled so that the farthest lies 0.15 to 0.3 m from their mean (for 64: 7 to 12 corners,
0.7 to 13.6 kg at 1000 kg/m^3, 332 kg in all), turned at random and dropped from four staggered layers of
a square grid (spacing so that no two bounding spheres overlap, the lowest layer 0.5 m up, 0.8 m between
layers) onto a ground plane; 60 Hz, gravity 9.81, friction 0.6, the same shapes, poses and masses in every
engine, all bodies awake throughout.
- Marbellous: its defaults (sequential impulses, 4 sub-steps, 4 iterations, continuous collision on),
  ``sleeping=False``; and again as ``marbellous-noccd`` with ``ccd=False`` (the peers have none on);
- PyBullet: one ``GEOM_MESH`` of the hull's corners per body (Bullet's ``btConvexHullShape``, with its
  default collision margin of 1 mm, the hull rests that far above what it touches) as a maximal-coordinate
  rigid body, in the hull's principal axes with its exact principal moments (``localInertiaDiagonal``);
  its default solver (10 iterations), no damping (its default 0.04 off, as Marbellous has none), sleeping
  off; Bullet multiplies two bodies' friction, so each gets ``sqrt(0.6)``;
- MuJoCo: one mesh geom of the hull's corners per body (MuJoCo collides a mesh as its convex hull), a free
  joint each, mass and inertia from density 1000 over the mesh (MuJoCo's own; they agree with the hull's
  to 1e-7), its defaults (Newton solver, Euler integrator, pyramidal friction cones, soft contacts); and
  again as ``mujoco-implicitfast``, the same but for the ``implicitfast`` integrator that MuJoCo
  recommends (with Euler the full pile goes unstable at 1.0 s).
  A run that MuJoCo flags unstable is reported as failed, not timed.
Reported per engine: ms per step (the ``step()`` calls only, best of ``--repeats``), the lowest point of any
hull at the end relative to the ground (m, from each body's pose and the hull's corners; below 0: sunk into
the ground), how many hulls still move faster than 0.05 m/s at the end, and the total kinetic energy at the
end (J, from each body's velocities and the hull's exact mass properties).  An engine whose bodies end with
non-finite poses is reported as failed.

    python bench/bench_hulls.py [--quick] [--json FILE]
"""
import json
import math
import os
import sys
import time

import numpy as np
from scipy.spatial.transform import Rotation

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

import marbellous as mb  # noqa: E402
from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402
from bench.peers.axes import R as PEER_AXES  # noqa: E402
from bench.peers.axes import quat_to_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco, time_pybullet  # noqa: E402

DT = 1.0 / 60.0
SEED = 20261202
POINTS = 12                 # random points per hull
RADII = (0.15, 0.3)         # the farthest point from the points' mean (m)
DENSITY = 1000.0
FRICTION = 0.6
LAYERS = 4
LOWEST = 0.5                # height of the lowest layer's centres (m)
LAYER = 0.8                 # height between layers (m)
MOVING = 0.05               # a hull faster than this (m/s) is still moving


def hulls(count):
    """The ``count`` hulls of the scene, the same on every call."""
    rng = np.random.default_rng(SEED)
    out = []
    for _ in range(count):
        p = rng.normal(size=(POINTS, 3))
        p -= p.mean(axis=0)
        p *= rng.uniform(*RADII) / np.linalg.norm(p, axis=1).max()
        out.append(mb.ConvexHull(p))
    return out


def poses(shapes):
    """Where each hull starts: centres of mass (m, Marbellous axes, y up) on ``LAYERS`` staggered layers of
    a square grid, and random (w, x, y, z) orientations."""
    rng = np.random.default_rng(SEED + 1)
    count = len(shapes)
    side = max(1, math.ceil(math.sqrt(count / LAYERS)))
    reach = max(s.bounding_radius() for s in shapes)
    spacing = math.ceil((2.0 * reach + 0.05) / 0.05) * 0.05
    assert LAYER > 2.0 * reach and LOWEST > reach, "the hulls would start overlapping"
    positions, orientations = [], []
    for k in range(count):
        layer, slot = divmod(k, side * side)
        row, col = divmod(slot, side)
        stagger = 0.25 * spacing * (layer % 2)
        positions.append(np.array([spacing * (col - 0.5 * (side - 1)) + stagger, LOWEST + LAYER * layer,
                                   spacing * (row - 0.5 * (side - 1)) + stagger]))
        q = rng.normal(size=4)
        orientations.append(q / np.linalg.norm(q))
    return positions, orientations


def _matrix(q):
    """The rotation matrix of a (w, x, y, z) quaternion."""
    return Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()


def measures(shapes, positions, rotations, velocities, spins):
    """``(lowest point (m), hulls moving, kinetic energy (J))`` from each body's centre of mass, rotation
    (hull frame to world), velocity and angular velocity (world frame), all in Marbellous axes (y up).
    Raises RuntimeError when a pose or velocity is not finite (the engine blew up)."""
    if not all(np.all(np.isfinite(a)) for a in (positions, rotations, velocities, spins)):
        raise RuntimeError("non-finite poses or velocities at the end (the pile blew up)")
    lowest, moving, energy = math.inf, 0, 0.0
    for s, x, r, v, w in zip(shapes, positions, rotations, velocities, spins):
        lowest = min(lowest, float(np.min(s.vertices @ r[1]) + x[1]))
        moving += int(np.linalg.norm(v) > MOVING)
        m, inertia = s.mass_properties(DENSITY)
        energy += 0.5 * m * float(v @ v) + 0.5 * float(w @ (r @ inertia @ r.T) @ w)
    return lowest, moving, energy


def run_marbellous(count, steps, ccd=True):
    shapes = hulls(count)
    w = mb.World(sleeping=False, ccd=ccd)
    w.add_static(mb.Plane(), friction=FRICTION)
    bodies = [w.add_body(s, position=x, orientation=q, density=DENSITY, friction=FRICTION)
              for s, x, q in zip(shapes, *poses(shapes))]
    w.step(DT)
    seconds = 0.0
    for _ in range(steps):
        t = time.perf_counter()
        w.step(DT)
        seconds += time.perf_counter() - t
    return (1e3 * seconds / steps, *measures(shapes, [b.position for b in bodies],
                                             [_matrix(b.orientation) for b in bodies],
                                             [b.velocity for b in bodies], [b.angular_velocity for b in bodies]))


def _principal(shape):
    """The hull's principal moments at ``DENSITY`` (kg m^2) and the rotation ``E`` (columns: the principal
    axes in the hull's frame, det +1)."""
    moments, e = np.linalg.eigh(shape.mass_properties(DENSITY)[1])
    if np.linalg.det(e) < 0.0:
        e[:, 2] = -e[:, 2]
    return moments, e


def run_pybullet(count, steps):
    shapes = hulls(count)
    mu = math.sqrt(FRICTION)        # Bullet multiplies the two coefficients
    p, kw = direct_client(DT, ground_friction=mu)
    ids, frames = [], []
    for s, x, q in zip(shapes, *poses(shapes)):
        moments, e = _principal(s)
        sid = p.createCollisionShape(p.GEOM_MESH, vertices=(s.vertices @ e).tolist(), **kw)
        turn = PEER_AXES @ _matrix(q) @ e        # the principal frame in peer axes
        mass = s.mass_properties(DENSITY)[0]
        bid = p.createMultiBody(mass, sid, basePosition=list(to_peer(x)),
                                baseOrientation=list(Rotation.from_matrix(turn).as_quat()),
                                useMaximalCoordinates=True, **kw)
        # (the mass again: for a maximal-coordinate body, setting the inertia alone sets its mass to 0)
        p.changeDynamics(bid, -1, mass=mass, localInertiaDiagonal=list(moments), lateralFriction=mu,
                         linearDamping=0.0, angularDamping=0.0, activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING,
                         **kw)
        ids.append(bid)
        frames.append(e)
    ms = time_pybullet(p, kw, steps)
    xs, rots, vs, ws = [], [], [], []
    for bid, e in zip(ids, frames):
        x, r = p.getBasePositionAndOrientation(bid, **kw)
        v, w = p.getBaseVelocity(bid, **kw)
        xs.append(PEER_AXES.T @ np.array(x))
        rots.append(PEER_AXES.T @ np.array(p.getMatrixFromQuaternion(r)).reshape(3, 3) @ e.T)
        vs.append(PEER_AXES.T @ np.array(v))
        ws.append(PEER_AXES.T @ np.array(w))
    p.disconnect(**kw)
    return (ms, *measures(shapes, xs, rots, vs, ws))


def mujoco_model(shapes, integrator="Euler"):
    """The scene as an MJCF model: a mesh asset per hull (its corners in the hull's frame) and a body with a
    free joint per hull, at its pose in peer axes; ``integrator`` as MuJoCo names them (its default Euler)."""
    import mujoco
    meshes = "".join(f'<mesh name="h{k}" vertex="{_f(s.vertices)}"/>' for k, s in enumerate(shapes))
    bodies = "".join(f'<body pos="{_f(to_peer(x))}" quat="{_f(quat_to_peer(q))}"><freejoint/>'
                     f'<geom type="mesh" mesh="h{k}"/></body>' for k, (x, q) in enumerate(zip(*poses(shapes))))
    return mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -9.81" integrator="{integrator}"/>'
        f'<default><geom friction="{FRICTION:.17g} 0.005 0.0001" density="{DENSITY:.17g}"/></default>'
        f'<asset>{meshes}</asset><worldbody><geom type="plane" size="50 50 1"/>{bodies}</worldbody></mujoco>')


def run_mujoco(count, steps, integrator="Euler"):
    import mujoco
    shapes = hulls(count)
    model = mujoco_model(shapes, integrator)
    data = mujoco.MjData(model)
    ms = time_mujoco(model, data, steps, f"the pile of hulls ({integrator})")
    mujoco.mj_forward(model, data)          # poses of the final qpos (xpos lags a step behind mj_step)
    rots = [PEER_AXES.T @ data.xmat[1 + k].reshape(3, 3) for k in range(count)]
    adr = model.jnt_dofadr[:count]
    vs = [PEER_AXES.T @ data.qvel[a:a + 3] for a in adr]
    ws = [PEER_AXES.T @ (data.xmat[1 + k].reshape(3, 3) @ data.qvel[a + 3:a + 6]) for k, a in enumerate(adr)]
    return (ms, *measures(shapes, [PEER_AXES.T @ data.xpos[1 + k] for k in range(count)], rots, vs, ws))


def run_mujoco_implicitfast(count, steps):
    return run_mujoco(count, steps, "implicitfast")


def run_marbellous_no_ccd(count, steps):
    return run_marbellous(count, steps, ccd=False)


RUNS = {"marbellous": run_marbellous, "marbellous-noccd": run_marbellous_no_ccd, "pybullet": run_pybullet,
        "mujoco": run_mujoco, "mujoco-implicitfast": run_mujoco_implicitfast}


def main():
    args = bench_arguments(__doc__)
    count, steps = (16, 60) if args.quick else (64, 300)
    shapes = hulls(count)
    results = {name: r if isinstance(r, dict) else {"ms_per_step": r[0], "lowest_point_m": r[1], "moving": r[2],
                                                     "kinetic_energy_j": r[3]}
               for name, r in best_results(RUNS, args.repeats, count, steps).items()}
    masses = [s.mass_properties(DENSITY)[0] for s in shapes]
    corners = [len(s.vertices) for s in shapes]
    print(f"{count} convex hulls ({min(corners)} to {max(corners)} corners, {min(masses):.2f} to {max(masses):.1f} "
          f"kg, {sum(masses):.0f} kg in all) dropped into a pile, {steps} steps at 60 Hz")
    base = results.get("marbellous", {}).get("ms_per_step")
    print(f"{'engine':20s} {'ms/step':>9s} {'marbellous/x':>13s} {'lowest point (m)':>17s} {'moving':>7s} "
          f"{'kinetic (J)':>12s}")
    for name, r in results.items():
        if "failed" in r:
            print(f"{name:20s} failed: {r['failed']}")
            continue
        ratio = f"{base / r['ms_per_step']:13.2f}" if base else f"{'-':>13s}"
        print(f"{name:20s} {r['ms_per_step']:9.3f} {ratio} {r['lowest_point_m']:17.4f} {r['moving']:7d} "
              f"{r['kinetic_energy_j']:12.3g}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco")})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "hulls", "machine": machine, "quick": args.quick, "hulls": count,
                       "steps": steps, "dt": DT, "repeats": args.repeats, "seed": SEED, "corners": corners,
                       "masses_kg": masses, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
