"""Collision shapes and their mass properties.

A shape describes geometry in its own local frame, centred on its origin.  Dynamic shapes
(`Sphere`, `Box`, `Capsule`) also know their mass properties; static-only shapes (`Plane`, and
`HeightField` and `TriangleMesh` in their own modules) can only be attached with ``World.add_static``
or used in ``marbellous.collide``.

Every shape exposes to the kernels a type code (``collision.shape_types``), a record of
``N_SHAPE_PARAMS`` floats, and optional bulk geometry (a float64 and an int64 array) for meshes and
height fields.
"""
import math

import numpy as np

from .._validate import as_float, as_vec3
from ..collision import shape_types as st


class Shape:
    """Base class of all shapes.  Not instantiated directly."""

    _type = -1
    #: True for shapes that cannot move (plane, height field, triangle mesh).
    is_static_only = False

    def _params(self):
        """The kernel record: float64 array of ``N_SHAPE_PARAMS`` parameters."""
        raise TypeError(f"{type(self).__name__} is not a concrete shape")

    def _geometry(self):
        """Bulk geometry for the kernels: ``(float64 array, int64 array)``; empty for primitives."""
        return np.zeros(0, np.float64), np.zeros(0, np.int64)

    def mass_properties(self, density):
        """``(mass, inertia)`` of the shape filled with ``density`` (kg/m^3).

        ``mass`` in kg; ``inertia`` a (3, 3) tensor in kg m^2 about the shape's centre, in its frame.
        """
        raise TypeError(f"{type(self).__name__} is static only and has no mass properties")

    def bounding_radius(self):
        """Radius (m) of a sphere about the shape's origin that contains it (inf if unbounded)."""
        return math.inf


class Sphere(Shape):
    """A solid ball of ``radius`` metres centred on its origin.

    Inertia: ``I = 2/5 m r^2`` about every axis.
    """

    _type = st.SPHERE

    def __init__(self, radius):
        self.radius = as_float("radius", radius, positive=True)

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self.radius
        return p

    def volume(self):
        """Volume in m^3: ``4/3 pi r^3``."""
        return 4.0 / 3.0 * math.pi * self.radius ** 3

    def mass_properties(self, density):
        m = density * self.volume()
        return m, np.eye(3) * (0.4 * m * self.radius ** 2)

    def bounding_radius(self):
        return self.radius

    def __repr__(self):
        return f"Sphere(radius={self.radius!r})"


class Box(Shape):
    """A solid cuboid with ``half_extents = (hx, hy, hz)`` metres, centred on its origin.

    Inertia: ``I_xx = m/3 (hy^2 + hz^2)`` and cyclic (``m/12 (a^2 + b^2)`` with full side lengths).
    """

    _type = st.BOX

    def __init__(self, half_extents):
        h = as_vec3("half_extents", half_extents)
        if not np.all(h > 0.0):
            raise ValueError(f"half_extents must all be > 0, got {tuple(h)}")
        self.half_extents = h

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0:3] = self.half_extents
        return p

    def volume(self):
        """Volume in m^3: ``8 hx hy hz``."""
        hx, hy, hz = self.half_extents
        return 8.0 * hx * hy * hz

    def mass_properties(self, density):
        m = density * self.volume()
        hx, hy, hz = self.half_extents
        return m, np.diag([m / 3.0 * (hy * hy + hz * hz), m / 3.0 * (hx * hx + hz * hz),
                           m / 3.0 * (hx * hx + hy * hy)])

    def bounding_radius(self):
        return float(np.linalg.norm(self.half_extents))

    def __repr__(self):
        return f"Box(half_extents={tuple(float(v) for v in self.half_extents)!r})"


class Capsule(Shape):
    """A cylinder of ``radius`` and length ``2 half_height`` along local y, capped by two hemispheres.

    Inertia (cylinder mass ``mc``, both caps together ``ms``, ``h = 2 half_height``, ``r = radius``):
    ``I_yy = mc r^2/2 + ms 2/5 r^2`` and
    ``I_xx = I_zz = mc (r^2/4 + h^2/12) + ms (2/5 r^2 + h^2/4 + 3/8 h r)``.
    """

    _type = st.CAPSULE

    def __init__(self, radius, half_height):
        self.radius = as_float("radius", radius, positive=True)
        self.half_height = as_float("half_height", half_height, positive=True)

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self.radius
        p[1] = self.half_height
        return p

    def volume(self):
        """Volume in m^3: ``pi r^2 h + 4/3 pi r^3``."""
        r, h = self.radius, 2.0 * self.half_height
        return math.pi * r * r * h + 4.0 / 3.0 * math.pi * r ** 3

    def mass_properties(self, density):
        r, h = self.radius, 2.0 * self.half_height
        mc = density * math.pi * r * r * h
        ms = density * 4.0 / 3.0 * math.pi * r ** 3
        iyy = mc * r * r / 2.0 + ms * 0.4 * r * r
        ixx = mc * (r * r / 4.0 + h * h / 12.0) + ms * (0.4 * r * r + h * h / 4.0 + 3.0 / 8.0 * h * r)
        return mc + ms, np.diag([ixx, iyy, ixx])

    def bounding_radius(self):
        return self.radius + self.half_height

    def __repr__(self):
        return f"Capsule(radius={self.radius!r}, half_height={self.half_height!r})"


class Plane(Shape):
    """The static half-space ``dot(normal, x) <= offset``: its surface is ``dot(normal, x) == offset``.

    ``normal`` is normalised; the solid lies below it.  Static only.
    """

    _type = st.PLANE
    is_static_only = True

    def __init__(self, normal=(0.0, 1.0, 0.0), offset=0.0):
        n = as_vec3("normal", normal)
        length = float(np.linalg.norm(n))
        if length < 1e-12:
            raise ValueError("normal must be a non-zero vector")
        self.normal = n / length
        self.offset = as_float("offset", offset)

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0:3] = self.normal
        p[3] = self.offset
        return p

    def __repr__(self):
        return f"Plane(normal={tuple(float(v) for v in self.normal)!r}, offset={self.offset!r})"
