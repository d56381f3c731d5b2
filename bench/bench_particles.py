"""Particles, side by side with PyBullet and MuJoCo: a heap of grains in a box, and swinging chains of rods.

Two scenes, 60 Hz, gravity 9.81, one untimed step and then 300 timed steps (5 s):
- "heap": ``N`` particles (N = 1000 and 4000; ``--quick``: 1000 only) of radius 0.05 m, mass 0.1 kg,
  friction 0.5, restitution 0, poured from a column of 10 x 10 per layer (pitch 0.12 m, the lowest layer
  0.2 m up, ``N / 100`` layers, each layer half a pitch along x and z from the one below, each centre jittered
  by up to 5 mm per axis by ``numpy.random.default_rng(SEED)``) into an open box: a ground plane and four
  static box walls 2 m high around a floor of 2 m x 2 m, friction 0.5 on all of them.  The column collapses
  on landing and spreads to the walls (a column of aligned layers lands as a lattice that stands for seconds).
  - Marbellous: ``add_particles(collide_particles=True)``, its defaults (16 sub-steps of position-based
    dynamics per step); point masses that collide as spheres but do not turn, so they cannot roll;
  - PyBullet: each grain a ``GEOM_SPHERE`` maximal-coordinate rigid body (solid-sphere inertia), its default
    solver (10 iterations), no damping (its default 0.04 off), sleeping off; Bullet multiplies two bodies'
    friction, so each sphere, the ground and the walls get ``sqrt(0.5)``;
  - MuJoCo (``mujoco-pgs``): sphere geoms on free joints, the walls box geoms of the world body; the
    projected Gauss-Seidel solver at 10 iterations, as in ``python -m bench``'s pile (``bench/peers/
    mujoco_world.py``), its defaults otherwise (Euler integrator, pyramidal friction cones, soft contacts,
    ``condim`` 3: no rolling friction).  Not its default Newton solver: on the formed heap of 1000 it took
    17.5 s a step here (a sparse factorisation over all 6000 degrees of freedom), hours for a run.
  The peers' spheres turn and roll (no engine here has rolling friction on).  Reported per engine and N: ms per
  step (best of ``--repeats``), the slowest single step (ms), and from the final positions and velocities: the
  deepest overlap of two grains (m, ``2 r - |x_a - x_b|`` over the pairs a KD-tree finds), the deepest a grain
  is into the floor (m, ``r - y``; below 0: none touches it), how many escaped (centre outside the box's
  inside or below the floor), the highest speed at the end (m/s), how many grains still move faster than
  0.05 m/s ("settled": none), and the highest grain centre (m: how far the heap has flattened).
- "chain": 20 chains of 50 particles (0.02 kg, radius 0.01 m) 2 cm apart, joined by rods, each pinned to the
  world at its first particle 2 m up, started straight and horizontal so that they swing down (0.1 m apart
  across the swing, which they never leave; nothing collides).
  - Marbellous: one set of particles, one network of ``kind="rod"`` edges, ``pin`` of each chain's first
    particle; no damping;
  - PyBullet: 49 sphere bodies per chain (single-link multibodies, PyBullet's default, as in
    ``bench_joints``; solid-sphere inertia; collisions, damping off), each held by a ``JOINT_POINT2POINT``
    constraint whose pivot is its parent bead's centre (the pin for the first): in the bead's own frame the
    pivot lies 2 cm back along the chain, so each body is a rod with its mass at the far end, the point-mass
    chain the particles are, up to the spheres' spin inertia (2/5 m r^2, a tenth of a link's m L^2); 10
    iterations.  A multibody of 49 ``JOINT_SPHERICAL`` links would be the same chain in reduced coordinates,
    but PyBullet 3.2.7 does not report its state past 30 spherical links (the joint positions, 7 + 4 per link,
    exceed its state buffer of 128; at 49 links the first links' states read back as zeros, the last joints'
    as empty), and pivots at the beads' midpoints would make a different mechanism (the centres' distance
    then depends on the spheres' turning);
  - MuJoCo: each chain one tree of nested bodies, the pin a body welded to the world, then 49 bodies each on
    a ``ball`` joint at its parent's centre, a sphere geom 2 cm on (0.02 kg, contacts off); its defaults
    (Newton, Euler); and again as ``mujoco-implicitfast`` with the integrator MuJoCo recommends.
  Reported per engine: ms per step (best of ``--repeats``), the largest relative stretch of any link at the
  end (``|d| / L - 1``, from the sphere or particle centres), and the share of the chains' energy lost by the
  end (J lost over the 96 J a straight hanging chain would have released; kinetic energy of the centres'
  motion, the spheres' spin left out; not printed when a link is stretched by over 10%, the chain then no
  longer the same).  An engine whose positions end non-finite is reported as failed; so is a run MuJoCo flags
  unstable (NaN or huge accelerations, after which it resets the state; the time given is the first flagged
  step's).

    python bench/bench_particles.py [--quick] [--repeats N] [--json FILE]
"""
import json
import math
import os
import sys
import time

