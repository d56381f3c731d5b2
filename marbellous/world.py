"""``World``: the public face of a simulation: it validates and converts what users pass, and calls the
state's operations (``state/world_state.py``) and the step (``pipeline/step.py``).  No physics here."""
from __future__ import annotations

import math
import platform
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ._numba.clock import AVAILABLE as CLOCK_AVAILABLE
from ._validate import (MAX_ACCELERATION, MAX_COORD, MAX_DENSITY, MAX_DT, MAX_HERTZ,
                        MAX_FORCE, MAX_INERTIA_RATIO, MAX_MASS,
                        MAX_SIZE, MAX_SPEED, MAX_STIFFNESS, MIN_DENSITY, MIN_DT, MIN_HERTZ, MIN_MASS, as_choice,
                        as_direction, as_filter_bits, as_flag, as_float, as_int, as_limits, as_motor_speed, as_quat,
                        as_vec3)
from .body import Body
from .collision.broadphase import GRID
from .collision.broadphase import METHODS as BROADPHASE_CODES
from .constraints import BallJoint, Cable, Constraint, FixedJoint, Hinge, Rod, Slider, Spring
from .deformables import particle_layout as P
from .deformables.particle_queries import raycast_particles, raycast_triangles
from .cloth import Cloth, new_cloth
from .fluid import Fluid
from .fluids.coupling import drag_particles, place_obstacles, push_bodies
from .soft import SoftBody, new_soft_body
from .particles import Network, Particles, edge_rows, particle_rows
from .dynamics.integrators import INTEGRATORS
from .dynamics.mass_properties import compound_mass_properties, conditioned_inertia
from .dynamics.rigid import inverse_inertia_np
from .material import material_values
from .math3d import quat_conj, quat_product, quat_to_matrix_np
from .pipeline.contact_events import approach_table, contact_events
from .pipeline.context import MAX_THREADS
from .pipeline.profile import StepProfile, step_profile
from .pipeline.precompile import await_kernel
from .pipeline.raycast import query_box_world, raycast_world, raycast_world_grid
from .pipeline.shape_cast import shape_cast_world
from .pipeline.time_stepping import StepLoop
from .reports import Contact, ContactEvent, RayHit, StepReport
from .shapes.bounds import static_body_box
from .shapes.primitives import Shape
from .state import layout as L
from .state import snapshot as snapshots
from .state.snapshot import Snapshot
from .state.params import SOLVE_ORDERS, SOLVERS, TIME_STEPPING, Tunable, write_params
from .state.world_state import WorldState

BROADPHASES = tuple(BROADPHASE_CODES)
#: a body's shape: one shape, or a list of shapes and (shape, position[, orientation]) tuples (a compound)
ShapeArg = Shape | Sequence[Shape | tuple]
DEFAULT_DENSITY = 1000.0
DEFAULT_SUBSTEPS = 4
DEFAULT_ITERATIONS = 4
#: sub-steps of the particles' step per world step (World.particle_substeps)
DEFAULT_PARTICLE_SUBSTEPS = 16
#: global passes of the cloths' stretch per particle sub-step (World.cloth_stretch_passes)
DEFAULT_CLOTH_STRETCH_PASSES = 0
#: the body table's columns the particles' step takes from before the bodies' step: position, velocity, force
_BODY_START = [L.POS, L.POS + 1, L.POS + 2, L.VEL, L.VEL + 1, L.VEL + 2, L.FORCE, L.FORCE + 1, L.FORCE + 2]
#: ``World.advance`` with ``max_steps=None`` takes at most this much simulated time (s) per call.
MAX_ADVANCE_TIME = 0.25
#: Most steps one ``World.advance`` call may be asked to take.
MAX_ADVANCE_STEPS = 1_000_000
#: Most times a step may be halved (``World.max_halvings``): its shortest interval is ``dt / 2**30``.
MAX_HALVINGS = 30


def _parse_shapes(shape):
    """Normalise ``shape`` (one shape or a list of shapes / (shape, position[, orientation]) tuples)."""
    items = shape if isinstance(shape, (list, tuple)) and not isinstance(shape, Shape) else [shape]
    if isinstance(shape, tuple) and len(shape) in (2, 3) and isinstance(shape[0], Shape) \
            and not isinstance(shape[1], Shape):
        items = [shape]
    if len(items) == 0:
        raise ValueError("shape must be a shape or a non-empty list of shapes")
    parts = []
    for k, item in enumerate(items):
        name = "shape" if len(items) == 1 else f"shape[{k}]"
        if type(item) is Shape or (isinstance(item, tuple) and item and type(item[0]) is Shape):
            raise TypeError(f"{name} must be a concrete shape (Sphere, Box, Capsule, Plane, HeightField, "
                            "TriangleMesh), not the base class Shape")
        if isinstance(item, Shape):
            parts.append((item, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])))
        elif isinstance(item, tuple) and 2 <= len(item) <= 3 and isinstance(item[0], Shape):
            pos = as_vec3(f"{name} position", item[1], bound=MAX_SIZE)
            quat = as_quat(f"{name} orientation", item[2]) if len(item) == 3 else np.array([1.0, 0, 0, 0])
            parts.append((item[0], pos, quat))
        else:
            raise TypeError(f"{name} must be a Shape or a (shape, position[, orientation]) tuple, got {item!r}")
    return parts


_check_flag = as_flag


def _moving_body(shape, position, orientation, velocity, angular_velocity):
    """The validated shapes (none static only), pose and velocities of a body that moves (``add_body``,
    ``add_kinematic``): ``(parts, position, orientation, velocity, angular_velocity)``."""
    parts = _parse_shapes(shape)
    for s, _, _ in parts:
        if s.is_static_only:
            raise ValueError(f"shape {type(s).__name__} is static only: use add_static")
    return (parts, as_vec3("position", position), as_quat("orientation", orientation),
            as_vec3("velocity", velocity, bound=MAX_SPEED, unit="m/s"),
            as_vec3("angular_velocity", angular_velocity, bound=MAX_SPEED, unit="rad/s"))


