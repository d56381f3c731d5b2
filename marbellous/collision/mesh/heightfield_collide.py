"""Convex shape against a static height field, and the height field's triangles.

Kernel record (``HeightField._params()``)::

    [dx, dz, x0, y0, z0, nx, nz, 0]

``geom_f[off_f + i * nz + j]`` is the height above ``y0`` of grid point ``(i, j)`` at
``x = x0 + i dx``, ``z = z0 + j dz`` (the shape's frame); ``geom_i`` holds nothing.

Cell ``(i, j)`` (``0 <= i < nx - 1``, ``0 <= j < nz - 1``) is split along the diagonal from
``p00 = (i, j)`` to ``p11 = (i + 1, j + 1)`` into triangle 0 ``(p00, p11, p10)`` (where
``u >= w``, with ``u, w`` the cell coordinates along x and z) and triangle 1 ``(p00, p01, p11)``,
both wound so their normals point up.  Triangle ``k`` of cell ``(i, j)`` has index
``2 (i (nz - 1) + j) + k``.  ``HeightField.height_at``/``normal_at`` use the same triangles, so
queries and collisions see one surface.

A triangle is tested only if its bounding box overlaps the shape's, grown by the prediction, as in
``mesh_collide``.  The box's pair test is not exact beyond contact: its 13 axes may all show gaps
below the prediction while the closest points (vertex against edge) lie farther apart, and a box
buried under the surface then gets the one-sided face's push-out from a triangle wholly above it.
The bounding-box test, a necessary condition of a distance within the prediction, settles that
per triangle, so the contacts do not depend on which two triangles share a cell.

Ghost-free across cells: every edge's neighbour and every vertex's six ring neighbours follow from
the grid (``triangle_contact``).  Beyond the border the field is continued linearly
(``h(-1, j) = 2 h(0, j) - h(1, j)``), so a border edge is flat to its virtual neighbour and two
tiles that meet with matching heights and slopes have no seam.
"""
import math

import numpy as np

from ..._numba.jit import njit, njit_inline
from ..shape_types import BOX, HULL, SPHERE
from ..aabb import boxes_overlap, ray_span_xz
from ..ray.triangle_ray import ray_triangle
from ..triangle.triangle_contact import MAX_ROWS, N_COLS, SEEN_ROWS, edge_is_true, vertex_ring_passes
from ..hull.polytope import hull_polytope, no_polytope
from ..triangle.triangle_convex import convex_local_bounds, convex_triangle, emit_unique, to_static_frame
from ..triangle.triangle_sphere import EDGE_AB, EDGE_CA, VERTEX_A, VERTEX_C, sphere_triangle
from ..vec3 import cross, dot, matrix, sub

#: Grid offsets of the corners of triangle k of a cell: ``CORNERS[k][c] = (di, dj)``.
CORNERS = (((0, 0), (1, 1), (1, 0)), ((0, 0), (0, 1), (1, 1)))
#: Grid offsets of the vertex opposite each edge in the neighbouring triangle.
OPPOSITE = (((0, 1), (2, 1), (0, -1)), ((-1, 0), (1, 2), (1, 0)))
#: Grid offsets of a vertex's six ring neighbours.
RING = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1))


@njit
def grid_height(params, geom_f, off_f, i, j):
    """Height (m, above ``y0``) of grid point ``(i, j)``, continued linearly up to one point
    beyond each border."""
    nx, nz = int(params[5]), int(params[6])
    i0 = min(max(i, 0), nx - 1)
    j0 = min(max(j, 0), nz - 1)
    di, dj = i - i0, j - j0
    # Straight-line code (inside the grid di = dj = 0 and both terms add an exact 0): a branch here
    # would make Numba count the references of both arrays at every call, 4x the cost of the rest.
    h = geom_f[off_f + i0 * nz + j0]
    h += di * (h - geom_f[off_f + (i0 - di) * nz + j0])
    h += dj * (geom_f[off_f + i0 * nz + j0] - geom_f[off_f + i0 * nz + j0 - dj])
    return h


@njit
def grid_point(params, geom_f, off_f, i, j):
    """Position (3-tuple, m, shape frame) of grid point ``(i, j)``."""
    return (params[2] + i * params[0], params[3] + grid_height(params, geom_f, off_f, i, j),
            params[4] + j * params[1])


@njit
def cell_triangle(params, geom_f, off_f, i, j, k):
    """Corners ``(a, b, c)`` and unit normal of triangle ``k`` of cell ``(i, j)``."""
    ca = CORNERS[k]
    a = grid_point(params, geom_f, off_f, i + ca[0][0], j + ca[0][1])
    b = grid_point(params, geom_f, off_f, i + ca[1][0], j + ca[1][1])
    c = grid_point(params, geom_f, off_f, i + ca[2][0], j + ca[2][1])
    cr = cross(sub(b, a), sub(c, a))
    length = math.sqrt(dot(cr, cr))
    return a, b, c, (cr[0] / length, cr[1] / length, cr[2] / length)


