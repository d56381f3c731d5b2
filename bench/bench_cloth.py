"""Cloth, side by side with PyBullet and MuJoCo: a square sheet dropped onto a sphere resting on the ground.

The scene, 60 Hz (dt = 1/60 s), gravity 9.81, one untimed step and then 180 timed steps (3 s): a square cloth of
``N`` x ``N`` vertices (N = 32, 64 and 128; ``--quick``: 32 only), 1 m x 1 m (grid spacing ``1 / (N - 1)`` m),
0.5 kg in all, started flat and horizontal, centred 0.5 m above the top of a static sphere of radius 0.3 m whose
centre is 0.3 m above a static ground plane (so the sheet starts 1.1 m up; y up in Marbellous, z up in PyBullet
and MuJoCo, converted by ``bench/peers/axes.py``), friction 0.5 everywhere, thickness 0.01 m.  The sheet falls
0.5 m and drapes over the sphere; its corners end a few cm above the ground (1 m across, it reaches the ground
only by stretching).
- Marbellous (``marbellous``): ``mb.cloth_grid(1, 1, N, N)`` and ``w.add_cloth(..., mass=0.5, thickness=0.01,
  position=(0, 1.1, 0))``, its defaults otherwise (stretch stiffness 1e4 N/m per unit strain, bend stiffness
  1e-3, damping 0.01 1/s, friction 0.5, self collision on); and again with ``self_collision=False``
  (``marbellous-noself``), and both again with the whole cloth's stretch and bending solved at once
  (``w.cloth_stretch_passes = 1``: ``marbellous-global``, ``marbellous-global-noself``).  ``World(sleeping=False)``,
  the sphere and the plane added with ``add_static``.
  Skipped, and said so, while the installed Marbellous has no ``add_cloth``/``cloth_grid``.
- PyBullet (``pybullet``): its deformable world (``resetSimulation(RESET_USE_DEFORMABLE_WORLD)``, the implicit
  ``btDeformableMultiBodyDynamicsWorld``), the sheet an OBJ of the same grid (each square cut along one diagonal)
  loaded by ``loadSoftBody`` as a mass-spring cloth (``useMassSpring=1``, ``useBendingSprings=1``, ``mass=0.5``,
  ``useSelfCollision=1``, ``useFaceContact=1``, ``collisionMargin=0.01``, ``frictionCoeff=0.5``), the sphere a
  static ``GEOM_SPHERE`` body and the ground a ``GEOM_PLANE``, each with lateral friction 0.5 (Bullet combines a
  soft body's and a rigid body's friction by multiplying them: 0.25 in effect), ``sparseSdfVoxelSize=0.25`` as in
  PyBullet's own deformable examples.  Settings, and why:
  - ``springElasticStiffness = 100`` N/m per spring.  With structural springs alone a square grid's membrane
    stiffness (N/m per unit strain) equals its springs' stiffness whatever the spacing, so Marbellous' 1e4 would
    be 1e4 per spring; but at 60 Hz the sheet blew up on touching the sphere at 1e4 even with 10 sub-steps, and
    at 1e3 with 10 sub-steps; 100 with 10 sub-steps held (N = 32).  So PyBullet's sheet is 100 x softer than
    Marbellous' (it stretches visibly: see the stretch columns);
  - ``numSubSteps = 10`` (10 sub-steps of 1/600 s per 60 Hz step): without sub-steps, and with 4, the sheet
    blew up on touching the sphere even at stiffness 100;
  - ``springDampingStiffness = 0.1`` with ``springDampingAllDirections=1``, as in PyBullet's cloth examples
    (there is no direct counterpart of Marbellous' relative-velocity damping of 0.01 1/s);
  - ``springBendingStiffness = 7.2 B / h^2`` (``B`` = 1e-3, ``h`` the spacing: 6.9 N/m at N = 32, 29 at 64, 116
    at 128): a bending spring joins two vertices about ``2 h`` apart across a fold, and this stiffness stores the
    same energy as a hinge of bending stiffness ``B`` at a fold of 90 degrees (a spring's energy grows as the
    fourth power of the fold angle, a hinge's as the square, so they agree at one angle only).
- MuJoCo (``mujoco``): a 2-D ``flexcomp type="grid"`` (``count="N N 1"``, ``mass="0.5"``, ``radius="0.005"``:
  half the thickness, the flex's surface inflated by it on both sides), its edges held by ``<edge
  equality="true"/>`` (soft equality constraints solved with the contacts: MuJoCo's inextensible cloth),
  ``<contact condim="3" friction="0.5" selfcollide="auto"/>``, the sphere and the plane geoms of the world
  body with friction 0.5 (MuJoCo combines by ``max``); its defaults otherwise (Newton solver, Euler integrator,
  soft contacts, whose time constant MuJoCo raises to two steps, 1/30 s, at 60 Hz: they sink under load).  No
  bending stiffness: a flex gets it only from ``<elasticity>``, whose forces are explicit, and with
  ``young = 12 B / t^3`` (``elastic2d="bend"``, ``t`` = 0.01 m) or with the membrane's ``young = 1e4 / t``
  (``elastic2d="both"``) the sheet blew up at 60 Hz (N = 32).  Again as ``mujoco-implicitfast`` with the
  integrator MuJoCo recommends.  At N = 128 MuJoCo refuses the model (a grid's spacing, 7.9 mm, must exceed the
  flex's diameter, 1 cm): reported as failed rather than run with a thinner sheet.
Reported per engine and N: ms per step (best of ``--repeats``), the slowest single step (ms, in that run), and
from the final vertex positions: the deepest any vertex is inside the sphere (m, ``r - |x - c|``; below 0: none
is), the deepest any is under the plane (m, ``-y``), and the relative stretch ``|d| / L - 1`` of the grid's
structural edges (the pairs of vertices one spacing apart at the start; ``L`` their starting distance): the
largest and the mean.  A run whose positions end non-finite fails; so does one MuJoCo flags unstable (NaN or huge
accelerations, after which it resets the state) or whose clock it reset.  After each step, outside the timed
part, the vertices are read: a run in which one moved faster than 100 m/s in a step (the sheet reaches 3.1 m/s
in its fall), or whose positions are not finite, is stopped and reported as blown up (``blew_up``): a cloth that
blows up slows down by orders of magnitude and its contact tables grow without bound (Marbellous' 128 x 128 with
self collision asked for 12 GB in its third step after blowing up).  A run slower than 2 s a step (over its first
3 or more steps) is stopped and reported as capped; an engine capped or blown up is not run at larger N
(``not_run``); after a run longer than 60 s the engine's other repeats are left out (their timing noise is small
next to such a step).  A run that runs out of memory fails.

    python bench/bench_cloth.py [--quick] [--repeats N] [--json FILE] [--engines marbellous,marbellous-noself]

``--engines`` runs only the engines named (default: all of them).
"""
import json
import os
import sys
import tempfile
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
from bench.peers.timing import BlewUp, Capped, NotAvailable, bench_arguments, best_of  # noqa: E402

