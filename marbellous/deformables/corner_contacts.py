"""The corners of bodies against cloth triangles: a box or a hull on a cloth rests on its triangles, not only on
its vertices.

The particles' contacts with the shapes (particle_contacts.py) are the vertices' spheres against the shapes, so a
sharp body met a cloth only at its vertices: a 10 cm cube dropped inside one triangle of a coarse sheet (legs of
0.5 m) fell through it to the ground.  Here each corner ``x_c`` of a box or hull is a point against the cloth's
triangles, as a cloth's vertex is in triangle_contacts.py: on the side ``s = +-1`` of the triangle that the
shape's centre was on at the step's start, no closer to its plane than half the cloth's thickness ``t``, where
its foot lies inside the triangle (barycentric weights ``b_i >= 0``):

    C = s n . (x_c - sum_i b_i x_i) - t / 2 >= 0
    grad_c = s n,   grad_i = -b_i s n,   dlambda = -C / (w_c + sum_i b_i^2 w_i)

with ``w_c = 1/m + (r x n) . I^-1 (r x n)`` the body's generalised inverse mass at the corner along ``n``
(0 for a static or kinematic body); the body takes its part as a positional impulse (body_motion.push_body), so
momentum is conserved.  A corner farther behind the triangle than it and the triangle moved apart in the sub-step
is left alone (it was never over the triangle from the front).  A triangle corner that the ground holds takes no
part of a push into the ground (``particle_contacts.held_inverse_mass``); when all three are held the body takes
the whole push, as velocity only what its own motion closed in the sub-step (as ``particle_contacts._shape_pair``
does).  Coulomb friction across ``n``, on positions: the corner's motion relative to the triangle in the
sub-step is undone when shorter than ``mu_s C``, else shortened by ``mu_d C`` (the geometric means of the body's
and the cloth's coefficients).

Candidates, once per step: the (shape, triangle) pairs where the path of one of the shape's corners over the
step comes within half the thickness of the triangle's box swept over the step (ten 10 cm cubes lying on a 50 x 50
sheet: 222 pairs, 2.4 ms of a 70 ms step at 16 sub-steps; the pairs whose shape's ball meets the triangle's box
were 1600, and cost 24 ms); not a soft body's surface (its nodes take their contacts in its
implicit step, soft_step.py), nor a triangle with a corner pinned to the body.  Not for the triangles of the
whole-cloth solve (stretch_solve.py), whose contacts with bodies are solved with the sheet: pushed outside it, a
1 kg box landing on its trampoline left the box and sheet with 65 % more energy than the box brought.  Not
handled: a body's edge through a triangle with both ends outside it (pushing the point of the edge over the
triangle's edge out along the triangle's normal kept a 1 kg box on the spring-at-a-time trampoline from coming
to rest), and spheres and capsules (their round faces meet the vertices first on a sheet finer than they are).
"""
import math

from .._numba.jit import njit, njit_inline
from ..collision.hull.hull_layout import counts
from ..collision.shape_types import BOX, HULL
from ..math3d import quat_product, quat_step, rotated
from ..state.layout import (F_ALIVE, F_SENSOR, FLAGS, FRICTION, OMEGA, POS, QUAT, S_BODY, S_LOCAL_POS,
                            S_LOCAL_QUAT, S_OFF_F, S_OFF_I, S_PARAMS, S_RADIUS, S_TYPE, SHAPE_COUNT, SHAPE_START,
                            STATIC_FRICTION, VEL)
from .body_motion import body_pose, inverse_mass_along, point_velocity, push_body, to_world
from .particle_contacts import append_pair, held_inverse_mass
from .particle_layout import (CL_THICKNESS, P_FLAGS, P_FRICTION, P_INV_MASS, P_PIN_BODY, P_POS, P_PREV,
                              P_STATIC_FRICTION, P_VEL, PP_PINNED, PP_SOFT, T_A, T_CLOTH)
from .triangle_contacts import foot_weights


@njit_inline
def corner_count(sf, si, geom_i, s):
    """How many corners shape row ``s`` has: 8 for a box, its vertices for a hull, 0 for a round shape."""
    kind = si[s, S_TYPE]
    if kind == BOX:
        return 8
    if kind == HULL:
        return counts(geom_i, si[s, S_OFF_I])[0]
    return 0


@njit_inline
def corner(sf, si, geom_f, s, k):
    """Corner ``k`` of shape row ``s`` in the shape's frame (m): a box's ``(+-hx, +-hy, +-hz)``, a hull's vertex."""
    if si[s, S_TYPE] == BOX:
        return (sf[s, S_PARAMS] * (1.0 if k & 1 else -1.0), sf[s, S_PARAMS + 1] * (1.0 if k & 2 else -1.0),
                sf[s, S_PARAMS + 2] * (1.0 if k & 4 else -1.0))
    o = si[s, S_OFF_F] + 3 * k
    return geom_f[o], geom_f[o + 1], geom_f[o + 2]


