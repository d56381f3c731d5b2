"""Axis-aligned bounding boxes of placed shapes: ``[minx, miny, minz, maxx, maxy, maxz]`` (m).

Sphere: ``c +- r``.  Capsule: its segment's end points ``c +- R e_y h`` grown by ``r``.
Box: ``c +- |R| h`` (the absolute rotation matrix times the half extents); a hull likewise, from its own
bounding box.  Planes, height fields and
meshes are static: their boxes are computed once when they are added (``static_box``).
``boxes_overlap`` tests a triangle's box against a query box (meshes and height fields).
"""
import math

from .._numba.jit import njit
from . import shape_types as st


@njit
def sphere_aabb(c, r):
    """Corners ``(lo, hi)`` (3-tuples, m) of the box of the sphere with centre ``c`` and radius ``r``."""
    return (c[0] - r, c[1] - r, c[2] - r), (c[0] + r, c[1] + r, c[2] + r)


@njit
def hull_bounds(pos, rot, params, margin):
    """Corners ``(lo, hi)`` (3-tuples, m) of a box holding the hull at pose ``(pos, rot)``, grown by ``margin``
    (m): its own bounding box (half extents ``params[0:3]``, centre ``params[3:6]`` in its frame) turned,
    ``c +- |R| e`` with ``c = pos + R centre``."""
    c = (pos[0] + rot[0, 0] * params[3] + rot[0, 1] * params[4] + rot[0, 2] * params[5],
         pos[1] + rot[1, 0] * params[3] + rot[1, 1] * params[4] + rot[1, 2] * params[5],
         pos[2] + rot[2, 0] * params[3] + rot[2, 1] * params[4] + rot[2, 2] * params[5])
    e = (abs(rot[0, 0]) * params[0] + abs(rot[0, 1]) * params[1] + abs(rot[0, 2]) * params[2] + margin,
         abs(rot[1, 0]) * params[0] + abs(rot[1, 1]) * params[1] + abs(rot[1, 2]) * params[2] + margin,
         abs(rot[2, 0]) * params[0] + abs(rot[2, 1]) * params[1] + abs(rot[2, 2]) * params[2] + margin)
    return (c[0] - e[0], c[1] - e[1], c[2] - e[2]), (c[0] + e[0], c[1] + e[1], c[2] + e[2])


@njit
def shape_bounds(stype, pos, rot, params):
    """Corners ``(lo, hi)`` (3-tuples, m) of the world AABB of a moving shape (sphere, capsule, box, hull) at pose
    ``(pos, rot)``; unbounded (+-inf) for any other type."""
    if stype == st.SPHERE:
        return sphere_aabb((pos[0], pos[1], pos[2]), params[0])
    if stype == st.CAPSULE:
        r, hh = params[0], params[1]
        e = (abs(rot[0, 1]) * hh + r, abs(rot[1, 1]) * hh + r, abs(rot[2, 1]) * hh + r)
    elif stype == st.BOX:
        e = (abs(rot[0, 0]) * params[0] + abs(rot[0, 1]) * params[1] + abs(rot[0, 2]) * params[2],
             abs(rot[1, 0]) * params[0] + abs(rot[1, 1]) * params[1] + abs(rot[1, 2]) * params[2],
             abs(rot[2, 0]) * params[0] + abs(rot[2, 1]) * params[1] + abs(rot[2, 2]) * params[2])
    elif stype == st.HULL:
        return hull_bounds(pos, rot, params, 0.0)
    else:
        return (-math.inf, -math.inf, -math.inf), (math.inf, math.inf, math.inf)
    return (pos[0] - e[0], pos[1] - e[1], pos[2] - e[2]), (pos[0] + e[0], pos[1] + e[1], pos[2] + e[2])


@njit
def shape_aabb(stype, pos, rot, params, out):
    """Write the world AABB of a primitive (sphere, capsule, box) at pose ``(pos, rot)`` into ``out``;
    unbounded (+-inf) for any other type."""
    lo, hi = shape_bounds(stype, pos, rot, params)
    for k in range(3):
        out[k] = lo[k]
        out[3 + k] = hi[k]


@njit
def boxes_overlap(a, b, c, lo, hi):
    """True if the bounding box of triangle ``abc`` overlaps the box ``lo..hi``:
    ``min(a, b, c) <= hi`` and ``max(a, b, c) >= lo`` on every axis."""
    for ax in range(3):
        if min(a[ax], min(b[ax], c[ax])) > hi[ax] or max(a[ax], max(b[ax], c[ax])) < lo[ax]:
            return False
    return True


#: Relative allowance of ``sphere_misses_box``: a sphere closer to the box than ``(1 + 1e-9)`` times its
#: reach is left to the exact test, so rounding in the box distance never drops a contact.
SPHERE_BOX_ROUNDING = 1e-9


@njit
def sphere_misses_box(c, reach, a, b, cc):
    """True if the sphere of centre ``c`` (m) and radius ``reach`` (m) misses the bounding box of
    triangle ``a b cc``: the box distance ``d`` with ``d_k = max(min_k - c_k, 0, c_k - max_k)`` has
    ``|d| > reach``.  Every point of the triangle is then farther than ``reach``, so an exact test would
    find no contact either (tighter than :func:`boxes_overlap` with the sphere's box near its corners)."""
    d2 = 0.0
    for ax in range(3):
        lo = min(a[ax], min(b[ax], cc[ax]))
        hi = max(a[ax], max(b[ax], cc[ax]))
        e = max(lo - c[ax], c[ax] - hi, 0.0)
        d2 += e * e
    limit = reach * (1.0 + SPHERE_BOX_ROUNDING)
    return d2 > limit * limit


@njit
def ray_span_xz(o, d, t_max, x0, x1, z0, z1):
    """``(t0, t1)``: the part ``t0 <= t <= t1`` of the ray ``o + t d``, ``0 <= t <= t_max``, over the rectangle
    ``x0..x1, z0..z1`` of the x-z plane (slab test per axis); ``t0 > t1`` when it misses."""
    t0, t1 = 0.0, t_max
    for ax, lo, hi in ((0, x0, x1), (2, z0, z1)):
        if d[ax] == 0.0:
            if o[ax] < lo or o[ax] > hi:
                return math.inf, -math.inf
        else:
            ta = (lo - o[ax]) / d[ax]
            tb = (hi - o[ax]) / d[ax]
            t0 = max(t0, min(ta, tb))
            t1 = min(t1, max(ta, tb))
    return t0, t1