DT = 1.0 / 60.0
G = 9.81
STEPS = 180                 # timed steps (3 s), after one untimed
SIZE = 1.0                  # side of the square sheet (m)
MASS = 0.5                  # the sheet's mass (kg)
RADIUS = 0.3                # the sphere's radius (m)
CENTRE = np.array([0.0, RADIUS, 0.0])      # the sphere's centre (m, Marbellous axes): resting on the ground
DROP = 0.5                  # from the sphere's top to the sheet at the start (m)
HEIGHT = CENTRE[1] + RADIUS + DROP         # the sheet's starting height (m)
THICKNESS = 0.01            # (m)
FRICTION = 0.5

# --- the peers' settings (see the docstring for why) ------------------------------------------------------------
BEND = 1.0e-3               # Marbellous' default bend stiffness, which PyBullet's bending springs stand for
PB_STRETCH = 100.0          # springElasticStiffness (N/m per spring)
PB_SUBSTEPS = 10            # numSubSteps per 60 Hz step
PB_DAMPING = 0.1            # springDampingStiffness
PB_MARGIN = 0.01            # collisionMargin (m)
PB_VOXEL = 0.25             # sparseSdfVoxelSize (m)
MJ_RADIUS = 0.5 * THICKNESS  # the flex's radius (m)

