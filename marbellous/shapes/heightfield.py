"""Static height fields (height maps): a grid of heights, with height and normal queries.

``HeightField(heights, spacing=(dx, dz), origin=(x0, y0, z0))``: ``heights[i, j]`` (m) is the
height above ``y0`` of the point at ``x = x0 + i dx``, ``z = z0 + j dz`` in the shape's frame.  Each
grid cell is two triangles split along the diagonal from ``(i, j)`` to ``(i + 1, j + 1)``; the
surface is piecewise linear on them, and ``height_at``/``normal_at`` report exactly the surface
that collisions use (``normal_at`` is the normal of the triangle under the point, the gradient of
the interpolation).  The solid lies below the surface.

Kernel record (``_params()``)::

    [dx, dz, x0, y0, z0, nx, nz, 0]

and ``_geometry()`` is ``(heights.ravel() (row i, column j), empty int64 array)``; see
``collision/heightfield_collide.py``.
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._validate import MAX_COORD, as_direction, as_float, as_real_array, as_size, as_vec3
from ..collision import shape_types as st
from ..collision.ray.raycast_static import raycast_static
from .primitives import Shape

#: Most grid points of a height field.
MAX_POINTS = 1 << 26


class HeightField(Shape):
    """A static height field over the x-z plane; see the module docstring.

    ``heights`` (nx, nz) finite floats (m, within +-1e12) with ``nx, nz >= 2`` and at most
    ``MAX_POINTS`` points; ``spacing`` ``(dx, dz)`` in [1e-6, 1e6] m; ``origin`` ``(x0, y0, z0)`` (m).
    Immutable: ``heights`` is a read-only array, ``origin`` a new array on each read.
    """

    __slots__ = ("_heights", "_dx", "_dz", "_origin")
    _type = st.HEIGHTFIELD
    is_static_only = True

    def __init__(self, heights: ArrayLike, spacing: ArrayLike = (1.0, 1.0),
                 origin: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        if isinstance(heights, np.ndarray) and heights.ndim == 2 and heights.size > MAX_POINTS:
            raise ValueError(f"heights: at most {MAX_POINTS} points are supported, got {heights.size}")
        h = as_real_array("heights", heights)
        if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
            raise ValueError(f"heights must be a 2D array with at least 2 x 2 points, got shape {h.shape}")
        if h.size > MAX_POINTS:
            raise ValueError(f"heights: at most {MAX_POINTS} points are supported, got {h.size}")
        if not np.all(np.isfinite(h)):
            raise ValueError("heights must be finite (no NaN or inf)")
        if np.any(np.abs(h) > MAX_COORD):
            raise ValueError(f"heights must be within +-{MAX_COORD:g} m")
        if isinstance(spacing, (str, bytes)) or not hasattr(spacing, "__len__"):
            raise TypeError(f"spacing must be two numbers (dx, dz), got {spacing!r}")
        if len(spacing) != 2:
            raise ValueError(f"spacing must be two numbers (dx, dz), got {len(spacing)} values")
        dx = as_size("spacing[0]", spacing[0])
        dz = as_size("spacing[1]", spacing[1])
        o = as_vec3("origin", origin)
        o.flags.writeable = False
        h = np.ascontiguousarray(h)
        h.flags.writeable = False
        self._init(_heights=h, _dx=dx, _dz=dz, _origin=o)

    @property
    def heights(self) -> np.ndarray:
        """Heights (m) above ``origin[1]``, shape (nx, nz), a read-only array."""
        return self._heights.view()

    @property
    def dx(self) -> float:
        """Grid spacing along x (m)."""
        return self._dx

    @property
    def dz(self) -> float:
        """Grid spacing along z (m)."""
        return self._dz

    @property
    def origin(self) -> np.ndarray:
        """Position (m) of grid point (0, 0) at height 0, in the shape's frame (a new array)."""
        return self._origin.copy()

    @property
    def shape(self) -> tuple[int, int]:
        """``(nx, nz)``: number of grid points along x and z."""
        return self._heights.shape

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0], p[1] = self._dx, self._dz
        p[2:5] = self._origin
        p[5], p[6] = self._heights.shape
        return p

    def _geometry(self):
        return self._heights.reshape(-1).copy(), np.zeros(0, np.int64)

    def local_aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """``(min, max)`` corners (m) of the field's box in its own frame (new arrays)."""
        nx, nz = self._heights.shape
        lo = np.array([self._origin[0], self._origin[1] + self._heights.min(), self._origin[2]])
        hi = np.array([self._origin[0] + (nx - 1) * self._dx, self._origin[1] + self._heights.max(),
                       self._origin[2] + (nz - 1) * self._dz])
        return lo, hi

    def bounding_radius(self) -> float:
        """Radius (m) of a sphere about the shape's origin that contains the field."""
        lo, hi = self.local_aabb()
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", corners, corners))))

    def _locate(self, x, z):
        """Cell ``(i, j)`` and cell coordinates ``(u, w)`` in [0, 1] of the point ``(x, z)``."""
        x = as_float("x", x)
        z = as_float("z", z)
        nx, nz = self._heights.shape
        fx = (x - self._origin[0]) / self._dx
        fz = (z - self._origin[2]) / self._dz
        eps = 1e-9
        if not (-eps <= fx <= nx - 1 + eps):
            raise ValueError(f"x must lie within the field, {self._origin[0]} .. "
                             f"{self._origin[0] + (nx - 1) * self._dx}, got {x!r}")
        if not (-eps <= fz <= nz - 1 + eps):
            raise ValueError(f"z must lie within the field, {self._origin[2]} .. "
                             f"{self._origin[2] + (nz - 1) * self._dz}, got {z!r}")
        i = min(max(int(math.floor(fx)), 0), nx - 2)
        j = min(max(int(math.floor(fz)), 0), nz - 2)
        return i, j, fx - i, fz - j

    def height_at(self, x: float, z: float) -> float:
        """The surface's y (m, shape frame) above the point ``(x, z)``.

        Linear on the cell's triangle: ``u >= w`` (triangle 0):
        ``h00 + u (h10 - h00) + w (h11 - h10)``, else ``h00 + w (h01 - h00) + u (h11 - h01)``.
        """
        i, j, u, w = self._locate(x, z)
        h = self._heights
        if u >= w:
            y = h[i, j] + u * (h[i + 1, j] - h[i, j]) + w * (h[i + 1, j + 1] - h[i + 1, j])
        else:
            y = h[i, j] + w * (h[i, j + 1] - h[i, j]) + u * (h[i + 1, j + 1] - h[i, j + 1])
        return float(self._origin[1] + y)

    def normal_at(self, x: float, z: float) -> np.ndarray:
        """Unit surface normal (shape frame) at ``(x, z)``: ``normalize(-dh/dx, 1, -dh/dz)`` of the
        triangle under the point (on the diagonal, triangle 0)."""
        i, j, u, w = self._locate(x, z)
        h = self._heights
        if u >= w:
            gx = (h[i + 1, j] - h[i, j]) / self._dx
            gz = (h[i + 1, j + 1] - h[i + 1, j]) / self._dz
        else:
            gx = (h[i + 1, j + 1] - h[i, j + 1]) / self._dx
            gz = (h[i, j + 1] - h[i, j]) / self._dz
        n = np.array([-gx, 1.0, -gz])
        return n / np.linalg.norm(n)

    def raycast(self, origin: ArrayLike, direction: ArrayLike, max_distance: float = math.inf):
        """Nearest hit of a ray in the field's frame: ``(distance, point, normal)`` or ``None``."""
        o = as_vec3("origin", origin)
        d = as_direction("direction", direction)
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True)
        out = np.zeros(8)
        geom_f, geom_i = self._geometry()
        if not raycast_static(st.HEIGHTFIELD, np.zeros(3), np.eye(3), self._params(), geom_f, geom_i,
                              0, 0, o, d, max_distance, out):
            return None
        return float(out[0]), out[1:4].copy(), out[4:7].copy()

    def __repr__(self):
        nx, nz = self._heights.shape
        return f"HeightField({nx} x {nz} points, spacing=({self._dx}, {self._dz}), origin={tuple(self._origin)})"
