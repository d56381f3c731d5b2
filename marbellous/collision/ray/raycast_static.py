"""Ray casts against static height fields and triangle meshes, through their acceleration.

The ray ``origin + t direction`` (world frame, unit direction, ``0 <= t <= max_distance``) is moved
into the shape's frame (``o = R^T (origin - pos)``, ``d = R^T direction``), walked through the
height field's cells, the mesh's 2D grid or BVH (or every triangle), and the nearest hit is
returned.  Triangles are hit from both sides; the reported normal is the face normal turned
against the ray.  Ties between triangles go to the lower triangle index, so every acceleration
gives the same answer.
"""
import math

from ..._numba.jit import njit
from .. import shape_types as st
from ..mesh import mesh_layout as ml
from ..mesh.bvh_static import bvh_raycast
from ..mesh.grid2d import grid_raycast
from ..mesh.heightfield_collide import cell_triangle, heightfield_raycast
from ..vec3 import dot, to_local, to_world
from .triangle_ray import ray_triangle


@njit
def _mesh_brute(geom_f, geom_i, off_f, off_i, n_tri, o, d, t_max):
    best_t, best_tri = math.inf, -1
    for t in range(n_tri):
        a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, t)
        if n[0] == 0.0 and n[1] == 0.0 and n[2] == 0.0:      # degenerate
            continue
        h = ray_triangle(o, d, a, b, c, t_max)
        if h < best_t:
            best_t, best_tri = h, t
    return best_t, best_tri


@njit
def raycast_static(type_b, pos_b, rot_b, params_b, geom_f, geom_i, off_f, off_i, origin, direction,
                   max_distance, out):
    """Nearest hit of a ray on the static shape b (HEIGHTFIELD or MESH).

    ``pos_b`` (3,), ``rot_b`` (3, 3): the shape's placement; ``origin`` (3,) m and ``direction``
    (3,) unit, world frame; ``max_distance`` m (may be inf).  On a hit writes ``out[0]`` distance
    (m), ``out[1:4]`` point, ``out[4:7]`` unit normal facing the ray, ``out[7]`` triangle index,
    and returns True; else returns False and leaves ``out`` alone.
    """
    o = to_local(rot_b, (origin[0] - pos_b[0], origin[1] - pos_b[1], origin[2] - pos_b[2]))
    d = to_local(rot_b, (direction[0], direction[1], direction[2]))
    if type_b == st.HEIGHTFIELD:
        t, tri = heightfield_raycast(params_b, geom_f, off_f, o, d, max_distance)
        if tri < 0:
            return False
        cell = tri // 2
        nz1 = int(params_b[6]) - 1
        a, b, c, n = cell_triangle(params_b, geom_f, off_f, cell // nz1, cell % nz1, tri % 2)
    else:
        accel = int(params_b[2])
        if accel == ml.ACCEL_GRID2D:
            t, tri = grid_raycast(params_b, geom_f, geom_i, off_f, off_i, o, d, max_distance)
        elif accel == ml.ACCEL_BVH:
            t, tri = bvh_raycast(geom_f, geom_i, off_f, off_i, o, d, max_distance)
        else:
            t, tri = _mesh_brute(geom_f, geom_i, off_f, off_i, int(params_b[1]), o, d, max_distance)
        if tri < 0:
            return False
        a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, tri)
    if dot(n, d) > 0.0:
        n = (-n[0], -n[1], -n[2])
    nw = to_world(rot_b, n)
    out[0] = t
    for k in range(3):
        out[1 + k] = origin[k] + t * direction[k]
        out[4 + k] = nw[k]
    out[7] = tri
    return True