MAX_SPEED = 100.0           # a vertex faster than this (m/s, from its move in a step) means the run blew up
CAP_S = 2.0                 # a run slower than this a step (s) is stopped
CAP_AFTER = 3               # ... judged over at least this many steps
LONG_RUN_S = 60.0           # after a run this long (s), no more repeats of that engine at that N



def spacing(n):
    """The grid's spacing (m) for ``n`` x ``n`` vertices."""
    return SIZE / (n - 1)


def pb_bending(n):
    """PyBullet's bending-spring stiffness (N/m) for ``n`` x ``n`` vertices: the energy of a hinge of bending
    stiffness ``BEND`` at a 90-degree fold, ``BEND phi^2 / 2``, over that of a spring across it between vertices
    about one spacing from the fold, ``k (2 h (1 - cos(phi / 2)))^2 / 2``."""
    phi = 0.5 * np.pi
    return float(BEND * phi ** 2 / (2.0 * (1.0 - np.cos(0.5 * phi))) ** 2 / spacing(n) ** 2)


def structural_edges(x0, n):
    """The grid's structural edges ``(E, 2)``: the pairs of starting positions ``x0`` one spacing apart (found by
    distance, so whatever order an engine keeps its vertices in); ``2 n (n - 1)`` of them."""
    h = spacing(n)
    pairs = cKDTree(x0).query_pairs(1.01 * h, output_type="ndarray")
    pairs = pairs[np.linalg.norm(x0[pairs[:, 0]] - x0[pairs[:, 1]], axis=1) > 0.99 * h]
    if len(pairs) != 2 * n * (n - 1):
        raise RuntimeError(f"found {len(pairs)} structural edges in the starting grid, not {2 * n * (n - 1)}")
    return pairs


def measures(x0, x, n):
    """``(deepest inside the sphere (m), deepest under the plane (m), largest stretch, mean stretch)`` from the
    starting and final vertex positions ``x0``, ``x`` (Marbellous axes); RuntimeError when any is not finite."""
    if not np.all(np.isfinite(x)):
        raise RuntimeError("non-finite vertex positions at the end (the cloth blew up)")
    if len(x) != n * n:
        raise RuntimeError(f"{len(x)} vertices, not {n * n}")
    e = structural_edges(x0, n)
    rest = np.linalg.norm(x0[e[:, 0]] - x0[e[:, 1]], axis=1)
    stretch = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1) / rest - 1.0
    inside = float(np.max(RADIUS - np.linalg.norm(x - CENTRE, axis=1)))
    return inside, float(np.max(-x[:, 1])), float(np.max(stretch)), float(np.mean(stretch))


def _spread(x):
    """How far apart the vertices ``x`` are at most along an axis (m)."""
    return float(np.max(np.ptp(x, axis=0)))


