"""The staggered (MAC) grid: where each quantity lives, its values beyond the boundary, and interpolation.

The fluid box is ``n = (nx, ny, nz)`` cubic cells of side ``h`` (a 2D fluid is one cell deep and periodic in z,
so every z difference vanishes).  Pressure and dye live at cell centres; velocity component ``c`` lives on the
faces normal to axis ``c``: ``q[c, i, j, k]`` is the flow through the *lower* face of cell ``(i, j, k)`` along
``c`` (for ``c = 0`` the face at ``x = i h``).  A periodic axis of ``n`` cells has ``n`` faces (face ``n`` is
face ``0``); a walled axis has ``n + 1``, of which face ``0`` is stored (and held at zero) and face ``n`` is not
(the wall lets nothing through).  Positions below are in cells, measured from the box's lower corner.

A velocity component tangential to a wall is extended beyond it by a ghost value that puts the wall's own
velocity exactly on the wall (no slip, or a sliding lid):

    q_ghost = 2 U_wall - q_inside

``wall`` (6 x 3, m/s) holds the velocity of the sides x-, x+, y-, y+, z-, z+.
"""
import math

from .._numba.jit import njit, njit_inline


@njit
def tangential_index(index, count, periodic, wall_low, wall_high, offset, sign):
    """Fold ``index`` (-1 .. count) of an axis tangential to the component into the stored range: returns the
    index and the ghost value's ``offset + sign * q`` bookkeeping (unchanged inside the box)."""
    if periodic:
        return index % count, offset, sign
    if index < 0:
        return 0, offset + sign * 2.0 * wall_low, -sign
    if index >= count:
        return count - 1, offset + sign * 2.0 * wall_high, -sign
    return index, offset, sign


@njit
def face_value(q, c, i, j, k, n, periodic, wall):
    """Velocity component ``c`` (m/s) on face ``(i, j, k)`` of its grid, with the walls' ghost values: along
    axis ``c`` the index may run 0 .. n (the far wall), across it -1 .. n."""
    offset = 0.0
    sign = 1.0
    inside = True
    if c == 0:
        if periodic[0]:
            i = i % n[0]
        elif i <= 0 or i >= n[0]:
            inside = False
        j, offset, sign = tangential_index(j, n[1], periodic[1], wall[2, 0], wall[3, 0], offset, sign)
        k, offset, sign = tangential_index(k, n[2], periodic[2], wall[4, 0], wall[5, 0], offset, sign)
    elif c == 1:
        if periodic[1]:
            j = j % n[1]
        elif j <= 0 or j >= n[1]:
            inside = False
        i, offset, sign = tangential_index(i, n[0], periodic[0], wall[0, 1], wall[1, 1], offset, sign)
        k, offset, sign = tangential_index(k, n[2], periodic[2], wall[4, 1], wall[5, 1], offset, sign)
    else:
        if periodic[2]:
            k = k % n[2]
        elif k <= 0 or k >= n[2]:
            inside = False
        i, offset, sign = tangential_index(i, n[0], periodic[0], wall[0, 2], wall[1, 2], offset, sign)
        j, offset, sign = tangential_index(j, n[1], periodic[1], wall[2, 2], wall[3, 2], offset, sign)
    if not inside:
        return offset
    return offset + sign * q[c, i, j, k]


@njit
def cell_value(s, i, j, k, n, periodic):
    """A cell-centred value beyond the box: periodic axes wrap, walls repeat the nearest cell (no flux)."""
    i = i % n[0] if periodic[0] else min(max(i, 0), n[0] - 1)
    j = j % n[1] if periodic[1] else min(max(j, 0), n[1] - 1)
    k = k % n[2] if periodic[2] else min(max(k, 0), n[2] - 1)
    return s[i, j, k]


@njit
def pad_faces(q, n, periodic, wall, dims, out):
    """``out[c, i + 1, j + 1, k + 1]`` = :func:`face_value` of ``q`` for i in -1 .. n (likewise j, k): the
    faces with one layer of ghosts around them, shape (3, nx + 2, ny + 2, nz + 2), so that interpolation
    reads them directly.  (A stored face is its own value: a wall's face 0 is held at zero.)"""
    for c in range(dims):
        for i in range(-1, n[0] + 1):
            for j in range(-1, n[1] + 1):
                inside = 0 <= i < n[0] and 0 <= j < n[1]
                for k in range(-1, n[2] + 1):
                    if inside and 0 <= k < n[2]:
                        out[c, i + 1, j + 1, k + 1] = q[c, i, j, k]
                    else:
                        out[c, i + 1, j + 1, k + 1] = face_value(q, c, i, j, k, n, periodic, wall)