@njit_inline
def _triangle_frame(pf, tri, t):
    """``(a, b, c, unit normal, ok)`` of triangle ``t`` (its corners' rows; the normal of its counter-clockwise
    side; ``ok`` False for a degenerate triangle)."""
    a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
    u = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
    v = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    size = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    if size < 1e-20:
        return a, b, c, (0.0, 0.0, 1.0), False
    return a, b, c, (n[0] / size, n[1] / size, n[2] / size), True


@njit
def corner_candidates(pf, pi, tri, n_tri, cloth_f, bf, bi, sf, si, geom_f, geom_i, nb, dt, reach, out):
    """List the candidate ``(shape, triangle, side)`` rows into ``out`` (module docstring); returns how many there
    are (rows past ``out``'s end are not written).  A shape's box: the ball of its radius about its centre, swept
    back over the step along the body's velocity (the particles' sub-steps take the bodies back that way,
    body_motion.py), grown by ``reach`` (m), how far a particle may fall in the step beyond its velocity's sweep;
    a pair is kept where the path of one of its corners over the step (turned back along the body's angular
    velocity) comes as near the triangle's box; its side of a triangle: the one its centre is on at the step's
    start."""
    if n_tri == 0:
        return 0
    lo_all, hi_all = _swept_bounds(pf, tri, n_tri, dt)
    n = 0
    for b in range(nb):
        f = bi[b, FLAGS]
        if (f & F_ALIVE) == 0 or (f & F_SENSOR) != 0:
            continue
        s0 = bi[b, SHAPE_START]
        for s in range(s0, s0 + bi[b, SHAPE_COUNT]):
            if corner_count(sf, si, geom_i, s) == 0:
                continue
            end = to_world((bf[b, POS], bf[b, POS + 1], bf[b, POS + 2]),
                           (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3]),
                           (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]))
            start = (end[0] - bf[b, VEL] * dt, end[1] - bf[b, VEL + 1] * dt, end[2] - bf[b, VEL + 2] * dt)
            grow = sf[s, S_RADIUS] + reach
            box_lo = (min(start[0], end[0]) - grow, min(start[1], end[1]) - grow, min(start[2], end[2]) - grow)
            box_hi = (max(start[0], end[0]) + grow, max(start[1], end[1]) + grow, max(start[2], end[2]) + grow)
            if not _overlap(box_lo, box_hi, lo_all, hi_all, 0.0):
                continue
            q_end = quat_product((bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3]),
                                 (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2],
                                  sf[s, S_LOCAL_QUAT + 3]))
            q_start = quat_step(q_end, (bf[b, OMEGA], bf[b, OMEGA + 1], bf[b, OMEGA + 2]), -dt)
            for t in range(n_tri):
                if not _meets(pi, tri, t, b):
                    continue
                lo, hi = _swept_bounds(pf, tri[t:t + 1], 1, dt)
                half = 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]
                if not _overlap(box_lo, box_hi, lo, hi, half):
                    continue
                # (and a corner's path over the step, start to end, comes that near: a box lying on a sheet has
                # a hundred triangles within its ball and a few under its corners)
                near = False
                for j in range(corner_count(sf, si, geom_i, s)):
                    local = corner(sf, si, geom_f, s, j)
                    r0, r1 = rotated(q_start, local), rotated(q_end, local)
                    x0 = (start[0] + r0[0], start[1] + r0[1], start[2] + r0[2])
                    x1 = (end[0] + r1[0], end[1] + r1[1], end[2] + r1[2])
                    if _overlap((min(x0[0], x1[0]), min(x0[1], x1[1]), min(x0[2], x1[2])),
                                (max(x0[0], x1[0]), max(x0[1], x1[1]), max(x0[2], x1[2])), lo, hi, half + reach):
                        near = True
                        break
                if not near:
                    continue
                a, _, _, normal, ok = _triangle_frame(pf, tri, t)
                if not ok:
                    continue
                side = (start[0] - pf[a, P_POS]) * normal[0] + (start[1] - pf[a, P_POS + 1]) * normal[1] \
                    + (start[2] - pf[a, P_POS + 2]) * normal[2]
                if n < out.shape[0]:
                    out[n, 2] = 1 if side >= 0.0 else -1
                n = append_pair(out, n, s, t)
    return n


