"""``Fluid``: incompressible Navier-Stokes on a regular grid, in 2D or 3D (kernels in ``fluids/``).

The momentum and mass equations of a fluid of uniform density ``rho`` and kinematic viscosity ``nu``,

    du/dt + (u . grad) u = -grad(p) / rho + nu laplacian(u) + g        div u = 0

are split over a step into advection (MacCormack), the body force ``g``, viscosity (backward Euler) and the
pressure projection, which finds the pressure that makes the velocity divergence-free.  The grid is
staggered (MAC): pressure at cell centres, each velocity component on the faces normal to it, so that the
divergence and the pressure gradient are compact central differences, the projection has no checkerboard
null space, and walls and bodies are boundary conditions on faces.  Gravity only adds a hydrostatic pressure
to a fluid of uniform density, so it changes no flow: ``pressure`` leaves it out.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from ._validate import MAX_COORD, MAX_DT, MIN_DT, _short, as_float, as_int, as_real_array, as_vector
from .fluids.advection import advect_scalar, advect_velocity
from .fluids.forces import add_body_force
from .fluids.mac_grid import pad_cells, pad_faces, sample_cells, sample_velocities
from .fluids.pressure import divergence, prepare, solve_pressure, subtract_gradient
from .fluids.viscosity import diffuse

#: the sides of the box, in the order of the wall-velocity table
SIDES = ("x-", "x+", "y-", "y+", "z-", "z+")
#: the boundary kinds of an axis
BOUNDARIES = ("wall", "periodic")
#: most cells along an axis, and in all
MAX_RESOLUTION = 4096
MAX_CELLS = 64 * 1024 * 1024
#: most conjugate-gradient iterations of one pressure solve
MAX_PRESSURE_ITERATIONS = 5000
#: largest speed (m/s) that may be written into a fluid
MAX_FLUID_SPEED = 1.0e4


def _axes(boundary, dims):
    """``boundary`` (one kind, or one per axis) as a tuple of ``dims`` kinds."""
    if isinstance(boundary, str):
        kinds = (boundary,) * dims
    else:
        try:
            kinds = tuple(boundary)
        except TypeError:
            raise TypeError(f"boundary must be 'wall', 'periodic' or one of these per axis, got "
                            f"{_short(boundary)}") from None
        if len(kinds) != dims:
            raise ValueError(f"boundary must name {dims} axes for a {dims}D fluid, got {_short(boundary)}")
    for kind in kinds:
        if kind not in BOUNDARIES:
            raise ValueError(f"boundary must be 'wall' or 'periodic' (per axis), got {_short(boundary)}")
    return kinds


class Fluid:
    """An incompressible fluid filling the box ``origin .. origin + resolution * cell_size`` (m).

    ``resolution`` is ``(nx, ny)`` for a 2D fluid in the x-y plane or ``(nx, ny, nz)``; ``density`` in
    kg/m^3, ``viscosity`` the kinematic viscosity in m^2/s (water 1e-6, air 1.5e-5); ``boundary`` is
    ``"wall"`` (no-slip walls), ``"periodic"``, or one of these per axis; ``surface`` (m, a height in y) is
    where the liquid ends for buoyancy in a world.  ``tolerance`` bounds the volume any cell may gain or lose
    over a step, as a fraction of the cell (the pressure solve runs until ``max |div u| dt <= tolerance``).
    """

    def __init__(self, resolution: ArrayLike, cell_size: float, *, origin: ArrayLike = (0.0, 0.0, 0.0),
                 density: float = 1000.0, viscosity: float = 1.0e-6, boundary="wall", surface: float | None = None,
                 tolerance: float = 1.0e-6):
        if isinstance(resolution, (str, bytes)) or not hasattr(resolution, "__len__"):
            raise TypeError(f"resolution must be (nx, ny) or (nx, ny, nz), got {_short(resolution)}")
        if len(resolution) not in (2, 3):
            raise ValueError(f"resolution must be (nx, ny) or (nx, ny, nz), got {_short(resolution)}")
        dims = len(resolution)
        counts = [as_int(f"resolution[{a}]", resolution[a], lo=1, hi=MAX_RESOLUTION) for a in range(dims)]
        if math.prod(counts) > MAX_CELLS:
            raise ValueError(f"resolution has {math.prod(counts)} cells; at most {MAX_CELLS} are allowed")
        kinds = _axes(boundary, dims)
        h = as_float("cell_size", cell_size, positive=True, lo=1e-6, hi=1e3, unit="m")
        where = as_vector("origin", origin, 3, bound=MAX_COORD, unit="m")
        rho = as_float("density", density, positive=True, lo=1e-3, hi=1e5, unit="kg/m^3")
        nu = as_float("viscosity", viscosity, nonnegative=True, hi=1e3, unit="m^2/s")
        tol = as_float("tolerance", tolerance, positive=True, lo=1e-14, hi=1e-1)
        self._dims = dims
        self._n = np.array(counts + [1] * (3 - dims), np.int64)
        self._periodic = np.array([k == "periodic" for k in kinds] + [True] * (3 - dims), np.bool_)
        self._kinds = kinds
        self._h = h
        self._origin = where
        self._density = rho
        self._viscosity = nu
        self._tolerance = tol
        self._surface = None
        self.surface = surface
        self._wall = np.zeros((6, 3))
        self._force = np.zeros(3)
        shape = tuple(self._n)
        self._q = np.zeros((3,) + shape)
        self._p = np.zeros(shape)
        self._dye = np.zeros(shape)
        self._solid = np.zeros(shape, np.uint8)
        self._fixed = np.zeros((3,) + shape, np.uint8)
        for axis in range(3):
            if not self._periodic[axis]:
                index = [slice(None)] * 3
                index[axis] = 0
                self._fixed[(axis,) + tuple(index)] = 1
        self._coefficients = np.zeros((7,) + shape)
        self._precon = np.zeros(shape)
        self._prepared = False
        self._flow = None
        self._static_cells = None           # (key, solid cells, velocities) of a world's static bodies
        self._world = None
        self._time = 0.0
        self._pressure_iterations = 0
        self._viscosity_iterations = 0

    # --- description -------------------------------------------------------------------------------------
    @property
    def dimensions(self) -> int:
        """2 or 3."""
        return self._dims

    @property
    def resolution(self) -> tuple[int, ...]:
        """Cells along each axis."""
        return tuple(int(v) for v in self._n[:self._dims])

    @property
    def cell_size(self) -> float:
        """The side of a cell (m)."""
        return self._h

    @property
    def origin(self) -> np.ndarray:
        """The box's lower corner (m), a copy."""
        return self._origin.copy()

    @property
    def size(self) -> np.ndarray:
        """The box's extent along each axis (m)."""
        return self._n[:self._dims] * self._h

    @property
    def boundary(self) -> tuple[str, ...]:
        """The boundary kind of each axis."""
        return self._kinds

    @property
    def density(self) -> float:
        """kg/m^3."""
        return self._density

    @property
    def viscosity(self) -> float:
        """Kinematic viscosity (m^2/s)."""
        return self._viscosity

    @viscosity.setter
    def viscosity(self, value: float):
        self._viscosity = as_float("viscosity", value, nonnegative=True, hi=1e3, unit="m^2/s")

    @property
    def tolerance(self) -> float:
        """The most volume a cell may gain or lose over a step, as a fraction of the cell."""
        return self._tolerance

    @property
    def surface(self) -> float | None:
        """Height (m, along y) of the liquid's surface for buoyancy, or None (the box is full)."""
        return self._surface

    @surface.setter
    def surface(self, value: float | None):
        self._surface = None if value is None else as_float("surface", value, lo=-MAX_COORD, hi=MAX_COORD, unit="m")

    @property
    def time(self) -> float:
        """Seconds stepped so far."""
        return self._time

    @property
    def pressure_iterations(self) -> int:
        """Conjugate-gradient iterations of the last step's pressure solve."""
        return self._pressure_iterations

    @property
    def viscosity_iterations(self) -> int:
        """Conjugate-gradient iterations of the last step's viscosity solve (0 without viscosity)."""
        return self._viscosity_iterations

    # --- fields -------------------------------------------------------------------------------------------
    @property
    def body_force(self) -> np.ndarray:
        """Acceleration (m/s^2) acting on the fluid everywhere, a copy."""
        return self._force[:self._dims].copy()

    @body_force.setter
    def body_force(self, value: ArrayLike):
        force = as_vector("body_force", value, self._dims, bound=1e4, unit="m/s^2")
        self._force[:self._dims] = force

    @property
    def velocity(self) -> np.ndarray:
        """Velocity (m/s) at the cell centres, ``(nx, ny[, nz], d)``: each component the mean of the two faces
        around the centre; a copy.  Assigning ``(nx, ny[, nz], d)`` sets each face to the mean of its two
        cells (walls keep theirs); the next step projects what was assigned."""
        out = np.empty(tuple(self._n) + (self._dims,))
        for c in range(self._dims):
            upper = np.roll(self._q[c], -1, axis=c)
            if not self._periodic[c]:
                index = [slice(None)] * 3
                index[c] = -1
                upper[tuple(index)] = 0.0
            out[..., c] = 0.5 * (self._q[c] + upper)
        return out[:, :, 0] if self._dims == 2 else out

    @velocity.setter
    def velocity(self, value: ArrayLike):
        field = self._field("velocity", value, self.resolution + (self._dims,), MAX_FLUID_SPEED, "m/s")
        if self._dims == 2:
            field = field[:, :, None, :]
        q = np.zeros_like(self._q)
        for c in range(self._dims):
            q[c] = 0.5 * (field[..., c] + np.roll(field[..., c], 1, axis=c))
        self._q[:] = np.where(self._fixed, self._q, q)
        self._flow = None

    def set_velocity(self, function: Callable[[np.ndarray], ArrayLike]):
        """Set every face to ``function(points)``, where ``points`` (N, d) are the faces' centres (m) and the
        result (N, d) m/s: the exact start for a known flow (each face takes its own component)."""
        if not callable(function):
            raise TypeError(f"function must be callable, got {_short(function)}")
        q = np.zeros_like(self._q)
        n = self._n
        grids = np.meshgrid(np.arange(n[0]), np.arange(n[1]), np.arange(n[2]), indexing="ij")
        for c in range(self._dims):
            centres = np.stack([g + (0.0 if a == c else 0.5) for a, g in enumerate(grids)], -1).reshape(-1, 3)
            points = self._origin + centres * self._h
            values = self._field("function's result", function(points[:, :self._dims]),
                                 (len(points), self._dims), MAX_FLUID_SPEED, "m/s")
            q[c] = values[:, c].reshape(tuple(n))
        self._q[:] = np.where(self._fixed, self._q, q)
        self._flow = None

    @property
    def pressure(self) -> np.ndarray:
        """Pressure (Pa) at the cell centres from the last step, without the hydrostatic part; a copy.  Only
        its differences matter: it is shifted to mean zero over the fluid."""
        p = self._p.copy()
        return p[:, :, 0] if self._dims == 2 else p

    @property
    def dye(self) -> np.ndarray:
        """A passive scalar at the cell centres (any unit: smoke density, ink), carried by the flow; a copy;
        assignable."""
        d = self._dye.copy()
        return d[:, :, 0] if self._dims == 2 else d

    @dye.setter
    def dye(self, value: ArrayLike):
        field = self._field("dye", value, self.resolution, 1e30, "")
        self._dye[:] = field[:, :, None] if self._dims == 2 else field

    def divergence(self) -> np.ndarray:
        """The discrete divergence of the velocity (1/s) in each cell, the net outflow per unit volume."""
        out = np.empty(tuple(self._n))
        divergence(self._q, self._n, self._periodic, self._wall, self._dims, self._h, out)
        out[self._solid != 0] = 0.0
        return out[:, :, 0] if self._dims == 2 else out

    def kinetic_energy(self) -> float:
        """``sum rho |u|^2 / 2`` over the faces times the cell volume (J; in 2D per metre of depth)."""
        volume = self._h ** self._dims
        return 0.5 * self._density * volume * float(np.sum(self._q[:self._dims] ** 2))

    def velocity_at(self, points: ArrayLike) -> np.ndarray:
        """The velocity (m/s) interpolated at ``points`` (N, d) m; points outside the box read its edge."""
        pts = self._points(points)
        out = np.empty((len(pts), self._dims))
        sample_velocities(self._padded(), (pts - self._origin) / self._h, self._n, self._periodic, self._dims, out)
        return out

    def dye_at(self, points: ArrayLike) -> np.ndarray:
        """The dye interpolated at ``points`` (N, d) m."""
        pts = self._points(points)
        out = np.empty(len(pts))
        padded = np.empty((1,) + tuple(self._n + 2))
        pad_cells(self._dye, self._n, self._periodic, padded)
        sample_cells(padded, (pts - self._origin) / self._h, self._n, self._periodic, out)
        return out

    def set_wall_velocity(self, side: str, velocity: ArrayLike):
        """Make the wall ``side`` ("x-", "x+", "y-", "y+", "z-" or "z+") slide at ``velocity`` (d components,
        m/s) along itself, like a cavity's lid; its component across the wall must be zero."""
        if side not in SIDES[:2 * self._dims]:
            raise ValueError(f"side must be one of {', '.join(SIDES[:2 * self._dims])}, got {_short(side)}")
        axis = SIDES.index(side) // 2
        if self._periodic[axis]:
            raise ValueError(f"side {side!r} is on a periodic axis, which has no wall")
        v = as_vector("velocity", velocity, self._dims, bound=MAX_FLUID_SPEED, unit="m/s")
        if v[axis] != 0.0:
            raise ValueError(f"velocity must slide along the wall {side!r}: its component along the wall's "
                             f"normal must be 0, got {v[axis]!r}")
        self._wall[SIDES.index(side), :self._dims] = v
        self._flow = None

    # --- stepping -----------------------------------------------------------------------------------------
    def step(self, dt: float):
        """Advance the fluid by ``dt`` seconds (1e-6 .. 1): advect (dye, then velocity), body force, viscosity,
        pressure projection.  Stable at any Courant number; most accurate at ``dt ~ cell_size / speed``."""
        dt = as_float("dt", dt, lo=MIN_DT, hi=MAX_DT, unit="s")
        if self._world is not None:
            raise ValueError("this fluid is stepped by the world it was added to (World.step)")
        self._advance(dt)

    def _advance(self, dt):
        """One step of ``dt`` s, as a list of stages (the pressure from the last step, ``p``, is applied half
        before and half after the advection, so that the trajectories feel it at both ends: second order in
        time; the projection then corrects ``p`` by the increment that the new velocity needs)."""
        n, periodic, wall, dims, h, rho = self._n, self._periodic, self._wall, self._dims, self._h, self._density
        steps = dt / h
        if not self._prepared:
            self._prepare()
        flow = self._padded()
        if np.any(self._dye):                                                         # 1. carry the dye
            carried = np.empty_like(self._dye)
            advect_scalar(self._dye, flow, n, periodic, dims, steps, carried, np.empty((3,) + self._dye.shape),
                          np.empty((1,) + tuple(self._n + 2)))
            self._dye = carried
        pushed = self._q.copy()                                                       # 2. advect u - dt/2 grad p
        subtract_gradient(pushed, self._p, 0.5 * dt / (rho * h), n, self._coefficients)
        moved = np.empty_like(self._q)
        advect_velocity(flow, pushed, self._fixed, steps, n, periodic, wall, dims, moved,
                        np.empty((3,) + self._q.shape), np.empty_like(flow))
        subtract_gradient(moved, self._p, 0.5 * dt / (rho * h), n, self._coefficients)   # 3. - dt/2 grad p
        self._q = moved
        add_body_force(self._q, self._fixed, self._force, dt, dims)                   # 4. body force
        self._viscosity_iterations = 0
        if self._viscosity > 0.0:                                                     # 5. viscosity
            self._viscosity_iterations = diffuse(self._q, self._fixed, self._viscosity * dt / h ** 2, n, periodic,
                                                 wall, dims, np.empty((4,) + self._q.shape))
        self._project(dt)                                                             # 6. pressure projection
        self._flow = None
        self._time += dt

    def _padded(self):
        """The faces with a layer of ghost values around them (for interpolation), cached until they change."""
        if self._flow is None:
            self._flow = np.zeros((3,) + tuple(self._n + 2))
            pad_faces(self._q, self._n, self._periodic, self._wall, self._dims, self._flow)
        return self._flow

    def _prepare(self):
        """The pressure solve's matrix and preconditioner for the present walls and bodies."""
        prepare(self._n, self._periodic, self._fixed, self._solid, self._coefficients, self._precon)
        self._prepared = True

    def _project(self, dt):
        """Make the velocity divergence-free (the pressure solve to ``tolerance``)."""
        n, h, rho = self._n, self._h, self._density
        b = np.empty_like(self._p)
        divergence(self._q, n, self._periodic, self._wall, self._dims, h, b)
        b *= -rho * h * h / dt
        b[self._solid != 0] = 0.0
        limit = self._tolerance * rho * h * h / (dt * dt)
        work = np.empty((4,) + self._p.shape)
        increment = np.zeros_like(self._p)
        self._pressure_iterations, _ = solve_pressure(increment, b, n, self._solid, self._coefficients,
                                                      self._precon, limit, MAX_PRESSURE_ITERATIONS, work)
        subtract_gradient(self._q, increment, dt / (rho * h), n, self._coefficients)
        self._p += increment

    # --- in a world -----------------------------------------------------------------------------------------
    def _clear_obstacles(self):
        """No solid cells: only the walls are fixed."""
        self._static_cells = None
        self._solid[:] = 0
        self._fixed[:] = 0
        for axis in range(3):
            if not self._periodic[axis]:
                index = [slice(None)] * 3
                index[axis] = 0
                self._fixed[(axis,) + tuple(index)] = 1
                self._q[(axis,) + tuple(index)] = 0.0
        self._prepared = False
        self._flow = None

    def _state(self):
        """What a step or a user can change, as arrays (for a world's snapshot)."""
        surface = math.nan if self._surface is None else self._surface
        return {"velocity": self._q.copy(), "pressure": self._p.copy(), "dye": self._dye.copy(),
                "solid": self._solid.copy(), "fixed": self._fixed.copy(), "walls": self._wall.copy(),
                "scalars": np.array([self._time, self._viscosity, surface, *self._force])}

    def _check_state(self, state):
        """Raise ValueError unless ``state`` (from :meth:`_state`) fits this fluid: the right arrays and
        shapes, finite values, walls that slide along themselves."""
        if not isinstance(state, dict) or set(state) != set(self._state()):
            raise ValueError("snapshot holds a fluid state of the wrong form")
        shapes = {"velocity": self._q.shape, "pressure": self._p.shape, "dye": self._dye.shape,
                  "solid": self._solid.shape, "fixed": self._fixed.shape, "walls": (6, 3), "scalars": (6,)}
        for name, shape in shapes.items():
            arr = state[name]
            if not isinstance(arr, np.ndarray) or arr.shape != shape:
                raise ValueError(f"snapshot holds a fluid {name} of the wrong shape (this fluid: {shape})")
        for name in ("velocity", "pressure", "dye", "walls"):
            if not np.all(np.isfinite(state[name])):
                raise ValueError(f"snapshot holds a fluid {name} that is not finite")
        scalars = state["scalars"]
        if not (np.isfinite(scalars[[0, 1, 3, 4, 5]]).all() and scalars[1] >= 0.0):
            raise ValueError("snapshot holds fluid settings that are not finite (or a negative viscosity)")
        for side in range(6):
            if state["walls"][side, side // 2] != 0.0 or (self._periodic[side // 2] and np.any(state["walls"][side])):
                raise ValueError("snapshot holds a wall velocity across a wall (or on a periodic side)")

    def _load(self, state):
        """Take a state checked by :meth:`_check_state`."""
        self._q[:] = state["velocity"]
        self._p[:] = state["pressure"]
        self._dye[:] = state["dye"]
        self._solid[:] = state["solid"] != 0
        self._fixed[:] = state["fixed"] != 0
        self._wall[:] = state["walls"]
        self._time, self._viscosity = float(state["scalars"][0]), float(state["scalars"][1])
        self._surface = None if math.isnan(state["scalars"][2]) else float(state["scalars"][2])
        self._force[:] = state["scalars"][3:]
        self._prepared = False
        self._flow = None

    # --- helpers ------------------------------------------------------------------------------------------
    def _field(self, name, value, shape, bound, unit):
        arr = as_real_array(name, value)
        if arr.shape != tuple(shape):
            raise ValueError(f"{name} must have shape {tuple(shape)}, got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite (no NaN or inf)")
        if np.any(np.abs(arr) > bound):
            raise ValueError(f"{name} must be within +-{bound:g} {unit}".rstrip())
        return arr

    def _points(self, points):
        pts = as_real_array("points", points)
        if pts.ndim == 1:
            pts = pts[None, :]
        if pts.ndim != 2 or pts.shape[1] != self._dims:
            raise ValueError(f"points must have shape (N, {self._dims}), got {pts.shape}")
        if not np.all(np.isfinite(pts)) or np.any(np.abs(pts) > MAX_COORD):
            raise ValueError(f"points must be finite and within +-{MAX_COORD:g} m")
        return np.concatenate([pts, np.full((len(pts), 1), self._origin[2] + 0.5 * self._h)], axis=1) \
            if self._dims == 2 else pts

    def __repr__(self):
        return (f"Fluid(resolution={self.resolution}, cell_size={self._h:g}, boundary={self._kinds}, "
                f"density={self._density:g}, viscosity={self._viscosity:g})")