class World:
    """A physics world: bodies, shapes and constraints advanced in time with SI units, y up.

    ``gravity`` (m/s^2); ``solver`` in ``"sequential_impulse"``, ``"penalty"``, ``"lcp"``; ``iterations``
    and ``substeps`` (None: defaults chosen so stacks stand at 60 Hz); ``integrator`` in
    ``"explicit_euler"``, ``"semi_implicit_euler"``, ``"verlet"``, ``"rk4"``; ``broadphase`` in
    ``"brute"``, ``"sap"``, ``"grid"``, ``"bvh"``, ``"octree"``, ``"kdtree"``, ``"bsp"``; ``threads`` for the
    contact passes of large scenes (1: serial, the default; see :attr:`threads`); ``time_stepping`` in
    ``"fixed"``, ``"retroactive"``, ``"conservative"`` and ``ccd`` (continuous collision) as
    :attr:`time_stepping` and :attr:`ccd` describe.
    """

    # Physical tunables: validated on assignment; docs/architecture.md explains each in physical terms.
    speculative_distance = Tunable(0.02, "gap (m) below which a contact is made before bodies touch",
                                    nonnegative=True, hi=MAX_SIZE)
    contact_hertz = Tunable(60.0, "stiffness of contact position correction, as a frequency (Hz); "
                                   "capped at a quarter of the sub-step rate", lo=MIN_HERTZ, hi=MAX_HERTZ)
    contact_damping_ratio = Tunable(10.0, "damping ratio of contact position correction", nonnegative=True,
                                    hi=1e6)
    joint_hertz = Tunable(60.0, "stiffness of rod and cable correction (Hz); capped at half the sub-step rate",
                           lo=MIN_HERTZ, hi=MAX_HERTZ)
    joint_damping_ratio = Tunable(2.0, "damping ratio of rod and cable correction", nonnegative=True, hi=1e6)
    max_push_speed = Tunable(3.0, "fastest speed (m/s) at which overlapping bodies are pushed apart",
                              positive=True, hi=MAX_SPEED)
    slide_speed = Tunable(0.01, "tangential speed (m/s) above which a new contact slides (dynamic "
                                 "friction) rather than sticks (static friction)", nonnegative=True,
                          hi=MAX_SPEED)
    velocity_tolerance = Tunable(1e-5, "the solver stops iterating a sub-step once no velocity changes by "
                                        "more than this (m/s)", nonnegative=True, hi=MAX_SPEED)
    sleep_linear_speed = Tunable(0.05, "a body slower than this (m/s) is at rest", nonnegative=True,
                                 hi=MAX_SPEED)
    sleep_angular_speed = Tunable(0.05, "a body turning slower than this (rad/s) is at rest", nonnegative=True,
                                  hi=MAX_SPEED)
    time_to_sleep = Tunable(0.5, "seconds an island must rest before it sleeps", positive=True, hi=1e9)
    penalty_hertz = Tunable(30.0, "solver \"penalty\": frequency (Hz) of the contact springs, capped at "
                                   "0.064 times the sub-step rate for stability", lo=MIN_HERTZ,
                            hi=MAX_HERTZ)
    lcp_sweeps = Tunable(100.0, "solver \"lcp\": most projected Gauss-Seidel sweeps per solve (a whole "
                                 "number)", lo=1.0, hi=1e6)
    lcp_relaxation = Tunable(1.0, "solver \"lcp\": over-relaxation factor of projected Gauss-Seidel, in "
                                   "(0, 2)", positive=True, hi=1.99)
    max_penetration = Tunable(0.005, "time_stepping \"retroactive\": a step that ends with a pair of shapes "
                                     "overlapping deeper than this (m), and deeper than when it began, is undone "
                                     "and taken as two halves", positive=True, hi=MAX_SIZE)

    __slots__ = ("_tunables", "_params_dt", "_gravity", "_solver", "_integrator", "_broadphase", "_iterations",
                 "_adaptive_iterations", "_pair_cache", "_solve_order", "_substeps", "_substeps_auto", "_threads",
                 "_ccd", "_sleeping", "_state", "_body_at", "_constraint_at", "_living", "_living_constraints",
                 "_accumulator", "_time_stepping",
                 "_retroactive", "_max_halvings", "_last", "_stepped", "_gone", "_living_particles",
                 "_living_networks", "_living_cloths", "_living_softs", "_living_fluids", "_particle_substeps",
                 "_particle_substeps_auto",
                 "_cloth_stretch_passes",
                 "__weakref__")

    def __init__(self, gravity=(0.0, -9.81, 0.0), *, solver="sequential_impulse", iterations=None,
                 substeps=None, integrator="semi_implicit_euler", broadphase="grid", ccd=True, sleeping=True,
                 threads=1, time_stepping="fixed"):
        self._tunables = {}
        self._params_dt = None  # dt the parameters were last written for (None: write them again)
        self._last = None       # the last step's StepLoop if it took several intervals, or its StepReport if a
        #                         setting changed since (None: one interval, of _params_dt)
        self._max_halvings = 10
        self._stepped = False   # a step was taken since the world was made or restored (contact_events)
        self._gone = []         # rows of bodies removed since the last step (contact_events leaves them out)
        broadphase = as_choice("broadphase", broadphase, BROADPHASES)
        self._state = WorldState(BROADPHASE_CODES[broadphase])
        self._broadphase = broadphase
        self._body_at = []             # the Body handle of each body row (None: free)
        self._constraint_at = []       # the constraint handle of each constraint row
        self._living = {}              # live bodies in creation order (a dict used as an ordered set)
        self._living_constraints = {}
        self._living_particles = {}    # live Particles handles in creation order
        self._living_networks = {}     # live Network handles in creation order
        self._living_cloths = {}       # live Cloth handles in creation order
        self._living_softs = {}        # live SoftBody handles in creation order
        self._living_fluids = {}       # fluids stepped with the world, in the order they were added
        self.particle_substeps = None
        self._cloth_stretch_passes = DEFAULT_CLOTH_STRETCH_PASSES
        self._accumulator = 0.0
        self.gravity = gravity
        self.solver = solver
        self.integrator = integrator
        self.iterations = iterations
        self._adaptive_iterations = False
        self._pair_cache = True
        self._solve_order = SOLVE_ORDERS[0]
        self.substeps = substeps
        self.threads = threads
        self.ccd = ccd
        self.sleeping = sleeping
        self.time_stepping = time_stepping

    # --- properties -------------------------------------------------------------------------------
    @property
    def gravity(self) -> np.ndarray:
        """Gravitational acceleration (m/s^2), each component within +-1e6."""
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value: ArrayLike) -> None:
        self._gravity = as_vec3("gravity", value, bound=MAX_ACCELERATION, unit="m/s^2")
        self._parameters_changed()

    @property
    def solver(self) -> str:
        """Collision handling: ``"sequential_impulse"``, ``"penalty"`` or ``"lcp"``."""
        return self._solver

    @solver.setter
    def solver(self, value: str) -> None:
        self._solver = as_choice("solver", value, SOLVERS)
        self._state.solver = SOLVERS.index(self._solver)
        self._state.invalidate()
        self._parameters_changed()

    @property
    def integrator(self) -> str:
        """``"explicit_euler"``, ``"semi_implicit_euler"``, ``"verlet"`` or ``"rk4"``."""
        return self._integrator

    @integrator.setter
    def integrator(self, value: str) -> None:
        self._integrator = as_choice("integrator", value, INTEGRATORS)
        self._state.invalidate()      # (the step's tier depends on it: world_state.scene_tier)
        self._parameters_changed()

    @property
    def broadphase(self) -> str:
        """Broad phase: one of ``BROADPHASES``; all find the same pairs in the same order, only speed differs."""
        return self._broadphase

    @broadphase.setter
    def broadphase(self, value: str) -> None:
        self._broadphase = as_choice("broadphase", value, BROADPHASES)
        self._state.set_broadphase(BROADPHASE_CODES[self._broadphase])
        self._parameters_changed()

    @property
    def iterations(self) -> int:
        """Most velocity iterations per sub-step (the solver stops earlier once converged); ``None`` sets the
        default, 4.  See also :attr:`adaptive_iterations`."""
        return self._iterations

    @iterations.setter
    def iterations(self, value: int | None) -> None:
        self._iterations = DEFAULT_ITERATIONS if value is None else as_int("iterations", value, lo=1, hi=10000)
        self._parameters_changed()

    @property
    def adaptive_iterations(self) -> bool:
        """Whether deep stacks get more velocity passes than :attr:`iterations` (off by default): a sub-step
        may then take up to two passes per body of the deepest stack (its support depth over the contacts), at
        most 128, those past :attr:`iterations` only while a velocity still changes by 1 mm/s.  A tower of 20
        cubes then keeps its axis for seconds longer; but a heavy heap, its weight now carried down to its
        lowest contacts, sinks deeper into the ground (dynamics/support_depth.py)."""
        return self._adaptive_iterations

    @adaptive_iterations.setter
    def adaptive_iterations(self, value: bool) -> None:
        self._adaptive_iterations = _check_flag("adaptive_iterations", value)
        self._parameters_changed()

    @property
    def pair_cache(self) -> bool:
        """Whether a pair of bodies that has hardly moved relative to each other since the last step keeps that
        step's contact points instead of being tested again (on by default; Jolt's body pair cache): while body
        b has moved less than 0.2 mm and turned less than 0.5 degrees in body a's frame since its points were
        found, and the two move no faster towards each other, they are carried along with the two bodies and
        their depths measured again.  An awake stack of boxes then spends a third of the narrow phase's time,
        and its solver, meeting the same points step after step, settles in fewer passes.  Pairs with a lone
        sphere are always tested (pipeline/pair_cache.py)."""
        return self._pair_cache

    @pair_cache.setter
    def pair_cache(self, value: bool) -> None:
        self._pair_cache = _check_flag("pair_cache", value)
        self._parameters_changed()

    @property
    def solve_order(self) -> str:
        """Order in which the sequential-impulse passes visit the contacts: one of ``SOLVE_ORDERS``.

        ``"coloured"`` (the default): in colour bundles, several contacts at once (dynamics/contact_bundles.py),
        on :attr:`threads` threads when asked.  ``"bottom_up"``: one by one, in order of importance for
        stacking: the contacts nearest whatever cannot move (the ground, static, kinematic and sleeping bodies)
        first, then those one body further up, and so on (the support depth, dynamics/support_depth.py), so
        that each pass carries a stack's correction up from the ground.  A tower of 20 cubes drifts about
        half as far; each pass costs about twice as much, always serial.  The penalty and LCP schemes ignore it.
        """
        return self._solve_order

    @solve_order.setter
    def solve_order(self, value: str) -> None:
        self._solve_order = as_choice("solve_order", value, SOLVE_ORDERS)
        self._parameters_changed()

    @property
    def threads(self) -> int:
        """Threads of the sequential-impulse contact passes (1 to 64; default 1, serial).

        With ``threads = n > 1`` a step with at least 256 contacts solves them in ``n`` regions of the scene
        at once (dynamics/contact_regions.py): deterministic, the same bit for bit on every run, but not
        bit-identical to the serial solver, as contacts are visited in another order.  Needs Numba's
        OpenMP or TBB threading layer to pay (a thread launch costs ~1 us there, ~80 us with its
        fallback "workqueue"); ``NUMBA_NUM_THREADS`` caps the threads actually used.  On a 2-vCPU machine
        the serial wide solver is as fast (docs/architecture.md, "Threads").
        """
        return self._threads

    @threads.setter
    def threads(self, value: int) -> None:
        self._threads = as_int("threads", value, lo=1, hi=MAX_THREADS)
        self._state.threads = self._threads
        self._state.invalidate()      # (the context's scratch is sized for the threads)
        self._parameters_changed()

    @property
    def substeps(self) -> int:
        """Sub-steps per step: each integrates, solves and relaxes over dt / substeps.  Set to None (the
        default) for 4, or more in steps longer than 4/120 s so that no sub-step is longer than 1/120 s
        (``state/params.MAX_SUBSTEP``), and more while an awake body turns so fast that it would turn by more
        than 0.25 rad in a sub-step (up to 64 sub-steps, ``state/params.MAX_TURN_SUBSTEPS``); a number given
        here is taken exactly."""
        return self._substeps

    @substeps.setter
    def substeps(self, value: int | None) -> None:
        self._substeps = DEFAULT_SUBSTEPS if value is None else as_int("substeps", value, lo=1, hi=1000)
        self._substeps_auto = value is None
        self._parameters_changed()

    @property
    def ccd(self) -> bool:
        """Continuous collision (default True): contacts are predicted along each body's motion in the step
        (speculative contacts), and the impacts of bodies that move far in a step for their size (or added
        with ``ccd=True``) are found by time of impact, taken in time order and each resolved at its time,
        the rest of the step going on from there (docs/architecture.md, "Time stepping and continuous
        collision").  False: neither (bodies added with ``ccd=True`` too).  The penalty scheme takes no
        impacts at their time (its springs would give back an impulse's work as energy): there, fast bodies
        can pass through thin shapes."""
        return self._ccd

    @ccd.setter
    def ccd(self, value: bool) -> None:
        self._ccd = _check_flag("ccd", value)
        self._parameters_changed()

    @property
    def time_stepping(self) -> str:
        """How a step of ``dt`` is taken (``StepReport`` in :attr:`last_step` tells how the last one was):

        - ``"fixed"`` (default): one step of ``dt`` with its sub-steps (cut at the times of impact of fast
          bodies when :attr:`ccd` is on);
        - ``"retroactive"``: a step that ends with a pair of shapes overlapping deeper than
          ``max_penetration`` (and deeper than when it began) is undone and taken as two half steps, each
          of which may halve again, down to ``dt / 2**max_halvings``;
        - ``"conservative"``: the step advances to the earliest time at which a new contact can begin (a
          conservative bound from distances and speeds; touching contacts do not limit it), resolves it
          there, and goes on until ``dt`` is used up, never by less than ``dt / 2**max_halvings`` at a time.

        :attr:`time` advances by exactly ``dt`` in every mode.
        """
        return self._time_stepping

    @time_stepping.setter
    def time_stepping(self, value: str) -> None:
        self._time_stepping = as_choice("time_stepping", value, TIME_STEPPING)
        self._retroactive = self._time_stepping == "retroactive"
        self._parameters_changed()

    @property
    def max_halvings(self) -> int:
        """How many times a step may be halved (``"retroactive"``), or cut at impacts no shorter than
        ``dt / 2**max_halvings`` (``"conservative"``, continuous collision): an int in [0, 30], default 10."""
        return self._max_halvings

    @max_halvings.setter
    def max_halvings(self, value: int) -> None:
        self._max_halvings = as_int("max_halvings", value, lo=0, hi=MAX_HALVINGS)
        self._parameters_changed()

    def _parameters_changed(self) -> None:
        """A setting changed: the next step writes the parameters again (the last step's report is kept)."""
        if self._last is None and self._params_dt is not None:
            self._last = StepReport(1, 0, 0, self._params_dt)
        self._params_dt = None

    @property
    def last_step(self) -> StepReport:
        """How the last :meth:`step` was taken: intervals, halvings, time-of-impact events and the shortest
        interval (s); all zero before the first step."""
        loop = self._last
        if isinstance(loop, StepReport):
            return loop
        if loop is not None:
            return StepReport(loop.steps, loop.halvings, loop.toi_events, loop.smallest_dt)
        if self._params_dt is None:
            return StepReport(0, 0, 0, 0.0)
        return StepReport(1, 0, 0, self._params_dt)

    @property
    def sleeping(self) -> bool:
        """Whether resting islands fall asleep."""
        return self._sleeping

    @sleeping.setter
    def sleeping(self, value: bool) -> None:
        self._sleeping = _check_flag("sleeping", value)
        self._parameters_changed()

    @property
    def profiling(self) -> bool:
        """Whether steps time their stages for :attr:`profile` (costs ~20 ns per stage; off by default)."""
        return bool(self._state.params_i[L.PI_PROFILE])

    @profiling.setter
    def profiling(self, value: bool) -> None:
        value = _check_flag("profiling", value)
        if value and not CLOCK_AVAILABLE:
            raise RuntimeError("profiling needs the x86-64 cycle counter; this machine is "
                               f"{platform.machine()!r}")
        self._state.params_i[L.PI_PROFILE] = int(value)

    @property
    def profile(self) -> StepProfile:
        """:class:`StepProfile` of the steps taken while :attr:`profiling` was on (since the last
        :meth:`reset_profile`): seconds per stage, mean pairs, contacts and iterations per step."""
        return step_profile(self._state.stats)

    def reset_profile(self) -> None:
        """Start the :attr:`profile` totals again from zero."""
        self._state.stats[L.STAT_PROFILED_STEPS:] = 0

    @property
    def time(self) -> float:
        """Simulated time so far (s)."""
        return float(self._state.ws[L.W_TIME])

    @property
    def bodies(self) -> list[Body]:
        """The live bodies, in creation order."""
        return list(self._living)

    @property
    def constraints(self) -> list[Constraint | Network]:
        """The live springs, rods, cables and joints, in creation order, then the live particle networks."""
        return list(self._living_constraints) + list(self._living_networks)

    @property
    def particles(self) -> list[Particles]:
        """The live sets of particles, in creation order."""
        return list(self._living_particles)

    @property
    def cloths(self) -> list[Cloth]:
        """The live cloths, in creation order."""
        return list(self._living_cloths)

    @property
    def soft_bodies(self) -> list[SoftBody]:
        """The live soft bodies, in creation order."""
        return list(self._living_softs)

    @property
    def fluids(self) -> list[Fluid]:
        """The fluids this world steps, in the order they were added."""
        return list(self._living_fluids)

    @property
    def particle_substeps(self) -> int:
        """Sub-steps of the particles' step per world step (1 to 1000): more make springs and rods stiffer and
        contacts tighter, at proportional cost (deformables/particle_step.py).  Set to None (the default) for 16,
        or more while a heavy body rests on light particles, so that it does not sink through them (up to 128,
        deformables/load_substeps.py; :attr:`particle_substeps_taken` tells how many the last step took); a
        number given here is taken exactly."""
        return self._particle_substeps

    @particle_substeps.setter
    def particle_substeps(self, value: int | None) -> None:
        self._particle_substeps = (DEFAULT_PARTICLE_SUBSTEPS if value is None
                                   else as_int("particle_substeps", value, lo=1, hi=1000))
        self._particle_substeps_auto = value is None

    @property
    def particle_substeps_taken(self) -> int:
        """Sub-steps the particles' last step took (0 before the first, or without particles)."""
        return self._state.particles.substeps_taken

    @property
    def cloth_stretch_passes(self) -> int:
        """Passes per particle sub-step of the solve that takes the stretch and bending of a whole cloth at once
        (0 to 100; default 0: each spring and hinge on its own, as a network's).  Each pass is one linear solve of
        a backward-Euler step of all the cloth's springs and flat hinges, which holds a fine, stiff sheet
        together where one spring at a time lets it stretch and shake (a 128 x 128 sheet draped over a sphere:
        its edges within 2 % instead of 169 %).  Bodies' contacts with such cloth, and its contacts with itself and
        other cloth, are solved with its step (deformables/stretch_solve.py, deformables/layer_contacts.py)."""
        return self._cloth_stretch_passes

    @cloth_stretch_passes.setter
    def cloth_stretch_passes(self, value: int) -> None:
        self._cloth_stretch_passes = as_int("cloth_stretch_passes", value, lo=0, hi=100)

    # --- particles and networks ----------------------------------------------------------------------------
    def add_particles(self, positions: ArrayLike, *, mass: float | ArrayLike = 1.0,
                      radius: float | ArrayLike = 0.01, velocity: ArrayLike = (0.0, 0.0, 0.0), friction: float = 0.5,
                      static_friction: float | None = None, restitution: float = 0.0, damping: float = 0.0,
                      collide_particles: bool = False) -> Particles:
        """Add a set of particles: point masses with a radius, at ``positions`` (m, ``(N, 3)``).

        ``mass`` (kg, each particle's) and ``radius`` (m) a number or one per particle; ``velocity`` (m/s) a
        3-vector or ``(N, 3)``; ``friction`` (dynamic) and ``static_friction`` (None: ``friction``) Coulomb
        coefficients and ``restitution`` combine with a body's as two bodies' do; ``damping`` (1/s): the rate
        at which each particle's velocity relative to the set's mean decays (internal motion is damped, the
        set's motion is not).  Particles collide with every shape of the world's bodies, pushing them back;
        with ``collide_particles`` also with the other particles that have it.
        """
        f, i = particle_rows(positions, mass, radius, velocity, friction, static_friction, restitution, damping,
                             collide_particles)
        handle = Particles(self, self._state.particles.add_set(f, i))
        self._living_particles[handle] = None
        return handle

    def add_network(self, particles: Particles, edges: ArrayLike, *, kind: str = "spring",
                    stiffness: float | None = None, damping: float = 0.0, rest_length: float | ArrayLike | None = None,
                    breaking_force: float | None = None) -> Network:
        """Join pairs of ``particles`` by springs, rods or cables (``kind``): ``edges`` ``(E, 2)`` particle
        indices.  ``rest_length`` (m; a number or one per edge; None: the distances now) is a spring's rest
        length, a rod's length, a cable's largest length; ``stiffness`` (N/m) is required for springs and
        unused otherwise; ``damping`` (N s/m) damps a spring's stretching; an edge whose tension passes
        ``breaking_force`` (N; None: never) breaks.
        """
        if not isinstance(particles, Particles) or particles._world is not self:
            raise TypeError(f"particles must be a Particles of this world, got {particles!r}")
        f, i, kind = edge_rows(particles, edges, kind, stiffness, damping, rest_length, breaking_force)
        handle = Network(self, self._state.particles.add_network(particles._group, f, i), particles, kind)
        self._living_networks[handle] = None
        return handle

    def add_cloth(self, vertices: ArrayLike, triangles: ArrayLike, *, mass: float, stretch_stiffness: float = 1.0e4,
                  bend_stiffness: float = 1.0e-3, damping: float = 0.01, thickness: float = 0.01,
                  friction: float = 0.5, self_collision: bool = True, tear_strain: float | None = None,
                  position: ArrayLike = (0.0, 0.0, 0.0), orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0)) -> Cloth:
        """Add a cloth: the triangle mesh ``vertices`` (m, ``(V, 3)``, its rest shape, placed at ``position``
        and ``orientation``) and ``triangles`` (``(T, 3)`` vertex indices; ``cloth_grid`` makes a sheet).

        ``mass`` (kg): the whole cloth's, spread over the vertices by area.  ``stretch_stiffness`` (N/m): the
        membrane's force per unit width per unit strain; ``bend_stiffness`` (N m): its bending rigidity,
        moment per unit width per unit curvature; ``damping`` (1/s): the rate at which each vertex's velocity
        relative to the cloth's mean decays.  ``thickness`` (m): points stay this far from its triangles, and
        its vertices half of it from every shape.  ``friction``: Coulomb coefficient (static and dynamic) with
        shapes.  ``self_collision``: its vertices meet its own triangles (a fold does not pass through
        itself).  ``tear_strain``: an edge stretched past ``1 + tear_strain`` times its rest length tears, and
        the cloth splits along the tear (None: never).  The cloth collides with every shape of the world's
        bodies (two ways), with other cloths, and with particles made with ``collide_particles``.
        """
        record, f, i, ef, ei = new_cloth(vertices, triangles, mass, stretch_stiffness, bend_stiffness, damping,
                                         thickness, friction, self_collision, tear_strain, position, orientation)
        self._state.particles.add_cloth(record, f, i, ef, ei)
        handle = Cloth(self, record)
        self._living_cloths[handle] = None
        return handle

    def add_soft_body(self, vertices: ArrayLike, tetrahedra: ArrayLike, *, density: float = 1000.0,
                      young_modulus: float = 1.0e5, poisson_ratio: float = 0.3, damping: float = 0.0,
                      friction: float = 0.5, position: ArrayLike = (0.0, 0.0, 0.0),
                      orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0), radius: float | None = None) -> SoftBody:
        """Add a soft body: the tetrahedral mesh ``vertices`` (m, ``(V, 3)``, its rest shape, placed at
        ``position`` and ``orientation``) and ``tetrahedra`` (``(K, 4)`` vertex indices; ``tet_box`` and
        ``tetrahedralize`` make them).

        ``density`` (kg/m^3); ``young_modulus`` (Pa) and ``poisson_ratio`` (below 0.5): the material of linear
        elasticity, with each tetrahedron's rotation removed (corotated), so that it turns without strain;
        ``damping`` (s): stiffness-proportional (Rayleigh) damping, a vibration of angular frequency ``w``
        decays at the rate ``damping w^2 / 2`` (the implicit step damps fast vibrations as well).  The nodes
        are spheres of ``radius`` (m; None: a quarter of the mesh's shortest edge) with the Coulomb coefficient
        ``friction``: they collide with every shape of the world's bodies (two ways), with other soft bodies'
        nodes, with cloths and with particles made with ``collide_particles``.  Each step advances the nodes'
        velocities by one backward-Euler step of the elastic forces (stable for stiff materials at 60 Hz).
        """
        record, f, i, tf, ti = new_soft_body(vertices, tetrahedra, density, young_modulus, poisson_ratio, damping,
                                             friction, position, orientation, radius)
        self._state.particles.add_soft(record, f, i, tf, ti)
        handle = SoftBody(self, record)
        self._living_softs[handle] = None
        return handle

    # --- bodies -------------------------------------------------------------------------------------
    def add_fluid(self, fluid: Fluid) -> Fluid:
        """Step ``fluid`` (a 3D :class:`Fluid`) with this world from now on: the bodies are obstacles that the
        fluid flows around and that push it aside; below ``fluid.surface`` they float (buoyancy for their
        submerged volume), and bodies, particles and cloth in the fluid feel its drag.  Returns ``fluid``."""
        if not isinstance(fluid, Fluid):
            raise TypeError(f"fluid must be a Fluid, got {fluid!r}")
        if fluid.dimensions != 3:
            raise ValueError("fluid must be a 3D Fluid to join a world (a 2D fluid has no volume to share with "
                             "bodies): make it with a resolution (nx, ny, nz)")
        if fluid._world is not None:
            raise ValueError("fluid is already in a world (remove it from there first)")
        fluid._world = self
        self._living_fluids[fluid] = None
        return fluid

    def add_body(self, shape: ShapeArg, *, position: ArrayLike = (0.0, 0.0, 0.0),
                 orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0), velocity: ArrayLike = (0.0, 0.0, 0.0),
                 angular_velocity: ArrayLike = (0.0, 0.0, 0.0), mass: float | None = None,
                 density: float | None = None, friction: float = 0.5, static_friction: float | None = None,
                 restitution: float = 0.0, rolling_friction: float = 0.0, torsional_friction: float = 0.0,
                 linear_damping: float = 0.0, angular_damping: float = 0.0, sensor: bool = False,
                 group: int = 1, mask: int = -1, ccd: bool | None = None) -> Body:
        """Add a dynamic rigid body and return its :class:`Body`.

        ``shape``: a shape, or a list of shapes / ``(shape, position[, orientation])`` tuples (a compound;
        the body's origin becomes the compound's centre of mass).  Give ``mass`` (kg) or ``density``
        (kg/m^3, default 1000), not both.  ``friction`` is the sliding (dynamic) Coulomb coefficient,
        ``static_friction`` the sticking one (None: same), ``restitution`` in [0, 1],
        ``rolling_friction`` (m) the lever arm of the rolling resistance: the resisting torque is at most
        ``rolling_friction * normal force`` (0.01 = 1 cm), and ``torsional_friction`` (m) likewise resists
        spinning about the contact normal; each combines by maximum with the other body's.
        ``linear_damping`` and ``angular_damping`` (1/s) slow the body as ``dv/dt = -c v`` (``0.5``: a
        velocity falls to ``1/e`` in 2 s); all of these can be changed later through the :class:`Body`.
        ``group`` and ``mask`` filter collisions: two
        bodies collide only if ``a.group & b.mask`` and ``b.group & a.mask`` are both nonzero (64-bit
        integers; the defaults, 1 and -1 (all bits), let everything collide).  Bounds (``marbellous._validate``):
        position within +-1e12 m, velocities within +-1e9 m/s (rad/s), mass 1e-30 .. 1e30 kg,
        density 1e-6 .. 1e6 kg/m^3, friction 0 .. 1000; a compound's parts within 1e6 m of its origin; the
        principal moments of inertia within a factor 1e10 of each other; moments more than
        ``MAX_MOMENT_RATIO`` (1e4) below the largest are raised to that (``Body.inertia`` gives the tensor
        simulated: a needle's spin about its own axis would otherwise take up the contacts' rounding as
        hundreds of rad/s).  ``ccd`` (continuous collision, while
        the world's :attr:`ccd` is on): None sweeps the body when it moves far in a step for its size, True
        always, False never (not even its motion in its bounding box).
        """
        parts, pos, quat, vel, omega = _moving_body(shape, position, orientation, velocity, angular_velocity)
        if mass is not None and density is not None:
            raise ValueError("give mass or density, not both")
        if mass is not None:
            mass = as_float("mass", mass, lo=MIN_MASS, hi=MAX_MASS, unit="kg")
        rho = DEFAULT_DENSITY if density is None else as_float("density", density, lo=MIN_DENSITY,
                                                                 hi=MAX_DENSITY, unit="kg/m^3")
        material = material_values(friction, static_friction, restitution, rolling_friction, torsional_friction,
                                   linear_damping, angular_damping)
        sensor = _check_flag("sensor", sensor)
        ccd = None if ccd is None else _check_flag("ccd", ccd)
        group, mask = as_filter_bits("group", group), as_filter_bits("mask", mask)
        m, com, inertia = compound_mass_properties(parts, rho, mass)
        if mass is None and not MIN_MASS <= m <= MAX_MASS:
            raise ValueError(f"density: the body's mass from density {rho!r} kg/m^3 would be {m:.3g} kg, "
                             f"outside {MIN_MASS:g} .. {MAX_MASS:g} kg")
        moments = np.linalg.eigvalsh(inertia) if np.all(np.isfinite(inertia)) else np.zeros(3)
        if not (moments[0] > 0.0 and moments[2] <= MAX_INERTIA_RATIO * moments[0]):
            raise ValueError(f"shape: the body's principal moments of inertia ({moments[0]:.3g} .. {moments[2]:.3g} "
                             f"kg m^2) differ by more than a factor {MAX_INERTIA_RATIO:g}; so thin a body spins "
                             "up from rounding alone: make it thicker or its parts closer")
        inertia = conditioned_inertia(inertia)
        inverse = inverse_inertia_np(inertia)
        # Shapes are stored relative to the centre of mass: the body's origin is its centre of mass.
        parts = [(s, p - com, q) for s, p, q in parts]
        flags = L.F_SENSOR if sensor else 0
        if ccd is not None:
            flags |= L.F_CCD_ALWAYS if ccd else L.F_CCD_NEVER
        if np.array_equal(inertia, np.eye(3) * inertia[0, 0]):
            flags |= L.F_ISOTROPIC
        row = self._state.insert_body(parts, pos, quat, vel, omega, m, inertia, inverse, material, flags, None,
                                      group, mask)
        return self._new_body_handle(row, parts)

    def add_static(self, shape: ShapeArg, *, position: ArrayLike = (0.0, 0.0, 0.0),
                   orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0), friction: float = 0.5,
                   static_friction: float | None = None, restitution: float = 0.0, rolling_friction: float = 0.0,
                   torsional_friction: float = 0.0, sensor: bool = False, group: int = 1, mask: int = -1) -> Body:
        """Add a static (immovable) body: any shape, including Plane, HeightField and TriangleMesh.

        ``friction``, ``static_friction``, ``restitution``, ``rolling_friction`` (m), ``torsional_friction``
        (m), ``group`` and ``mask`` as for :meth:`add_body`.
        """
        parts = _parse_shapes(shape)
        pos = as_vec3("position", position)
        quat = as_quat("orientation", orientation)
        material = material_values(friction, static_friction, restitution, rolling_friction, torsional_friction)
        flags = L.F_STATIC | (L.F_SENSOR if _check_flag("sensor", sensor) else 0)
        group, mask = as_filter_bits("group", group), as_filter_bits("mask", mask)
        zero = np.zeros(3)
        row = self._state.insert_body(parts, pos, quat, zero, zero, math.inf, None, None, material, flags,
                                      static_body_box(parts, pos, quat), group, mask)
        return self._new_body_handle(row, parts)

    def add_kinematic(self, shape: ShapeArg, *, position: ArrayLike = (0.0, 0.0, 0.0),
                      orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0), velocity: ArrayLike = (0.0, 0.0, 0.0),
                      angular_velocity: ArrayLike = (0.0, 0.0, 0.0), friction: float = 0.5,
                      static_friction: float | None = None, restitution: float = 0.0, rolling_friction: float = 0.0,
                      torsional_friction: float = 0.0, sensor: bool = False, group: int = 1,
                      mask: int = -1) -> Body:
        """Add a kinematic body: one that moves by its velocities only (a moving platform, a door, a
        paddle), as if of infinite mass.  It pushes and carries dynamic bodies (by its contacts' friction)
        and is never pushed; gravity and forces do not act on it, and it never sleeps.

        Set its ``velocity`` and ``angular_velocity`` (m/s, rad/s) or call :meth:`Body.move_to` each step;
        assigning its ``position`` or ``orientation`` teleports it (no velocity: what it lands on is not
        thrown).  ``shape``: a shape or compound of shapes that dynamic bodies may have (not a plane, height
        field or mesh); the materials, ``sensor``, ``group`` and ``mask`` as for :meth:`add_body`.
        """
        parts, pos, quat, vel, omega = _moving_body(shape, position, orientation, velocity, angular_velocity)
        material = material_values(friction, static_friction, restitution, rolling_friction, torsional_friction)
        flags = L.F_KINEMATIC | (L.F_SENSOR if _check_flag("sensor", sensor) else 0)
        group, mask = as_filter_bits("group", group), as_filter_bits("mask", mask)
        row = self._state.insert_body(parts, pos, quat, vel, omega, math.inf, None, None, material, flags, None,
                                      group, mask)
        return self._new_body_handle(row, parts)

    def _new_body_handle(self, row, parts):
        body = Body(self, row, int(self._state.bodies.revision[row]),
                    [(s, p.copy(), q.copy()) for s, p, q in parts])
        if row == len(self._body_at):
            self._body_at.append(body)
        else:
            self._body_at[row] = body
        self._living[body] = None
        return body

    def _check_body(self, body, name):
        """The row of ``body``, which must be a live body of this world."""
        if not isinstance(body, Body):
            raise TypeError(f"{name} must be a Body, got {body!r}")
        if body._world is not self:
            raise ValueError(f"{name} does not belong to this world (or was removed)")
        return body._index

    def _wake(self, row):
        """Wake body row ``row`` (and reset its rest timer)."""
        self._state.wake(row)

    def remove(self, body_or_constraint: Body | Constraint) -> None:
        """Remove a body (with the constraints attached to it) or a constraint; other handles stay valid.

        The removed object's handle raises on any later use; bodies that rested on a removed body wake."""
        obj = body_or_constraint
        if isinstance(obj, (Particles, Network)):
            self._remove_particles_or_network(obj)
        elif isinstance(obj, Fluid):
            if obj._world is not self:
                raise ValueError("body_or_constraint does not belong to this world (or was removed)")
            del self._living_fluids[obj]
            obj._world = None
            obj._clear_obstacles()
        elif isinstance(obj, (Cloth, SoftBody)):
            if obj._world is not self or not obj._record.alive:
                raise ValueError("body_or_constraint does not belong to this world (or was removed)")
            if isinstance(obj, Cloth):
                self._state.particles.remove_cloth(obj._record)
                del self._living_cloths[obj]
            else:
                self._state.particles.remove_soft(obj._record)
                del self._living_softs[obj]
            obj._world = None
        elif isinstance(obj, Body):
            i = self._check_body(obj, "body_or_constraint")
            for c in self.constraints:
                if c.body_a is obj or c.body_b is obj:
                    self.remove(c)
            self._wake_neighbours(i)
            self._gone.append(i)
            self._state.particles.forget_body(i)
            self._state.free_body(i)
            self._body_at[i] = None
            del self._living[obj]
            obj._world = None
        elif isinstance(obj, Constraint):
            if obj._world is not self:
                raise ValueError("body_or_constraint does not belong to this world (or was removed)")
            ends = self._state.ki[obj._index, L.K_BODY_A:L.K_BODY_B + 1].copy()
            self._state.free_constraint(obj._index)
            self._mark_jointed(ends)
            self._constraint_at[obj._index] = None
            del self._living_constraints[obj]
            obj._world = None
        else:
            raise TypeError(f"body_or_constraint must be a Body, a constraint, Particles, a Network, a Cloth, a "
                            f"SoftBody or a Fluid, got {obj!r}")

    def _remove_particles_or_network(self, obj):
        """Remove a set of particles (with its networks) or a network."""
        if obj._world is not self or not obj._group.alive:
            raise ValueError("body_or_constraint does not belong to this world (or was removed)")
        ps = self._state.particles
        if isinstance(obj, Particles):
            ps.remove_set(obj._group)
            del self._living_particles[obj]
        else:
            ps.remove_network(obj._group)
        for net in [n for n in self._living_networks if not n._group.alive]:
            del self._living_networks[net]
            net._world = None
        obj._world = None

    def _wake_neighbours(self, i):
        """Wake the sleeping bodies that may rest on body row ``i``: those whose boxes touch its box, and the
        rest of its island."""
        st = self._state
        n = st.bodies.end
        box = st.aabbs[i]
        boxes = st.aabbs[:n]
        touching = np.all(boxes[:, :3] <= box[3:], axis=1) & np.all(box[:3] <= boxes[:, 3:], axis=1)
        island = st.bi[i, L.ISLAND]
        same_island = (st.bi[:n, L.ISLAND] == island) & (island >= 0)
        sleeping = (st.bi[:n, L.FLAGS] & L.F_SLEEPING) != 0
        for j in np.flatnonzero(sleeping & (touching | same_island)):
            st.wake(int(j))

    # --- constraints -------------------------------------------------------------------------------
    def _insert_constraint(self, cls, ctype, a, b, anchor_a, anchor_b, length, stiffness=0.0, damping=0.0,
                           breaking_force=None):
        ia = self._check_body(a, "a")
        ib = -1 if b is None else self._check_body(b, "b")
        if ia == ib:
            raise ValueError("a and b must be different bodies")
        st = self._state
        fixed = L.F_STATIC | L.F_KINEMATIC
        if st.bi[ia, L.FLAGS] & fixed and (ib < 0 or st.bi[ib, L.FLAGS] & fixed):
            raise ValueError("a constraint needs at least one dynamic body")
        brk = math.inf if breaking_force is None else as_float("breaking_force", breaking_force, positive=True,
                                                                 unit="N")
        c = st.insert_constraint(ctype, ia, ib, anchor_a, anchor_b, length, stiffness, damping, brk)
        handle = cls(self, c, int(st.constraints.revision[c]), a, b)
        if c == len(self._constraint_at):
            self._constraint_at.append(handle)
        else:
            self._constraint_at[c] = handle
        self._living_constraints[handle] = None
        st.wake(ia)
        if ib >= 0:
            st.wake(ib)
        return handle

    def add_spring(self, a: Body, b: Body | None, *, rest_length: float, stiffness: float, damping: float = 0.0,
                   anchor_a: ArrayLike = (0.0, 0.0, 0.0), anchor_b: ArrayLike = (0.0, 0.0, 0.0),
                   breaking_force: float | None = None) -> Spring:
        """Connect two bodies (``b=None``: a fixed world point ``anchor_b``) by a damped Hooke spring.

        ``F = -k (l - l0) - c dl/dt`` with ``rest_length`` l0 (m), ``stiffness`` k (N/m), ``damping`` c
        (N s/m); anchors in each body's frame (m).  Past ``breaking_force`` (N) it breaks for good.
        """
        l0 = as_float("rest_length", rest_length, nonnegative=True, hi=2 * MAX_COORD, unit="m")
        k = as_float("stiffness", stiffness, nonnegative=True, hi=MAX_STIFFNESS, unit="N/m")
        c = as_float("damping", damping, nonnegative=True, hi=MAX_STIFFNESS, unit="N s/m")
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        return self._insert_constraint(Spring, L.KT_SPRING, a, b, pa, pb, l0, k, c, breaking_force)

    def add_rod(self, a: Body, b: Body | None, *, length: float | None = None, anchor_a: ArrayLike = (0.0, 0.0, 0.0),
                anchor_b: ArrayLike = (0.0, 0.0, 0.0)) -> Rod:
        """Keep the anchors of ``a`` and ``b`` (``b=None``: the world point ``anchor_b``) at a fixed distance.

        ``length`` (m; None: the current distance).  Solved with the contacts as a stiff constraint:
        the separating velocity along the rod is driven to zero.
        """
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        length = self._joint_length("length", length, a, b, pa, pb)
        return self._insert_constraint(Rod, L.KT_ROD, a, b, pa, pb, length)

    def add_cable(self, a: Body, b: Body | None, *, max_length: float, anchor_a: ArrayLike = (0.0, 0.0, 0.0),
                  anchor_b: ArrayLike = (0.0, 0.0, 0.0)) -> Cable:
        """An inextensible cable: the anchors stay at most ``max_length`` (m) apart, slack when closer."""
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        length = as_float("max_length", max_length, positive=True, hi=2 * MAX_COORD, unit="m")
        return self._insert_constraint(Cable, L.KT_CABLE, a, b, pa, pb, length)

    # --- joints -------------------------------------------------------------------------------------------
    def add_ball_joint(self, a: Body, b: Body | None, *, anchor: ArrayLike,
                       breaking_force: float | None = None) -> BallJoint:
        """Join ``a`` and ``b`` (``b=None``: the world) at the world point ``anchor`` (m): it stays one
        point of both, and they turn freely about it.  Past ``breaking_force`` (N) the joint breaks."""
        return self._insert_joint(BallJoint, L.KT_BALL, a, b, as_vec3("anchor", anchor), None, breaking_force)

    def add_hinge(self, a: Body, b: Body | None, *, anchor: ArrayLike, axis: ArrayLike,
                  limits: tuple[float, float] | None = None, motor_speed: float | None = None,
                  max_motor_torque: float = 0.0, breaking_force: float | None = None) -> Hinge:
        """A hinge at the world point ``anchor`` (m) about the world direction ``axis`` (at creation; it
        then turns with ``b``): ``a`` turns relative to ``b`` (None: the world) about the axis only.

        ``limits=(lower, upper)`` bound :attr:`Hinge.angle` (rad, within [-pi, pi]); a motor drives
        :attr:`Hinge.angular_speed` towards ``motor_speed`` (rad/s) with at most ``max_motor_torque``
        (N m).  Past ``breaking_force`` (N) the hinge breaks."""
        hinge = self._insert_joint(Hinge, L.KT_HINGE, a, b, as_vec3("anchor", anchor), as_direction("axis", axis),
                                   breaking_force, limits, motor_speed, "max_motor_torque", max_motor_torque)
        return hinge

    def add_slider(self, a: Body, b: Body | None, *, anchor: ArrayLike, axis: ArrayLike,
                   limits: tuple[float, float] | None = None, motor_speed: float | None = None,
                   max_motor_force: float = 0.0, breaking_force: float | None = None) -> Slider:
        """A slider along the world direction ``axis`` through the world point ``anchor`` (m): ``a`` moves
        relative to ``b`` (None: the world) along the axis only, and does not turn relative to it.

        ``limits=(lower, upper)`` bound :attr:`Slider.position` (m); a motor drives :attr:`Slider.speed`
        towards ``motor_speed`` (m/s) with at most ``max_motor_force`` (N).  Past ``breaking_force`` (N) the
        slider breaks."""
        return self._insert_joint(Slider, L.KT_SLIDER, a, b, as_vec3("anchor", anchor), as_direction("axis", axis),
                                  breaking_force, limits, motor_speed, "max_motor_force", max_motor_force)

    def add_fixed_joint(self, a: Body, b: Body | None, *, breaking_force: float | None = None) -> FixedJoint:
        """Weld ``a`` to ``b`` (None: the world) in their present relative pose.  Past ``breaking_force`` (N)
        the weld breaks."""
        ia = self._check_body(a, "a")
        return self._insert_joint(FixedJoint, L.KT_FIXED, a, b, self._state.bf[ia, L.POS:L.POS + 3].copy(), None,
                                  breaking_force)

    def _insert_joint(self, cls, ctype, a, b, anchor, axis, breaking_force, limits=None, motor_speed=None,
                      most_name="", most=0.0):
        """Validate the rest of a joint's arguments, then write it: anchors and axis in each body's frame and
        the bodies' relative orientation now."""
        ia = self._check_body(a, "a")
        ib = -1 if b is None else self._check_body(b, "b")
        bf = self._state.bf
        if limits is not None:
            limits = as_limits("limits", limits, cls._LIMIT_RANGE, cls._UNIT)
        if motor_speed is not None:
            motor_speed = as_motor_speed(motor_speed, cls._UNIT)
        most = as_float(most_name, most, nonnegative=True, hi=MAX_FORCE) if most_name else 0.0
        ra = quat_to_matrix_np(bf[ia, L.QUAT:L.QUAT + 4])
        rb = np.eye(3) if ib < 0 else quat_to_matrix_np(bf[ib, L.QUAT:L.QUAT + 4])
        anchor_a = ra.T @ (anchor - bf[ia, L.POS:L.POS + 3])
        anchor_b = anchor if ib < 0 else rb.T @ (anchor - bf[ib, L.POS:L.POS + 3])
        handle = self._insert_constraint(cls, ctype, a, b, anchor_a, anchor_b, 0.0, breaking_force=breaking_force)
        st = self._state
        row, flags = st.kf[handle._index], st.ki[handle._index]
        qa = bf[ia, L.QUAT:L.QUAT + 4]
        qb = np.array([1.0, 0.0, 0.0, 0.0]) if ib < 0 else bf[ib, L.QUAT:L.QUAT + 4]
        row[L.K_REF_QUAT:L.K_REF_QUAT + 4] = quat_product.py_func(quat_conj.py_func(qb), qa)
        if axis is not None:
            row[L.K_AXIS_A:L.K_AXIS_A + 3] = ra.T @ axis
            row[L.K_AXIS_B:L.K_AXIS_B + 3] = rb.T @ axis
        if limits is not None:
            row[L.K_LOWER], row[L.K_UPPER] = limits
            flags[L.K_FLAGS] |= L.KF_LIMITS
        if motor_speed is not None:
            row[L.K_MOTOR_SPEED] = motor_speed
            flags[L.K_FLAGS] |= L.KF_MOTOR
        row[L.K_MOTOR_MAX] = most
        for i in (ia, ib):
            if i >= 0:
                st.bi[i, L.FLAGS] |= L.F_JOINTED
        return handle

    def _mark_jointed(self, rows):
        """Set or clear ``F_JOINTED`` on body ``rows`` as they have a live joint or not."""
        st = self._state
        n = st.constraints.end
        ki = st.ki[:n]
        live = (ki[:, L.K_TYPE] >= L.KT_BALL) & ((ki[:, L.K_FLAGS] & L.KF_ALIVE) != 0)
        joined = set(ki[live, L.K_BODY_A].tolist()) | set(ki[live, L.K_BODY_B].tolist())
        for i in rows:
            if i >= 0:
                if i in joined:
                    st.bi[i, L.FLAGS] |= L.F_JOINTED
                else:
                    st.bi[i, L.FLAGS] &= ~L.F_JOINTED

    def _joint_length(self, name, length, a, b, pa, pb):
        if length is not None:
            return as_float(name, length, positive=True, hi=2 * MAX_COORD, unit="m")
        bf = self._state.bf
        ia = self._check_body(a, "a")
        wa = bf[ia, L.POS:L.POS + 3] + quat_to_matrix_np(bf[ia, L.QUAT:L.QUAT + 4]) @ pa
        if b is None:
            wb = pb
        else:
            ib = self._check_body(b, "b")
            wb = bf[ib, L.POS:L.POS + 3] + quat_to_matrix_np(bf[ib, L.QUAT:L.QUAT + 4]) @ pb
        d = float(np.linalg.norm(wb - wa))
        if not d >= 1e-9:
            raise ValueError(f"{name} is None and the anchors coincide: give a positive {name}")
        return d

    # --- time ------------------------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Advance the simulation by exactly ``dt`` seconds (in ``substeps`` equal sub-steps, or more, none
        longer than 1/120 s, in several intervals as :attr:`time_stepping` and :attr:`ccd` ask:
        :attr:`last_step`); ``dt`` in [1e-6, 1] s (``_validate.MIN_DT``, ``MAX_DT``)."""
        if (self._retroactive or self._living_particles or self._living_cloths or self._living_softs
                or self._living_fluids):
            dt, body_start = self._begin_step(dt)
            self._end_step(dt, -1 if self._retroactive else self._state.step(), body_start)
        else:       # rigid bodies alone at fixed steps: the compiled step, then only what it or an event asks for
            if type(dt) is not float or dt != self._params_dt:
                dt = self._parameters_for(dt)
            status = self._state.step()
            if status != 0 or self._gone or self._last is not None or not self._stepped:
                self._end_step(dt, status, None)

    def _parameters_for(self, dt):
        """``dt`` (s) checked, and the step's parameters written for it; returns it as a float."""
        if type(dt) is not float or dt != self._params_dt:    # (the last dt was validated)
            dt = as_float("dt", dt, lo=MIN_DT, hi=MAX_DT, unit="s")
            if dt != self._params_dt:
                write_params(self, dt, self._state.params_f, self._state.params_i)
                self._params_dt = dt
        return dt

    def _compile_ahead(self, dt, first=()):
        """Start compiling the step of ``dt`` seconds as the world is now in helper processes, when it is not in
        the kernel cache (``pipeline/precompile.ahead``), after the ray cast (:meth:`raycast`, which waits for
        it) and ``first`` (``[(kernel, arguments)]`` the program calls, such as ``query.pair_test_call``'s): a
        program that casts rays before its first step (the game) finds all compiled on two cores.  The first
        step finishes it."""
        self._parameters_for(dt)
        self._state.compile_ahead([self._ray_kernel(np.zeros(3), np.array([0.0, -1.0, 0.0]), 1.0, -1),
                                   *first])
        self._params_dt = None          # (no step has been taken with them: the first writes them again)

    def _begin_step(self, dt):
        """The step's first part, before the rigid bodies' step: ``dt`` checked and written into the
        parameters, the fluids' forces on the bodies and particles; returns ``(dt, body_start)``
        (``body_start``: the bodies' rows the particles' step needs, None without particles)."""
        dt = self._parameters_for(dt)
        particles = bool(self._living_particles or self._living_cloths or self._living_softs)
        for fluid in self._living_fluids:
            push_bodies(fluid, self.bodies, self._gravity, dt)
            if particles:
                drag_particles(fluid, self._state.particles, self._gravity, dt)
        body_start = np.ascontiguousarray(self._state.bf[:self._state.bodies.end, _BODY_START]) if particles else None
        return dt, body_start

    def _end_step(self, dt, status, body_start):
        """The step's last part, after the rigid bodies' step returned ``status`` (-1: not taken, the
        retroactive mode takes it in intervals): the intervals a time of impact asks for, then the particles'
        and the fluids' steps."""
        self._stepped = True
        if self._gone:
            self._gone = []
        if status != 0:
            self._step_in_intervals(dt, status)
        elif self._last is not None:
            self._last = None
        if body_start is not None:
            self._state.particles.step(self._state, dt, self._gravity, self._particle_substeps,
                                      self._particle_substeps_auto, self._cloth_stretch_passes, body_start)
        for fluid in self._living_fluids:
            place_obstacles(fluid, self.bodies)
            fluid._advance(dt)

    def _step_in_intervals(self, dt, status):
        """The step of ``dt`` seconds in several intervals (``pipeline/time_stepping.py``): after a first
        attempt of the whole step that stopped at an impact (``status``: "fixed" and "conservative"), or
        retroactively."""
        st = self._state
        pf, pi = st.params_f, st.params_i
        loop = StepLoop(st, lambda tau: write_params(self, tau, pf, pi, step_dt=dt), dt, pf[L.PF_MIN_INTERVAL])
        try:
            if self._retroactive:
                loop.retroactive_span(dt, 0, self._max_halvings, self.max_penetration, None)
            else:
                loop.run_span(dt, status)
            loop.finish()
        finally:
            if loop.rewritten:
                self._params_dt = None      # (the parameters hold the last interval's length)
        self._last = loop

    def advance(self, frame_time: float, dt: float = 1.0 / 120.0, max_steps: int | None = None) -> float:
        """Game-loop accumulator: take as many fixed steps of ``dt`` as ``frame_time`` (s) allows.

        Returns the interpolation ``alpha = leftover / dt`` in [0, 1) for rendering between the last two
        states.  Time is kept in whole steps plus a remainder so no step is lost to round-off.
        ``max_steps`` caps the steps of this call (None: as many as 0.25 s of simulated time,
        ``ceil(0.25 / dt)``; at most 1,000,000); the excess frame time is dropped, so a stalled frame
        (or a huge ``frame_time``) never stalls the game.  ``frame_time`` >= 0 s, finite; ``dt`` in
        [1e-6, 1] s.
        """
        frame_time = as_float("frame_time", frame_time, nonnegative=True, unit="s")
        dt = as_float("dt", dt, lo=MIN_DT, hi=MAX_DT, unit="s")
        if max_steps is None:
            max_steps = math.ceil(MAX_ADVANCE_TIME / dt)
        else:
            max_steps = as_int("max_steps", max_steps, lo=1, hi=MAX_ADVANCE_STEPS)
        acc = self._accumulator + frame_time
        # A step is due when the accumulator reaches dt up to round-off in the sum.
        due = acc / dt + 1e-9
        if due >= max_steps + 1:          # (also when acc / dt overflows to inf)
            n = max_steps
            acc = n * dt
        else:
            n = math.floor(due)
        for _ in range(n):
            self.step(dt)
        self._accumulator = max(acc - n * dt, 0.0)
        alpha = self._accumulator / dt
        return alpha if alpha < 1.0 else math.nextafter(1.0, 0.0)

    # --- queries ------------------------------------------------------------------------------------------
    def contacts(self) -> list[Contact]:
        """The contacts that the last step's collision detection found (at the poses the step began with),
        with the impulses the solver applied at each."""
        st = self._state
        cf, ci = st.cache_f, st.cache_i
        at = self._body_at
        out = []
        for c in range(st.n_cached):
            f, i = cf[c], ci[c]
            out.append(Contact(at[i[L.C_BODY_A]], at[i[L.C_BODY_B]], f[L.C_POINT:L.C_POINT + 3].copy(),
                               f[L.C_NORMAL:L.C_NORMAL + 3].copy(), float(f[L.C_DEPTH]), float(f[L.C_SUM_N]),
                               f[L.C_SUM_T:L.C_SUM_T + 3].copy()))
        return out

    def contact_events(self) -> list[ContactEvent]:
        """What began and ended touching during the last step: one :class:`ContactEvent` per pair of bodies
        (not per contact point), begins first, each kind in the order of the bodies' creation slots.

        A pair touches when its shapes overlap or the solver pushed on them; a speculative contact that
        stays open (a near miss) is no begin.  Resting pairs, asleep or not, make no events; sensors make
        them as they start and stop overlapping.  Empty before the first step and after :meth:`restore`.
        """
        if not self._stepped:
            return []
        st = self._state
        n = st.n_cached
        after = (st.cache_f[:n], st.cache_i[:n])
        loop = self._last if isinstance(self._last, StepLoop) else None
        if loop is None:
            m = int(st.stats[L.STAT_PREVIOUS])
            kept = st.stats[L.STAT_KEPT] != 0       # (the step began with its cache and kept it as it was)
            before = after if kept else (st.contact_table_f(False)[:m], st.contact_table_i(False)[:m])
            approach = approach_table(*after)
        else:
            before = loop.start_contacts
            approach = loop.approach_speeds()
        at = self._body_at
        return [ContactEvent(kind, at[a], at[b], point, normal, speed)
                for kind, a, b, point, normal, speed in contact_events(before, after, approach, self._gone)]

    def _ray_kernel(self, o, d, max_distance, mask):
        """``(kernel, arguments)``: the bodies' ray cast of :meth:`raycast` for its checked arguments, the grid's
        own kernel when the broad phase is the grid; ``arguments[-1]`` receives the hit."""
        st = self._state
        nb = st.bodies.end
        candidates = np.zeros(max(nb, 1), dtype=np.int64)
        if st.broadphase_code == GRID:
            return raycast_world_grid, (st.bf, st.bi, st.sf, st.si, st.geom_f, st.geom_i, st.aabbs, st.bp_f,
                                        st.bp_i, nb, o, d, max_distance, mask, candidates, np.zeros(8))
        return raycast_world, (st.bf, st.bi, st.sf, st.si, st.geom_f, st.geom_i, st.aabbs, st.bp_f, st.bp_i,
                               st.broadphase_code, nb, o, d, max_distance, mask, candidates, np.zeros(8))

    def raycast(self, origin: ArrayLike, direction: ArrayLike, max_distance: float = math.inf, *,
                mask: int = -1) -> RayHit | None:
        """The nearest body surface along the ray ``origin + t direction``, ``0 <= t <= max_distance`` (m).

        ``origin`` within +-1e12 m; ``direction`` any finite nonzero vector (normalised here, safely for
        huge or tiny components); ``max_distance`` >= 0 (inf: unbounded); only bodies whose ``group & mask``
        is nonzero are hit (the default -1: every body).  Returns a :class:`RayHit` or None.
        A ray that starts inside a solid shape hits it at distance 0.
        """
        o = as_vec3("origin", origin)
        d = as_direction("direction", direction)
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True, unit="m")
        mask = as_filter_bits("mask", mask)
        kernel, arguments = self._ray_kernel(o, d, max_distance, mask)
        await_kernel(kernel)
        found = kernel(*arguments)
        hit = arguments[-1]
        ps = self._state.particles
        if ps.n:
            nearest = hit[0] if found else max_distance
            row = raycast_particles(ps.pf, ps.pi, ps.n, o, d, nearest, hit)
            tri = ps.kernel_cloth_tables()[0]
            triangle = raycast_triangles(ps.pf, tri, tri.shape[0], o, d, hit[0] if row >= 0 else nearest, hit)
            if triangle >= 0:
                owner = int(tri[triangle, P.T_CLOTH])
                if owner < len(ps.cloths):
                    handle = next(h for h in self._living_cloths if h._record is ps.cloths[owner])
                else:
                    handle = next(h for h in self._living_softs if h._record is ps.softs[owner - len(ps.cloths)])
                first = int(np.searchsorted(tri[:, P.T_CLOTH], owner))
                return RayHit(None, hit[2:5].copy(), hit[5:8].copy(), float(hit[0]), handle, triangle - first)
            if row >= 0:
                group = next(g for g in ps.sets if g.start <= row < g.start + g.count)
                handle = next(h for h in self._living_particles if h._group is group)
                return RayHit(None, hit[2:5].copy(), hit[5:8].copy(), float(hit[0]), handle, row - group.start)
        if not found:
            return None
        return RayHit(self._body_at[int(hit[1])], hit[2:5].copy(), hit[5:8].copy(), float(hit[0]))

    def shape_cast(self, shape: Shape, start: ArrayLike, end: ArrayLike, *,
                   orientation: ArrayLike = (1.0, 0.0, 0.0, 0.0), mask: int = -1) -> RayHit | None:
        """The first body that ``shape`` (a sphere, box, capsule or convex hull) meets as it slides, without
        turning, from ``start`` to ``end`` (m) at ``orientation``: a :class:`RayHit` whose ``distance`` (m) is
        how far along the sweep it got, ``point`` where it touches and ``normal`` the hit surface's, pointing
        back at the shape; None if it meets nothing.  Only bodies whose ``group & mask`` is nonzero are hit; a shape
        that already overlaps a body hits it at distance 0.  Bodies are taken at their poses now.
        """
        if not isinstance(shape, Shape):
            raise TypeError(f"shape must be a Sphere, Box, Capsule or ConvexHull, got {type(shape).__name__}")
        if shape.is_static_only:
            raise ValueError(f"shape {type(shape).__name__} cannot be cast: give a Sphere, Box, Capsule or ConvexHull")
        a = as_vec3("start", start)
        b = as_vec3("end", end)
        quat = as_quat("orientation", orientation)
        mask = as_filter_bits("mask", mask)
        st = self._state
        nb = st.bodies.end
        hit = np.zeros(8)
        candidates = np.zeros(max(nb, 1), dtype=np.int64)
        cast_f, cast_i = shape._geometry()        # a hull's geometry, after the world's
        geom_f = np.concatenate([st.geom_f, cast_f]) if cast_f.size else st.geom_f
        geom_i = np.concatenate([st.geom_i, cast_i]).astype(np.int64) if cast_i.size else st.geom_i
        found = shape_cast_world(st.bf, st.bi, st.sf, st.si, geom_f, geom_i, st.aabbs, st.bp_f, st.bp_i,
                                 st.broadphase_code, nb, shape._type, np.asarray(shape._params(), np.float64),
                                 st.geom_f.size, st.geom_i.size, a, b, quat, mask, candidates, hit)
        if not found:
            return None
        return RayHit(self._body_at[int(hit[1])], hit[2:5].copy(), hit[5:8].copy(), float(hit[0]))

    def query_box(self, lower: ArrayLike, upper: ArrayLike) -> list[Body]:
        """The bodies whose bounding boxes (at their poses now) overlap the box from corner ``lower`` to
        corner ``upper`` (m, world axes), in creation-slot order; an unbounded shape's box (a plane) overlaps
        every box.  ``lower <= upper`` in each coordinate, within +-1e12 m."""
        lo = as_vec3("lower", lower)
        hi = as_vec3("upper", upper)
        if not np.all(lo <= hi):
            raise ValueError(f"lower must be <= upper in every coordinate, got lower={lo.tolist()}, "
                             f"upper={hi.tolist()}")
        st = self._state
        nb = st.bodies.end
        out = np.zeros(max(nb, 1), dtype=np.int64)
        count = query_box_world(st.bf, st.bi, st.sf, st.si, st.aabbs, st.bp_f, st.bp_i, st.broadphase_code, nb,
                                lo, hi, out)
        return [self._body_at[int(i)] for i in out[:count]]

    # --- state -------------------------------------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        """The whole state (bodies, constraints, time, caches) as a picklable :class:`Snapshot`."""
        snapshot = snapshots.take(self._state, self._accumulator)
        snapshot.fluids = tuple(fluid._state() for fluid in self._living_fluids)
        return snapshot

    def restore(self, snapshot: Snapshot) -> None:
        """Return to ``snapshot`` (taken of this world, or of one built the same way).

        Bodies and constraints added after the snapshot are removed; their handles become invalid.  A
        snapshot holding a body or constraint removed since is refused, as is any snapshot whose tables
        were changed into something this world could not be in; a refused restore changes nothing.
        """
        arrays = snapshots.validate(self._state, snapshot)
        fluids = list(self._living_fluids)
        if not isinstance(snapshot.fluids, tuple) or len(snapshot.fluids) > len(fluids):
            raise ValueError("snapshot holds fluids this world no longer has; restore a snapshot taken of this "
                             "world or of one built the same way")
        for fluid, state in zip(fluids, snapshot.fluids):
            fluid._check_state(state)
        st = self._state
        snapshots.restore(st, arrays)
        for at, living, slots in ((self._body_at, self._living, st.bodies),
                                  (self._constraint_at, self._living_constraints, st.constraints)):
            for row, handle in enumerate(at):
                if handle is not None and (not slots.in_use(row) or slots.revision[row] != handle._revision):
                    handle._world = None
                    at[row] = None
                    del living[handle]
            del at[slots.end:]
        for living in (self._living_particles, self._living_networks):
            for handle in [h for h in living if not h._group.alive]:
                handle._world = None
                del living[handle]
        for living in (self._living_cloths, self._living_softs):
            for handle in [h for h in living if not h._record.alive]:
                handle._world = None
                del living[handle]
        for fluid, state in zip(fluids, snapshot.fluids):
            fluid._load(state)
        for fluid in fluids[len(snapshot.fluids):]:
            self.remove(fluid)
        self._accumulator = float(snapshot.accumulator)
        self._stepped = False

    def state_hash(self) -> str:
        """A hash of the whole state, bit for bit (hex string): equal hashes mean identical worlds."""
        return self.snapshot().state_hash()