import numpy as np
from scipy.spatial import cKDTree

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

import marbellous as mb  # noqa: E402
from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402
from bench.peers.axes import from_peer, to_peer  # noqa: E402
from bench.peers.mujoco_world import mjcf_numbers as _f  # noqa: E402
from bench.peers.pybullet_world import direct_client  # noqa: E402
from bench.peers.timing import bench_arguments, best_results, time_mujoco, time_pybullet  # noqa: E402

DT = 1.0 / 60.0
G = 9.81
SEED = 20261202

# --- the heap -------------------------------------------------------------------------------------------------
RADIUS = 0.05               # a grain's radius (m)
MASS = 0.1                  # a grain's mass (kg)
FRICTION = 0.5
INSIDE = 1.0                # the box's inside: |x|, |z| < INSIDE (m)
WALL = 0.05                 # half thickness of a wall (m)
WALL_HEIGHT = 2.0           # (m)
COLUMN = 10                 # grains per row and per column of a layer of the pour
PITCH = 0.12                # distance between grains' centres in the pour (m)
LOWEST = 0.2                # height of the pour's lowest layer (m)
JITTER = 0.005              # largest random offset of a grain's centre along each axis (m)
SETTLED = 0.05              # a heap whose fastest grain is slower than this (m/s) has settled

# --- the chains -----------------------------------------------------------------------------------------------
CHAINS = 20
LINKS = 50                  # particles per chain (the first pinned: 49 rods)
BEAD_MASS = 0.02            # (kg)
BEAD_RADIUS = 0.01          # (m)
ROD = 0.02                  # rod length (m)
PIN_HEIGHT = 2.0            # (m)
CHAIN_GAP = 0.1             # between two chains' planes of swing (m)
STRETCHED = 0.1             # links stretched by more than this: the chains' energy is not worth comparing


# --- heap: the scene and its measures --------------------------------------------------------------------------
def pour(count):
    """The grains' starting centres (m, Marbellous axes, y up), ``(count, 3)``: layers of ``COLUMN`` x ``COLUMN``
    from the bottom up, centred over the box, each layer a half pitch along x and z from the one below (so that
    the column does not land as a stable lattice but falls apart into a heap), jittered; the same on every
    call."""
    layers = math.ceil(count / COLUMN ** 2)
    assert PITCH - 2.0 * RADIUS > 2.0 * JITTER, "the grains would start overlapping"
    i, k, j = np.meshgrid(np.arange(COLUMN), np.arange(COLUMN), np.arange(layers), indexing="ij")
    grid = np.column_stack([i.ravel(), j.ravel(), k.ravel()])
    grid = grid[np.lexsort((grid[:, 2], grid[:, 0], grid[:, 1]))][:count]        # bottom layer first
    shift = PITCH * np.where(grid[:, 1] % 2 == 1, 0.25, -0.25)         # alternate layers half a pitch apart
    x = np.column_stack([PITCH * (grid[:, 0] - 0.5 * (COLUMN - 1)) + shift, LOWEST + PITCH * grid[:, 1],
                         PITCH * (grid[:, 2] - 0.5 * (COLUMN - 1)) + shift])
    return x + np.random.default_rng(SEED).uniform(-JITTER, JITTER, x.shape)


