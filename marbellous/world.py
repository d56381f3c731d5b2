"""``World``: owns the state tables of bodies, shapes and constraints and advances them in time."""
import math
import platform
from dataclasses import dataclass

import numpy as np

from ._numba.clock import AVAILABLE as CLOCK_AVAILABLE
from ._validate import as_choice, as_float, as_int, as_quat, as_vec3
from .body import Body
from .collision.aabb import shape_aabb
from .collision.broadphase import METHODS as BROADPHASE_CODES
from .collision.broadphase import make_state as make_broadphase_state
from .constraints import Cable, Constraint, Rod, Spring
from .dynamics.integrators import INTEGRATORS
from .dynamics.rigid import inverse_inertia_np
from .math3d import quat_to_matrix_np
from .pipeline import step as S
from .pipeline.profile import step_profile
from .pipeline.raycast import raycast_world
from .pipeline.tables import MAX_THREADS, compiled_entry, pack_tables, record_address
from .shapes.primitives import Shape
from .state import layout as L

_STEP_OK = S.OK

SOLVERS = ("sequential_impulse", "penalty", "lcp")
BROADPHASES = tuple(BROADPHASE_CODES)
DEFAULT_DENSITY = 1000.0
DEFAULT_SUBSTEPS = 4
DEFAULT_ITERATIONS = 4


@dataclass(frozen=True)
class RayHit:
    """The nearest surface a ray hit: ``body``, ``point`` (m), unit ``normal`` there, ``distance`` (m)."""

    body: Body
    point: np.ndarray
    normal: np.ndarray
    distance: float


@dataclass(frozen=True)
class Contact:
    """A contact point found by the last step's collision detection (at the poses the step began with).

    ``normal`` points from ``body_a`` to ``body_b``; ``depth > 0`` is overlap (m), ``depth <= 0`` a
    speculative contact with gap ``-depth``.  ``normal_impulse`` (N s) and ``tangent_impulse`` (N s,
    world vector) are what the solver applied at this point over the step.
    """

    body_a: Body
    body_b: Body
    point: np.ndarray
    normal: np.ndarray
    depth: float
    normal_impulse: float
    tangent_impulse: np.ndarray


@dataclass
class Snapshot:
    """The whole state of a world at one instant (plain arrays: picklable, comparable by ``state_hash``)."""

    tables: dict
    counts: tuple
    accumulator: float

    def state_hash(self):
        """A hash of every state array, bit for bit (hex string)."""
        import hashlib

        h = hashlib.sha256()
        for key in sorted(self.tables):
            arr = np.ascontiguousarray(self.tables[key])
            h.update(key.encode())
            h.update(str(arr.shape).encode())
            h.update(arr.tobytes())
        return h.hexdigest()


class _Tunable:
    """A physical tunable of the world (a float): validated on assignment, refreshes the kernel parameters."""

    def __init__(self, default, doc, **rule):
        self.default = default
        self.rule = rule
        self.__doc__ = doc

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        return obj.__dict__.get(self.name, self.default)

    def __set__(self, obj, value):
        obj.__dict__[self.name] = as_float(self.name, value, **self.rule)
        obj._params_dt = None


class _ContactTable:
    """One of a world's two contact tables (pair ``kind``: ``"_contact_f"`` or ``"_contact_i"``) by its role:
    the warm-start cache (``cache``), or the table the next step fills.  The step swaps the roles;
    ``stats[S_CACHE_SIDE]`` says which table is the cache."""

    def __init__(self, kind, cache):
        self.kind = kind
        self.cache = cache

    def _side(self, obj):
        side = int(obj._stats[S.S_CACHE_SIDE])
        return side if self.cache else 1 - side

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        return getattr(obj, self.kind)[self._side(obj)]

    def __set__(self, obj, table):
        getattr(obj, self.kind)[self._side(obj)] = table


def _grow(arr, needed):
    """``arr`` with at least ``needed`` rows (capacity doubling); new rows are zero."""
    cap = arr.shape[0]
    if needed <= cap:
        return arr
    new_cap = max(needed, 2 * cap, 8)
    out = np.zeros((new_cap,) + arr.shape[1:], dtype=arr.dtype)
    out[:cap] = arr
    return out


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
        if isinstance(item, Shape):
            parts.append((item, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])))
        elif isinstance(item, tuple) and 2 <= len(item) <= 3 and isinstance(item[0], Shape):
            pos = as_vec3(f"{name} position", item[1])
            quat = as_quat(f"{name} orientation", item[2]) if len(item) == 3 else np.array([1.0, 0, 0, 0])
            parts.append((item[0], pos, quat))
        else:
            raise TypeError(f"{name} must be a Shape or a (shape, position[, orientation]) tuple, got {item!r}")
    return parts


