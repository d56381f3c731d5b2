"""Points that outline a world's bodies, particles and cloths, for framing the camera.

A sphere, box or capsule is outlined by the corners of its box (exact for boxes), a triangle mesh by
its vertices and a height field by its grid points, so a large ramp or terrain frames by its surface
rather than by its box; infinite planes have no outline and are left out.  A particle, and a cloth's
vertex (a sphere of half the cloth's thickness), is outlined by the corners of its box.
"""
import numpy as np

from ..shapes.heightfield import HeightField
from ..shapes.mesh import TriangleMesh
from ..shapes.hull import ConvexHull
from ..constraints import Constraint
from ..shapes.primitives import Box, Capsule, Plane, Sphere
from .transforms import quat_to_matrix
from .world_internals import particle_table

_CORNER_SIGNS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def shape_points(shape, position, rotation):
    """Points (K, 3) (m) whose bounding box is that of ``shape`` placed at ``position`` (m) with
    ``rotation`` (3, 3); none for a plane."""
    if isinstance(shape, Plane):
        return np.zeros((0, 3))
    if isinstance(shape, (TriangleMesh, ConvexHull)):
        return shape.vertices @ rotation.T + position
    if isinstance(shape, HeightField):
        nx, nz = shape.heights.shape
        i, j = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
        local = np.stack([i * shape.dx, shape.heights, j * shape.dz], axis=-1).reshape(-1, 3) + shape.origin
        return local @ rotation.T + position
    if isinstance(shape, Sphere):
        half = np.full(3, shape.radius)
    elif isinstance(shape, Box):
        half = np.abs(rotation) @ shape.half_extents
    elif isinstance(shape, Capsule):
        half = np.abs(rotation[:, 1]) * shape.half_height + shape.radius
    else:
        raise TypeError(f"shape must be a Sphere, Box, Capsule, ConvexHull, Plane, HeightField or TriangleMesh, "
                        f"got {shape!r}")
    return position + _CORNER_SIGNS * half


def _sphere_corners(centers, radii):
    """The corners (8 N, 3) (m) of the boxes of the spheres at ``centers`` (N, 3) (m) of ``radii`` (N,) (m)."""
    return (centers[:, None, :] + _CORNER_SIGNS[None] * np.reshape(radii, (-1, 1, 1))).reshape(-1, 3)


def world_points(world):
    """Points (K, 3) (m) that outline ``world``: those of every shape of its bodies
    (:func:`shape_points`), the fixed world anchors of its constraints, and the corners of the box of every
    particle, of every cloth's vertex and of every soft body's node, and of every fluid's box."""
    parts = []
    for b in world.bodies:
        rot = quat_to_matrix(b.orientation)
        pos = b.position
        for shape, local_pos, local_quat in b.shapes:
            parts.append(shape_points(shape, pos + rot @ local_pos, rot @ quat_to_matrix(local_quat)))
    parts.append(np.array([c.anchor_b for c in world.constraints
                           if isinstance(c, Constraint) and c.body_b is None]).reshape(-1, 3))
    centers, radii, _ = particle_table(world)
    parts.append(_sphere_corners(centers, radii))
    for cloth in world.cloths:
        x = cloth.positions
        parts.append(_sphere_corners(x, np.full(len(x), 0.5 * cloth.thickness)))
    for body in world.soft_bodies:
        x = body.positions
        parts.append(_sphere_corners(x, np.full(len(x), body.radius)))
    for fluid in world.fluids:
        half = 0.5 * fluid.size
        parts.append(fluid.origin + half + _CORNER_SIGNS * half)
    return np.concatenate(parts)
