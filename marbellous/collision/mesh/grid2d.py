"""The lecture's 2D grid over a level mesh: triangles rasterised into x-z cells.

A level has no (or few) overhangs and the marble stays near the surface, so looked at from above
only the triangles in the marble's 2D cells can touch it.  The grid has ``nx * nz`` square cells
of side ``cell`` (m) from ``(x0, z0)`` in the mesh's frame; cell ``(ix, iz)`` is number
``iz * nx + ix``.  Each cell keeps only triangle indices (the vertex and index buffers are reused),
in CSR form: ``cell_start`` (ncells + 1) and ``cell_tris`` (ascending in each cell).

Rasterisation (the lecture's variant of scanline filling for big cells): for each row of cells
the triangle's x extent is the minimum and maximum of the x where its edges cross the row's two
grid lines and of its corners inside the row; every cell between them gets the triangle.  Extents
are widened by ``PAD`` cells so rounding never loses a triangle (extra candidates cost only time).

Each cell also keeps a second, *grown* list: the triangles that come within ``FAT_MARGIN`` cells of
it (the same rasterisation with the rows and extents widened by the margin ``d``).  A triangle that
meets a box whose centre lies in cell ``k`` and which reaches at most ``d`` beyond that cell on each
side is in cell ``k``'s grown list, because every point of the box lies in the cell grown by ``d``.

Queries: a shape's x-z bounding box that fits its centre's grown cell takes that one list as it is
(ascending, no repeats: the marble's case, with no merging at all).  A larger box gives a rectangle of
cells, whose lists are merged into one ascending, duplicate-free candidate list.  A ray walks the cells
it crosses (2D DDA) through the plain lists.
"""
import math

import numpy as np

from ..._numba.jit import njit
from ..aabb import ray_span_xz
from ..ray.triangle_ray import ray_triangle
from . import mesh_layout as ml

#: Query rectangles of up to this many cells merge their sorted lists; larger ones gather and sort.
MERGE_CELLS = 16
#: Margin of the grown cell lists, in cells: a query box reaching at most this far beyond its centre's
#: cell reads that cell's grown list alone.
FAT_MARGIN = 0.5
#: Next-triangle mark of a used-up cell list in the merge (above every triangle index).
ENDED = np.iinfo(np.int64).max
#: Widening of every rasterised extent, as a fraction of a cell (rounding allowance).
PAD = 1e-9


@njit
def _row_extent(ax, az, bx, bz, cx, cz, z_lo, z_hi):
    """x extent ``(xmin, xmax)`` of triangle (a, b, c) projected to x-z, within ``z_lo <= z <= z_hi``."""
    xmin = math.inf
    xmax = -math.inf
    px = (ax, bx, cx)
    pz = (az, bz, cz)
    for i in range(3):
        if z_lo <= pz[i] <= z_hi:
            xmin = min(xmin, px[i])
            xmax = max(xmax, px[i])
        j = (i + 1) % 3
        for zl in (z_lo, z_hi):
            if (pz[i] - zl) * (pz[j] - zl) < 0.0:
                x = px[i] + (zl - pz[i]) / (pz[j] - pz[i]) * (px[j] - px[i])
                xmin = min(xmin, x)
                xmax = max(xmax, x)
    return xmin, xmax


@njit
def _cell_range(v, origin, cell, count):
    """Clamped cell index of coordinate ``v``."""
    i = int(math.floor((v - origin) / cell))
    return min(max(i, 0), count - 1)


@njit
def _rasterise(verts, tris, degenerate, x0, z0, cell, nx, nz, margin, cell_start, cell_tris, fill):
    """Count (``fill`` False: into ``cell_start[1:]``) or write (``fill`` True) each triangle's cells,
    every cell grown by ``margin`` (m) on each side."""
    pad = PAD * cell + margin
    cursor = cell_start.copy()
    for t in range(tris.shape[0]):
        if degenerate[t]:
            continue
        a, b, c = tris[t, 0], tris[t, 1], tris[t, 2]
        ax, az = verts[a, 0], verts[a, 2]
        bx, bz = verts[b, 0], verts[b, 2]
        cx, cz = verts[c, 0], verts[c, 2]
        zmin = min(az, min(bz, cz))
        zmax = max(az, max(bz, cz))
        r0 = _cell_range(zmin - pad, z0, cell, nz)
        r1 = _cell_range(zmax + pad, z0, cell, nz)
        for r in range(r0, r1 + 1):
            z_lo = max(zmin, z0 + r * cell - pad)
            z_hi = min(zmax, z0 + (r + 1) * cell + pad)
            xl, xr = _row_extent(ax, az, bx, bz, cx, cz, z_lo, z_hi)
            if xl > xr:
                continue
            c0 = _cell_range(xl - pad, x0, cell, nx)
            c1 = _cell_range(xr + pad, x0, cell, nx)
            for col in range(c0, c1 + 1):
                k = r * nx + col
                if fill:
                    cell_tris[cursor[k]] = t
                    cursor[k] += 1
                else:
                    cell_start[k + 1] += 1


