"""Soft bodies, side by side with PyBullet and MuJoCo: an elastic cube of tetrahedra dropped onto the ground.

The scene, 60 Hz (dt = 1/60 s), gravity 9.81, one untimed step and then 120 timed steps (2 s): a cube 0.5 m on a
side, density 1000 kg/m^3 (125 kg), Young's modulus 1e5 Pa, Poisson's ratio 0.3, friction 0.5, started at rest
with its lower face 0.3 m above a static ground (its centre at 0.55 m; y up in Marbellous, z up in PyBullet and
MuJoCo, converted by ``bench/peers/axes.py``).  It lands after 0.25 s (at 2.4 m/s) and bounces and rings on
the ground for the rest of the run.  The mesh is ``mb.tet_box((0.25, 0.25, 0.25), (n, n, n))``, ``n`` cells a
side each cut into six tetrahedra: n = 6, 12 and 20, 1,296, 10,368 and 48,000 tetrahedra (343, 2,197 and 9,261
nodes; ``--quick``: n = 6 only); every engine gets this same mesh, node for node and tetrahedron for
tetrahedron.  Every engine's nodes collide as spheres (or with a margin) of the radius Marbellous gives them by
default, a quarter of the shortest edge: ``0.125 / n`` m (21, 10 and 6 mm).
- Marbellous (``marbellous``): ``World(gravity=(0, -9.81, 0), sleeping=False)``, the ground ``add_static(
  mb.Plane(), friction=0.5)``, ``w.add_soft_body(vertices, tetrahedra, density=1000, young_modulus=1e5,
  poisson_ratio=0.3, damping=0, friction=0.5, position=(0, 0.55, 0))``, its defaults otherwise: corotated
  linear elements, one backward-Euler step solved by conjugate gradients in each of the 16 particle sub-steps,
  each node's mass a quarter of its tetrahedra's (lumped).  Its first step compiles the kernels (minutes, once;
  cached on disk afterwards): the untimed step.
- PyBullet (``pybullet``): its deformable world (``resetSimulation(RESET_USE_DEFORMABLE_WORLD)``), the mesh
  written as a legacy ASCII VTK unstructured grid (cell type 10) and loaded by ``loadSoftBody`` with
  ``useNeoHookean=1``, ``NeoHookeanMu = E / (2 (1 + nu))`` and ``NeoHookeanLambda = E nu / ((1 + nu) (1 - 2
  nu))`` (38,462 and 57,692 Pa), ``NeoHookeanDamping=0`` (as Marbellous' ``damping=0``), ``mass=125``
  (presumably spread evenly over the nodes: Bullet's VTK loader gives every node the same mass, then scales
  them), ``collisionMargin`` the node radius, ``frictionCoeff=0.5``, ``useSelfCollision=0``,
  ``useFaceContact=1``, ``sparseSdfVoxelSize=0.25`` as in PyBullet's deformable examples; the ground has
  lateral friction 0.5 (Bullet multiplies a soft body's friction by a rigid body's: 0.25 in effect).
  Settings, and why:
  - ``numSubSteps``: 4 at n = 6, 8 at 12, 16 at 20 (sub-steps of 1/240, 1/480 and 1/960 s), the fewest tried
    that held.  With fewer the cube blew up (nodes thousands of metres apart within a few steps): at n = 6
    with 1, 2 and 3 on landing (with 1 also with ``NeoHookeanDamping=0.01``), at n = 12 with 4 in free fall
    (step 6) and 6 on landing, at n = 20 with 8 in free fall (step 5; 12 was not tried).  At n = 6 with 10
    sub-steps the cube lands and rings as with 4.  Bullet's deformable solver takes the elastic forces
    explicitly (its backward-Euler objective holds the damping and the contacts; PyBullet does not expose its
    implicit option), so its step must stay under about ``2 / w_max``, and the highest frequency ``w_max``
    grows as ``sqrt(E / rho) / h`` with the element size ``h``;
  - the ground is a static ``GEOM_BOX`` 20 m x 20 m x 2 m whose top face is at height 0, not a ``GEOM_PLANE``:
    on a plane the deformable world held the cube ``0.1 m + collisionMargin`` above it (0.1 m with a margin
    of 1 mm, 0.12 with 2 cm, 0.15 with 5 cm; n = 6, 4 sub-steps), and on the box it rests at the margin.  (The
    cloth bench's PyBullet sheet ended with its lowest vertex 0.11 m up, its margin 0.01 m: probably the same.)
- MuJoCo (``mujoco``, ``mujoco-discrete``): a ``flexcomp type="direct" dim="3"`` with the same points and
  tetrahedra (``point``, ``element``), ``mass="125"`` (flexcomp spreads it evenly over the points),
  ``radius`` the node radius, ``<elasticity young="1e5" poisson="0.3" damping="0"/>`` (MuJoCo 4's 3-D flex is
  a Saint Venant-Kirchhoff material of linear tetrahedra: the same Lame parameters, Green strain),
  ``<contact condim="3" friction="0.5 0.005 0.0001" selfcollide="none"/>``, a plane geom of the world body
  with friction 0.5 (MuJoCo combines by ``max``); its defaults otherwise (Newton solver, soft contacts whose
  time constant MuJoCo raises to two steps, 1/30 s, at 60 Hz).  ``mujoco``: its default ``Euler``
  integrator, in which flex elasticity is explicit.  ``mujoco-discrete``: ``integrator="discrete"``, the one
  MuJoCo 4 documents for implicit flex elasticity (``implicit`` and ``implicitfast`` do not support it).  A
  ``flexcomp type="grid" dim="3" count="7 7 7"`` makes 1,296 tetrahedra too (six per cell), and at n = 6
  with ``discrete`` the same lowest and highest node and volume to four digits through the run; ``direct`` is
  used so that every engine has exactly the same mesh.
Reported per engine and n: ms per step (best of ``--repeats``), the slowest single step (ms, in that run), the setup
(building the world, loading or compiling the model; s) and the untimed first step (s), and from the final node
positions: the volume over the starting volume (the sum of the tetrahedra's signed volumes), the lowest node's
height at the end and the lowest over the whole run (m; a node resting on the ground stands at about the node
radius, less where contacts are soft; below 0: in the ground), the highest node (m; the cube is 0.5 m tall unloaded,
about 12 mm less at rest under its weight, ``rho g H^2 / (2 E)``), and the fastest node in the last step (m/s, its
move over dt).  After each step, outside the timed part, the nodes are read: a run in which one moved faster than
100 m/s in a step (the cube lands at 2.4 m/s), or whose positions are not finite, or that MuJoCo flags unstable (NaN
or huge accelerations, after which it resets the state), is stopped and reported as blown up (``blew_up``).  A run
slower than 5 s a step (over its first 3 or more steps) is stopped and reported as capped; an engine capped or blown
up is not run at larger n (``not_run``); after a run longer than 60 s the engine's other repeats are left out (their
timing noise is small next to such a step).  A run that runs out of memory fails.  MuJoCo's other warnings are
counted (``warnings``: ``INERTIA`` is its effective-inertia solve stopping short of its tolerance).

    python bench/bench_soft.py [--quick] [--repeats N] [--json FILE] [--engines marbellous,pybullet]

``--engines`` runs only the engines named (default: all of them).
"""
import json
import os
import sys
import tempfile
import time

