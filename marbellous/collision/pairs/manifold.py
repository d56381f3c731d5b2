"""Contact manifolds of faces: clipping an incident face against a reference face's side planes, and reducing
the clipped polygon to the points that keep a body resting on it.

A face contact (box on box, hull on hull, hull on a plane) can have many points; the solver needs no more
than four to hold a body flat: the deepest, the one farthest from it, the one spanning the largest triangle
with those two, and the one adding the most area outside that triangle.
"""
import numpy as np

from ..._numba.jit import njit
from ..vec3 import any_perpendicular, cross, dot


@njit
def area2(px, py, qx, qy, rx, ry):
    """Twice the signed area of the 2-D triangle ``p q r``."""
    return (qx - px) * (ry - py) - (qy - py) * (rx - px)


@njit
def reduce_to_four(pts, keep, m, chosen):
    """Pick at most 4 of the ``m`` points ``pts[keep[:m]]`` (2-D coordinates, column 2 = -depth).

    Writes the picked indices into ``chosen`` and returns how many.
    """
    if m <= 4:
        for q in range(m):
            chosen[q] = keep[q]
        return m
    i1 = keep[0]
    for q in range(1, m):
        if pts[keep[q], 2] < pts[i1, 2]:
            i1 = keep[q]
    i2 = i1
    best = 0.0
    for q in range(m):
        v = keep[q]
        d2 = (pts[v, 0] - pts[i1, 0]) ** 2 + (pts[v, 1] - pts[i1, 1]) ** 2
        if d2 > best:
            best = d2
            i2 = v
    chosen[0] = i1
    if i2 == i1:
        return 1
    chosen[1] = i2
    i3 = i1
    best = 0.0
    for q in range(m):
        v = keep[q]
        a = abs(area2(pts[i1, 0], pts[i1, 1], pts[i2, 0], pts[i2, 1], pts[v, 0], pts[v, 1]))
        if a > best:
            best = a
            i3 = v
    if i3 == i1:
        return 2
    chosen[2] = i3
    sigma = 1.0 if area2(pts[i1, 0], pts[i1, 1], pts[i2, 0], pts[i2, 1], pts[i3, 0], pts[i3, 1]) >= 0.0 else -1.0
    i4 = -1
    best = 0.0
    for q in range(m):
        v = keep[q]
        a = min(sigma * area2(pts[i1, 0], pts[i1, 1], pts[i2, 0], pts[i2, 1], pts[v, 0], pts[v, 1]),
                sigma * area2(pts[i2, 0], pts[i2, 1], pts[i3, 0], pts[i3, 1], pts[v, 0], pts[v, 1]),
                sigma * area2(pts[i3, 0], pts[i3, 1], pts[i1, 0], pts[i1, 1], pts[v, 0], pts[v, 1]))
        if a < best:
            best = a
            i4 = v
    if i4 < 0:
        return 3
    chosen[3] = i4
    return 4


@njit
def reduce_touching_first(pts, keep, m, chosen, scratch):
    """Pick at most ``len(chosen)`` (>= 4) of the ``m`` points ``pts[keep[:m]]`` (column 2 = -depth), touching
    points first: the points that touch or overlap (``depth >= 0``) are reduced to four by
    :func:`reduce_to_four`, and the places left go to the speculative points nearest to touching, in that
    order (the ones a falling body meets first).
    Spread alone would keep far corners of a tilted face and drop a corner resting in the ground, or about
    to hit it.  ``scratch``: ``m`` ints.  Writes the picked indices into ``chosen``; returns how many."""
    touching = 0
    for q in range(m):
        if pts[keep[q], 2] <= 0.0:
            scratch[touching] = keep[q]
            touching += 1
    picked = reduce_to_four(pts, scratch, touching, chosen)
    while picked < chosen.shape[0]:
        best = -1
        for q in range(m):
            v = keep[q]
            if pts[v, 2] > 0.0 and (best < 0 or pts[v, 2] < pts[best, 2]):
                taken = False
                for k in range(picked):
                    taken = taken or chosen[k] == v
                if not taken:
                    best = v
        if best < 0:
            break
        chosen[picked] = best
        picked += 1
    return picked


@njit
def reduce_on_plane(xs, count, normal, offset, prediction, most):
    """The points ``xs[:count]`` (rows of an (n, 3) array, m) within ``prediction`` (m) above the plane
    ``normal . x = offset``, at most ``most`` of them, touching first (:func:`reduce_touching_first`, in the
    plane's own 2-D coordinates).  Returns ``(heights, chosen, kept)``: each point's height above the plane
    (m, minus its depth) and the picked points' indices ``chosen[:kept]``."""
    t1 = any_perpendicular(normal)
    t2 = cross(normal, t1)
    pts = np.empty((count, 3))
    keep = np.empty(count, np.int64)
    chosen = np.empty(most, np.int64)
    kept = 0
    for q in range(count):
        x = (xs[q, 0], xs[q, 1], xs[q, 2])
        pts[q, 0] = dot(x, t1)
        pts[q, 1] = dot(x, t2)
        pts[q, 2] = dot(x, normal) - offset
        if pts[q, 2] <= prediction:
            keep[kept] = q
            kept += 1
    kept = reduce_touching_first(pts, keep, kept, chosen, np.empty(kept, np.int64))
    return pts[:, 2], chosen, kept


@njit
def clip_polygon(poly, labels, src, count, side, offset, label):
    """Sutherland-Hodgman: keep the part of polygon ``poly[src, :count]`` with ``side . x <= offset``,
    writing it into ``poly[1 - src]``; a new vertex is named by the polygon edge it cuts and ``label``.
    Returns the new count."""
    dst = 1 - src
    out = 0
    prev = count - 1
    cap = poly.shape[1]
    for cur in range(count):
        dp = side[0] * poly[src, prev, 0] + side[1] * poly[src, prev, 1] + side[2] * poly[src, prev, 2] - offset
        dc = side[0] * poly[src, cur, 0] + side[1] * poly[src, cur, 1] + side[2] * poly[src, cur, 2] - offset
        edge = labels[src, prev, 1]
        if (dc <= 0.0) != (dp <= 0.0) and out < cap:
            f = dp / (dp - dc)
            for m in range(3):
                poly[dst, out, m] = poly[src, prev, m] + f * (poly[src, cur, m] - poly[src, prev, m])
            labels[dst, out, 0] = label if dc <= 0.0 else edge
            labels[dst, out, 1] = edge if dc <= 0.0 else label
            out += 1
        if dc <= 0.0 and out < cap:
            for m in range(3):
                poly[dst, out, m] = poly[src, cur, m]
            labels[dst, out, 0] = labels[src, cur, 0]
            labels[dst, out, 1] = labels[src, cur, 1]
            out += 1
        prev = cur
    return out
