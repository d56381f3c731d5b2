"""Collision shapes and their mass properties.

A shape describes geometry in its own local frame, centred on its origin.  Dynamic shapes
(`Sphere`, `Box`, `Capsule`) also know their mass properties; static-only shapes (`Plane`, and
`HeightField` and `TriangleMesh` in their own modules) can only be attached with ``World.add_static``
or used in ``marbellous.collide``.

Every shape exposes to the kernels a type code (``collision.shape_types``), a record of
``N_SHAPE_PARAMS`` floats, and optional bulk geometry (a float64 and an int64 array) for meshes and
height fields.

Shapes are immutable: the world copies a shape's record and geometry when a body is added, so a shape
that changed afterwards would disagree with what the kernels use.  Assigning any attribute of a shape
raises ``AttributeError``; vector attributes are returned as new arrays and bulk arrays (vertices,
triangles, heights) as read-only views.  Sizes are in [1e-6, 1e6] m (``marbellous._validate``).
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._validate import MAX_SIZE, MIN_SIZE, as_direction, as_float, as_size, as_vec3
from ..collision import shape_types as st


class Shape:
    """Base class of all shapes.  Not instantiated directly.  Shapes are immutable (see the module
    docstring): their constructors set their slots with :meth:`_init`, and assignment raises."""

    __slots__ = ("__weakref__",)
    _type = -1
    #: True for shapes that cannot move (plane, height field, triangle mesh).
    is_static_only = False

    def _init(self, **values):
        """Set the shape's slots (only constructors call this)."""
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable: cannot set {name!r} (make a new shape)")

    def __delattr__(self, name):
        raise AttributeError(f"{type(self).__name__} is immutable: cannot delete {name!r}")

    def __setstate__(self, state):
        """Unpickling: set the slots again (arrays read-only, as the constructor left them)."""
        slots = state[1] if isinstance(state, tuple) else state
        for name, value in (slots or {}).items():
            if isinstance(value, np.ndarray) and not name.startswith("_geom"):   # (kernels take _geom_*)
                value.flags.writeable = False
            object.__setattr__(self, name, value)

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self

    def _params(self):
        """The kernel record: float64 array of ``N_SHAPE_PARAMS`` parameters."""
        raise TypeError(f"{type(self).__name__} is not a concrete shape")

    def _geometry(self):
        """Bulk geometry for the kernels: ``(float64 array, int64 array)``; empty for primitives."""
        return np.zeros(0, np.float64), np.zeros(0, np.int64)

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        """``(mass, inertia)`` of the shape filled with ``density`` (kg/m^3).

        ``mass`` in kg; ``inertia`` a (3, 3) tensor in kg m^2 about the shape's centre, in its frame.
        """
        raise TypeError(f"{type(self).__name__} is static only and has no mass properties")

    def bounding_radius(self) -> float:
        """Radius (m) of a sphere about the shape's origin that contains it (inf if unbounded)."""
        return math.inf


class Sphere(Shape):
    """A solid ball of ``radius`` metres centred on its origin.

    Inertia: ``I = 2/5 m r^2`` about every axis.
    """

    __slots__ = ("_radius",)
    _type = st.SPHERE

    def __init__(self, radius: float) -> None:
        self._init(_radius=as_size("radius", radius))

    @property
    def radius(self) -> float:
        """Radius (m), in [1e-6, 1e6]."""
        return self._radius

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self.radius
        return p

    def volume(self) -> float:
        """Volume in m^3: ``4/3 pi r^3``."""
        return 4.0 / 3.0 * math.pi * self.radius ** 3

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        m = density * self.volume()
        return m, np.eye(3) * (0.4 * m * self.radius ** 2)

    def bounding_radius(self) -> float:
        return self.radius

    def __repr__(self):
        return f"Sphere(radius={self.radius!r})"


