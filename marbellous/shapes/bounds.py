"""World bounding boxes of static bodies, computed once when they are added (they never move).

A shape with a local box (height fields, meshes) is bounded by its eight corners placed in the world;
a primitive by ``collision.aabb.shape_aabb``; a plane is unbounded (an infinite box).
"""
import numpy as np

from ..collision.aabb import shape_aabb
from ..math3d import quat_to_matrix_np


def static_body_box(parts, position, orientation):
    """World AABB ``[minx, miny, minz, maxx, maxy, maxz]`` (m) of a static body's ``parts`` ((shape, local
    position, local orientation) tuples) at ``position`` (m) and ``orientation`` (unit quaternion)."""
    r_body = quat_to_matrix_np(orientation)
    box = np.array([np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf])
    for s, p, q in parts:
        rot = r_body @ quat_to_matrix_np(q)
        centre = position + r_body @ p
        part = np.empty(6)
        if hasattr(s, "local_aabb"):
            lo, hi = s.local_aabb()
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            world = corners @ rot.T + centre
            part[:3], part[3:] = world.min(axis=0), world.max(axis=0)
        else:
            shape_aabb(s._type, centre, rot, s._params(), part)
        box[:3] = np.minimum(box[:3], part[:3])
        box[3:] = np.maximum(box[3:], part[3:])
    return box