@njit
def build_grid(verts, tris, degenerate, x0, z0, cell, nx, nz, margin):
    """CSR cell lists ``(cell_start, cell_tris)`` of the grid, each cell grown by ``margin`` (m; 0 for
    the plain lists); triangles ascending in each cell."""
    cell_start = np.zeros(nx * nz + 1, np.int64)
    dummy = np.zeros(0, np.int64)
    _rasterise(verts, tris, degenerate, x0, z0, cell, nx, nz, margin, cell_start, dummy, False)
    for k in range(nx * nz):
        cell_start[k + 1] += cell_start[k]
    cell_tris = np.empty(cell_start[nx * nz], np.int64)
    _rasterise(verts, tris, degenerate, x0, z0, cell, nx, nz, margin, cell_start, cell_tris, True)
    return cell_start, cell_tris


@njit
def sorted_unique(buf, count):
    """Sort ``buf[:count]`` in place (insertion sort for short lists) and drop repeats; new count."""
    if count > 32:
        buf[:count] = np.sort(buf[:count])
    else:
        for i in range(1, count):
            x = buf[i]
            j = i - 1
            while j >= 0 and buf[j] > x:
                buf[j + 1] = buf[j]
                j -= 1
            buf[j + 1] = x
    m = 0
    for i in range(count):
        if m == 0 or buf[i] != buf[m - 1]:
            buf[m] = buf[i]
            m += 1
    return m


@njit
def grid_candidates(params, geom_i, off_i, lo, hi):
    """Ascending, duplicate-free triangle indices of the cells under the x-z box ``lo..hi``.

    Returns ``(array, first, count)``: the candidates are ``array[first:first + count]``.
    """
    x0, z0, cell = params[3], params[4], params[5]
    nx, nz = int(params[6]), int(params[7])
    if hi[0] < x0 or hi[2] < z0 or lo[0] > x0 + nx * cell or lo[2] > z0 + nz * cell:
        return geom_i, 0, 0
    # the box inside its centre's cell grown by the margin: that cell's grown list holds every candidate
    ix = _cell_range(0.5 * (lo[0] + hi[0]), x0, cell, nx)
    iz = _cell_range(0.5 * (lo[2] + hi[2]), z0, cell, nz)
    margin = FAT_MARGIN * cell
    if (lo[0] >= x0 + ix * cell - margin and hi[0] <= x0 + (ix + 1) * cell + margin
            and lo[2] >= z0 + iz * cell - margin and hi[2] <= z0 + (iz + 1) * cell + margin):
        k = off_i + geom_i[off_i + ml.I_FAT_START] + iz * nx + ix
        first = geom_i[k]
        return geom_i, off_i + geom_i[off_i + ml.I_FAT_TRIS] + first, geom_i[k + 1] - first
    c0 = _cell_range(lo[0], x0, cell, nx)
    c1 = _cell_range(hi[0], x0, cell, nx)
    r0 = _cell_range(lo[2], z0, cell, nz)
    r1 = _cell_range(hi[2], z0, cell, nz)
    starts = off_i + geom_i[off_i + ml.I_CELL_START]
    tris = off_i + geom_i[off_i + ml.I_CELL_TRIS]
    rows = r1 - r0 + 1
    cols = c1 - c0 + 1
    total = 0
    for r in range(r0, r1 + 1):
        total += geom_i[starts + r * nx + c1 + 1] - geom_i[starts + r * nx + c0]
    buf = np.empty(total, np.int64)
    if rows * cols > MERGE_CELLS:
        m = 0
        for r in range(r0, r1 + 1):
            for k in range(geom_i[starts + r * nx + c0], geom_i[starts + r * nx + c1 + 1]):
                buf[m] = geom_i[tris + k]
                m += 1
        return buf, 0, sorted_unique(buf, m)
    # k-way merge of the (ascending) cell lists, dropping repeats; each list's next triangle is kept in
    # ``lists[0]`` (ENDED once the list is used up), its read position in ``lists[1]``, its end in ``lists[2]``
    lists = np.empty((3, MERGE_CELLS), np.int64)
    k = 0
    for r in range(r0, r1 + 1):
        for col in range(c0, c1 + 1):
            first, stop = geom_i[starts + r * nx + col], geom_i[starts + r * nx + col + 1]
            lists[0, k] = geom_i[tris + first] if first < stop else ENDED
            lists[1, k] = first
            lists[2, k] = stop
            k += 1
    m = 0
    while True:
        best = 0
        for q in range(1, k):
            if lists[0, q] < lists[0, best]:
                best = q
        low = lists[0, best]
        if low == ENDED:
            return buf, 0, m
        if m == 0 or buf[m - 1] != low:
            buf[m] = low
            m += 1
        nxt = lists[1, best] + 1
        lists[1, best] = nxt
        lists[0, best] = geom_i[tris + nxt] if nxt < lists[2, best] else ENDED