def walls():
    """The four walls as ``(centre, half extents)`` in Marbellous axes (y up): their inner faces at
    ``|x| = INSIDE`` and ``|z| = INSIDE``, standing on the ground."""
    long = INSIDE + 2.0 * WALL
    out = []
    for s in (-1.0, 1.0):
        out.append((np.array([s * (INSIDE + WALL), 0.5 * WALL_HEIGHT, 0.0]), np.array([WALL, 0.5 * WALL_HEIGHT, long])))
        out.append((np.array([0.0, 0.5 * WALL_HEIGHT, s * (INSIDE + WALL)]), np.array([long, 0.5 * WALL_HEIGHT, WALL])))
    return out


def heap_measures(x, v):
    """``(deepest overlap of two grains (m), deepest into the floor (m), escaped, top speed (m/s), grains
    faster than SETTLED, highest centre (m))`` from the grains' final centres ``x`` and velocities ``v``
    (Marbellous axes); RuntimeError when any is not finite."""
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise RuntimeError("non-finite positions or velocities at the end (the heap blew up)")
    pairs = cKDTree(x).query_pairs(2.0 * RADIUS, output_type="ndarray")
    overlap = 0.0
    if len(pairs):
        overlap = float(np.max(2.0 * RADIUS - np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)))
    floor = float(np.max(RADIUS - x[:, 1]))
    escaped = int(np.count_nonzero((np.abs(x[:, 0]) > INSIDE) | (np.abs(x[:, 2]) > INSIDE) | (x[:, 1] < 0.0)))
    speed = np.linalg.norm(v, axis=1)
    return overlap, floor, escaped, float(np.max(speed)), int(np.count_nonzero(speed > SETTLED)), float(np.max(x[:, 1]))


def _timed_steps(step, steps):
    """``(ms per step, slowest step (ms))`` over ``steps`` calls of ``step`` after an untimed one."""
    step()
    seconds, slowest = 0.0, 0.0
    for _ in range(steps):
        t = time.perf_counter()
        step()
        took = time.perf_counter() - t
        seconds += took
        slowest = max(slowest, took)
    return 1e3 * seconds / steps, 1e3 * slowest


def heap_marbellous(count, steps):
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane(), friction=FRICTION)
    for centre, half in walls():
        w.add_static(mb.Box(tuple(half)), position=centre, friction=FRICTION)
    p = w.add_particles(pour(count), mass=MASS, radius=RADIUS, friction=FRICTION, collide_particles=True)
    ms, slowest = _timed_steps(lambda: w.step(DT), steps)
    return ms, slowest, *heap_measures(p.positions, p.velocities)


def heap_pybullet(count, steps):
    mu = math.sqrt(FRICTION)        # Bullet multiplies the two coefficients
    p, kw = direct_client(DT, ground_friction=mu)
    for centre, half in walls():
        wid = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=list(np.abs(to_peer(half))), **kw),
                                basePosition=list(to_peer(centre)), **kw)
        p.changeDynamics(wid, -1, lateralFriction=mu, **kw)
    sphere = p.createCollisionShape(p.GEOM_SPHERE, radius=RADIUS, **kw)
    ids = p.createMultiBody(MASS, sphere, batchPositions=to_peer(pour(count)).tolist(), useMaximalCoordinates=True,
                            **kw)
    for bid in ids:
        p.changeDynamics(bid, -1, lateralFriction=mu, linearDamping=0.0, angularDamping=0.0,
                         activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING, **kw)
    ms, slowest = _timed_steps(lambda: p.stepSimulation(**kw), steps)
    x = from_peer([p.getBasePositionAndOrientation(b, **kw)[0] for b in ids])
    v = from_peer([p.getBaseVelocity(b, **kw)[0] for b in ids])
    p.disconnect(**kw)
    return ms, slowest, *heap_measures(x, v)