@njit_inline
def _swept_bounds(pf, tri, n_tri, dt):
    """``(lo, hi)`` lists: the box of the corners of triangles ``0 .. n_tri - 1`` of ``tri`` over the step of ``dt``
    s, at their velocities."""
    lo, hi = [1e300, 1e300, 1e300], [-1e300, -1e300, -1e300]
    for t in range(n_tri):
        for q in range(3):
            p = tri[t, T_A + q]
            for k in range(3):
                x0, x1 = pf[p, P_POS + k], pf[p, P_POS + k] + pf[p, P_VEL + k] * dt
                lo[k] = min(lo[k], x0, x1)
                hi[k] = max(hi[k], x0, x1)
    return lo, hi


@njit_inline
def _overlap(lo_a, hi_a, lo_b, hi_b, grow):
    """Whether box ``a`` meets box ``b`` grown by ``grow`` (m)."""
    for k in range(3):
        if lo_b[k] - grow > hi_a[k] or hi_b[k] + grow < lo_a[k]:
            return False
    return True


@njit_inline
def _meets(pi, tri, t, b):
    """Whether body row ``b``'s corners meet triangle ``t``: one of a cloth (a soft body's surface nodes take their
    contacts in its implicit step, soft_step.py) none of whose corners is pinned to the body."""
    for q in range(3):
        p = tri[t, T_A + q]
        if (pi[p, P_FLAGS] & PP_SOFT) != 0:
            return False
        if (pi[p, P_FLAGS] & PP_PINNED) != 0 and pi[p, P_PIN_BODY] == b:
            return False
    return True


@njit
def corner_contacts(pf, tri, cloth_f, bf, bi, bx, sf, si, geom_f, geom_i, pairs, n_pairs, back, h, ground, slot):
    """The position pass over the candidate ``(shape, triangle, side)`` pairs (module docstring) in the sub-step
    of ``h`` s ending ``back`` s before the step's end, with the particles that the ground holds (``ground``,
    ``particle_contacts.ground_normals``)."""
    for k in range(n_pairs):
        s, t, side = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        if slot[tri[t, T_A]] >= 0 or slot[tri[t, T_A + 1]] >= 0 or slot[tri[t, T_A + 2]] >= 0:
            continue
        b = si[s, S_BODY]
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        centre = to_world(x_b, q_b, (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]))
        # (no corner of a shape whose ball lies wholly in front of the triangle's slab can touch it)
        a, _, _, normal, ok = _triangle_frame(pf, tri, t)
        height = side * ((centre[0] - pf[a, P_POS]) * normal[0] + (centre[1] - pf[a, P_POS + 1]) * normal[1]
                         + (centre[2] - pf[a, P_POS + 2]) * normal[2])
        if not ok or height >= sf[s, S_RADIUS] + 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]:
            continue
        q_s = quat_product(q_b, (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2],
                                 sf[s, S_LOCAL_QUAT + 3]))
        for j in range(corner_count(sf, si, geom_i, s)):
            r = rotated(q_s, corner(sf, si, geom_f, s, j))
            _corner_triangle(pf, tri, cloth_f, bf, bi, bx, b, x_b, q_b,
                             (centre[0] + r[0], centre[1] + r[1], centre[2] + r[2]), t, side, h, ground)


@njit_inline
def _corner_triangle(pf, tri, cloth_f, bf, bi, bx, b, x_b, q_b, x_c, t, side, h, ground):
    """Corner ``x_c`` (m, world) of body row ``b`` (posed ``x_b``, ``q_b``) against triangle ``t`` from side
    ``side``: the push out and the friction of the module docstring."""
    a, bb, c, normal, ok = _triangle_frame(pf, tri, t)
    if not ok:
        return
    n = (side * normal[0], side * normal[1], side * normal[2])
    half = 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]
    w = (x_c[0] - pf[a, P_POS], x_c[1] - pf[a, P_POS + 1], x_c[2] - pf[a, P_POS + 2])
    d = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    if d >= half:
        return
    # barycentric weights of the corner's foot on the triangle's plane
    b0, b1, b2 = foot_weights(
        (pf[bb, P_POS] - pf[a, P_POS], pf[bb, P_POS + 1] - pf[a, P_POS + 1], pf[bb, P_POS + 2] - pf[a, P_POS + 2]),
        (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2]), w)
    if b0 < 0.0 or b1 < 0.0 or b2 < 0.0:
        return
    # the corner's motion relative to the triangle's point under it in this sub-step: one that was behind the
    # triangle at the sub-step's start is left alone
    motion = _relative_motion(pf, bf, bi, bx, b, x_b, x_c, (a, bb, c), (b0, b1, b2),
                              (pf[a, P_INV_MASS], pf[bb, P_INV_MASS], pf[c, P_INV_MASS]), h)
    if d - (motion[0] * n[0] + motion[1] * n[1] + motion[2] * n[2]) < -half:
        return
    back_n = (-n[0], -n[1], -n[2])
    wc = inverse_mass_along(bf, bi, b, x_b, q_b, x_c, n)
    wa, wb, wcc = held_inverse_mass(pf, ground, a, back_n), held_inverse_mass(pf, ground, bb, back_n), \
        held_inverse_mass(pf, ground, c, back_n)
    cloth_w = b0 * b0 * wa + b1 * b1 * wb + b2 * b2 * wcc
    share = 1.0
    if cloth_w <= 0.0 and wc > 0.0:
        # (the ground holds the triangle: the body takes the push, as velocity the part its own motion closed in the
        # sub-step)
        u = point_velocity(bf, bi, bx, b, x_b, x_c)
        closing = -(u[0] * n[0] + u[1] * n[1] + u[2] * n[2]) * h
        share = min(1.0, max(0.0, closing) / (half - d))
    elif cloth_w <= 0.0:
        wa, wb, wcc = pf[a, P_INV_MASS], pf[bb, P_INV_MASS], pf[c, P_INV_MASS]
        cloth_w = b0 * b0 * wa + b1 * b1 * wb + b2 * b2 * wcc
    denominator = wc + cloth_w
    if denominator <= 0.0:
        return
    dlambda = (half - d) / denominator
    _move(pf, bf, bi, bx, b, x_b, q_b, x_c, (a, bb, c), (b0, b1, b2), (wa, wb, wcc), n, dlambda, h, share)
    _friction(pf, bf, bi, bx, b, x_b, q_b, x_c, (a, bb, c), (b0, b1, b2), (wa, wb, wcc), n, half - d, h)