@njit
def pad_cells(s, n, periodic, out):
    """``out[0, i + 1, j + 1, k + 1]`` = :func:`cell_value` of ``s`` for i in -1 .. n (likewise j, k): shape
    (1, nx + 2, ny + 2, nz + 2), laid out like :func:`pad_faces`' output."""
    for i in range(-1, n[0] + 1):
        for j in range(-1, n[1] + 1):
            for k in range(-1, n[2] + 1):
                out[0, i + 1, j + 1, k + 1] = cell_value(s, i, j, k, n, periodic)


@njit_inline
def into_box(x, count, periodic):
    """A position along one axis (cells) brought into ``[0, count]``: wrapped around a periodic axis, held
    at a wall."""
    if periodic:
        return x - count * math.floor(x / count)
    return min(max(x, 0.0), float(count))


@njit_inline
def interpolate_padded(padded, c, shift_x, shift_y, shift_z, x, y, z, n, periodic):
    """Trilinear interpolation at ``(x, y, z)`` (cells) of field ``c`` of a padded grid (:func:`pad_faces`
    or :func:`pad_cells`) whose samples sit at ``index + shift`` (cells) along each axis; returns ``(value,
    smallest, largest)`` over the corners used (for limiting)."""
    sx = into_box(x, n[0], periodic[0]) - shift_x
    sy = into_box(y, n[1], periodic[1]) - shift_y
    i0 = min(int(math.floor(sx)), n[0] - 1)
    j0 = min(int(math.floor(sy)), n[1] - 1)
    fx = sx - i0
    fy = sy - j0
    if n[2] == 1:
        k0 = 0
        fz = 0.0
        layers = 1
    else:
        sz = into_box(z, n[2], periodic[2]) - shift_z
        k0 = min(int(math.floor(sz)), n[2] - 1)
        fz = sz - k0
        layers = 2
    value = 0.0
    lo = math.inf
    hi = -math.inf
    for dk in range(layers):
        wz = fz if dk == 1 else 1.0 - fz
        for dj in range(2):
            wy = fy if dj == 1 else 1.0 - fy
            for di in range(2):
                wx = fx if di == 1 else 1.0 - fx
                corner = padded[c, i0 + 1 + di, j0 + 1 + dj, k0 + 1 + dk]
                value += wx * wy * wz * corner
                lo = min(lo, corner)
                hi = max(hi, corner)
    return value, lo, hi


@njit_inline
def interpolate_face(padded, c, x, y, z, n, periodic):
    """Velocity component ``c`` (m/s) at ``(x, y, z)`` (cells) from the padded faces ``padded``
    (:func:`pad_faces`); returns ``(value, smallest, largest)``."""
    return interpolate_padded(padded, c, 0.0 if c == 0 else 0.5, 0.0 if c == 1 else 0.5, 0.0 if c == 2 else 0.5,
                              x, y, z, n, periodic)


@njit_inline
def interpolate_cell(padded, x, y, z, n, periodic):
    """A cell-centred field at ``(x, y, z)`` (cells) from its padded copy (:func:`pad_cells`); returns
    ``(value, smallest, largest)``."""
    return interpolate_padded(padded, 0, 0.5, 0.5, 0.5, x, y, z, n, periodic)


@njit_inline
def velocity_at(padded, x, y, z, n, periodic, dims):
    """The interpolated velocity (m/s) at ``(x, y, z)`` (cells) from the padded faces; z is 0 in 2D."""
    u = interpolate_face(padded, 0, x, y, z, n, periodic)[0]
    v = interpolate_face(padded, 1, x, y, z, n, periodic)[0]
    w = interpolate_face(padded, 2, x, y, z, n, periodic)[0] if dims == 3 else 0.0
    return u, v, w


@njit_inline
def face_centre(c, i, j, k):
    """Where face ``(i, j, k)`` of component ``c`` is (cells)."""
    return (i + (0.0 if c == 0 else 0.5), j + (0.0 if c == 1 else 0.5), k + (0.0 if c == 2 else 0.5))


@njit
def sample_velocities(padded, cells, n, periodic, dims, out):
    """``out[r]`` = the velocity (m/s) at ``cells[r]`` (positions in cells) from the padded faces."""
    for r in range(cells.shape[0]):
        u, v, w = velocity_at(padded, cells[r, 0], cells[r, 1], cells[r, 2], n, periodic, dims)
        out[r, 0] = u
        out[r, 1] = v
        if dims == 3:
            out[r, 2] = w


@njit
def sample_cells(padded, cells, n, periodic, out):
    """``out[r]`` = the cell-centred field at ``cells[r]`` (positions in cells) from its padded copy."""
    for r in range(cells.shape[0]):
        out[r] = interpolate_cell(padded, cells[r, 0], cells[r, 1], cells[r, 2], n, periodic)[0]
