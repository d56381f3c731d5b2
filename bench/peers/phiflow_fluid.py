"""The benchmark's fluid in PhiFlow (``phi``, NumPy backend, float64), for ``bench/bench_fluid.py``.

A ``StaggeredGrid`` velocity in the unit box, walls all round (``0``; a lid ``{'y+': vec(x=lid, y=0)}``), the dye a
``CenteredGrid`` with zero-gradient walls.  A step of ``dt`` s, with PhiFlow's own functions where they run:

1. the dye by ``advect.mac_cormack``, the velocity by ``advect.mac_cormack`` too, except under a moving lid, where
   it fails in PhiFlow 3.4.0 (its clamp pads the field with the wall's vector value: ``AssertionError: Cannot pad
   tensor ... because non-batch dimension 'vector' is missing``) and ``advect.semi_lagrangian`` is used instead
   (one trace and one interpolation per face instead of two of each and the clamp: less work).  The traces use
   the midpoint rule (``midpoint`` below, written like PhiFlow's ``advect.euler``: PhiFlow has Euler and RK4);
2. viscosity (when ``viscosity > 0``): backward Euler, ``u - nu dt laplace(u) = u*``, solved for each component
   by ``math.solve_linear`` with ``Solve('CG')`` on ``math.laplace`` with zero padding, the lid's ghost value
   ``U`` added to the right side of the top row: ``diffuse.implicit`` fails on a ``StaggeredGrid`` with walls in
   PhiFlow 3.4.0 (``ValueError: Shape (x=127, y=128) has no dimension 'idx'``), with a zero boundary too;
3. ``fluid.make_incompressible`` with ``Solve('CG', rel_tol=0, abs_tol=tolerance / dt)`` (no preconditioner, from a
   zero pressure: PhiFlow's default; started from the last step's pressure, its CG was stopped as ``Diverged`` by
   PhiML's check that the residual grew 1e5-fold, at step 203 of the cavity).  PhiML stops on the residual's
   L2 norm (over all cells), stricter than Marbellous' largest cell: its divergence ends lower.
"""
import warnings

import numpy as np
from phi import field
from phi import math as pm
from phi.field import CenteredGrid, StaggeredGrid, sample
from phi.geom import Box
from phi.math import Solve, extrapolation, spatial
from phi.physics import advect, fluid

pm.set_global_precision(64)
# make_incompressible sets rank_deficiency=1 itself (walls all round: the pressure's constant is free) and then
# warns about it on every solve
warnings.filterwarnings("ignore", message="Rank deficiency", category=RuntimeWarning)


def midpoint(data, velocity, dt, v0=None):
    """The midpoint rule (second-order Runge-Kutta), in the form of PhiFlow's ``advect.euler`` integrator."""
    if v0 is None:
        v0 = sample(velocity, data.geometry, at=data.sampled_at, boundary=data.boundary)
    half = sample(velocity, data.points + 0.5 * dt * v0, at=data.sampled_at, boundary=data.boundary)
    return data.points + dt * half