def _time_mujoco(model, data, steps, what):
    """``time_mujoco`` (ms per step), and when MuJoCo flags the run unstable, a RuntimeError that says when: the
    time of the first flagged step, from an untimed replay of the same run (the run is deterministic).  A run
    whose clock does not end at ``steps + 1`` steps (MuJoCo reset the state without a warning) fails too."""
    import mujoco
    try:
        ms = time_mujoco(model, data, steps, what)
    except RuntimeError:
        replay = mujoco.MjData(model)
        for k in range(steps + 1):
            mujoco.mj_step(model, replay)
            if replay.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
                raise RuntimeError(f"MuJoCo flagged {what} unstable at {(k + 1) * DT:.2f} s (NaN or huge "
                                   f"accelerations) and reset the state") from None
        raise
    if abs(data.time - (steps + 1) * model.opt.timestep) > 1e-6:
        raise RuntimeError(f"MuJoCo reset {what} to its start (its clock reads {data.time:.2f} s)")
    return ms


def heap_mujoco(count, steps):
    import mujoco
    grains = "".join(f'<body pos="{_f(to_peer(x))}"><freejoint/><geom type="sphere" size="{RADIUS:.17g}" '
                     f'mass="{MASS:.17g}"/></body>' for x in pour(count))
    boxes = "".join(f'<geom type="box" pos="{_f(to_peer(c))}" size="{_f(np.abs(to_peer(h)))}"/>' for c, h in walls())
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -{G:.17g}" solver="PGS" iterations="10"/>'
        f'<size memory="2G"/>'
        f'<default><geom friction="{FRICTION:.17g} 0.005 0.0001"/></default>'
        f'<worldbody><geom type="plane" size="50 50 1"/>{boxes}{grains}</worldbody></mujoco>')
    data = mujoco.MjData(model)
    ms = _time_mujoco(model, data, steps, f"the heap of {count} spheres")
    q, a, d = data.qpos, model.jnt_qposadr[:count], model.jnt_dofadr[:count]
    x = from_peer(np.column_stack([q[a], q[a + 1], q[a + 2]]))    # (qpos: xpos lags a step behind mj_step)
    v = from_peer(np.column_stack([data.qvel[d], data.qvel[d + 1], data.qvel[d + 2]]))   # (world frame)
    return ms, None, *heap_measures(x, v)


HEAP_RUNS = {"marbellous": heap_marbellous, "pybullet": heap_pybullet, "mujoco-pgs": heap_mujoco}


# --- chains: the scene and its measures -----------------------------------------------------------------------
def chain_start():
    """The beads' starting centres (m, Marbellous axes), ``(CHAINS * LINKS, 3)``, chain by chain from its pin:
    straight along +x, 2 m up, the chains ``CHAIN_GAP`` apart along z."""
    k, c = np.meshgrid(np.arange(LINKS), np.arange(CHAINS))
    return np.column_stack([ROD * k.ravel(), np.full(k.size, PIN_HEIGHT),
                            CHAIN_GAP * (c.ravel() - 0.5 * (CHAINS - 1))])


def released():
    """Energy (J) that the chains, hanging straight down, would have released from the start: each bead ``k``
    falls ``k L``."""
    return CHAINS * BEAD_MASS * G * ROD * sum(range(LINKS))


def chain_measures(x, v):
    """``(largest stretch |d| / L - 1 of any link, share of the energy lost)`` from the beads' centres ``x``
    and velocities ``v`` at the end (Marbellous axes, chain by chain); RuntimeError when any is not finite."""
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise RuntimeError("non-finite positions or velocities at the end (the chains blew up)")
    x = x.reshape(CHAINS, LINKS, 3)
    stretch = float(np.max(np.linalg.norm(np.diff(x, axis=1), axis=2) / ROD - 1.0))
    energy = 0.5 * BEAD_MASS * float(np.sum(v * v)) + BEAD_MASS * G * float(np.sum(x[:, :, 1] - PIN_HEIGHT))
    return stretch, -energy / released()


def chain_marbellous(steps):
    w = mb.World(sleeping=False)
    p = w.add_particles(chain_start(), mass=BEAD_MASS, radius=BEAD_RADIUS)
    first = np.arange(CHAINS) * LINKS
    edges = np.concatenate([np.column_stack([f + np.arange(LINKS - 1), f + np.arange(1, LINKS)]) for f in first])
    w.add_network(p, edges, kind="rod", rest_length=ROD)
    p.pin(first)
    ms, _ = _timed_steps(lambda: w.step(DT), steps)
    return ms, *chain_measures(p.positions, p.velocities)


