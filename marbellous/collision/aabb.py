"""Axis-aligned bounding boxes of placed shapes: ``[minx, miny, minz, maxx, maxy, maxz]`` (m).

Sphere: ``c +- r``.  Capsule: its segment's end points ``c +- R e_y h`` grown by ``r``.
Box: ``c +- |R| h`` (the absolute rotation matrix times the half extents).  Planes, height fields and
meshes are static: their boxes are computed once when they are added (``static_box``).
``boxes_overlap`` tests a triangle's box against a query box (meshes and height fields).
"""
import math

from .._jit import njit
from . import shape_types as st


@njit
def sphere_aabb(c, r):
    """Corners ``(lo, hi)`` (3-tuples, m) of the box of the sphere with centre ``c`` and radius ``r``."""
    return (c[0] - r, c[1] - r, c[2] - r), (c[0] + r, c[1] + r, c[2] + r)


@njit
def shape_aabb(stype, pos, rot, params, out):
    """Write the world AABB of a primitive (sphere, capsule, box) at pose ``(pos, rot)`` into ``out``;
    unbounded (+-inf) for any other type."""
    if stype == st.SPHERE:
        lo, hi = sphere_aabb((pos[0], pos[1], pos[2]), params[0])
        for k in range(3):
            out[k] = lo[k]
            out[3 + k] = hi[k]
    elif stype == st.CAPSULE:
        r, hh = params[0], params[1]
        for k in range(3):
            e = abs(rot[k, 1]) * hh + r
            out[k] = pos[k] - e
            out[3 + k] = pos[k] + e
    elif stype == st.BOX:
        for k in range(3):
            e = abs(rot[k, 0]) * params[0] + abs(rot[k, 1]) * params[1] + abs(rot[k, 2]) * params[2]
            out[k] = pos[k] - e
            out[3 + k] = pos[k] + e
    else:
        for k in range(3):
            out[k] = -math.inf
            out[3 + k] = math.inf


@njit
def merge_aabb(acc, box):
    """Grow ``acc`` to contain ``box`` (both rows of 6)."""
    for k in range(3):
        if box[k] < acc[k]:
            acc[k] = box[k]
        if box[3 + k] > acc[3 + k]:
            acc[3 + k] = box[3 + k]


@njit
def boxes_overlap(a, b, c, lo, hi):
    """True if the bounding box of triangle ``abc`` overlaps the box ``lo..hi``:
    ``min(a, b, c) <= hi`` and ``max(a, b, c) >= lo`` on every axis."""
    for ax in range(3):
        if min(a[ax], min(b[ax], c[ax])) > hi[ax] or max(a[ax], max(b[ax], c[ax])) < lo[ax]:
            return False
    return True
