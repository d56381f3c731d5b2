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
import math

import numpy as np

from .._validate import as_float, as_vec3
from ..collision import shape_types as st
from ..collision.ray.raycast_static import raycast_static
from .primitives import Shape

#: Most grid points of a height field.
MAX_POINTS = 1 << 26


class HeightField(Shape):
    """A static height field over the x-z plane; see the module docstring.

    ``heights`` (nx, nz) finite floats with ``nx, nz >= 2``; ``spacing`` ``(dx, dz)`` > 0 (m);
    ``origin`` ``(x0, y0, z0)`` (m).
    """

    _type = st.HEIGHTFIELD
    is_static_only = True

    def __init__(self, heights, spacing=(1.0, 1.0), origin=(0.0, 0.0, 0.0)):
        try:
            h = np.array(heights, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError("heights must be a 2D array of numbers") from None
        if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
            raise ValueError(f"heights must be a 2D array with at least 2 x 2 points, got shape {h.shape}")
        if h.size > MAX_POINTS:
            raise ValueError(f"heights: at most {MAX_POINTS} points are supported, got {h.size}")
        if not np.all(np.isfinite(h)):
            raise ValueError("heights must be finite (no NaN or inf)")
        try:
            sp = np.array(spacing, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"spacing must be two numbers (dx, dz), got {spacing!r}") from None
        if sp.shape != (2,):
            raise ValueError(f"spacing must be two numbers (dx, dz), got shape {sp.shape}")
        self.dx = as_float("spacing[0]", float(sp[0]), positive=True)
        self.dz = as_float("spacing[1]", float(sp[1]), positive=True)
        self.origin = as_vec3("origin", origin)
        self.heights = np.ascontiguousarray(h)
        self.heights.flags.writeable = False

    @property
    def shape(self):
        """``(nx, nz)``: number of grid points along x and z."""
        return self.heights.shape

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0], p[1] = self.dx, self.dz
        p[2:5] = self.origin
        p[5], p[6] = self.heights.shape
        return p

    def _geometry(self):
        return self.heights.reshape(-1).copy(), np.zeros(0, np.int64)

    def local_aabb(self):
        """``(min, max)`` corners (m) of the field's box in its own frame (new arrays)."""
        nx, nz = self.heights.shape
        lo = np.array([self.origin[0], self.origin[1] + self.heights.min(), self.origin[2]])
        hi = np.array([self.origin[0] + (nx - 1) * self.dx, self.origin[1] + self.heights.max(),
                       self.origin[2] + (nz - 1) * self.dz])
        return lo, hi

    def bounding_radius(self):
        """Radius (m) of a sphere about the shape's origin that contains the field."""
        lo, hi = self.local_aabb()
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", corners, corners))))

    def _locate(self, x, z):
        """Cell ``(i, j)`` and cell coordinates ``(u, w)`` in [0, 1] of the point ``(x, z)``."""
        x = as_float("x", x)
        z = as_float("z", z)
        nx, nz = self.heights.shape
        fx = (x - self.origin[0]) / self.dx
        fz = (z - self.origin[2]) / self.dz
        eps = 1e-9
        if not (-eps <= fx <= nx - 1 + eps):
            raise ValueError(f"x must lie within the field, {self.origin[0]} .. "
                             f"{self.origin[0] + (nx - 1) * self.dx}, got {x!r}")
        if not (-eps <= fz <= nz - 1 + eps):
            raise ValueError(f"z must lie within the field, {self.origin[2]} .. "
                             f"{self.origin[2] + (nz - 1) * self.dz}, got {z!r}")
        i = min(max(int(math.floor(fx)), 0), nx - 2)
        j = min(max(int(math.floor(fz)), 0), nz - 2)
        return i, j, fx - i, fz - j

    def height_at(self, x, z):
        """The surface's y (m, shape frame) above the point ``(x, z)``.

        Linear on the cell's triangle: ``u >= w`` (triangle 0):
        ``h00 + u (h10 - h00) + w (h11 - h10)``, else ``h00 + w (h01 - h00) + u (h11 - h01)``.
        """
        i, j, u, w = self._locate(x, z)
        h = self.heights
        if u >= w:
            y = h[i, j] + u * (h[i + 1, j] - h[i, j]) + w * (h[i + 1, j + 1] - h[i + 1, j])
        else:
            y = h[i, j] + w * (h[i, j + 1] - h[i, j]) + u * (h[i + 1, j + 1] - h[i, j + 1])
        return float(self.origin[1] + y)

    def normal_at(self, x, z):
        """Unit surface normal (shape frame) at ``(x, z)``: ``normalize(-dh/dx, 1, -dh/dz)`` of the
        triangle under the point (on the diagonal, triangle 0)."""
        i, j, u, w = self._locate(x, z)
        h = self.heights
        if u >= w:
            gx = (h[i + 1, j] - h[i, j]) / self.dx
            gz = (h[i + 1, j + 1] - h[i + 1, j]) / self.dz
        else:
            gx = (h[i + 1, j + 1] - h[i, j + 1]) / self.dx
            gz = (h[i, j + 1] - h[i, j]) / self.dz
        n = np.array([-gx, 1.0, -gz])
        return n / np.linalg.norm(n)

    def raycast(self, origin, direction, max_distance=math.inf):
        """Nearest hit of a ray in the field's frame: ``(distance, point, normal)`` or ``None``."""
        o = as_vec3("origin", origin)
        d = as_vec3("direction", direction)
        length = float(np.linalg.norm(d))
        if length < 1e-12:
            raise ValueError("direction must be a non-zero vector")
        max_distance = as_float("max_distance", max_distance, nonnegative=True, allow_inf=True)
        out = np.zeros(8)
        geom_f, geom_i = self._geometry()
        if not raycast_static(st.HEIGHTFIELD, np.zeros(3), np.eye(3), self._params(), geom_f, geom_i,
                              0, 0, o, d / length, max_distance, out):
            return None
        return float(out[0]), out[1:4].copy(), out[4:7].copy()

    def __repr__(self):
        nx, nz = self.heights.shape
        return f"HeightField({nx} x {nz} points, spacing=({self.dx}, {self.dz}), origin={tuple(self.origin)})"