def _material(friction, static_friction, restitution, rolling_friction):
    mu = as_float("friction", friction, nonnegative=True)
    mu_s = mu if static_friction is None else as_float("static_friction", static_friction, nonnegative=True)
    e = as_float("restitution", restitution, lo=0.0, hi=1.0)
    roll = as_float("rolling_friction", rolling_friction, nonnegative=True)
    return mu, mu_s, e, roll


class World:
    """A physics world: bodies, shapes and constraints advanced in time with SI units, y up.

    ``gravity`` (m/s^2); ``solver`` in ``"sequential_impulse"``, ``"penalty"``, ``"lcp"``; ``iterations``
    and ``substeps`` (None: defaults chosen so stacks stand at 60 Hz); ``integrator`` in
    ``"explicit_euler"``, ``"semi_implicit_euler"``, ``"verlet"``, ``"rk4"``; ``broadphase`` in
    ``"brute"``, ``"sap"``, ``"grid"``, ``"bvh"``, ``"octree"``, ``"kdtree"``, ``"bsp"``; ``threads`` for the
    contact passes of large scenes (1: serial, the default; see :attr:`threads`).
    """

    # Physical tunables: validated on assignment; docs/architecture.md explains each in physical terms.
    speculative_distance = _Tunable(0.02, "gap (m) below which a contact is made before bodies touch",
                                    nonnegative=True)
    contact_hertz = _Tunable(60.0, "stiffness of contact position correction, as a frequency (Hz); "
                                   "capped at a quarter of the sub-step rate", positive=True)
    contact_damping_ratio = _Tunable(10.0, "damping ratio of contact position correction", nonnegative=True)
    joint_hertz = _Tunable(60.0, "stiffness of rod and cable correction (Hz); capped at half the sub-step rate",
                           positive=True)
    joint_damping_ratio = _Tunable(2.0, "damping ratio of rod and cable correction", nonnegative=True)
    max_push_speed = _Tunable(3.0, "fastest speed (m/s) at which overlapping bodies are pushed apart",
                              positive=True)
    slide_speed = _Tunable(0.01, "tangential speed (m/s) above which a new contact slides (dynamic "
                                 "friction) rather than sticks (static friction)", nonnegative=True)
    velocity_tolerance = _Tunable(1e-5, "the solver stops iterating a sub-step once no velocity changes by "
                                        "more than this (m/s)", nonnegative=True)
    sleep_linear_speed = _Tunable(0.05, "a body slower than this (m/s) is at rest", nonnegative=True)
    sleep_angular_speed = _Tunable(0.05, "a body turning slower than this (rad/s) is at rest", nonnegative=True)
    time_to_sleep = _Tunable(0.5, "seconds an island must rest before it sleeps", positive=True)
    penalty_hertz = _Tunable(30.0, "solver \"penalty\": frequency (Hz) of the contact springs, capped at "
                                   "0.064 times the sub-step rate for stability", positive=True)
    lcp_sweeps = _Tunable(100.0, "solver \"lcp\": most projected Gauss-Seidel sweeps per solve (a whole "
                                 "number)", lo=1.0, hi=1e6)
    lcp_relaxation = _Tunable(1.0, "solver \"lcp\": over-relaxation factor of projected Gauss-Seidel, in "
                                   "(0, 2)", positive=True, hi=1.99)

    def __init__(self, gravity=(0.0, -9.81, 0.0), *, solver="sequential_impulse", iterations=None,
                 substeps=None, integrator="semi_implicit_euler", broadphase="grid", ccd=True, sleeping=True,
                 threads=1):
        self._params_f = np.zeros(S.PF_LEN)
        self._params_i = np.zeros(S.PI_LEN, dtype=np.int64)
        self._params_dt = None  # dt the parameters were last computed for (None: recompute)
        # The step's record of the tables below (pipeline/tables.py): None whenever one of them is replaced
        self._tables = None
        self._step_entry = self._step_argument = None
        self.gravity = gravity
        self.solver = solver
        self.integrator = integrator
        self.iterations = DEFAULT_ITERATIONS if iterations is None else iterations
        self.substeps = DEFAULT_SUBSTEPS if substeps is None else substeps
        self.threads = threads
        self.ccd = ccd
        self.sleeping = sleeping
        self._bf = np.zeros((8, L.BF_COLS))
        self._bi = np.zeros((8, L.BI_COLS), dtype=np.int64)
        self._sf = np.zeros((8, L.SF_COLS))
        self._si = np.zeros((8, L.SI_COLS), dtype=np.int64)
        self._kf = np.zeros((8, L.KF_COLS))
        self._ki = np.zeros((8, L.KI_COLS), dtype=np.int64)
        self._geom_f = np.zeros(0)
        self._geom_i = np.zeros(0, dtype=np.int64)
        self._ws = np.zeros(L.WS_COLS)
        self._nb = 0
        self._ns = 0
        self._nk = 0
        self._bodies = []        # Body handle per row (None once removed)
        self._constraints = []   # Constraint handle per row (None once removed)
        self._accumulator = 0.0
        self._stats = np.zeros(S.STATS_LEN, dtype=np.int64)
        # Collision detection: body boxes, broad-phase state, candidate pairs, contact points (this
        # step's and last step's, swapped after each step: the last one is the warm-start cache).
        self._aabbs = np.zeros((8, 6))
        self.broadphase = broadphase
        self._pairs = np.zeros((64, 2), dtype=np.int64)
        self._raw_f = np.zeros((64, 7))
        self._raw_i = np.zeros(64, dtype=np.int64)
        # The two contact tables (float, int): the step fills one and keeps the other as its warm-start
        # cache, then they swap roles (stats[S_CACHE_SIDE] says which is the cache): see _pcf, _cf.
        self._contact_f = [np.zeros((64, L.CF_COLS)), np.zeros((64, L.CF_COLS))]
        self._contact_i = [np.zeros((64, L.CI_COLS), dtype=np.int64), np.zeros((64, L.CI_COLS), dtype=np.int64)]

    # --- properties -------------------------------------------------------------------------------
    @property
    def gravity(self):
        """Gravitational acceleration (m/s^2)."""
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value):
        self._gravity = as_vec3("gravity", value)
        self._params_dt = None

    @property
    def solver(self):
        """Collision handling: ``"sequential_impulse"``, ``"penalty"`` or ``"lcp"``."""
        return self._solver

    @solver.setter
    def solver(self, value):
        self._solver = as_choice("solver", value, SOLVERS)
        self._params_dt = None

    @property
    def integrator(self):
        """``"explicit_euler"``, ``"semi_implicit_euler"``, ``"verlet"`` or ``"rk4"``."""
        return self._integrator

    @integrator.setter
    def integrator(self, value):
        self._integrator = as_choice("integrator", value, INTEGRATORS)
        self._params_dt = None

    @property
    def broadphase(self):
        """Broad phase: one of ``BROADPHASES``; all find the same pairs in the same order, only speed differs."""
        return self._broadphase

    @broadphase.setter
    def broadphase(self, value):
        self._broadphase = as_choice("broadphase", value, BROADPHASES)
        self._bp_f, self._bp_i = make_broadphase_state(BROADPHASE_CODES[self._broadphase], self._aabbs.shape[0])
        self._tables = None
        self._params_dt = None

    @property
    def iterations(self):
        """Most velocity iterations per sub-step (the solver stops earlier once converged)."""
        return self._iterations

    @iterations.setter
    def iterations(self, value):
        self._iterations = as_int("iterations", value, lo=1, hi=10000)
        self._params_dt = None

    @property
    def threads(self):
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
    def threads(self, value):
        self._threads = as_int("threads", value, lo=1, hi=MAX_THREADS)
        self._params_dt = None
        self._tables = None           # (the record's scratch is sized for the threads)

    @property
    def substeps(self):
        """Sub-steps per step: each integrates, solves and relaxes over dt / substeps."""
        return self._substeps

    @substeps.setter
    def substeps(self, value):
        self._substeps = as_int("substeps", value, lo=1, hi=1000)
        self._params_dt = None

    @property
    def ccd(self):
        """Continuous collision: contacts are predicted along each body's motion in the step (speculative)."""
        return self._ccd

    @ccd.setter
    def ccd(self, value):
        self._ccd = self._check_flag("ccd", value)
        self._params_dt = None

    @property
    def sleeping(self):
        """Whether resting islands fall asleep."""
        return self._sleeping

    @sleeping.setter
    def sleeping(self, value):
        self._sleeping = self._check_flag("sleeping", value)
        self._params_dt = None

    @property
    def profiling(self):
        """Whether steps time their stages for :attr:`profile` (costs ~20 ns per stage; off by default)."""
        return bool(self._params_i[S.P_PROFILE])

    @profiling.setter
    def profiling(self, value):
        value = self._check_flag("profiling", value)
        if value and not CLOCK_AVAILABLE:
            raise RuntimeError("profiling needs the x86-64 cycle counter; this machine is "
                               f"{platform.machine()!r}")
        self._params_i[S.P_PROFILE] = int(value)

    @property
    def profile(self):
        """:class:`StepProfile` of the steps taken while :attr:`profiling` was on (since the last
        :meth:`reset_profile`): seconds per stage, mean pairs, contacts and iterations per step."""
        return step_profile(self._stats)

    def reset_profile(self):
        """Start the :attr:`profile` totals again from zero."""
        self._stats[S.S_PROFILED_STEPS:] = 0

    @property
    def time(self):
        """Simulated time so far (s)."""
        return float(self._ws[L.W_TIME])

    @property
    def bodies(self):
        """The live bodies, in creation order."""
        return [b for b in self._bodies if b is not None]

    @property
    def constraints(self):
        """The live springs, rods and cables, in creation order."""
        return [c for c in self._constraints if c is not None]

    # --- bodies -------------------------------------------------------------------------------------
    def add_body(self, shape, *, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), mass=None, density=None,
                 friction=0.5, static_friction=None, restitution=0.0, rolling_friction=0.0,
                 sensor=False):
        """Add a dynamic rigid body and return its :class:`Body`.

        ``shape``: a shape, or a list of shapes / ``(shape, position[, orientation])`` tuples (a compound;
        the body's origin becomes the compound's centre of mass).  Give ``mass`` (kg) or ``density``
        (kg/m^3, default 1000), not both.  ``friction`` is the sliding (dynamic) Coulomb coefficient,
        ``static_friction`` the sticking one (None: same), ``restitution`` in [0, 1],
        ``rolling_friction`` (m) the lever arm of the rolling resistance.
        """
        parts = _parse_shapes(shape)
        for s, _, _ in parts:
            if s.is_static_only:
                raise ValueError(f"shape {type(s).__name__} is static only: use add_static")
        pos = as_vec3("position", position)
        quat = as_quat("orientation", orientation)
        vel = as_vec3("velocity", velocity)
        omega = as_vec3("angular_velocity", angular_velocity)
        if mass is not None and density is not None:
            raise ValueError("give mass or density, not both")
        if mass is not None:
            mass = as_float("mass", mass, positive=True)
        rho = DEFAULT_DENSITY if density is None else as_float("density", density, positive=True)
        material = _material(friction, static_friction, restitution, rolling_friction)
        sensor = self._check_flag("sensor", sensor)
        m, com, inertia = self._compound_mass(parts, rho, mass)
        # Shapes are stored relative to the centre of mass: the body's origin is its centre of mass.
        parts = [(s, p - com, q) for s, p, q in parts]
        return self._insert(parts, pos, quat, vel, omega, m, inertia, material, static=False, sensor=sensor)

    def add_static(self, shape, *, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                   friction=0.5, static_friction=None, restitution=0.0, rolling_friction=0.0, sensor=False):
        """Add a static (immovable) body: any shape, including Plane, HeightField and TriangleMesh."""
        parts = _parse_shapes(shape)
        pos = as_vec3("position", position)
        quat = as_quat("orientation", orientation)
        material = _material(friction, static_friction, restitution, rolling_friction)
        sensor = self._check_flag("sensor", sensor)
        zero = np.zeros(3)
        return self._insert(parts, pos, quat, zero, zero, math.inf, None, material, static=True, sensor=sensor)

    @staticmethod
    def _check_flag(name, value):
        if not isinstance(value, bool):
            raise TypeError(f"{name} must be True or False, got {value!r}")
        return value

    @staticmethod
    def _compound_mass(parts, density, mass):
        """Mass (kg), centre of mass (m, body frame) and inertia about it (kg m^2) of the shapes.

        Parallel-axis theorem: ``I = sum R_i I_i R_i^T + m_i (|d_i|^2 E - d_i d_i^T)``, ``d_i = p_i - com``.
        With ``mass`` given, the density is scaled so the total is ``mass``.
        """
        props = [(s.mass_properties(density), p, q) for s, p, q in parts]
        total = sum(mp[0] for mp, _, _ in props)
        com = sum(mp[0] * p for mp, p, _ in props) / total
        inertia = np.zeros((3, 3))
        for (m_i, i_i), p, q in props:
            r = quat_to_matrix_np(q)
            d = p - com
            inertia += r @ i_i @ r.T + m_i * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
        if mass is not None:
            inertia *= mass / total
            total = mass
        return total, com, inertia

    def _insert(self, parts, pos, quat, vel, omega, mass, inertia, material, *, static, sensor):
        """Write a validated body and its shapes into the tables (nothing here can fail on user input)."""
        self._tables = None
        i = self._nb
        self._bf = _grow(self._bf, i + 1)
        self._bi = _grow(self._bi, i + 1)
        if self._aabbs.shape[0] < self._bf.shape[0]:
            self._aabbs = _grow(self._aabbs, self._bf.shape[0])
            self._bp_f, self._bp_i = make_broadphase_state(BROADPHASE_CODES[self.broadphase],
                                                           self._bf.shape[0])
        s0 = self._ns
        self._sf = _grow(self._sf, s0 + len(parts))
        self._si = _grow(self._si, s0 + len(parts))
        geom_f, geom_i = [self._geom_f], [self._geom_i]
        off_f, off_i = self._geom_f.size, self._geom_i.size
        for k, (s, p, q) in enumerate(parts):
            row = s0 + k
            self._sf[row, L.S_PARAMS:L.S_PARAMS + 8] = s._params()
            self._sf[row, L.S_LOCAL_POS:L.S_LOCAL_POS + 3] = p
            self._sf[row, L.S_LOCAL_QUAT:L.S_LOCAL_QUAT + 4] = q
            self._sf[row, L.S_RADIUS] = s.bounding_radius()
            gf, gi = s._geometry()
            self._si[row] = (s._type, i, off_f, off_i)
            geom_f.append(gf)
            geom_i.append(gi)
            off_f += gf.size
            off_i += gi.size
        self._geom_f = np.concatenate(geom_f)
        self._geom_i = np.concatenate(geom_i).astype(np.int64)
        bf = self._bf[i]
        bf[:] = 0.0
        bf[L.POS:L.POS + 3] = pos
        bf[L.PREV_POS:L.PREV_POS + 3] = pos
        bf[L.QUAT:L.QUAT + 4] = quat
        bf[L.VEL:L.VEL + 3] = vel
        bf[L.OMEGA:L.OMEGA + 3] = omega
        bf[L.MASS] = mass
        bf[L.FRICTION], bf[L.STATIC_FRICTION], bf[L.RESTITUTION], bf[L.ROLLING] = material
        if not static:
            bf[L.INV_MASS] = 1.0 / mass
            bf[L.I_BODY:L.I_BODY + 9] = inertia.ravel()
            bf[L.INV_I:L.INV_I + 9] = inverse_inertia_np(inertia).ravel()
        flags = L.F_ALIVE | L.F_RESTART
        if static:
            flags |= L.F_STATIC
        elif np.array_equal(inertia, np.eye(3) * inertia[0, 0]):
            flags |= L.F_ISOTROPIC
        if sensor:
            flags |= L.F_SENSOR
        self._bi[i] = (flags, s0, len(parts), 1, -1, -1)
        self._aabbs[i] = self._static_box(parts, pos, quat) if static else 0.0
        self._nb += 1
        self._ns += len(parts)
        body = Body(self, i, [(s, p.copy(), q.copy()) for s, p, q in parts])
        self._bodies.append(body)
        return body

    @staticmethod
    def _static_box(parts, pos, quat):
        """World AABB of a static body's shapes (m); unbounded shapes give an infinite box."""
        r_body = quat_to_matrix_np(quat)
        box = np.array([np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf])
        for s, p, q in parts:
            rot = r_body @ quat_to_matrix_np(q)
            centre = pos + r_body @ p
            part = np.empty(6)
            if hasattr(s, "local_aabb"):
                lo, hi = s.local_aabb()
                corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                                    for z in (lo[2], hi[2])])
                world = corners @ rot.T + centre
                part[:3], part[3:] = world.min(axis=0), world.max(axis=0)
            else:
                shape_aabb(s._type, centre, rot, s._params(), part)
            box[:3] = np.minimum(box[:3], part[:3])
            box[3:] = np.maximum(box[3:], part[3:])
        return box

    def _check_body(self, body, name):
        if not isinstance(body, Body):
            raise TypeError(f"{name} must be a Body, got {body!r}")
        if body._world is not self:
            raise ValueError(f"{name} does not belong to this world (or was removed)")
        return body._index

    def _wake(self, index):
        """Wake body row ``index`` (and reset its rest timer)."""
        self._bi[index, L.FLAGS] &= ~L.F_SLEEPING
        self._bf[index, L.SLEEP_TIME] = 0.0

    def remove(self, body_or_constraint):
        """Remove a body (with the constraints attached to it) or a constraint; other handles stay valid."""
        obj = body_or_constraint
        if isinstance(obj, Body):
            i = self._check_body(obj, "body_or_constraint")
            for c in self.constraints:
                if c.body_a is obj or c.body_b is obj:
                    self.remove(c)
            self._bi[i, L.FLAGS] = 0
            self._bf[i, L.INV_MASS] = 0.0
            self._bodies[i] = None
            obj._world = None
        elif isinstance(obj, Constraint):
            if obj._world is not self:
                raise ValueError("body_or_constraint does not belong to this world (or was removed)")
            self._ki[obj._index, L.K_FLAGS] = 0
            self._constraints[obj._index] = None
            obj._world = None
        else:
            raise TypeError(f"body_or_constraint must be a Body or a constraint, got {obj!r}")

    # --- constraints -------------------------------------------------------------------------------
    def _insert_constraint(self, cls, ctype, a, b, anchor_a, anchor_b, length, stiffness=0.0, damping=0.0,
                           breaking_force=None):
        ia = self._check_body(a, "a")
        ib = -1 if b is None else self._check_body(b, "b")
        if ia == ib:
            raise ValueError("a and b must be different bodies")
        if self._bi[ia, L.FLAGS] & L.F_STATIC and (ib < 0 or self._bi[ib, L.FLAGS] & L.F_STATIC):
            raise ValueError("a constraint needs at least one dynamic body")
        brk = math.inf if breaking_force is None else as_float("breaking_force", breaking_force, positive=True)
        c = self._nk
        self._kf = _grow(self._kf, c + 1)
        self._ki = _grow(self._ki, c + 1)
        row = self._kf[c]
        row[:] = 0.0
        row[L.K_ANCHOR_A:L.K_ANCHOR_A + 3] = anchor_a
        row[L.K_ANCHOR_B:L.K_ANCHOR_B + 3] = anchor_b
        row[L.K_LENGTH] = length
        row[L.K_STIFFNESS] = stiffness
        row[L.K_DAMPING] = damping
        row[L.K_BREAKING] = brk
        self._ki[c] = (ctype, ia, ib, L.KF_ALIVE)
        self._nk += 1
        self._tables = None
        handle = cls(self, c, a, b)
        self._constraints.append(handle)
        self._wake(ia)
        if ib >= 0:
            self._wake(ib)
        return handle

    def add_spring(self, a, b, *, rest_length, stiffness, damping=0.0, anchor_a=(0.0, 0.0, 0.0),
                   anchor_b=(0.0, 0.0, 0.0), breaking_force=None):
        """Connect two bodies (``b=None``: a fixed world point ``anchor_b``) by a damped Hooke spring.

        ``F = -k (l - l0) - c dl/dt`` with ``rest_length`` l0 (m), ``stiffness`` k (N/m), ``damping`` c
        (N s/m); anchors in each body's frame (m).  Past ``breaking_force`` (N) it breaks for good.
        """
        l0 = as_float("rest_length", rest_length, nonnegative=True)
        k = as_float("stiffness", stiffness, nonnegative=True)
        c = as_float("damping", damping, nonnegative=True)
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        return self._insert_constraint(Spring, L.C_SPRING, a, b, pa, pb, l0, k, c, breaking_force)

    def add_rod(self, a, b, *, length=None, anchor_a=(0.0, 0.0, 0.0), anchor_b=(0.0, 0.0, 0.0)):
        """Keep the anchors of ``a`` and ``b`` (``b=None``: the world point ``anchor_b``) at a fixed distance.

        ``length`` (m; None: the current distance).  Solved with the contacts as a stiff constraint:
        the separating velocity along the rod is driven to zero.
        """
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        length = self._joint_length("length", length, a, b, pa, pb)
        return self._insert_constraint(Rod, L.C_ROD, a, b, pa, pb, length)

    def add_cable(self, a, b, *, max_length, anchor_a=(0.0, 0.0, 0.0), anchor_b=(0.0, 0.0, 0.0)):
        """An inextensible cable: the anchors stay at most ``max_length`` (m) apart, slack when closer."""
        pa = as_vec3("anchor_a", anchor_a)
        pb = as_vec3("anchor_b", anchor_b)
        length = as_float("max_length", max_length, positive=True)
        return self._insert_constraint(Cable, L.C_CABLE, a, b, pa, pb, length)

    def _joint_length(self, name, length, a, b, pa, pb):
        if length is not None:
            return as_float(name, length, positive=True)
        ia = self._check_body(a, "a")
        wa = self._bf[ia, L.POS:L.POS + 3] + quat_to_matrix_np(self._bf[ia, L.QUAT:L.QUAT + 4]) @ pa
        if b is None:
            wb = pb
        else:
            ib = self._check_body(b, "b")
            wb = self._bf[ib, L.POS:L.POS + 3] + quat_to_matrix_np(self._bf[ib, L.QUAT:L.QUAT + 4]) @ pb
        d = float(np.linalg.norm(wb - wa))
        if d <= 0.0:
            raise ValueError(f"{name} is None and the anchors coincide: give a positive {name}")
        return d

    # --- time ------------------------------------------------------------------------------------------
    def step(self, dt):
        """Advance the simulation by exactly ``dt`` seconds (in ``substeps`` equal sub-steps)."""
        if type(dt) is not float or dt != self._params_dt:    # (the last dt was validated)
            dt = as_float("dt", dt, positive=True)
            if dt != self._params_dt:
                self._refresh_params(dt)
        if self._tables is None:
            self._pack_tables()
        # (this step's contacts become the cache of the next: the kernel swaps the two contact tables)
        status = self._step_entry(self._step_argument)
        while status != _STEP_OK:       # a buffer was too small: grow it and run the step again
            if status == S.GROW_PAIRS:
                self._pairs = _grow(self._pairs, int(self._stats[S.S_PAIRS]))
            else:
                self._grow_contacts(int(self._stats[S.S_CONTACTS]))
            self._pack_tables()
            status = self._step_entry(self._step_argument)

    # The contact tables by role: the cache (the last step's contacts, ``_npc`` rows) and the one the next
    # step fills.
    _pcf = _ContactTable("_contact_f", cache=True)
    _pci = _ContactTable("_contact_i", cache=True)
    _cf = _ContactTable("_contact_f", cache=False)
    _ci = _ContactTable("_contact_i", cache=False)

    @property
    def _npc(self):
        return int(self._stats[S.S_CACHED])

    @_npc.setter
    def _npc(self, n):
        self._stats[S.S_CACHED] = n

    def _pack_tables(self):
        """The step's record of the current tables (pipeline/tables.py), kept until a table is replaced, and
        the compiled step with its argument: the record's address, valid while ``_tables`` holds it."""
        self._tables = pack_tables(self._bf, self._bi, self._sf, self._si, self._kf, self._ki, self._ws,
                                   self._geom_f, self._geom_i, self._aabbs, self._bp_f, self._bp_i, self._pairs,
                                   self._raw_f, self._raw_i, self._cf, self._ci, self._pcf, self._pci,
                                   self._params_f, self._params_i, self._stats, self._nb, self._nk, self._threads)
        self._step_argument = record_address(self._tables)
        self._step_entry = compiled_entry(S.step_world_at, self._step_argument)

    def _refresh_params(self, dt):
        """Fill the kernel parameter arrays for steps of ``dt`` seconds."""
        pf, pi = self._params_f, self._params_i
        pf[S.P_DT] = dt
        pf[S.P_GRAVITY:S.P_GRAVITY + 3] = self._gravity
        h = dt / self.substeps
        pf[S.P_SPECULATIVE] = self.speculative_distance
        # Contacts no stiffer than a quarter of the sub-step rate, joints half (stable for any dt).
        pf[S.P_CONTACT_HERTZ] = min(self.contact_hertz, 0.25 / h)
        pf[S.P_CONTACT_ZETA] = self.contact_damping_ratio
        pf[S.P_JOINT_HERTZ] = min(self.joint_hertz, 0.5 / h)
        pf[S.P_JOINT_ZETA] = self.joint_damping_ratio
        pf[S.P_MAX_PUSH] = self.max_push_speed
        pf[S.P_SLIDE_SPEED] = self.slide_speed
        pf[S.P_TOLERANCE] = self.velocity_tolerance
        pf[S.P_SLEEP_LINEAR] = self.sleep_linear_speed
        pf[S.P_SLEEP_ANGULAR] = self.sleep_angular_speed
        pf[S.P_TIME_TO_SLEEP] = self.time_to_sleep if self.sleeping else 0.0
        # A contact closing no faster than gravity makes in one sub-step is resting, not bouncing.
        pf[S.P_RESTITUTION_SPEED] = float(np.linalg.norm(self._gravity)) * h
        pf[S.P_SWEEP] = 1.0 if self.ccd else 0.0
        pi[S.P_INTEGRATOR] = INTEGRATORS.index(self.integrator)
        pi[S.P_SUBSTEPS] = self.substeps
        pi[S.P_ITERATIONS] = self.iterations
        pi[S.P_BROADPHASE] = BROADPHASE_CODES[self.broadphase]
        pi[S.P_SOLVER] = SOLVERS.index(self.solver)
        pi[S.P_THREADS] = self.threads
        pf[S.P_PENALTY_HERTZ] = self.penalty_hertz
        pi[S.P_LCP_SWEEPS] = int(self.lcp_sweeps)
        pf[S.P_LCP_SOR] = self.lcp_relaxation
        self._params_dt = dt

    def _grow_contacts(self, n):
        """Room for ``n`` contact points in the narrow-phase buffer and both contact tables, all grown to one
        capacity (the tables swap roles every step, so the step's scratch is sized by either)."""
        self._tables = None
        n = max(n, self._cf.shape[0], self._pcf.shape[0], self._raw_f.shape[0])
        self._raw_f = _grow(self._raw_f, n)
        self._raw_i = _grow(self._raw_i, n)
        self._cf = _grow(self._cf, n)
        self._ci = _grow(self._ci, n)
        self._pcf = _grow(self._pcf, n)
        self._pci = _grow(self._pci, n)

    def contacts(self):
        """The contacts that the last step's collision detection found (at the poses the step began with),
        with the impulses the solver applied at each."""
        out = []
        for c in range(self._npc):
            f, i = self._pcf[c], self._pci[c]
            out.append(Contact(self._bodies[i[L.C_BODY_A]], self._bodies[i[L.C_BODY_B]],
                               f[L.C_POINT:L.C_POINT + 3].copy(), f[L.C_NORMAL:L.C_NORMAL + 3].copy(),
                               float(f[L.C_DEPTH]), float(f[L.C_SUM_N]), f[L.C_SUM_T:L.C_SUM_T + 3].copy()))
        return out

    def advance(self, frame_time, dt=1.0 / 120.0, max_steps=None):
        """Game-loop accumulator: take as many fixed steps of ``dt`` as ``frame_time`` (s) allows.

        Returns the interpolation ``alpha = leftover / dt`` in [0, 1) for rendering between the last two
        states.  Time is kept in whole steps plus a remainder so no step is lost to round-off.
        ``max_steps`` (None: unlimited) caps the steps per call; the excess time is dropped.
        """
        frame_time = as_float("frame_time", frame_time, nonnegative=True)
        dt = as_float("dt", dt, positive=True)
        if max_steps is not None:
            max_steps = as_int("max_steps", max_steps, lo=1)
        acc = self._accumulator + frame_time
        # A step is due when the accumulator reaches dt up to round-off in the sum.
        n = math.floor(acc / dt + 1e-9)
        if max_steps is not None and n > max_steps:
            n = max_steps
            acc = n * dt
        for _ in range(n):
            self.step(dt)
        self._accumulator = max(acc - n * dt, 0.0)
        alpha = self._accumulator / dt
        return alpha if alpha < 1.0 else math.nextafter(1.0, 0.0)

    def raycast(self, origin, direction, max_distance=math.inf):
        """The nearest body surface along the ray ``origin + t direction``, ``0 <= t <= max_distance`` (m).

        ``direction`` need not be unit length (it must not be zero).  Returns a :class:`RayHit` or None.
        A ray that starts inside a solid shape hits it at distance 0.
        """
        o = as_vec3("origin", origin)
        d = as_vec3("direction", direction)
        length = float(np.linalg.norm(d))
        if length == 0.0:
            raise ValueError("direction must be a non-zero vector")
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True)
        hit = np.zeros(8)
        candidates = np.zeros(max(self._nb, 1), dtype=np.int64)
        found = raycast_world(self._bf, self._bi, self._sf, self._si, self._geom_f, self._geom_i, self._aabbs,
                              self._bp_f, self._bp_i, BROADPHASE_CODES[self.broadphase], self._nb, o,
                              d / length, max_distance, candidates, hit)
        if not found:
            return None
        return RayHit(self._bodies[int(hit[1])], hit[2:5].copy(), hit[5:8].copy(), float(hit[0]))

    # --- state -------------------------------------------------------------------------------------------
    _TABLES = ("_bf", "_bi", "_sf", "_si", "_kf", "_ki", "_ws", "_geom_f", "_geom_i", "_aabbs", "_pcf", "_pci")

    def snapshot(self):
        """The whole state (bodies, constraints, time, caches) as a picklable :class:`Snapshot`."""
        tables = {name: getattr(self, name).copy() for name in self._TABLES}
        return Snapshot(tables, (self._nb, self._ns, self._nk, self._npc), self._accumulator)

    def restore(self, snapshot):
        """Return to ``snapshot`` (taken of this world, or of one built the same way).

        Bodies and constraints added after the snapshot are removed; their handles become invalid.
        """
        if not isinstance(snapshot, Snapshot):
            raise TypeError(f"snapshot must be a Snapshot, got {snapshot!r}")
        nb, ns, nk, npc = snapshot.counts
        if nb > self._nb or nk > self._nk or ns > self._ns:
            raise ValueError("snapshot holds more bodies or constraints than this world: it was taken of a "
                             "world built differently")
        if not np.array_equal(snapshot.tables["_si"][:ns], self._si[:ns]):
            raise ValueError("snapshot's shapes differ from this world's: it was taken of a world built "
                             "differently")
        # A body removed since the snapshot cannot come back (its handle is gone): refused before any change.
        for k in range(nb):
            if snapshot.tables["_bi"][k, L.FLAGS] & L.F_ALIVE and self._bodies[k] is None:
                raise ValueError("snapshot holds a body that was removed since; restore it into a world "
                                 "built the same way")
        self._tables = None
        for name in self._TABLES:
            setattr(self, name, snapshot.tables[name].copy())
        for k in range(nb, self._nb):
            if self._bodies[k] is not None:
                self._bodies[k]._world = None
        for k in range(nk, self._nk):
            if self._constraints[k] is not None:
                self._constraints[k]._world = None
        del self._bodies[nb:]
        del self._constraints[nk:]
        self._nb, self._ns, self._nk, self._npc = nb, ns, nk, npc
        self._accumulator = snapshot.accumulator
        # Buffers sized for the restored tables; the broad phase rebuilds from a fresh state.
        self._grow_contacts(self._pcf.shape[0])
        self._bp_f, self._bp_i = make_broadphase_state(BROADPHASE_CODES[self.broadphase], self._aabbs.shape[0])

    def state_hash(self):
        """A hash of the whole state, bit for bit (hex string): equal hashes mean identical worlds."""
        return self.snapshot().state_hash()
