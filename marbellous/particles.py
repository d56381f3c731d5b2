"""``Particles`` and ``Network``: handles over a world's particle tables (``deformables/``).

Particles are point masses with a radius and no rotation: they fall, collide with every shape of the world's
bodies (two ways: what a particle gains, the body loses) and, with ``collide_particles``, with one another.
A network joins particles by springs, rods or cables.  Reading a property returns a copy; writing validates
and stores.  A handle whose set or network was removed (or dropped by a restore) raises on use.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._validate import (MAX_COORD, MAX_DAMPING, MAX_FORCE, MAX_MASS, MAX_SIZE, MAX_SPEED, MAX_STIFFNESS, MIN_MASS,
                        as_choice, as_flag, as_float, as_real_array, as_size, as_vec3)
from .deformables import particle_layout as P
from .material import validated
from .math3d import quat_to_matrix_np
from .state import layout as L

#: most particles in one set
MAX_PARTICLES = 10_000_000


def as_points(name, value, n, bound, unit):
    """``value`` as a new ``(n, 3)`` float array, every component finite and within ``+-bound``; a single
    3-vector is repeated ``n`` times when ``n`` is given."""
    arr = as_real_array(name, value)
    if arr.shape == (3,) and n is not None:
        arr = np.repeat(arr[None, :], n, axis=0)
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and arr.shape[0] != n):
        want = f"({n}, 3)" if n is not None else "(N, 3)"
        raise ValueError(f"{name} must have shape {want}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    if np.any(np.abs(arr) > bound):
        raise ValueError(f"{name} must have every component within +-{bound:g} {unit}")
    return arr


def as_integers(name, value):
    """``value`` (an int, or an array or nested sequences of ints, not bools) as a new int64 array."""
    if isinstance(value, (str, bytes, dict, set, frozenset)) or value is None:
        raise TypeError(f"{name} must be integers (particle indices), got {value!r:.60}")
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError, OverflowError):
        raise TypeError(f"{name} must be a (non-ragged) array of integers (particle indices)") from None
    if arr.dtype.kind not in "iu" or arr.dtype == np.bool_:
        raise TypeError(f"{name} must be integers (particle indices), got an array of {arr.dtype}")
    if arr.dtype.kind == "u" and arr.size and arr.max() > np.iinfo(np.int64).max:
        raise ValueError(f"{name} holds an index too large for int64")
    return arr.astype(np.int64)


def as_indices(name, value, n):
    """``value`` (None: all; an int or a sequence of ints) as an int64 array of rows ``0 .. n - 1``."""
    if value is None:
        return np.arange(n, dtype=np.int64)
    arr = as_integers(name, value).reshape(-1)
    if arr.size and (arr.min() < -n or arr.max() >= n):
        raise ValueError(f"{name} must be particle indices in [0, {n}), got values from {arr.min()} to {arr.max()}")
    return np.where(arr < 0, arr + n, arr)


class Particles:
    """A set of particles in a world (``World.add_particles``).  Indices count from 0 within the set."""

    __slots__ = ("_world", "_group", "__weakref__")

    def __init__(self, world, group):
        self._world = world
        self._group = group

    def _rows(self):
        """``(pf rows, pi rows)``: views of the set's rows; raises once the set is gone."""
        g = self._group
        if self._world is None or not g.alive:
            raise ValueError("these particles have been removed from their world")
        ps = self._world._state.particles
        return ps.pf[g.start:g.start + g.count], ps.pi[g.start:g.start + g.count]

    def __len__(self):
        return self._rows()[0].shape[0]

    @property
    def positions(self) -> np.ndarray:
        """Positions (m), ``(N, 3)``; assigning moves the particles (and the pins of those pinned to the
        world)."""
        return self._rows()[0][:, P.P_POS:P.P_POS + 3].copy()

    @positions.setter
    def positions(self, value: ArrayLike) -> None:
        f, i = self._rows()
        x = as_points("positions", value, f.shape[0], MAX_COORD, "m")
        f[:, P.P_POS:P.P_POS + 3] = x
        world_pins = ((i[:, P.P_FLAGS] & P.PP_PINNED) != 0) & (i[:, P.P_PIN_BODY] < 0)
        f[world_pins, P.P_PIN:P.P_PIN + 3] = x[world_pins]

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (m/s), ``(N, 3)``; assignable (particles pinned to the world stay at rest)."""
        return self._rows()[0][:, P.P_VEL:P.P_VEL + 3].copy()

    @velocities.setter
    def velocities(self, value: ArrayLike) -> None:
        f, _ = self._rows()
        v = as_points("velocities", value, f.shape[0], MAX_SPEED, "m/s")
        v[f[:, P.P_INV_MASS] == 0.0] = 0.0
        f[:, P.P_VEL:P.P_VEL + 3] = v

    @property
    def mass(self) -> np.ndarray:
        """Each particle's mass (kg), ``(N,)``."""
        return self._rows()[0][:, P.P_MASS].copy()

    @property
    def radius(self) -> np.ndarray:
        """Each particle's radius (m), ``(N,)``."""
        return self._rows()[0][:, P.P_RADIUS].copy()

    @property
    def pinned(self) -> np.ndarray:
        """Whether each particle is pinned (to the world or to a body), ``(N,)`` bool."""
        return (self._rows()[1][:, P.P_FLAGS] & P.PP_PINNED) != 0

    def pin(self, indices: ArrayLike, body=None) -> None:
        """Hold the chosen particles where they are now: fixed in the world (``body=None``), or at their
        place on ``body``, moving with it (two ways: the body carries their weight)."""
        f, i = self._rows()
        rows = as_indices("indices", indices, f.shape[0])
        if body is None:
            f[rows, P.P_PIN:P.P_PIN + 3] = f[rows, P.P_POS:P.P_POS + 3]
            f[rows, P.P_INV_MASS] = 0.0
            f[rows, P.P_VEL:P.P_VEL + 3] = 0.0
            i[rows, P.P_PIN_BODY] = -1
        else:
            b = self._world._check_body(body, "body")
            bf = self._world._state.bf[b]
            rot = quat_to_matrix_np(bf[L.QUAT:L.QUAT + 4])
            f[rows, P.P_PIN:P.P_PIN + 3] = (f[rows, P.P_POS:P.P_POS + 3] - bf[L.POS:L.POS + 3]) @ rot
            f[rows, P.P_INV_MASS] = 1.0 / f[rows, P.P_MASS]
            i[rows, P.P_PIN_BODY] = b
        i[rows, P.P_FLAGS] |= P.PP_PINNED
        self._world._state.particles.tethers = None
    def unpin(self, indices: ArrayLike) -> None:
        """Let the chosen particles go (they keep their velocity; those pinned to the world start at rest)."""
        f, i = self._rows()
        rows = as_indices("indices", indices, f.shape[0])
        i[rows, P.P_FLAGS] &= ~P.PP_PINNED
        i[rows, P.P_PIN_BODY] = -1
        f[rows, P.P_INV_MASS] = 1.0 / f[rows, P.P_MASS]
        self._world._state.particles.tethers = None

    def apply_force(self, force: ArrayLike, indices: ArrayLike = None) -> None:
        """Add the world force ``force`` (N, a 3-vector) on each chosen particle (None: all) for the next
        step."""
        f, _ = self._rows()
        v = as_vec3("force", force, bound=MAX_FORCE, unit="N")
        rows = as_indices("indices", indices, f.shape[0])
        np.add.at(f, (rows, slice(P.P_FORCE, P.P_FORCE + 3)), v)

    def __repr__(self):
        alive = self._world is not None and self._group.alive
        return f"<Particles {self._group.count} particles{'' if alive else ' (removed)'}>"