@njit_inline
def _relative_motion(pf, bf, bi, bx, b, x_b, x_c, corners, weights, movable, h):
    """How far (m, a 3-tuple) the body's point at ``x_c`` moved in the sub-step of ``h`` s relative to the
    triangle's point of barycentric ``weights`` (its ``corners``' rows), counting the motion of the corners whose
    ``movable`` entry is positive (one that the ground holds moves with it)."""
    u = point_velocity(bf, bi, bx, b, x_b, x_c)
    out = [u[0] * h, u[1] * h, u[2] * h]
    for q in range(3):
        p = corners[q]
        if movable[q] > 0.0:
            for k in range(3):
                out[k] -= weights[q] * (pf[p, P_POS + k] - pf[p, P_PREV + k])
    return out[0], out[1], out[2]


@njit_inline
def _move(pf, bf, bi, bx, b, x_b, q_b, x_c, corners, weights, inverse_masses, along, dlambda, h, share):
    """Move the body's point ``x_c`` by the positional impulse ``dlambda along`` (kg m; ``share`` of it as
    velocity, body_motion.push_body) and the triangle's corners the other way, each by ``w_i b_i dlambda``."""
    push_body(bf, bi, bx, b, x_b, q_b, x_c, (dlambda * along[0], dlambda * along[1], dlambda * along[2]), h, True,
              share)
    for q in range(3):
        p = corners[q]
        for k in range(3):
            pf[p, P_POS + k] -= inverse_masses[q] * weights[q] * dlambda * along[k]


@njit_inline
def _friction(pf, bf, bi, bx, b, x_b, q_b, x_c, corners, weights, inverse_masses, n, depth, h):
    """Coulomb friction of the corner on the triangle whose overlap ``depth`` (m) along ``n`` was just removed
    (module docstring)."""
    # (the motion of every corner counts: the ground holds a corner against the normal only, and a sheet sliding
    # on it carries the body; counting only the movable ones, a box stood still on a sheet sliding down a 30 degree
    # slope under it)
    motion = _relative_motion(pf, bf, bi, bx, b, x_b, x_c, corners, weights,
                              (pf[corners[0], P_INV_MASS], pf[corners[1], P_INV_MASS], pf[corners[2], P_INV_MASS]), h)
    along = motion[0] * n[0] + motion[1] * n[1] + motion[2] * n[2]
    tangent = (motion[0] - along * n[0], motion[1] - along * n[1], motion[2] - along * n[2])
    slip = math.sqrt(tangent[0] ** 2 + tangent[1] ** 2 + tangent[2] ** 2)
    if slip <= 0.0:
        return
    a = corners[0]
    mu_s = math.sqrt(pf[a, P_STATIC_FRICTION] * bf[b, STATIC_FRICTION])
    mu_d = math.sqrt(pf[a, P_FRICTION] * bf[b, FRICTION])
    undo = slip if slip < mu_s * depth else min(slip, mu_d * depth)
    back = (-tangent[0] / slip, -tangent[1] / slip, -tangent[2] / slip)
    denominator = inverse_mass_along(bf, bi, b, x_b, q_b, x_c, back)
    for q in range(3):
        denominator += weights[q] * weights[q] * inverse_masses[q]
    if denominator > 0.0:
        _move(pf, bf, bi, bx, b, x_b, q_b, x_c, corners, weights, inverse_masses, back, undo / denominator, h, 1.0)
