"""Collision queries without a world: ``collide(shape_a, shape_b, ...)``.

The goal area of the game is such a query: ``collide(Box(...), Sphere(r), position_b=ball)``.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ._validate import as_quat, as_vec3
from .collision.pairs.dispatch import SPHERE_PAIR, collide_pair
from .collision.shape_types import SPHERE, sphere_coverage
from .math3d import quat_to_matrix_np
from .pipeline.precompile import await_kernel
from .shapes.primitives import Shape


class ContactPoint(NamedTuple):
    """One contact of two shapes: ``point`` (m, midway between the surfaces), ``normal`` (unit, from
    shape a to shape b), ``depth`` (m, > 0 overlap, 0 touching)."""

    point: np.ndarray
    normal: np.ndarray
    depth: float


def _as_shape(name, shape):
    if not isinstance(shape, Shape) or type(shape) is Shape:
        raise TypeError(f"{name} must be a marbellous shape (Sphere, Box, Capsule, Plane, ...), got {shape!r}")
    return shape


def pair_test_call(shape_a, shape_b, pos_a, rot_a, pos_b, rot_b, capacity):
    """``(kernel, arguments)``: the pair test of :func:`collide` for shapes ``shape_a`` and ``shape_b`` at
    positions ``pos_a``, ``pos_b`` (m, float64 (3,)) and rotation matrices ``rot_a``, ``rot_b`` (float64 (3, 3)),
    with room for ``capacity`` contact points in ``arguments[-3]`` (``(capacity, 7)``: point, normal, depth);
    the kernel returns how many it found.  A sphere's pairs go to the kernel compiled with the tests of the other
    shape's kind alone (``collision/pairs/dispatch.py``)."""
    params_a = np.ascontiguousarray(shape_a._params(), dtype=np.float64)
    params_b = np.ascontiguousarray(shape_b._params(), dtype=np.float64)
    geom_f_a, geom_i_a = shape_a._geometry()
    geom_f_b, geom_i_b = shape_b._geometry()
    # one blob per kind holding a's geometry, then b's
    geom_f = np.ascontiguousarray(np.concatenate([geom_f_a, geom_f_b]), dtype=np.float64)
    geom_i = np.ascontiguousarray(np.concatenate([geom_i_a, geom_i_b]), dtype=np.int64)
    pair_test = SPHERE_PAIR[sphere_coverage(shape_b._type if shape_a._type == SPHERE else shape_a._type)] \
        if SPHERE in (shape_a._type, shape_b._type) else collide_pair
    return pair_test, (shape_a._type, pos_a, rot_a, params_a, shape_b._type, pos_b, rot_b, params_b, geom_f,
                       geom_i, 0, 0, len(geom_f_a), len(geom_i_a), 0.0, np.zeros((capacity, 7)),
                       np.zeros(capacity, np.int64), 0)


def collide(shape_a: Shape, shape_b: Shape, *, position_a: ArrayLike = (0.0, 0.0, 0.0),
            orientation_a: ArrayLike = (1.0, 0.0, 0.0, 0.0), position_b: ArrayLike = (0.0, 0.0, 0.0),
            orientation_b: ArrayLike = (1.0, 0.0, 0.0, 0.0)) -> list[ContactPoint]:
    """Every contact point of ``shape_a`` and ``shape_b`` placed at the given poses.

    Positions in metres, orientations as (w, x, y, z) quaternions (normalised here).  Returns a list
    of :class:`ContactPoint` with ``depth >= 0`` (overlapping or touching), normals from a to b;
    ``[]`` when the shapes do not touch.  Static-only shapes (planes, height fields, meshes) are
    allowed; two static-only shapes report what their pair test reports (a plane pair: nothing).
    """
    _as_shape("shape_a", shape_a)
    _as_shape("shape_b", shape_b)
    pos_a = as_vec3("position_a", position_a)
    pos_b = as_vec3("position_b", position_b)
    rot_a = quat_to_matrix_np(as_quat("orientation_a", orientation_a))
    rot_b = quat_to_matrix_np(as_quat("orientation_b", orientation_b))
    capacity = 16
    while True:
        pair_test, arguments = pair_test_call(shape_a, shape_b, pos_a, rot_a, pos_b, rot_b, capacity)
        await_kernel(pair_test)
        n = pair_test(*arguments)
        if n <= capacity:
            break
        capacity = n
    out_f = arguments[-3]
    # "+ 0.0" turns the -0.0 of flipped normals into 0.0
    return [ContactPoint(out_f[k, 0:3] + 0.0, out_f[k, 3:6] + 0.0, float(out_f[k, 6]) + 0.0)
            for k in range(n) if out_f[k, 6] >= 0.0]
