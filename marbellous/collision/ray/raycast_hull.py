"""Ray cast against a convex hull: the ray clipped by the half-spaces of its faces (Cyrus-Beck).

In the hull's frame the ray ``o + t d`` is inside face ``f``'s half-space ``n_f . x <= d_f`` for
``t`` on one side of ``(d_f - n_f . o) / (n_f . d)``; the entry is the largest such bound over the faces the
ray enters (``n_f . d < 0``), the exit the least over those it leaves, and the ray hits if entry <= exit.
"""
import math

from ..._numba.jit import njit
from ..hull import hull_layout as hl
from ..vec3 import load, sub, to_local, to_world


@njit
def raycast_hull(pos, rot, geom_f, geom_i, off_f, off_i, origin, direction, max_distance, normal_out):
    """Ray against the hull at ``off_f``/``off_i`` of the blobs, placed at ``pos`` with rotation ``rot``:
    distance (m) or -1.0, with the outward normal in ``normal_out`` (conventions of ``raycast_primitives``:
    a ray starting inside hits at 0 with normal ``-direction``)."""
    o = to_local(rot, sub(load(origin), load(pos)))
    d = to_local(rot, load(direction))
    nf = geom_i[off_i + hl.I_NF]
    p0 = hl.planes_start(geom_i, off_f, off_i)
    t_in = -math.inf
    t_out = math.inf
    face = -1
    for f in range(nf):
        n = (geom_f[p0 + 4 * f], geom_f[p0 + 4 * f + 1], geom_f[p0 + 4 * f + 2])
        gap = geom_f[p0 + 4 * f + 3] - (n[0] * o[0] + n[1] * o[1] + n[2] * o[2])
        nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2]
        if nd == 0.0:
            if gap < 0.0:
                return -1.0
            continue
        t = gap / nd
        if nd < 0.0:
            if t > t_in:
                t_in = t
                face = f
        else:
            t_out = min(t_out, t)
    if t_in > t_out or t_in > max_distance or t_out < 0.0:
        return -1.0
    if t_in <= 0.0 or face < 0:
        for k in range(3):
            normal_out[k] = -direction[k]
        return 0.0
    nw = to_world(rot, (geom_f[p0 + 4 * face], geom_f[p0 + 4 * face + 1], geom_f[p0 + 4 * face + 2]))
    for k in range(3):
        normal_out[k] = nw[k]
    return t_in