import numpy as np

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
STEPS = 120                 # timed steps (2 s), after one untimed
SIDE = 0.5                  # the cube's side (m)
DENSITY = 1000.0            # (kg/m^3)
MASS = DENSITY * SIDE ** 3  # (kg)
YOUNG = 1.0e5               # Young's modulus (Pa)
POISSON = 0.3
FRICTION = 0.5
DROP = 0.3                  # from the ground to the cube's lower face at the start (m)
CENTRE = np.array([0.0, DROP + 0.5 * SIDE, 0.0])     # the cube's centre at the start (m, Marbellous axes)
SIZES = (6, 12, 20)         # cells a side: 1296, 10368 and 48000 tetrahedra

# --- the peers' settings (see the docstring for why) ------------------------------------------------------------
MU = YOUNG / (2.0 * (1.0 + POISSON))                                   # Lame's parameters (Pa)
LAMBDA = YOUNG * POISSON / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON))
PB_SUBSTEPS = {6: 4, 12: 8, 20: 16}     # numSubSteps per 60 Hz step, by n
PB_DAMPING = 0.0            # NeoHookeanDamping
PB_VOXEL = 0.25             # sparseSdfVoxelSize (m)
PB_GROUND = (10.0, 10.0, 1.0)           # the ground box's half extents (m, PyBullet axes), its top at height 0