def chain_pybullet(steps):
    p, kw = direct_client(DT)
    start = chain_start().reshape(CHAINS, LINKS, 3)
    sphere = p.createCollisionShape(p.GEOM_SPHERE, radius=BEAD_RADIUS, **kw)
    spin = 0.4 * BEAD_MASS * BEAD_RADIUS ** 2           # a solid sphere's moment of inertia (kg m^2)
    back = list(to_peer((-ROD, 0.0, 0.0)))               # the parent bead's centre, in a bead's frame at the start
    ids = []
    for c in range(CHAINS):
        parent = None
        for k in range(1, LINKS):
            bid = p.createMultiBody(BEAD_MASS, sphere, basePosition=list(to_peer(start[c, k])), **kw)
            p.setCollisionFilterGroupMask(bid, -1, 0, 0, **kw)
            # (the mass again: setting the inertia alone sets it to 0)
            p.changeDynamics(bid, -1, mass=BEAD_MASS, localInertiaDiagonal=[spin] * 3, linearDamping=0.0,
                             angularDamping=0.0, **kw)
            if parent is None:
                # (to the world: the bead is the constraint's parent and the pin its child frame)
                joint = p.createConstraint(bid, -1, -1, -1, p.JOINT_POINT2POINT, [0, 0, 0], back,
                                           list(to_peer(start[c, 0])), **kw)
            else:
                joint = p.createConstraint(parent, -1, bid, -1, p.JOINT_POINT2POINT, [0, 0, 0], [0, 0, 0], back, **kw)
            p.changeConstraint(joint, maxForce=1e9, **kw)
            ids.append(bid)
            parent = bid
    ms = time_pybullet(p, kw, steps)
    x = from_peer([p.getBasePositionAndOrientation(b, **kw)[0] for b in ids]).reshape(CHAINS, LINKS - 1, 3)
    v = from_peer([p.getBaseVelocity(b, **kw)[0] for b in ids]).reshape(CHAINS, LINKS - 1, 3)
    p.disconnect(**kw)
    x = np.concatenate([start[:, :1], x], axis=1)          # the pins
    v = np.concatenate([np.zeros((CHAINS, 1, 3)), v], axis=1)
    return ms, *chain_measures(x.reshape(-1, 3), v.reshape(-1, 3))


def _mujoco_chain(start):
    """One chain as nested MJCF bodies: the pin welded to the world, each next bead on a ball joint at its
    parent's centre, one rod on."""
    on = _f(to_peer((ROD, 0.0, 0.0)))
    back = _f(to_peer((-ROD, 0.0, 0.0)))
    bead = f'<geom type="sphere" size="{BEAD_RADIUS:.17g}" mass="{BEAD_MASS:.17g}" contype="0" conaffinity="0"/>'
    xml = ""
    for _ in range(LINKS - 1):
        xml = f'<body pos="{on}"><joint type="ball" pos="{back}"/>{bead}{xml}</body>'
    return f'<body pos="{_f(to_peer(start))}">{bead}{xml}</body>'


def chain_mujoco(steps, integrator="Euler"):
    import mujoco
    start = chain_start().reshape(CHAINS, LINKS, 3)
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -{G:.17g}" integrator="{integrator}"/>'
        f'<worldbody>{"".join(_mujoco_chain(start[c, 0]) for c in range(CHAINS))}</worldbody></mujoco>')
    data = mujoco.MjData(model)
    ms = _time_mujoco(model, data, steps, f"the chains ({integrator})")
    mujoco.mj_forward(model, data)              # the final qpos's poses (xpos lags a step behind mj_step)
    x = from_peer(data.xpos[1:])
    v = np.empty((model.nbody - 1, 3))
    velocity = np.empty(6)
    for b in range(1, model.nbody):
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, velocity, 0)
        v[b - 1] = from_peer(velocity[3:])      # (angular, then linear at the body's frame, world axes)
    return ms, *chain_measures(x, v)