class Network:
    """Springs, rods or cables between the particles of one set (``World.add_network``)."""

    __slots__ = ("_world", "_group", "_particles", "_kind", "__weakref__")

    def __init__(self, world, group, particles, kind):
        self._world = world
        self._group = group
        self._particles = particles
        self._kind = kind

    def _rows(self):
        g = self._group
        if self._world is None or not g.alive:
            raise ValueError("this network has been removed from its world")
        ps = self._world._state.particles
        return ps.ef[g.start:g.start + g.count], ps.ei[g.start:g.start + g.count]

    def __len__(self):
        return self._rows()[0].shape[0]

    @property
    def particles(self) -> Particles:
        """The particles the network joins."""
        return self._particles

    @property
    def kind(self) -> str:
        """``"spring"``, ``"rod"`` or ``"cable"``."""
        return self._kind

    @property
    def edges(self) -> np.ndarray:
        """The edges, ``(E, 2)`` particle indices within the set."""
        _, i = self._rows()
        return i[:, P.E_A:P.E_B + 1] - self._particles._group.start

    @property
    def rest_length(self) -> np.ndarray:
        """Each edge's rest length (spring), length (rod) or largest length (cable), m, ``(E,)``."""
        return self._rows()[0][:, P.E_REST].copy()

    @property
    def broken(self) -> np.ndarray:
        """Whether each edge has broken (its tension passed ``breaking_force``), ``(E,)`` bool."""
        return (self._rows()[1][:, P.E_FLAGS] & P.EB_BROKEN) != 0

    @property
    def forces(self) -> np.ndarray:
        """Each edge's tension in the last sub-step of the last step (N; > 0 pulls its ends together),
        ``(E,)``; 0 for a broken edge and a slack cable."""
        f, i = self._rows()
        return np.where(self.broken, 0.0, f[:, P.E_FORCE])

    def __repr__(self):
        alive = self._world is not None and self._group.alive
        return f"<Network of {self._group.count} {self._kind}s{'' if alive else ' (removed)'}>"