@njit
def _away(u, w, o):
    """Unit direction, perpendicular to edge ``u w``, from the edge towards ``o``."""
    d = sub(w, u)
    ld = math.sqrt(dot(d, d))
    d = (d[0] / ld, d[1] / ld, d[2] / ld)
    v = sub(o, u)
    s = dot(v, d)
    m = (v[0] - s * d[0], v[1] - s * d[1], v[2] - s * d[2])
    lm = math.sqrt(dot(m, m))
    return (m[0] / lm, m[1] / lm, m[2] / lm)


@njit
def neighbour_direction(params, geom_f, off_f, i, j, k, e, u, w):
    """``m2`` of edge ``e`` (from corner ``u`` to ``w``) of triangle ``k`` of cell ``(i, j)``."""
    op = OPPOSITE[k][e]
    return _away(u, w, grid_point(params, geom_f, off_f, i + op[0], j + op[1]))


@njit
def heightfield_vertex_is_true(params, geom_f, off_f, i, j, p):
    """Vertex Voronoi test at grid point ``(i, j)`` against its six ring neighbours."""
    v = grid_point(params, geom_f, off_f, i, j)
    for r in range(6):
        w = grid_point(params, geom_f, off_f, i + RING[r][0], j + RING[r][1])
        if not vertex_ring_passes(p, v, w):
            return False
    return True


@njit
def _cell_index(v, origin, step, cells):
    return min(max(int(math.floor((v - origin) / step)), 0), cells - 1)


