"""Layout of a triangle mesh's kernel record and of its slices of the geometry blobs.

``params`` (``N_SHAPE_PARAMS`` floats)::

    [n_vertices, n_triangles, accel, grid_x0, grid_z0, grid_cell, grid_nx, grid_nz]

``accel`` is ``ACCEL_BRUTE``, ``ACCEL_GRID2D`` or ``ACCEL_BVH``; the grid fields (m, m, m, counts)
describe the 2D grid over the mesh's local x-z plane (zero unless ``accel`` is the grid).

``geom_i[off_i : off_i + HEADER]`` holds the offsets (relative to ``off_i`` / ``off_f``) of every
section; a section that the chosen accel does not use is empty:

=================  =====  ==================================================================
section            blob   content
=================  =====  ==================================================================
``I_TRIS``         int    (T, 3) vertex indices, counter-clockwise seen from the front
``I_WELD``         int    (V,) welded id of each vertex
``I_RING_START``   int    (W + 1,) CSR start of each welded vertex's ring
``I_RING``         int    ring members (vertex indices)
``I_CELL_START``   int    (nx * nz + 1,) CSR start of each grid cell (cell ``iz * nx + ix``)
``I_CELL_TRIS``    int    triangle indices of each cell, ascending
``I_FAT_START``    int    (nx * nz + 1,) CSR start of each grid cell grown by ``grid2d.FAT_MARGIN`` cells
``I_FAT_TRIS``     int    triangle indices of each grown cell, ascending
``I_ORDER``        int    (T,) triangle indices in BVH leaf order
``I_N_NODES``      int    the number N of BVH nodes (not an offset)
``F_VERTS``        float  (V, 3) vertex positions in the mesh's frame, m
``F_TRIS``         float  (T, 12) per triangle ``[a, b, c, n]``: corners (m) and unit normal,
                          together so one query touches few cache lines; a degenerate
                          triangle has ``n = 0`` (and is in neither grid nor BVH)
``F_M2``           float  (T, 3, 3) neighbour's in-plane direction away from each edge
``F_NODES``        float  (N, 8) BVH nodes ``[min xyz, max xyz, first, count]``: a leaf has
                          ``count > 0`` triangles at ``order[first:]``; an inner node has
                          ``count = 0`` and children ``first`` and ``first + 1``
=================  =====  ==================================================================
"""
from ..._numba.jit import njit

ACCEL_BRUTE = 0
ACCEL_GRID2D = 1
ACCEL_BVH = 2
ACCELS = ("brute", "grid2d", "bvh")

I_TRIS = 0
I_WELD = 1
I_RING_START = 2
I_RING = 3
I_CELL_START = 4
I_CELL_TRIS = 5
I_ORDER = 6
I_N_NODES = 7
F_VERTS = 8
F_TRIS = 9
F_M2 = 10
F_NODES = 11
I_FAT_START = 12
I_FAT_TRIS = 13
HEADER = 14
#: Floats per triangle record and per BVH node record.
TRI_RECORD = 12
NODE_RECORD = 8


@njit
def vertex(geom_f, geom_i, off_f, off_i, v):
    """Position (3-tuple, m) of vertex ``v`` in the mesh's frame."""
    o = off_f + geom_i[off_i + F_VERTS] + 3 * v
    return (geom_f[o], geom_f[o + 1], geom_f[o + 2])


@njit
def corners(geom_f, geom_i, off_f, off_i, t):
    """Vertex indices ``(ia, ib, ic)`` of triangle ``t``."""
    o = off_i + geom_i[off_i + I_TRIS] + 3 * t
    return geom_i[o], geom_i[o + 1], geom_i[o + 2]


@njit
def triangle(geom_f, geom_i, off_f, off_i, t):
    """Corners ``a, b, c`` and unit normal ``n`` (3-tuples) of triangle ``t`` (``n = 0``: degenerate)."""
    o = off_f + geom_i[off_i + F_TRIS] + TRI_RECORD * t
    return ((geom_f[o], geom_f[o + 1], geom_f[o + 2]), (geom_f[o + 3], geom_f[o + 4], geom_f[o + 5]),
            (geom_f[o + 6], geom_f[o + 7], geom_f[o + 8]), (geom_f[o + 9], geom_f[o + 10], geom_f[o + 11]))


@njit
def neighbour_direction(geom_f, geom_i, off_f, off_i, t, k):
    """``m2`` of edge ``k`` of triangle ``t`` (see ``triangle_contact``)."""
    o = off_f + geom_i[off_i + F_M2] + 9 * t + 3 * k
    return (geom_f[o], geom_f[o + 1], geom_f[o + 2])