MAX_SPEED = 100.0           # a node faster than this (m/s, from its move in a step) means the run blew up
CAP_S = 5.0                 # a run slower than this a step (s) is stopped
CAP_AFTER = 3               # ... judged over at least this many steps
LONG_RUN_S = 60.0           # after a run this long (s), no more repeats of that engine at that n



def cube(n):
    """The cube's rest mesh for ``n`` cells a side, centred on the origin (Marbellous axes): ``(vertices (V, 3),
    tetrahedra (K, 4))``."""
    return mb.tet_box((0.5 * SIDE,) * 3, (n, n, n))


def node_radius(n):
    """The nodes' radius (m): Marbellous' default, a quarter of the mesh's shortest edge."""
    return 0.25 * SIDE / n


def volume(x, tets):
    """The sum of the tetrahedra's signed volumes (m^3) at positions ``x``."""
    a, b, c, d = (x[tets[:, k]] for k in range(4))
    return float(np.sum(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)))) / 6.0


def _check_start(x0, n):
    """RuntimeError unless the engine's nodes ``x0`` (Marbellous axes) are the mesh's vertices, in order, where
    the scene places them (so that the mesh's tetrahedra index them)."""
    vertices, _ = cube(n)
    if x0.shape != vertices.shape or not np.allclose(x0, vertices + CENTRE, atol=1e-6):
        raise RuntimeError(f"the engine's {len(x0)} nodes are not the mesh's {len(vertices)} vertices in order")


def _timed_steps(step, what, positions, unstable=None):
    """``(ms per step, slowest step (ms), lowest node over the run (m), the positions before the last step)`` over
    ``STEPS`` calls of ``step`` after an untimed one (whose seconds are returned too, last).  After each step,
    untimed, the nodes ``positions()``: BlewUp when they are not finite, when one moved faster than
    ``MAX_SPEED``, or when ``unstable()`` says why the engine flagged the step; Capped when the steps so far
    average over ``CAP_S`` after ``CAP_AFTER`` of them."""
    t = time.perf_counter()
    step()
    first = time.perf_counter() - t
    before = positions()
    lowest = float(np.min(before[:, 1]))
    seconds, slowest = 0.0, 0.0
    for k in range(STEPS):
        t = time.perf_counter()
        step()
        took = time.perf_counter() - t
        seconds += took
        slowest = max(slowest, took)
        x = positions()
        why = unstable() if unstable is not None else None
        speed = float(np.max(np.linalg.norm(x - before, axis=1))) / DT if np.all(np.isfinite(x)) else np.inf
        if why or not speed <= MAX_SPEED:
            spread = float(np.max(np.ptp(x, axis=0))) if np.all(np.isfinite(x)) else np.inf
            raise BlewUp(f"blew up: {what}, at step {k + 2} of {STEPS + 1} ({(k + 2) * DT:.2f} s), "
                         + (why if why else f"a node moved at {speed:.3g} m/s (over {MAX_SPEED:g})")
                         + f", its nodes then {spread:.3g} m apart at most; stopped")
        lowest = min(lowest, float(np.min(x[:, 1])))
        if k + 1 < STEPS:
            before = x
        if k + 1 >= CAP_AFTER and seconds / (k + 1) > CAP_S:
            raise Capped(f"capped: {what} took {seconds / (k + 1):.1f} s a step over its first {k + 1} timed steps "
                         f"(slowest {slowest:.1f} s); stopped")
    return 1e3 * seconds / STEPS, 1e3 * slowest, lowest, before, first