@njit
def collide_convex_heightfield(type_a, pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, geom_i,
                               off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of convex shape a (SPHERE, CAPSULE or BOX) with the static height field b.

    Arguments and buffer convention as ``mesh_collide.collide_convex_mesh``; contacts are in
    ascending triangle order with feature id ``triangle * 16 + code``, bit-for-bit repeats once.
    """
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    return _convex_heightfield(type_a, c, rot, params_a, no_polytope(), pos_b, rot_b, params_b, geom_f, off_f_b,
                               prediction, out_f, out_i, n)


@njit
def collide_sphere_heightfield(pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, off_f_b, prediction, out_f,
                               out_i, n):
    """:func:`collide_convex_heightfield` of a sphere, compiled with the sphere's triangle test alone."""
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    return _convex_heightfield(SPHERE, c, rot, params_a, no_polytope(), pos_b, rot_b, params_b, geom_f, off_f_b,
                               prediction, out_f, out_i, n)


@njit
def collide_hull_heightfield(pos_a, rot_a, params_a, off_f_a, off_i_a, pos_b, rot_b, params_b, geom_f, geom_i,
                             off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of the convex hull a (its blob slices at ``off_f_a``/``off_i_a``) with the static height
    field b; arguments otherwise as :func:`collide_convex_heightfield`."""
    c, rot = to_static_frame(pos_a, rot_a, pos_b, rot_b)
    poly = hull_polytope(c, rot, geom_f, geom_i, off_f_a, off_i_a)
    return _convex_heightfield(HULL, c, rot, params_a, poly, pos_b, rot_b, params_b, geom_f, off_f_b,
                               prediction, out_f, out_i, n)


@njit_inline
def _convex_heightfield(type_a, c, rot, params_a, poly, pos_b, rot_b, params_b, geom_f, off_f_b, prediction,
                        out_f, out_i, n):
    """Contacts of convex shape a (centre ``c`` and rotation ``rot`` in b's frame, a hull placed there as
    ``poly``) with the static height field b (inlined: each caller compiles its own kinds of ``type_a``)."""
    dx, dz, x0, y0, z0 = params_b[0], params_b[1], params_b[2], params_b[3], params_b[4]
    nx, nz = int(params_b[5]), int(params_b[6])
    lo, hi = convex_local_bounds(type_a, c, rot, params_a, prediction)
    if hi[0] < x0 or hi[2] < z0 or lo[0] > x0 + (nx - 1) * dx or lo[2] > z0 + (nz - 1) * dz:
        return n
    i0 = _cell_index(lo[0], x0, dx, nx - 1)
    i1 = _cell_index(hi[0], x0, dx, nx - 1)
    j0 = _cell_index(lo[2], z0, dz, nz - 1)
    j1 = _cell_index(hi[2], z0, dz, nz - 1)
    scratch = np.empty((MAX_ROWS, N_COLS))
    seen = np.empty((SEEN_ROWS, 7))
    n_seen = 0
    m_b = matrix(rot_b)
    for i in range(i0, i1 + 1):
        for j in range(j0, j1 + 1):
            h00 = geom_f[off_f_b + i * nz + j]
            h10 = geom_f[off_f_b + (i + 1) * nz + j]
            h01 = geom_f[off_f_b + i * nz + j + 1]
            h11 = geom_f[off_f_b + (i + 1) * nz + j + 1]
            if y0 + max(max(h00, h10), max(h01, h11)) < lo[1] or y0 + min(min(h00, h10), min(h01, h11)) > hi[1]:
                continue
            for k in range(2):
                a, b, cc, nrm = cell_triangle(params_b, geom_f, off_f_b, i, j, k)
                if not boxes_overlap(a, b, cc, lo, hi):
                    continue                          # too far: the cell's box overlaps, not this triangle's
                if type_a == SPHERE and sphere_triangle(c, params_a[0], a, b, cc, nrm, prediction)[0] < 0:
                    continue                          # missed: decided by values alone (no array call)
                m0 = m1 = m2 = (0.0, 0.0, 0.0)
                if type_a == BOX or type_a == HULL:
                    m0 = neighbour_direction(params_b, geom_f, off_f_b, i, j, k, 0, a, b)
                    m1 = neighbour_direction(params_b, geom_f, off_f_b, i, j, k, 1, b, cc)
                    m2 = neighbour_direction(params_b, geom_f, off_f_b, i, j, k, 2, cc, a)
                rows = convex_triangle(type_a, c, rot, params_a, poly, a, b, cc, nrm, m0, m1, m2, prediction,
                                       scratch)
                t = 2 * (i * (nz - 1) + j) + k
                for r in range(rows):
                    f = int(scratch[r, 7])
                    p = (scratch[r, 8], scratch[r, 9], scratch[r, 10])
                    if EDGE_AB <= f <= EDGE_CA:
                        e = f - EDGE_AB
                        u, w = (a, b) if e == 0 else ((b, cc) if e == 1 else (cc, a))
                        if not edge_is_true(p, (scratch[r, 0], scratch[r, 1], scratch[r, 2]),
                                            neighbour_direction(params_b, geom_f, off_f_b, i, j, k, e, u, w)):
                            continue
                    elif VERTEX_A <= f <= VERTEX_C:
                        corner = CORNERS[k][f - VERTEX_A]
                        if not heightfield_vertex_is_true(params_b, geom_f, off_f_b, i + corner[0],
                                                          j + corner[1], p):
                            continue
                    n, n_seen = emit_unique(scratch, r, pos_b, m_b, t, seen, n_seen, out_f, out_i, n)
    return n


@njit
def heightfield_raycast(params, geom_f, off_f, o, d, t_max):
    """Nearest triangle hit by the ray ``o + t d`` (shape frame): ``(t, triangle)`` or ``(inf, -1)``.

    Walks the cells under the ray's x-z projection (2D DDA) and stops once the best hit lies
    before the current cell's exit; ties go to the lower triangle index.
    """
    dx, dz, x0, z0 = params[0], params[1], params[2], params[4]
    nx, nz = int(params[5]), int(params[6])
    x1, z1 = x0 + (nx - 1) * dx, z0 + (nz - 1) * dz
    t0, t1 = ray_span_xz(o, d, t_max, x0, x1, z0, z1)
    if t0 > t1:
        return math.inf, -1
    i = _cell_index(o[0] + t0 * d[0], x0, dx, nx - 1)
    j = _cell_index(o[2] + t0 * d[2], z0, dz, nz - 1)
    si = 1 if d[0] > 0.0 else -1
    sj = 1 if d[2] > 0.0 else -1
    tni = (x0 + (i + (1 if si > 0 else 0)) * dx - o[0]) / d[0] if d[0] != 0.0 else math.inf
    tnj = (z0 + (j + (1 if sj > 0 else 0)) * dz - o[2]) / d[2] if d[2] != 0.0 else math.inf
    dti = dx / abs(d[0]) if d[0] != 0.0 else math.inf
    dtj = dz / abs(d[2]) if d[2] != 0.0 else math.inf
    best_t, best_tri = math.inf, -1
    while True:
        for k in range(2):
            a, b, c, nrm = cell_triangle(params, geom_f, off_f, i, j, k)
            h = ray_triangle(o, d, a, b, c, t_max)
            t = 2 * (i * (nz - 1) + j) + k
            if h < best_t or (h == best_t and h < math.inf and t < best_tri):
                best_t, best_tri = h, t
        exit_t = min(tni, tnj)
        if best_t <= exit_t or exit_t > t1:
            break
        if tni < tnj:
            i += si
            tni += dti
        else:
            j += sj
            tnj += dtj
        if i < 0 or i >= nx - 1 or j < 0 or j >= nz - 1:
            break
    return best_t, best_tri