@njit
def _test_cell(geom_f, geom_i, off_f, off_i, k, o, d, t_max, best_t, best_tri):
    """Nearest hit among cell ``k``'s triangles, ties to the lower triangle index."""
    starts = off_i + geom_i[off_i + ml.I_CELL_START]
    tris = off_i + geom_i[off_i + ml.I_CELL_TRIS]
    for j in range(geom_i[starts + k], geom_i[starts + k + 1]):
        t = geom_i[tris + j]
        a, b, c, n = ml.triangle(geom_f, geom_i, off_f, off_i, t)
        h = ray_triangle(o, d, a, b, c, t_max)
        if h < best_t or (h == best_t and h < math.inf and t < best_tri):
            best_t = h
            best_tri = t
    return best_t, best_tri


@njit
def grid_raycast(params, geom_f, geom_i, off_f, off_i, o, d, t_max):
    """Nearest triangle hit by the ray ``o + t d`` (t <= ``t_max``): ``(t, triangle)`` or ``(inf, -1)``.

    Walks the cells under the ray's x-z projection in order (Amanatides-Woo) and stops once the
    best hit lies before the current cell's exit: a nearer hit would be in a cell already visited.
    """
    x0, z0, cell = params[3], params[4], params[5]
    nx, nz = int(params[6]), int(params[7])
    x1, z1 = x0 + nx * cell, z0 + nz * cell
    t0, t1 = ray_span_xz(o, d, t_max, x0, x1, z0, z1)
    if t0 > t1:
        return math.inf, -1
    ix = _cell_range(o[0] + t0 * d[0], x0, cell, nx)
    iz = _cell_range(o[2] + t0 * d[2], z0, cell, nz)
    sx = 1 if d[0] > 0.0 else -1
    sz = 1 if d[2] > 0.0 else -1
    tnx = (x0 + (ix + (1 if sx > 0 else 0)) * cell - o[0]) / d[0] if d[0] != 0.0 else math.inf
    tnz = (z0 + (iz + (1 if sz > 0 else 0)) * cell - o[2]) / d[2] if d[2] != 0.0 else math.inf
    dtx = cell / abs(d[0]) if d[0] != 0.0 else math.inf
    dtz = cell / abs(d[2]) if d[2] != 0.0 else math.inf
    best_t, best_tri = math.inf, -1
    while True:
        best_t, best_tri = _test_cell(geom_f, geom_i, off_f, off_i, iz * nx + ix, o, d, t_max,
                                      best_t, best_tri)
        exit_t = min(tnx, tnz)
        if best_t <= exit_t or exit_t > t1:
            break
        if tnx < tnz:
            ix += sx
            tnx += dtx
        else:
            iz += sz
            tnz += dtz
        if ix < 0 or ix >= nx or iz < 0 or iz >= nz:
            break
    return best_t, best_tri
