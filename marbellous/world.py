"""``World``: owns the state tables of bodies, shapes and constraints and advances them in time."""
import math
from dataclasses import dataclass

import numpy as np

from . import layout as L
from ._validate import as_choice, as_float, as_int, as_quat, as_vec3
from .body import Body
from .constraints import Cable, Constraint, Rod, Spring
from .dynamics.integrators import INTEGRATORS
from .dynamics.rigid import inverse_inertia_np
from .math3d import quat_to_matrix_np
from .pipeline import step as S
from .shapes import Shape

SOLVERS = ("sequential_impulse", "penalty", "lcp")
BROADPHASES = ("brute", "sap", "grid", "bvh", "octree", "kdtree", "bsp")
DEFAULT_DENSITY = 1000.0


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
    ``"brute"``, ``"sap"``, ``"grid"``, ``"bvh"``, ``"octree"``, ``"kdtree"``, ``"bsp"``.
    """

    def __init__(self, gravity=(0.0, -9.81, 0.0), *, solver="sequential_impulse", iterations=None,
                 substeps=None, integrator="semi_implicit_euler", broadphase="sap", ccd=True, sleeping=True):
        self._gravity = as_vec3("gravity", gravity)
        self.solver = as_choice("solver", solver, SOLVERS)
        self.integrator = as_choice("integrator", integrator, INTEGRATORS)
        self.broadphase = as_choice("broadphase", broadphase, BROADPHASES)
        self.iterations = 8 if iterations is None else as_int("iterations", iterations, lo=1, hi=10000)
        self.substeps = 1 if substeps is None else as_int("substeps", substeps, lo=1, hi=1000)
        if not isinstance(ccd, bool):
            raise TypeError(f"ccd must be True or False, got {ccd!r}")
        if not isinstance(sleeping, bool):
            raise TypeError(f"sleeping must be True or False, got {sleeping!r}")
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
        self._params_f = np.zeros(S.PF_LEN)
        self._params_i = np.zeros(S.PI_LEN, dtype=np.int64)

    # --- properties -------------------------------------------------------------------------------
    @property
    def gravity(self):
        """Gravitational acceleration (m/s^2)."""
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value):
        self._gravity = as_vec3("gravity", value)

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
        i = self._nb
        self._bf = _grow(self._bf, i + 1)
        self._bi = _grow(self._bi, i + 1)
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
        if sensor:
            flags |= L.F_SENSOR
        self._bi[i] = (flags, s0, len(parts), 1, -1, -1)
        self._nb += 1
        self._ns += len(parts)
        body = Body(self, i, [(s, p.copy(), q.copy()) for s, p, q in parts])
        self._bodies.append(body)
        return body

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

    # --- time ------------------------------------------------------------------------------------------
    def step(self, dt):
        """Advance the simulation by exactly ``dt`` seconds (in ``substeps`` equal sub-steps)."""
        dt = as_float("dt", dt, positive=True)
        self._params_f[S.P_DT] = dt
        self._params_f[S.P_GRAVITY:S.P_GRAVITY + 3] = self._gravity
        self._params_i[S.P_INTEGRATOR] = INTEGRATORS.index(self.integrator)
        self._params_i[S.P_SUBSTEPS] = self.substeps
        S.step_world(self._bf, self._bi, self._kf, self._ki, self._ws, self._nb, self._nk,
                     self._params_f, self._params_i)

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

    # --- state -------------------------------------------------------------------------------------------
    _TABLES = ("_bf", "_bi", "_sf", "_si", "_kf", "_ki", "_ws", "_geom_f", "_geom_i")

    def snapshot(self):
        """The whole state (bodies, constraints, time, caches) as a picklable :class:`Snapshot`."""
        tables = {name: getattr(self, name).copy() for name in self._TABLES}
        return Snapshot(tables, (self._nb, self._ns, self._nk), self._accumulator)

    def restore(self, snapshot):
        """Return to ``snapshot`` (taken of this world, or of one built the same way).

        Bodies and constraints added after the snapshot are removed; their handles become invalid.
        """
        if not isinstance(snapshot, Snapshot):
            raise TypeError(f"snapshot must be a Snapshot, got {snapshot!r}")
        nb, ns, nk = snapshot.counts
        if nb > self._nb or nk > self._nk or ns > self._ns:
            raise ValueError("snapshot holds more bodies or constraints than this world: it was taken of a "
                             "world built differently")
        if not np.array_equal(snapshot.tables["_si"][:ns], self._si[:ns]):
            raise ValueError("snapshot's shapes differ from this world's: it was taken of a world built "
                             "differently")
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
        # Handles removed after the snapshot come back to life with their rows.
        for k in range(nb):
            alive = bool(self._bi[k, L.FLAGS] & L.F_ALIVE)
            if alive and self._bodies[k] is None:
                raise ValueError("snapshot holds a body that was removed since; restore it into a world "
                                 "built the same way")
        self._nb, self._ns, self._nk = nb, ns, nk
        self._accumulator = snapshot.accumulator

    def state_hash(self):
        """A hash of the whole state, bit for bit (hex string): equal hashes mean identical worlds."""
        return self.snapshot().state_hash()