class Box(Shape):
    """A solid cuboid with ``half_extents = (hx, hy, hz)`` metres, centred on its origin.

    Inertia: ``I_xx = m/3 (hy^2 + hz^2)`` and cyclic (``m/12 (a^2 + b^2)`` with full side lengths).
    """

    __slots__ = ("_half_extents",)
    _type = st.BOX

    def __init__(self, half_extents: ArrayLike, *more: float) -> None:
        if more:
            raise TypeError(f"Box takes half_extents as one (hx, hy, hz) sequence: Box(({half_extents!r}, "
                            f"{', '.join(repr(m) for m in more)})), not {1 + len(more)} separate arguments")
        h = as_vec3("half_extents", half_extents, bound=MAX_SIZE)
        if not np.all(h >= MIN_SIZE):
            raise ValueError(f"half_extents must all be >= {MIN_SIZE:g} m (and <= {MAX_SIZE:g} m), got {tuple(h)}")
        h.flags.writeable = False
        self._init(_half_extents=h)

    @property
    def half_extents(self) -> np.ndarray:
        """Half extents ``(hx, hy, hz)`` (m, each in [1e-6, 1e6]) as a new array."""
        return self._half_extents.copy()

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0:3] = self._half_extents
        return p

    def volume(self) -> float:
        """Volume in m^3: ``8 hx hy hz``."""
        hx, hy, hz = self._half_extents
        return 8.0 * hx * hy * hz

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        m = density * self.volume()
        hx, hy, hz = self._half_extents
        return m, np.diag([m / 3.0 * (hy * hy + hz * hz), m / 3.0 * (hx * hx + hz * hz),
                           m / 3.0 * (hx * hx + hy * hy)])

    def bounding_radius(self) -> float:
        return float(np.linalg.norm(self._half_extents))

    def __repr__(self):
        return f"Box(half_extents={tuple(float(v) for v in self._half_extents)!r})"


class Capsule(Shape):
    """A cylinder of ``radius`` and length ``2 half_height`` along local y, capped by two hemispheres.

    Inertia (cylinder mass ``mc``, both caps together ``ms``, ``h = 2 half_height``, ``r = radius``):
    ``I_yy = mc r^2/2 + ms 2/5 r^2`` and
    ``I_xx = I_zz = mc (r^2/4 + h^2/12) + ms (2/5 r^2 + h^2/4 + 3/8 h r)``.
    """

    __slots__ = ("_radius", "_half_height")
    _type = st.CAPSULE

    def __init__(self, radius: float, half_height: float) -> None:
        self._init(_radius=as_size("radius", radius), _half_height=as_size("half_height", half_height))

    @property
    def radius(self) -> float:
        """Radius (m), in [1e-6, 1e6]."""
        return self._radius

    @property
    def half_height(self) -> float:
        """Half the length of the cylinder part (m), in [1e-6, 1e6]."""
        return self._half_height

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0] = self.radius
        p[1] = self.half_height
        return p

    def volume(self) -> float:
        """Volume in m^3: ``pi r^2 h + 4/3 pi r^3``."""
        r, h = self.radius, 2.0 * self.half_height
        return math.pi * r * r * h + 4.0 / 3.0 * math.pi * r ** 3

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        r, h = self.radius, 2.0 * self.half_height
        mc = density * math.pi * r * r * h
        ms = density * 4.0 / 3.0 * math.pi * r ** 3
        iyy = mc * r * r / 2.0 + ms * 0.4 * r * r
        ixx = mc * (r * r / 4.0 + h * h / 12.0) + ms * (0.4 * r * r + h * h / 4.0 + 3.0 / 8.0 * h * r)
        return mc + ms, np.diag([ixx, iyy, ixx])

    def bounding_radius(self) -> float:
        return self.radius + self.half_height

    def __repr__(self):
        return f"Capsule(radius={self.radius!r}, half_height={self.half_height!r})"


class Plane(Shape):
    """The static half-space ``dot(normal, x) <= offset``: its surface is ``dot(normal, x) == offset``.

    ``normal`` is normalised; the solid lies below it.  Static only.
    """

    __slots__ = ("_normal", "_offset")
    _type = st.PLANE
    is_static_only = True

    def __init__(self, normal: ArrayLike = (0.0, 1.0, 0.0), offset: float = 0.0) -> None:
        n = as_direction("normal", normal)
        n.flags.writeable = False
        self._init(_normal=n, _offset=as_float("offset", offset, lo=-1e12, hi=1e12, unit="m"))

    @property
    def normal(self) -> np.ndarray:
        """Unit normal (new array): any finite nonzero vector given is normalised."""
        return self._normal.copy()

    @property
    def offset(self) -> float:
        """Offset (m) of the surface along the normal, within +-1e12."""
        return self._offset

    def _params(self):
        p = np.zeros(st.N_SHAPE_PARAMS)
        p[0:3] = self._normal
        p[3] = self._offset
        return p

    def __repr__(self):
        return f"Plane(normal={tuple(float(v) for v in self._normal)!r}, offset={self._offset!r})"
