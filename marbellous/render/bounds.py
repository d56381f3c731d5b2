"""Axis-aligned bounds of a world's shapes, and points outlining a world, for framing the camera.

Infinite planes have no bounds and are left out; every other shape is bounded exactly (spheres,
boxes, capsules) or by the rotated box of its local bounds (height fields, triangle meshes).
"""
import numpy as np

from ..shapes.primitives import Box, Capsule, Plane, Sphere
from .transforms import quat_to_matrix


def shape_bounds(shape, position, rotation):
    """``(lo, hi)`` corners (m) of ``shape`` placed at ``position`` (m) with ``rotation`` (3, 3), or None
    for a plane."""
    if isinstance(shape, Plane):
        return None
    if isinstance(shape, Sphere):
        half = np.full(3, shape.radius)
    elif isinstance(shape, Box):
        half = np.abs(rotation) @ shape.half_extents
    elif isinstance(shape, Capsule):
        half = np.abs(rotation[:, 1]) * shape.half_height + shape.radius
    else:   # HeightField, TriangleMesh: the rotated box of the local bounds
        lo, hi = shape.local_aabb()
        centre = rotation @ (0.5 * (lo + hi)) + position
        half = np.abs(rotation) @ (0.5 * (hi - lo))
        return centre - half, centre + half
    return position - half, position + half


def world_points(world):
    """Points (K, 3) (m) that outline ``world``: the corners of the bounds of every bounded shape of its
    bodies, and the fixed world anchors of its constraints."""
    boxes = []
    for b in world.bodies:
        rot = quat_to_matrix(b.orientation)
        pos = b.position
        for shape, local_pos, local_quat in b.shapes:
            box = shape_bounds(shape, pos + rot @ local_pos, rot @ quat_to_matrix(local_quat))
            if box is not None:
                boxes.append(box)
    anchors = np.array([c.anchor_b for c in world.constraints if c.body_b is None]).reshape(-1, 3)
    if not boxes:
        return anchors
    lo, hi = (np.array(c) for c in zip(*boxes))
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1
    return np.concatenate([np.where(bits[None], hi[:, None, :], lo[:, None, :]).reshape(-1, 3), anchors])
