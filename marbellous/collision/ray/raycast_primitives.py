"""Ray casts against the primitive shapes (sphere, capsule, box, plane).

Every kernel has the signature
``distance = raycast_<shape>(pos, rot, params, origin, direction, max_distance, normal_out)``:
the shape placed at ``pos`` (3,) with rotation matrix ``rot`` (3, 3), the ray ``origin + t direction``
with a unit ``direction`` and ``0 <= t <= max_distance`` (m, may be inf).  It returns the distance
``t`` of the first surface point (m) and writes the outward unit surface normal there into
``normal_out`` (3,), or returns ``-1.0`` (``normal_out`` untouched) when the ray misses.
The shapes are solid: a ray starting inside or on the surface hits at distance 0 with normal
``-direction``.
"""
import math

from ..._numba.jit import njit
from .. import shape_types as st
from ..vec3 import column, dot, load, madd, scale, sub, to_local, to_world

_MISS = -1.0


@njit
def _write(normal_out, v):
    normal_out[0] = v[0]
    normal_out[1] = v[1]
    normal_out[2] = v[2]


@njit
def _inside(normal_out, direction):
    """Hit at distance 0 for a ray starting inside: normal ``-direction``."""
    _write(normal_out, (-direction[0], -direction[1], -direction[2]))
    return 0.0


@njit
def _ray_ball(centre, r, o, d):
    """Entry distance of the ray ``o + t d`` (``d`` unit, ``o`` outside) into a ball, or inf.

    ``|o + t d - c|^2 = r^2`` with ``m = o - c``, ``b = m.d``, ``k = m.m - r^2``:
    ``t = -b - sqrt(b^2 - k)``, evaluated as ``k / (-b + sqrt(b^2 - k))`` to avoid cancellation.
    """
    m = sub(o, centre)
    b = dot(m, d)
    k = dot(m, m) - r * r
    if b >= 0.0:
        return math.inf
    disc = b * b - k
    if disc < 0.0:
        return math.inf
    return k / (-b + math.sqrt(disc))


@njit
def raycast_sphere(pos, rot, params, origin, direction, max_distance, normal_out):
    """Ray against a sphere ``[radius]``: distance (m) of the hit or -1.0 (see module doc)."""
    c = load(pos)
    o = load(origin)
    d = load(direction)
    r = params[0]
    m = sub(o, c)
    if dot(m, m) <= r * r:
        return _inside(normal_out, d)
    t = _ray_ball(c, r, o, d)
    if t == math.inf or t > max_distance:
        return _MISS
    _write(normal_out, scale(sub(madd(o, t, d), c), 1.0 / r))
    return t


@njit
def raycast_capsule(pos, rot, params, origin, direction, max_distance, normal_out):
    """Ray against a capsule ``[radius, half_height]`` (axis local y): distance (m) or -1.0.

    The capsule is the union of the lateral cylinder ``x^2 + z^2 <= r^2, |y| <= h`` and the two end
    balls, so the first entry is the earliest of the entries into each.
    """
    r, hh = params[0], params[1]
    c = load(pos)
    o = to_local(rot, sub(load(origin), c))
    d = to_local(rot, load(direction))
    y = min(max(o[1], -hh), hh)
    if o[0] * o[0] + (o[1] - y) ** 2 + o[2] * o[2] <= r * r:
        return _inside(normal_out, load(direction))
    best = math.inf
    nl = (0.0, 1.0, 0.0)
    a = d[0] * d[0] + d[2] * d[2]
    if a > 0.0:
        b = o[0] * d[0] + o[2] * d[2]
        k = o[0] * o[0] + o[2] * o[2] - r * r
        disc = b * b - a * k
        if b < 0.0 and k > 0.0 and disc >= 0.0:
            t = k / (-b + math.sqrt(disc))
            yt = o[1] + t * d[1]
            if -hh <= yt <= hh:
                best = t
                nl = ((o[0] + t * d[0]) / r, 0.0, (o[2] + t * d[2]) / r)
    for end in range(2):
        centre = (0.0, hh if end == 1 else -hh, 0.0)
        t = _ray_ball(centre, r, o, d)
        if t < best:
            best = t
            nl = scale(sub(madd(o, t, d), centre), 1.0 / r)
    if best == math.inf or best > max_distance:
        return _MISS
    _write(normal_out, to_world(rot, nl))
    return best


@njit
def raycast_box(pos, rot, params, origin, direction, max_distance, normal_out):
    """Ray against a box ``[hx, hy, hz]``: distance (m) or -1.0 (slab method in the box frame).

    Per axis the ray is inside the slab ``|x_k| <= h_k`` for ``t`` between ``(-h_k - o_k) / d_k`` and
    ``(h_k - o_k) / d_k``; the entry is the largest slab entry, on the face of that slab.
    """
    o = to_local(rot, sub(load(origin), load(pos)))
    d = to_local(rot, load(direction))
    if abs(o[0]) <= params[0] and abs(o[1]) <= params[1] and abs(o[2]) <= params[2]:
        return _inside(normal_out, load(direction))
    t_in = -math.inf
    t_out = math.inf
    face = 0
    for k in range(3):
        h = params[k]
        if d[k] == 0.0:
            if abs(o[k]) > h:
                return _MISS
            continue
        ta = (-h - o[k]) / d[k]
        tb = (h - o[k]) / d[k]
        if ta > tb:
            ta, tb = tb, ta
        if ta > t_in:
            t_in = ta
            face = k
        t_out = min(t_out, tb)
    if t_in > t_out or t_in < 0.0 or t_in > max_distance:
        return _MISS
    s = -1.0 if d[face] > 0.0 else 1.0
    _write(normal_out, scale(column(rot, face), s))
    return t_in


@njit
def raycast_plane(pos, rot, params, origin, direction, max_distance, normal_out):
    """Ray against the half-space plane ``[nx, ny, nz, offset]``: distance (m) or -1.0.

    ``t = (offset - n.o) / (n.d)`` for a ray coming from above (``n.d < 0``).
    """
    n = to_world(rot, (params[0], params[1], params[2]))
    off = params[3] + dot(n, load(pos))
    o = load(origin)
    d = load(direction)
    height = dot(n, o) - off
    if height <= 0.0:
        return _inside(normal_out, d)
    nd = dot(n, d)
    if nd >= 0.0:
        return _MISS
    t = height / -nd
    if t > max_distance:
        return _MISS
    _write(normal_out, n)
    return t


@njit
def raycast_primitive(shape_type, pos, rot, params, origin, direction, max_distance, normal_out):
    """Ray against a primitive of the given type code (sphere, capsule, box, plane); -1.0 otherwise."""
    if shape_type == st.SPHERE:
        return raycast_sphere(pos, rot, params, origin, direction, max_distance, normal_out)
    if shape_type == st.CAPSULE:
        return raycast_capsule(pos, rot, params, origin, direction, max_distance, normal_out)
    if shape_type == st.BOX:
        return raycast_box(pos, rot, params, origin, direction, max_distance, normal_out)
    if shape_type == st.PLANE:
        return raycast_plane(pos, rot, params, origin, direction, max_distance, normal_out)
    return _MISS
