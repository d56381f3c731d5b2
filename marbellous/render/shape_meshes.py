"""Triangles of the engine's shapes for drawing, and how a shape is placed over them.

Shapes with the same look share one mesh: every sphere is the unit sphere scaled by its radius, every
box the unit cube scaled by its half extents, every plane one unit square placed per frame; a capsule
shares its mesh with capsules of the same size; a height field or triangle mesh has a mesh of its own,
keyed by a weak reference to the shape object.  The triangles of a mesh are made only when the mesh is first uploaded.

Normals of a mesh are drawn as ``mat3(model) @ normal`` (then normalised), which is right because
every mesh is scaled uniformly or, for boxes and planes, only along its face normals.
"""
import weakref
from collections.abc import Callable, Hashable
from dataclasses import dataclass

import numpy as np

from ..shapes.heightfield import HeightField
from ..shapes.mesh import TriangleMesh
from ..shapes.hull import ConvexHull
from ..shapes.primitives import Box, Capsule, Plane, Sphere
from .geometry import box_triangles, capsule_triangles, flat, heightfield_triangles, uv_sphere


@dataclass(frozen=True)
class ShapeMesh:
    """How to draw a shape: the mesh ``key`` (shapes with equal keys share one GPU buffer), the per-axis
    ``scale`` (3,) from the mesh to the shape, whether the shape is ``round`` (a sphere or capsule, whose
    spin a plain colour would hide), and ``triangles()`` giving the mesh's ``(positions, normals)``,
    float32 (3 T, 3) in the shape's frame before scaling (m).

    A plane's mesh is the square ``|x|, |z| <= 1`` at ``y = 0`` facing +y; the renderer places it
    under the camera (:func:`plane_frame`).
    """

    key: Hashable
    scale: np.ndarray
    round: bool
    triangles: Callable


def _unit_plane():
    return flat([[-1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, -1.0]], [[0, 1, 2], [0, 2, 3]])


_SPHERE = ShapeMesh(("sphere",), np.ones(3), True, lambda: uv_sphere(1.0, 20, 40))
_PLANE = ShapeMesh(("plane",), np.ones(3), False, _unit_plane)
_described = weakref.WeakKeyDictionary()   # shape -> ShapeMesh, so a frame does not rebuild them


def shape_mesh(shape):
    """The :class:`ShapeMesh` of an engine shape (``Sphere``, ``Box``, ``Capsule``, ``ConvexHull``, ``Plane``,
    ``HeightField`` or ``TriangleMesh``); raises ``TypeError`` naming ``shape`` for anything else."""
    try:
        return _described[shape]
    except (KeyError, TypeError):
        pass
    if isinstance(shape, Sphere):
        mesh = ShapeMesh(_SPHERE.key, np.full(3, shape.radius), True, _SPHERE.triangles)
    elif isinstance(shape, Box):
        mesh = ShapeMesh(("box",), np.array(shape.half_extents, np.float64), False,
                         lambda: box_triangles((1.0, 1.0, 1.0)))
    elif isinstance(shape, Capsule):
        r, hh = shape.radius, shape.half_height
        mesh = ShapeMesh(("capsule", r, hh), np.ones(3), True, lambda: capsule_triangles(r, hh))
    elif isinstance(shape, Plane):
        mesh = _PLANE
    elif isinstance(shape, HeightField):
        field = weakref.ref(shape)     # (a weak key: equal only to itself while the shape lives)
        mesh = ShapeMesh(field, np.ones(3), False,
                         lambda: heightfield_triangles(field().heights, (field().dx, field().dz), field().origin))
    elif isinstance(shape, TriangleMesh):
        tri = weakref.ref(shape)
        mesh = ShapeMesh(tri, np.ones(3), False, lambda: flat(tri().vertices, tri().triangles))
    elif isinstance(shape, ConvexHull):
        hull = weakref.ref(shape)
        mesh = ShapeMesh(hull, np.ones(3), False, lambda: flat(hull().vertices, hull_triangles(hull().faces)))
    else:
        raise TypeError(f"shape must be a Sphere, Box, Capsule, ConvexHull, Plane, HeightField or TriangleMesh, "
                        f"got {shape!r}")
    _described[shape] = mesh
    return mesh


def hull_triangles(faces):
    """Triangles (T, 3) of a hull's polygon faces, each fanned from its first corner."""
    return np.array([(loop[0], loop[k], loop[k + 1]) for loop in faces for k in range(1, len(loop) - 1)], np.int64)


def plane_frame(plane):
    """``(rotation (3, 3), point (3,))`` of a :class:`Plane` in its shape frame: the rotation takes +y to
    the plane's normal, and ``point`` (m) is the plane's point nearest the shape's origin."""
    n = np.asarray(plane.normal, np.float64)
    u = np.cross(n, (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 0.0, 1.0))
    u /= np.linalg.norm(u)
    return np.column_stack([u, n, np.cross(u, n)]), n * plane.offset