def measures(x0, before, x, tets):
    """``(volume / starting volume, lowest node (m), highest node (m), fastest node in the last step (m/s))``
    from the starting, second-to-last and final positions (Marbellous axes); RuntimeError when not finite."""
    if not np.all(np.isfinite(x)):
        raise RuntimeError("non-finite node positions at the end (the cube blew up)")
    return (volume(x, tets) / volume(x0, tets), float(np.min(x[:, 1])), float(np.max(x[:, 1])),
            float(np.max(np.linalg.norm(x - before, axis=1))) / DT)


def _result(setup, timed, x0, x, tets):
    ms, slowest, lowest_ever, before, first = timed
    ratio, lowest, top, speed = measures(x0, before, x, tets)
    return {"ms_per_step": ms, "slowest_step_ms": slowest, "setup_s": setup, "first_step_s": first,
            "volume_ratio": ratio, "lowest_m": lowest, "lowest_ever_m": lowest_ever, "top_m": top,
            "max_speed_m_s": speed}


# --- Marbellous -------------------------------------------------------------------------------------------------
def run_marbellous(n):
    if not (hasattr(mb, "tet_box") and hasattr(mb.World, "add_soft_body")):
        raise NotAvailable("not available: this Marbellous has no mb.tet_box / World.add_soft_body yet")
    start = time.perf_counter()
    vertices, tets = cube(n)
    w = mb.World(gravity=(0.0, -G, 0.0), sleeping=False)
    w.add_static(mb.Plane(), friction=FRICTION)
    s = w.add_soft_body(vertices, tets, density=DENSITY, young_modulus=YOUNG, poisson_ratio=POISSON, damping=0.0,
                        friction=FRICTION, position=CENTRE)
    setup = time.perf_counter() - start
    x0 = s.positions
    _check_start(x0, n)
    timed = _timed_steps(lambda: w.step(DT), f"Marbellous' cube of {len(tets)} tetrahedra", lambda: s.positions)
    return _result(setup, timed, x0, s.positions, tets)


# --- PyBullet ---------------------------------------------------------------------------------------------------
def write_vtk(path, vertices, tets):
    """Write the mesh as a legacy ASCII VTK unstructured grid of tetrahedra (cell type 10), in PyBullet's axes."""
    with open(path, "w") as fh:
        fh.write(f"# vtk DataFile Version 2.0\nsoft cube\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                 f"POINTS {len(vertices)} double\n")
        np.savetxt(fh, to_peer(vertices), fmt="%.17g")
        fh.write(f"\nCELLS {len(tets)} {5 * len(tets)}\n")
        np.savetxt(fh, np.column_stack([np.full(len(tets), 4), tets]), fmt="%d")
        fh.write(f"\nCELL_TYPES {len(tets)}\n")
        np.savetxt(fh, np.full(len(tets), 10), fmt="%d")


def run_pybullet(n):
    import pybullet as p
    start = time.perf_counter()
    vertices, tets = cube(n)
    kw = {"physicsClientId": p.connect(p.DIRECT)}
    try:
        p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD, **kw)
        p.setGravity(*to_peer((0.0, -G, 0.0)), **kw)        # before the soft body: it takes gravity at loading
        p.setPhysicsEngineParameter(fixedTimeStep=DT, numSubSteps=PB_SUBSTEPS[n], sparseSdfVoxelSize=PB_VOXEL, **kw)
        ground = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=list(PB_GROUND), **kw),
                                   basePosition=[0.0, 0.0, -PB_GROUND[2]], **kw)
        p.changeDynamics(ground, -1, lateralFriction=FRICTION, **kw)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "cube.vtk")
            write_vtk(path, vertices, tets)
            body = p.loadSoftBody(path, basePosition=list(to_peer(CENTRE)), scale=1.0, mass=MASS,
                                  useNeoHookean=1, NeoHookeanMu=MU, NeoHookeanLambda=LAMBDA,
                                  NeoHookeanDamping=PB_DAMPING, useMassSpring=0, useBendingSprings=0,
                                  collisionMargin=node_radius(n), useSelfCollision=0, useFaceContact=1,
                                  frictionCoeff=FRICTION, **kw)
        setup = time.perf_counter() - start

        def positions():
            return from_peer(p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH, **kw)[1])

        x0 = positions()
        _check_start(x0, n)
        what = f"PyBullet's cube of {len(tets)} tetrahedra ({PB_SUBSTEPS[n]} sub-steps)"
        timed = _timed_steps(lambda: p.stepSimulation(**kw), what, positions)
        return _result(setup, timed, x0, positions(), tets)
    finally:
        p.disconnect(**kw)