def _timed_steps(step, what, positions):
    """``(ms per step, slowest step (ms))`` over ``STEPS`` calls of ``step`` after an untimed one.  After each
    step, untimed, the vertices ``positions()``: BlewUp when they are not finite or one moved faster than
    ``MAX_SPEED``; Capped when the steps so far average over ``CAP_S`` after ``CAP_AFTER`` of them, saying how far
    apart the vertices then are (a sheet that blew up spreads over metres, and its steps slow down)."""
    step()
    before = positions()
    seconds, slowest = 0.0, 0.0
    for k in range(STEPS):
        t = time.perf_counter()
        step()
        took = time.perf_counter() - t
        seconds += took
        slowest = max(slowest, took)
        x = positions()
        speed = float(np.max(np.linalg.norm(x - before, axis=1))) / DT if np.all(np.isfinite(x)) else np.inf
        if not speed <= MAX_SPEED:
            raise BlewUp(f"blew up: {what}, at step {k + 2} of {STEPS + 1}, a vertex moved at "
                         f"{speed:.3g} m/s (over {MAX_SPEED:g}), its vertices then {_spread(x):.3g} m apart at "
                         f"most; that step took {took:.1f} s; stopped")
        before = x
        if k + 1 >= CAP_AFTER and seconds / (k + 1) > CAP_S:
            spread = f", its vertices then {_spread(x):.3g} m apart at most"
            raise Capped(f"capped: {what} took {seconds / (k + 1):.1f} s a step over its first {k + 1} timed steps "
                         f"(slowest {slowest:.1f} s){spread}; stopped")
    return 1e3 * seconds / STEPS, 1e3 * slowest


# --- Marbellous -------------------------------------------------------------------------------------------------
def run_marbellous(n, self_collision=True, stretch_passes=0):
    if not (hasattr(mb, "cloth_grid") and hasattr(mb.World, "add_cloth")):
        raise NotAvailable("not available: this Marbellous has no mb.cloth_grid / World.add_cloth yet")
    w = mb.World(sleeping=False)
    if stretch_passes:
        w.cloth_stretch_passes = stretch_passes
    w.add_static(mb.Plane(), friction=FRICTION)
    w.add_static(mb.Sphere(RADIUS), position=CENTRE, friction=FRICTION)
    vertices, triangles = mb.cloth_grid(SIZE, SIZE, n, n)
    c = w.add_cloth(vertices, triangles, mass=MASS, thickness=THICKNESS, friction=FRICTION,
                    self_collision=self_collision, position=(0.0, HEIGHT, 0.0))
    x0 = c.positions
    what = f"Marbellous' cloth of {n} x {n}" + ("" if self_collision else " without self collision") \
        + (" solved whole" if stretch_passes else "")
    ms, slowest = _timed_steps(lambda: w.step(DT), what, lambda: c.positions)
    return ms, slowest, *measures(x0, c.positions, n)


def run_marbellous_noself(n):
    return run_marbellous(n, self_collision=False)


def run_marbellous_global(n):
    return run_marbellous(n, stretch_passes=1)


def run_marbellous_global_noself(n):
    return run_marbellous(n, self_collision=False, stretch_passes=1)


# --- PyBullet ---------------------------------------------------------------------------------------------------
def grid_obj(path, n):
    """Write the ``n`` x ``n`` sheet as an OBJ in PyBullet's axes (flat in x-y, centred at the origin), each
    square cut along one diagonal."""
    h = spacing(n)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v = np.column_stack([h * i.ravel() - 0.5 * SIZE, h * j.ravel() - 0.5 * SIZE, np.zeros(n * n)])
    k = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]).ravel()      # each square's first corner
    tri = np.concatenate([np.column_stack([k, k + n, k + n + 1]), np.column_stack([k, k + n + 1, k + 1])])
    with open(path, "w") as fh:
        np.savetxt(fh, v, fmt="v %.17g %.17g %.17g")
        np.savetxt(fh, tri + 1, fmt="f %d %d %d")


def pb_deformable_world(p, kw):
    """Set PyBullet's client ``kw`` up as a deformable world at 60 Hz in ``PB_SUBSTEPS`` sub-steps with a ground
    plane of friction ``FRICTION`` (the docstring's settings); returns the plane's id."""
    p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD, **kw)
    p.setGravity(*to_peer((0.0, -G, 0.0)), **kw)
    p.setPhysicsEngineParameter(fixedTimeStep=DT, numSubSteps=PB_SUBSTEPS, sparseSdfVoxelSize=PB_VOXEL, **kw)
    ground = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, **kw), **kw)
    p.changeDynamics(ground, -1, lateralFriction=FRICTION, **kw)
    return ground