class PhiFlowFluid:
    """An incompressible fluid of ``n = (nx, ny, nz)`` cells of side ``h`` m (``nz = 1``: 2D), walls all round."""

    def __init__(self, n, h, viscosity, density, tolerance, lid=0.0, max_iterations=5000):
        self.nx, self.ny, self.nz = (int(v) for v in n)
        self.dims = 2 if self.nz == 1 else 3
        self.names = "x,y" if self.dims == 2 else "x,y,z"
        self.h, self.nu, self.tol, self.lid = float(h), float(viscosity), tolerance, float(lid)
        self.max_iterations = max_iterations
        size = dict(zip("xyz", (self.nx, self.ny, self.nz)[:self.dims]))
        bounds = Box(**{a: s * self.h for a, s in size.items()})
        if lid:
            boundary = {"x": 0, "y-": 0, "y+": pm.vec(x=float(lid), y=0.0)}
            if self.dims == 3:
                boundary["z"] = 0
        else:
            boundary = 0
        self.v = StaggeredGrid(0.0, boundary, bounds=bounds, **size)
        self.dye = None
        self._dye_grid = CenteredGrid(0.0, extrapolation.ZERO_GRADIENT, bounds=bounds, **size)
        self._vector = self.v.values.shape.only("~vector")
        self._components = "xyz"[:self.dims]
        self._operators = {}
        self.pressure_iterations = None
        self.viscosity_iterations = None
        self.record = False

    def _operator(self, a):
        """``u -> u - a laplace(u)`` with zero padding, traced by PhiML into a sparse matrix (once per ``a``)."""
        if a not in self._operators:
            h = self.h
            self._operators[a] = pm.jit_compile_linear(lambda u: u - a * pm.laplace(u, dx=h,
                                                                                    padding=extrapolation.ZERO))
        return self._operators[a]

    def _diffuse(self, v, dt):
        a = self.nu * dt
        parts = []
        for c in self._components:
            u = v.vector[c].values
            if c == "x" and self.lid:
                top = np.zeros(u.shape.sizes)
                top[:, -1] = a * self.lid / self.h ** 2     # the lid's ghost value U in the top row's Laplacian
                u = u + pm.tensor(top, spatial(self.names))
            solve = Solve("CG", rel_tol=0.0, abs_tol=1e-8 * max(abs(self.lid), 1.0), max_iterations=500, x0=u)
            parts.append(pm.solve_linear(self._operator(a), u, solve))
        return v.with_values(pm.stack(parts, self._vector))

    def step(self, dt):
        if self.dye is not None:
            self.dye = advect.mac_cormack(self.dye, self.v, dt, integrator=midpoint)
        if self.lid:
            v = advect.semi_lagrangian(self.v, self.v, dt, integrator=midpoint)
        else:
            v = advect.mac_cormack(self.v, self.v, dt, integrator=midpoint)
        solve = Solve("CG", rel_tol=0.0, abs_tol=self.tol / dt, max_iterations=self.max_iterations)
        if self.record:
            with pm.SolveTape() as tape:
                if self.nu > 0.0:
                    v = self._diffuse(v, dt)
                self.v, _ = fluid.make_incompressible(v, (), solve)
            its = [int(r.iterations) for r in tape.solves]
            self.pressure_iterations = its[-1]
            self.viscosity_iterations = its[:-1] or None
        else:
            if self.nu > 0.0:
                v = self._diffuse(v, dt)
            self.v, _ = fluid.make_incompressible(v, (), solve)

    def max_divergence(self):
        return float(pm.max(abs(field.divergence(self.v).values)))

    # --- state as NumPy arrays in Marbellous' face layout (outside the timed steps) ----------------------------
    def faces(self):
        """The face velocities, (3, nx, ny, nz) m/s: PhiFlow stores only the faces between cells."""
        q = np.zeros((3, self.nx, self.ny, self.nz))
        for a, c in enumerate(self._components):
            values = self.v.vector[c].values.numpy(self.names)
            if self.dims == 2:
                values = values[..., None]
            index = [slice(None)] * 3
            index[a] = slice(1, None)
            q[(a,) + tuple(index)] = values
        return q

    def set_faces(self, q):
        parts = []
        for a, _ in enumerate(self._components):
            index = [slice(None)] * 3
            index[a] = slice(1, None)
            values = q[(a,) + tuple(index)]
            if self.dims == 2:
                values = values[..., 0]
            parts.append(pm.tensor(np.ascontiguousarray(values, dtype=np.float64), spatial(self.names)))
        self.v = self.v.with_values(pm.stack(parts, self._vector))

    def get_dye(self):
        if self.dye is None:
            return np.zeros((self.nx, self.ny, self.nz))
        d = self.dye.values.numpy(self.names)
        return d[..., None] if self.dims == 2 else d

    def set_dye(self, d):
        d = d[..., 0] if self.dims == 2 else d
        self.dye = self._dye_grid.with_values(pm.tensor(np.ascontiguousarray(d, dtype=np.float64),
                                                        spatial(self.names)))