# --- MuJoCo -----------------------------------------------------------------------------------------------------
def mjcf(n, integrator):
    """The scene's MJCF for MuJoCo with ``n`` cells a side and ``integrator``."""
    vertices, tets = cube(n)
    return (f'<mujoco><option timestep="{DT:.17g}" gravity="0 0 -{G:.17g}" integrator="{integrator}"/>'
            f'<worldbody><geom type="plane" size="50 50 1" friction="{FRICTION:.17g} 0.005 0.0001"/>'
            f'<flexcomp name="cube" type="direct" dim="3" pos="{_f(to_peer(CENTRE))}" '
            f'radius="{node_radius(n):.17g}" mass="{MASS:.17g}" point="{_f(to_peer(vertices))}" '
            f'element="{" ".join(str(int(i)) for i in tets.ravel())}">'
            f'<elasticity young="{YOUNG:.17g}" poisson="{POISSON:.17g}" damping="0"/>'
            f'<contact condim="3" friction="{FRICTION:.17g} 0.005 0.0001" selfcollide="none"/>'
            f'</flexcomp></worldbody></mujoco>')


def run_mujoco(n, integrator="Euler"):
    import mujoco
    start = time.perf_counter()
    _, tets = cube(n)
    try:
        model = mujoco.MjModel.from_xml_string(mjcf(n, integrator))
    except ValueError as e:
        raise NotAvailable(f"not available: MuJoCo {mujoco.__version__} refuses the model "
                           f"({' '.join(str(e).split())})") from None
    data = mujoco.MjData(model)
    bodies = model.flex_vertbodyid.copy()
    setup = time.perf_counter() - start
    if model.nflexelem != len(tets):
        raise RuntimeError(f"MuJoCo's flex has {model.nflexelem} tetrahedra, not {len(tets)}")

    def positions():
        mujoco.mj_kinematics(model, data)           # (cheap; mj_step recomputes it from qpos anyway)
        return from_peer(data.xpos[bodies])

    def unstable():
        bad = [w for w in ("BADQPOS", "BADQVEL", "BADQACC")
               if data.warning[getattr(mujoco.mjtWarning, f"mjWARN_{w}")].number > 0]
        if bad:
            return (f"MuJoCo flagged NaN or huge values ({', '.join(bad)}) and reset the state (its clock reads "
                    f"{data.time:.2f} s)")
        return None

    x0 = positions()
    _check_start(x0, n)
    what = f"MuJoCo's cube of {len(tets)} tetrahedra ({integrator})"
    timed = _timed_steps(lambda: mujoco.mj_step(model, data), what, positions, unstable)
    if abs(data.time - (STEPS + 1) * model.opt.timestep) > 1e-6:
        raise RuntimeError(f"MuJoCo reset {what} to its start (its clock reads {data.time:.2f} s)")
    warnings = {name[len("mjWARN_"):]: int(data.warning[w].number) for name, w in mujoco.mjtWarning.__members__.items()
                if name.startswith("mjWARN_") and data.warning[w].number > 0}   # (e.g. INERTIA: its solve gave up)
    return {**_result(setup, timed, x0, positions(), tets), "warnings": warnings}


def run_mujoco_discrete(n):
    return run_mujoco(n, "discrete")


RUNS = {"marbellous": run_marbellous, "pybullet": run_pybullet, "mujoco": run_mujoco,
        "mujoco-discrete": run_mujoco_discrete}


# --- the run --------------------------------------------------------------------------------------------------


