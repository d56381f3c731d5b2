"""Contacts of the convex primitives with a plane (the plane is always shape b).

A plane with local normal ``n_l`` and offset ``o`` placed at ``(p, R)`` is, in world coordinates,
the half-space ``x . n <= o + n . p`` with ``n = R n_l``.  A point ``x`` of shape a lies
``depth = o + n . p - n . x`` below the surface; the normal from a to the plane is ``-n``.
"""
from ..._numba.jit import njit
from ..vec3 import column, dot, load, madd, mat_to_world, matrix, scale
from .contact_output import add_contact


@njit
def world_plane(p, m, local_normal, offset):
    """World normal (3-tuple) and offset (m) of a plane with ``local_normal`` and ``offset`` placed at
    ``p`` (3-tuple) with rotation ``m`` (row-major 9-tuple, ``vec3.matrix``)."""
    normal = mat_to_world(m, local_normal)
    return normal, offset + dot(normal, p)


@njit
def _world_plane(pos, rot, params):
    """World normal (3-tuple) and offset (m) of a plane shape."""
    return world_plane(load(pos), matrix(rot), (params[0], params[1], params[2]), params[3])


@njit
def sphere_plane(c, r, pn, off, prediction):
    """Sphere ``(c, r)`` against the world half-space ``x . pn <= off``, as values
    ``(hit, p_on_a, normal, depth)`` (``sphere_sphere.ball_ball``).

    ``depth = offset - n . c + r``.
    """
    depth = off - dot(pn, c) + r
    normal = scale(pn, -1.0)
    if depth < -prediction:
        return False, c, normal, depth
    return True, madd(c, r, normal), normal, depth


@njit
def collide_sphere_plane(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Sphere a (``[radius]``) against plane b: one point, feature id 0.

    ``depth = offset - n . c + r``.
    """
    pn, off = _world_plane(pos_b, rot_b, params_b)
    hit, p, normal, depth = sphere_plane(load(pos_a), params_a[0], pn, off, prediction)
    return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n


@njit
def collide_capsule_plane(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Capsule a (``[radius, half_height]``) against plane b: the two end spheres, ids 0 (-y) and 1 (+y)."""
    pn, off = _world_plane(pos_b, rot_b, params_b)
    r, hh = params_a[0], params_a[1]
    c = load(pos_a)
    axis = column(rot_a, 1)
    normal = scale(pn, -1.0)
    for k in range(2):
        e = madd(c, hh if k == 1 else -hh, axis)
        depth = off - dot(pn, e) + r
        if depth >= -prediction:
            n = add_contact(out_f, out_i, n, madd(e, r, normal), normal, depth, k)
    return n


@njit
def collide_box_plane(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n):
    """Box a (``[hx, hy, hz]``) against plane b: up to the 4 deepest corners within ``prediction``.

    Corner ``k`` (feature id ``k``) is ``c + sum_i s_i h_i u_i`` with ``s_i = +1`` where bit ``i``
    of ``k`` is set, else ``-1``; its depth is ``offset - n . c - sum_i s_i h_i (n . u_i)``.
    Deeper corners come first; equal depths keep the corner order.
    """
    pn, off = _world_plane(pos_b, rot_b, params_b)
    c = load(pos_a)
    u0, u1, u2 = column(rot_a, 0), column(rot_a, 1), column(rot_a, 2)
    e0 = params_a[0] * dot(pn, u0)
    e1 = params_a[1] * dot(pn, u1)
    e2 = params_a[2] * dot(pn, u2)
    centre_depth = off - dot(pn, c)
    normal = scale(pn, -1.0)
    taken = 0
    for _ in range(4):
        best_k = -1
        best = -prediction
        for k in range(8):
            if taken & (1 << k):
                continue
            s0 = 1.0 if k & 1 else -1.0
            s1 = 1.0 if k & 2 else -1.0
            s2 = 1.0 if k & 4 else -1.0
            depth = centre_depth - s0 * e0 - s1 * e1 - s2 * e2
            if depth > best or (best_k < 0 and depth >= best):
                best = depth
                best_k = k
        if best_k < 0:
            break
        taken |= 1 << best_k
        s0 = params_a[0] if best_k & 1 else -params_a[0]
        s1 = params_a[1] if best_k & 2 else -params_a[1]
        s2 = params_a[2] if best_k & 4 else -params_a[2]
        corner = madd(madd(madd(c, s0, u0), s1, u1), s2, u2)
        n = add_contact(out_f, out_i, n, corner, normal, best, best_k)
    return n