def chain_mujoco_implicitfast(steps):
    return chain_mujoco(steps, "implicitfast")


CHAIN_RUNS = {"marbellous": chain_marbellous, "pybullet": chain_pybullet, "mujoco": chain_mujoco,
              "mujoco-implicitfast": chain_mujoco_implicitfast}


# --- the run --------------------------------------------------------------------------------------------------
def _cell(x, digits, width):
    return f"{'-':>{width}s}" if x is None else f"{x:{width}.{digits}}"


def main():
    args = bench_arguments(__doc__)
    counts, steps = ((1000,), 300) if args.quick else ((1000, 4000), 300)
    heap = {}
    for count in counts:
        for name, r in best_results(HEAP_RUNS, args.repeats, count, steps).items():
            if not isinstance(r, dict):
                r = {"ms_per_step": r[0], "slowest_step_ms": r[1], "deepest_overlap_m": r[2], "into_floor_m": r[3],
                     "escaped": r[4], "top_speed_m_s": r[5], "moving": r[6], "settled": r[6] == 0,
                     "highest_centre_m": r[7]}
            heap.setdefault(str(count), {})[name] = r
    chain = {name: r if isinstance(r, dict) else {"ms_per_step": r[0], "largest_stretch": r[1], "energy_lost": r[2]}
             for name, r in best_results(CHAIN_RUNS, args.repeats, steps).items()}
    print(f"heap: grains of radius {RADIUS} m, {MASS} kg, friction {FRICTION}, poured into a box of "
          f"{2 * INSIDE:g} m x {2 * INSIDE:g} m, {steps} steps at 60 Hz")
    print(f"{'N':>5s} {'engine':12s} {'ms/step':>9s} {'slowest':>8s} {'overlap (m)':>12s} {'floor (m)':>10s} "
          f"{'escaped':>8s} {'top speed':>10s} {'moving':>7s} {'settled':>8s} {'height (m)':>11s}")
    for count, by_engine in heap.items():
        for name, r in by_engine.items():
            if "failed" in r:
                print(f"{count:>5s} {name:12s} failed: {r['failed']}")
                continue
            print(f"{count:>5s} {name:12s} {r['ms_per_step']:9.3f} {_cell(r['slowest_step_ms'], '4g', 8)} "
                  f"{r['deepest_overlap_m']:12.2e} {r['into_floor_m']:10.2e} {r['escaped']:8d} "
                  f"{r['top_speed_m_s']:10.3g} {r['moving']:7d} {'yes' if r['settled'] else 'no':>8s} "
                  f"{r['highest_centre_m']:11.3f}")
    print(f"\nchains: {CHAINS} chains of {LINKS} beads ({BEAD_MASS} kg) on rods of {ROD} m, swinging down from "
          f"horizontal, {steps} steps at 60 Hz")
    print(f"{'engine':20s} {'ms/step':>9s} {'largest stretch':>16s} {'energy lost':>12s}")
    for name, r in chain.items():
        if "failed" in r:
            print(f"{name:20s} failed: {r['failed']}")
            continue
        lost = f"{100 * r['energy_lost']:11.1f}%" if r["largest_stretch"] < STRETCHED else f"{'(stretched)':>12s}"
        print(f"{name:20s} {r['ms_per_step']:9.3f} {r['largest_stretch']:16.2e} {lost}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco")})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "particles", "machine": machine, "quick": args.quick, "steps": steps, "dt": DT,
                       "repeats": args.repeats, "seed": SEED,
                       "heap": {"counts": list(counts), "radius_m": RADIUS, "mass_kg": MASS, "friction": FRICTION,
                                "inside_half_width_m": INSIDE, "settled_below_m_s": SETTLED, "results": heap},
                       "chain": {"chains": CHAINS, "links": LINKS, "bead_mass_kg": BEAD_MASS,
                                 "bead_radius_m": BEAD_RADIUS, "rod_m": ROD, "released_j": released(),
                                 "results": chain}}, f, indent=1)


if __name__ == "__main__":
    main()