def main():
    args = bench_arguments(__doc__, list(RUNS))
    load_start = os.getloadavg()
    sizes = SIZES[:1] if args.quick else SIZES
    results = {}
    stopped = {}                  # engine -> why it is not run at larger n (capped or blown up)
    for n in sizes:
        for name, run in RUNS.items():
            if name not in args.engines:
                continue
            if name in stopped:
                results.setdefault(str(n), {})[name] = {"not_run": stopped[name]}
                continue
            try:
                r = best_of(run, args.repeats, n, LONG_RUN_S)
            except ImportError:
                continue
            for why in ("capped", "blew_up"):
                if why in r:
                    stopped[name] = f"{why.replace('_', ' ')} at n = {n}"
            results.setdefault(str(n), {})[name] = r
            print(f"  n = {n} {name}: " + (", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                                                   for k, v in r.items())), file=sys.stderr, flush=True)
    substeps = ", ".join(f"{PB_SUBSTEPS[n]} at n = {n}" for n in sizes)
    radii = ", ".join(f"{node_radius(n):.3g}" for n in sizes)
    print(f"soft cube: {SIDE:g} m, {DENSITY:g} kg/m^3, E {YOUNG:g} Pa, nu {POISSON}, dropped {DROP} m onto the "
          f"ground, {STEPS} steps at 60 Hz (PyBullet sub-steps: {substeps}; node radius (m): {radii})")
    print(f"{'n':>3s} {'tets':>6s} {'engine':16s} {'ms/step':>9s} {'slowest':>8s} {'volume':>7s} {'lowest':>8s} "
          f"{'ever':>8s} {'top':>6s} {'speed':>7s}")
    for n, by_engine in results.items():
        tets = 6 * int(n) ** 3
        for name, r in by_engine.items():
            if "ms_per_step" not in r:
                what = next(iter(r))
                print(f"{n:>3s} {tets:6d} {name:16s} {what}: {r[what]}")
                continue
            print(f"{n:>3s} {tets:6d} {name:16s} {r['ms_per_step']:9.2f} {r['slowest_step_ms']:8.1f} "
                  f"{r['volume_ratio']:7.4f} {r['lowest_m']:8.4f} {r['lowest_ever_m']:8.4f} {r['top_m']:6.3f} "
                  f"{r['max_speed_m_s']:7.3f}")
    if args.json:
        machine = describe(ROOT, {e: version(e) for e in ("pybullet", "mujoco")
                                 if any(name.startswith(e) for name in args.engines)})
        with open(args.json, "w") as f:
            json.dump({"benchmark": "soft", "machine": machine, "engines": args.engines, "quick": args.quick,
                       "steps": STEPS, "dt": DT, "repeats": args.repeats, "sizes": list(sizes),
                       "tetrahedra": {str(n): 6 * n ** 3 for n in sizes},
                       "nodes": {str(n): (n + 1) ** 3 for n in sizes},
                       "node_radius_m": {str(n): node_radius(n) for n in sizes}, "side_m": SIDE,
                       "density_kg_m3": DENSITY, "mass_kg": MASS, "young_modulus_pa": YOUNG, "poisson_ratio": POISSON,
                       "friction": FRICTION, "drop_m": DROP, "start_centre_m": CENTRE.tolist(),
                       "cap_s_per_step": CAP_S,
                       "load_average_1_5_15_min": {"start": load_start, "end": os.getloadavg()},
                       "pybullet": {"num_substeps": {str(n): PB_SUBSTEPS[n] for n in sizes}, "neo_hookean_mu": MU,
                                    "neo_hookean_lambda": LAMBDA, "neo_hookean_damping": PB_DAMPING,
                                    "sparse_sdf_voxel_size_m": PB_VOXEL, "ground": "static box, top at 0",
                                    "collision_margin_m": "node radius"},
                       "mujoco": {"flexcomp": "direct, dim 3", "solver": "Newton",
                                  "integrators": {"mujoco": "Euler", "mujoco-discrete": "discrete"},
                                  "elasticity_damping": 0.0, "flex_radius_m": "node radius"},
                       "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