def _per_particle(name, value, n, check):
    """``value`` (a number or an ``(n,)`` array) as ``(n,)`` floats, each passing ``check(name, x)``."""
    if np.ndim(value) == 0:
        return np.full(n, check(name, value))
    arr = as_real_array(name, value, ndim=1)
    if arr.shape[0] != n:
        raise ValueError(f"{name} must be a number or have {n} entries (one per particle), got {arr.shape[0]}")
    for x in arr:
        check(name, float(x))
    return arr


def particle_rows(positions, mass, radius, velocity, friction, static_friction, restitution, damping,
                  collide_particles):
    """The validated rows ``(pf, pi)`` of a new set of particles (``World.add_particles``' arguments)."""
    x = as_points("positions", positions, None, MAX_COORD, "m")
    n = x.shape[0]
    if n == 0:
        raise ValueError("positions must hold at least one particle")
    if n > MAX_PARTICLES:
        raise ValueError(f"positions must hold at most {MAX_PARTICLES} particles, got {n}")
    f = np.zeros((n, P.PF_COLS))
    i = np.zeros((n, P.PI_COLS), dtype=np.int64)
    f[:, P.P_POS:P.P_POS + 3] = x
    f[:, P.P_VEL:P.P_VEL + 3] = as_points("velocity", velocity, n, MAX_SPEED, "m/s")
    f[:, P.P_MASS] = _per_particle("mass", mass, n, lambda k, v: as_float(k, v, lo=MIN_MASS, hi=MAX_MASS, unit="kg"))
    f[:, P.P_INV_MASS] = 1.0 / f[:, P.P_MASS]
    f[:, P.P_RADIUS] = _per_particle("radius", radius, n, as_size)
    f[:, P.P_FRICTION] = validated("friction", friction)
    f[:, P.P_STATIC_FRICTION] = validated("static_friction", friction if static_friction is None else static_friction)
    f[:, P.P_RESTITUTION] = validated("restitution", restitution)
    f[:, P.P_DAMPING] = as_float("damping", damping, nonnegative=True, hi=MAX_DAMPING, unit="1/s")
    i[:, P.P_FLAGS] = P.PP_COLLIDE if as_flag("collide_particles", collide_particles) else 0
    i[:, P.P_PIN_BODY] = -1
    i[:, P.P_CLOTH] = -1
    return f, i


def edge_rows(particles, edges, kind, stiffness, damping, rest_length, breaking_force):
    """The validated rows ``(ef, ei)`` of a new network on ``particles`` (``World.add_network``' arguments),
    the particle rows global."""
    kind = as_choice("kind", kind, tuple(P.EDGE_KINDS))
    f_rows, _ = particles._rows()
    n = f_rows.shape[0]
    e = as_integers("edges", edges)
    if e.ndim != 2 or e.shape[1] != 2 or e.shape[0] == 0:
        raise ValueError(f"edges must have shape (E, 2) with E >= 1, got {e.shape}")
    if e.min() < 0 or e.max() >= n:
        raise ValueError(f"edges must be particle indices in [0, {n}), got values from {e.min()} to {e.max()}")
    if np.any(e[:, 0] == e[:, 1]):
        raise ValueError("edges must join two different particles (an edge has the same index twice)")
    m = e.shape[0]
    x = f_rows[:, P.P_POS:P.P_POS + 3]
    if rest_length is None:
        rest = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
    else:
        rest = _per_particle("rest_length", rest_length, m,
                             lambda k, v: as_float(k, v, nonnegative=True, hi=MAX_SIZE, unit="m"))
    if kind == "spring":
        if stiffness is None:
            raise ValueError("stiffness (N/m) is required for a network of springs")
        k = as_float("stiffness", stiffness, positive=True, hi=MAX_STIFFNESS, unit="N/m")
    f = np.zeros((m, P.EF_COLS))
    i = np.zeros((m, P.EI_COLS), dtype=np.int64)
    f[:, P.E_REST] = rest
    f[:, P.E_COMPLIANCE] = 1.0 / k if kind == "spring" else 0.0
    f[:, P.E_DAMPING] = as_float("damping", damping, nonnegative=True, hi=MAX_DAMPING, unit="N s/m")
    f[:, P.E_TEAR] = np.inf
    f[:, P.E_BREAKING] = np.inf if breaking_force is None else as_float("breaking_force", breaking_force,
                                                                        positive=True, hi=MAX_FORCE, unit="N")
    i[:, P.E_A:P.E_B + 1] = e + particles._group.start
    i[:, P.E_KIND] = P.EDGE_KINDS[kind]
    return f, i, kind