def pb_cloth(p, kw, n, position, mass):
    """The ``n`` x ``n`` sheet loaded into PyBullet's client ``kw`` as the docstring's mass-spring cloth of ``mass``
    (kg), flat at ``position`` (m, Marbellous axes); returns its id."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cloth.obj")
        grid_obj(path, n)
        return p.loadSoftBody(path, basePosition=list(to_peer(position)), scale=1.0, mass=mass,
                              useNeoHookean=0, useMassSpring=1, useBendingSprings=1,
                              springElasticStiffness=PB_STRETCH, springDampingStiffness=PB_DAMPING,
                              springDampingAllDirections=1, springBendingStiffness=pb_bending(n),
                              useSelfCollision=1, useFaceContact=1, collisionMargin=PB_MARGIN,
                              frictionCoeff=FRICTION, **kw)


def run_pybullet(n):
    import pybullet as p
    kw = {"physicsClientId": p.connect(p.DIRECT)}
    try:
        pb_deformable_world(p, kw)
        ball = p.createMultiBody(0, p.createCollisionShape(p.GEOM_SPHERE, radius=RADIUS, **kw),
                                 basePosition=list(to_peer(CENTRE)), **kw)
        p.changeDynamics(ball, -1, lateralFriction=FRICTION, **kw)
        cloth = pb_cloth(p, kw, n, (0.0, HEIGHT, 0.0), MASS)

        def positions():
            return from_peer(p.getMeshData(cloth, -1, flags=p.MESH_DATA_SIMULATION_MESH, **kw)[1])

        x0 = positions()
        ms, slowest = _timed_steps(lambda: p.stepSimulation(**kw), f"PyBullet's cloth of {n} x {n}", positions)
        return ms, slowest, *measures(x0, positions(), n)
    finally:
        p.disconnect(**kw)


# --- MuJoCo -----------------------------------------------------------------------------------------------------
def run_mujoco(n, integrator="Euler"):
    import mujoco
    h = spacing(n)
    xml = (
        f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -{G:.17g}" integrator="{integrator}"/>'
        f'<size memory="2G"/>'
        f'<worldbody><geom type="plane" size="50 50 1" friction="{FRICTION:.17g} 0.005 0.0001"/>'
        f'<geom type="sphere" size="{RADIUS:.17g}" pos="{_f(to_peer(CENTRE))}" '
        f'friction="{FRICTION:.17g} 0.005 0.0001"/>'
        f'<flexcomp name="cloth" type="grid" dim="2" count="{n} {n} 1" spacing="{h:.17g} {h:.17g} {h:.17g}" '
        f'pos="{_f(to_peer((0.0, HEIGHT, 0.0)))}" radius="{MJ_RADIUS:.17g}" mass="{MASS:.17g}">'
        f'<contact condim="3" friction="{FRICTION:.17g} 0.005 0.0001" selfcollide="auto"/>'
        f'<edge equality="true"/></flexcomp></worldbody></mujoco>')
    try:
        model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as e:         # (at N = 128: a spacing of 7.9 mm under the flex's diameter of 1 cm)
        raise RuntimeError(f"MuJoCo refuses the flex of {n} x {n} with radius {MJ_RADIUS} m and spacing "
                           f"{h:.3g} m: {' '.join(str(e).split())}") from None
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    x0 = from_peer(data.flexvert_xpos)
    what = f"MuJoCo's cloth of {n} x {n} ({integrator})"
    ms, slowest = _timed_steps(lambda: mujoco.mj_step(model, data), what, lambda: from_peer(data.flexvert_xpos))
    if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
        raise RuntimeError(f"MuJoCo flagged {what} unstable (NaN or huge accelerations) and reset the state")
    if abs(data.time - (STEPS + 1) * model.opt.timestep) > 1e-6:
        raise RuntimeError(f"MuJoCo reset {what} to its start (its clock reads {data.time:.2f} s)")
    mujoco.mj_forward(model, data)              # the final qpos's vertices (flexvert_xpos lags a step behind)
    return ms, slowest, *measures(x0, from_peer(data.flexvert_xpos), n)


def run_mujoco_implicitfast(n):
    return run_mujoco(n, "implicitfast")


RUNS = {"marbellous": run_marbellous, "marbellous-noself": run_marbellous_noself,
        "marbellous-global": run_marbellous_global, "marbellous-global-noself": run_marbellous_global_noself,
        "pybullet": run_pybullet,
        "mujoco": run_mujoco, "mujoco-implicitfast": run_mujoco_implicitfast}


# --- the run --------------------------------------------------------------------------------------------------


def _as_result(measured):
    """A run's ``(ms per step, slowest step, inside sphere, under plane, stretch max, stretch mean)`` as the
    results dict."""
    return dict(zip(("ms_per_step", "slowest_step_ms", "inside_sphere_m", "under_plane_m", "stretch_max",
                     "stretch_mean"), measured))


def main():
    args = bench_arguments(__doc__, list(RUNS))
    sizes = (32,) if args.quick else (32, 64, 128)
    results = {}
    stopped = {}                  # engine -> why it is not run at larger N (capped or blown up)
    for n in sizes:
        for name, run in RUNS.items():
            if name not in args.engines:
                continue
            if name in stopped:
                results.setdefault(str(n), {})[name] = {"not_run": stopped[name]}
                continue
            try:
                r = best_of(lambda m, run=run: _as_result(run(m)), args.repeats, n, LONG_RUN_S)
            except ImportError:
                continue
            for why in ("capped", "blew_up"):
                if why in r:
                    stopped[name] = f"{why.replace('_', ' ')} at N = {n}"
            results.setdefault(str(n), {})[name] = r
            print(f"  N = {n} {name}: " + (", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                                                   for k, v in r.items())), file=sys.stderr, flush=True)
    print(f"cloth: {SIZE:g} m x {SIZE:g} m, {MASS} kg, dropped {DROP} m onto a sphere of radius {RADIUS} m on the "
          f"ground, {STEPS} steps at 60 Hz (PyBullet: {PB_SUBSTEPS} sub-steps, springs {PB_STRETCH:g} N/m)")
    print(f"{'N':>4s} {'engine':20s} {'ms/step':>9s} {'slowest':>8s} {'in sphere (m)':>14s} {'under plane':>12s} "
          f"{'stretch max':>12s} {'mean':>10s}")
    for n, by_engine in results.items():
        for name, r in by_engine.items():
            if "ms_per_step" not in r:
                what = next(iter(r))
                print(f"{n:>4s} {name:20s} {what}: {r[what]}")
                continue
            print(f"{n:>4s} {name:20s} {r['ms_per_step']:9.2f} {r['slowest_step_ms']:8.1f} "
                  f"{r['inside_sphere_m']:14.2e} {r['under_plane_m']:12.2e} {r['stretch_max']:12.2e} "
                  f"{r['stretch_mean']:10.2e}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco")
                                 if any(name.startswith(e) for name in args.engines)})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "cloth", "machine": machine, "engines": args.engines, "quick": args.quick,
                       "steps": STEPS, "dt": DT, "repeats": args.repeats, "sizes": list(sizes), "side_m": SIZE,
                       "mass_kg": MASS, "sphere_radius_m": RADIUS, "sphere_centre_m": CENTRE.tolist(),
                       "start_height_m": HEIGHT,
                       "thickness_m": THICKNESS, "friction": FRICTION, "cap_s_per_step": CAP_S,
                       "pybullet": {"spring_elastic_stiffness": PB_STRETCH, "num_substeps": PB_SUBSTEPS,
                                    "spring_damping_stiffness": PB_DAMPING, "collision_margin_m": PB_MARGIN,
                                    "sparse_sdf_voxel_size_m": PB_VOXEL,
                                    "spring_bending_stiffness": {str(n): pb_bending(n) for n in sizes}},
                       "mujoco": {"flex_radius_m": MJ_RADIUS, "edge_equality": True, "solver": "Newton"},
                       "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
