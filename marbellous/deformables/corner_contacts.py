"""The corners of bodies against cloth triangles: a box, a hull, a ball or a capsule on a cloth rests on its
triangles, not only on its vertices.

The particles' contacts with the shapes (particle_contacts.py) are the vertices' spheres against the shapes, so a
sharp body met a cloth only at its vertices: a 10 cm cube dropped inside one triangle of a coarse sheet (legs of
0.5 m) fell through it to the ground, and so did a 10 cm ball.  Here each corner ``x_c`` of a box or hull is a
point against the cloth's triangles (of a sphere, its centre, and of a capsule, its segment's ends, each moved
out by the radius ``r`` towards the triangle: ``x_c = c - r s n``), as a cloth's vertex is in
triangle_contacts.py: on the side ``s = +-1`` of the triangle that the shape's centre was on at the step's start,
no closer to its plane than half the cloth's thickness ``t``, where its foot lies inside the triangle
(barycentric weights ``b_i >= 0``):

    C = s n . (x_c - sum_i b_i x_i) - t / 2 >= 0
    grad_c = s n,   grad_i = -b_i s n,   dlambda = -C / (w_c + sum_i b_i^2 w_i)

with ``w_c = 1/m + (r x n) . I^-1 (r x n)`` the body's generalised inverse mass at the corner along ``n``
(0 for a static or kinematic body); the body takes its part as a positional impulse (body_motion.push_body), so
momentum is conserved.  A corner farther behind the triangle than it and the triangle moved apart in the sub-step
is left alone (it was never over the triangle from the front).  A triangle corner that the ground holds takes no
part of a push into the ground (``particle_contacts.held_inverse_mass``); when all three are held the body takes
the whole push, as velocity only what its own motion closed in the sub-step (as ``particle_contacts._shape_pair``
does).  Coulomb friction across ``n``, on positions: the corner's motion relative to the triangle in the
sub-step is undone while the sum of the friction's corrections stays within ``mu_s`` times the overlap removed,
else that sum is cut to ``mu_d`` times it (:func:`_friction`; the geometric means of the body's and the cloth's
coefficients).

A sub-step's corner contacts are found first, then solved together, ``CORNER_PASSES`` passes over them, each
contact's push summed over the passes and kept ``>= 0`` (a later pass takes back what an earlier one pushed too
far, never more): a box rests on four corners or more, and each corner's push turns it under the others.  Solved
one pass, as each was found, the last pushes of each sub-step were left standing: a box resting on a coarse
sheet's corners turned on it at 0.016 rad/s and crept down a 10 degree slope at 0.9 mm/s; at 20 degrees two
passes left 0.12 mm/s, four 0.06, eight 2 um/s.  Then :func:`corner_velocity_pass`, on the velocities, solved the same
way: what is left of the corners' approach is stopped and a body bounces by its restitution.  The passes are for the
bodies the cloth can move: when every body of a sub-step's corner contacts is static or kinematic (a sheet draped
over a fixed ball, whose centre is a corner against every triangle on it), only the cloth moves, each contact is one
more vertex-like contact, and both are solved in one pass (:func:`corner_passes`), as the vertices' contacts are: the
64 x 64 sheet of the cloth bench without self collision took 75 ms a step with eight and takes 43 with one, its
vertices as far outside the ball.

A sheet squeezed between a movable body and a static or kinematic one is held by the latter: those bodies'
contacts are found first and the corners of the triangles they touch count as held against them in ``ground``
(:func:`_hold_triangles`), so a movable body's corner pressing such a triangle takes the whole push; and a contact
whose free triangle corners carry under a tenth of the corner's point counts as held too (pushed through a free
corner of weight ``b`` alone, that corner moves ``1 / b`` times the push).  Shared by the inverse masses, a cube
pressing a triangle into a static ball moved the light triangle back into the ball at each pass, the ball's contact
pushed it out further, the two grew by half a pass, and cubes dropped on a sheet over a ball left at up to 1e5 m/s.

Candidates, once per step: the (shape, triangle) pairs where the path of one of the shape's corners over the
step comes within half the thickness of the triangle's box swept over the step (ten 10 cm cubes lying on a 50 x 50
sheet: 222 pairs, 2.4 ms of a 70 ms step at 16 sub-steps; the pairs whose shape's ball meets the triangle's box
were 1600, and cost 24 ms); not a soft body's surface (its nodes take their contacts in its
implicit step, soft_step.py), nor a triangle with a corner pinned to the body.  Not for the triangles of the
whole-cloth solve (stretch_solve.py), whose contacts with bodies are solved with the sheet: pushed outside it, a
1 kg box landing on its trampoline left the box and sheet with 65 % more energy than the box brought.

Edges where the cloth ends: a plank lying across a strip of cloth, its ends beyond the strip, has no corner over
it, and no vertex under it between the strip's vertices.  So each edge of a box or hull, and a capsule's segment,
is also tested against the candidate triangles that have an edge on the cloth's border (``T_BORDER``): the part
``lo <= s <= hi`` of the edge ``x(s) = x_0 + s (x_1 - x_0)`` whose foot lies inside the triangle is where all three
barycentric weights, linear in ``s``, are ``>= 0`` (:func:`_over_triangle`), and an end of that part where the
edge leaves the triangle over its border edge is a point of the body that meets the triangle as a corner does.
Inside the sheet the corners and the vertices hold a body; points of its edges over the shared edges between
triangles, tried as well, left a 1 kg box on the spring-at-a-time trampoline bobbing 2.7 mm after 12 s, against
0.5 mm without them.  Not handled: a body's edge pressed into the inside of a sheet with no vertex or corner near
(a sheet folded over a box's edge between its vertices).
"""
import math

from .._numba.jit import borrow, njit, njit_inline
from ..collision.hull.hull_layout import EDGE_COLS, counts, edges_start
from ..collision.shape_types import BOX, CAPSULE, HULL, SPHERE
from ..math3d import quat_product, quat_step, rotated
from ..state.layout import (F_ALIVE, F_SENSOR, FLAGS, FRICTION, OMEGA, POS, QUAT, RESTITUTION, S_BODY,
                            S_LOCAL_POS, S_LOCAL_QUAT, S_OFF_F, S_OFF_I, S_PARAMS, S_RADIUS, S_TYPE, SHAPE_COUNT,
                            SHAPE_START, STATIC_FRICTION, VEL)
from .body_motion import body_pose, inverse_mass_along, point_velocity, push_body, pushable, to_world
from .particle_contacts import append_pair, held_inverse_mass
from .particle_layout import (CL_THICKNESS, P_FLAGS, P_FRICTION, P_INV_MASS, P_PIN_BODY, P_POS, P_PREV,
                              P_RESTITUTION, P_STATIC_FRICTION, P_VEL, P_VEL0, PP_PINNED, PP_SOFT, T_A, T_BORDER,
                              T_CLOTH)
from .triangle_contacts import foot_weights


#: passes over a sub-step's corner contacts (module docstring)
CORNER_PASSES = 8

# a corner contact of the sub-step: floats ``cf``
C_WEIGHTS = 0    # the corner's foot's barycentric weights on the triangle, 3
C_NORMAL = 3     # unit normal from the triangle to the corner, 3
C_LOCAL = 6      # the corner in its body's frame (m), 3
C_INV_MASS = 9   # the triangle corners' inverse masses in the contact (0: held by the ground), 1/kg, 3
C_DEPTH = 12     # overlap removed so far in the sub-step (m)
C_VN0 = 13       # normal velocity of the corner relative to the triangle at the sub-step's start (m/s)
C_SHARE = 14     # the part of the normal push its body gets as velocity
C_HALF = 15      # half the cloth's thickness (m)
C_FRICTION = 16  # the sum of the friction's corrections so far in the sub-step (m), 3
#: how far outside a triangle (in barycentric weight) a point of a body's edge found over the triangle's edge may
#: be rounded and still touch it
EDGE_SLACK = 1e-9
C_DV_N = 19      # the velocity pass's normal change so far (m/s)
C_RADIUS = 20    # how far (m) the body's surface lies out from the corner (a sphere's, a capsule's radius)
C_COLS = 21
# and ints ``ci``: the body row, then the triangle's corners' particle rows
C_BODY = 0
C_CORNERS = 1
C_INT_COLS = 4


@njit_inline
def corner_count(sf, si, geom_i, s):
    """How many corners shape row ``s`` has: 8 for a box, its vertices for a hull, 1 for a sphere (its centre),
    2 for a capsule (its segment's ends), 0 for the others."""
    kind = si[s, S_TYPE]
    if kind == BOX:
        return 8
    if kind == HULL:
        return counts(geom_i, si[s, S_OFF_I])[0]
    if kind == SPHERE:
        return 1
    if kind == CAPSULE:
        return 2
    return 0


@njit_inline
def corner_radius(sf, si, s):
    """How far (m) shape row ``s``'s surface lies out from its corners: a sphere's or capsule's radius, else 0."""
    kind = si[s, S_TYPE]
    return sf[s, S_PARAMS] if kind == SPHERE or kind == CAPSULE else 0.0


@njit_inline
def corner(sf, si, geom_f, s, k):
    """Corner ``k`` of shape row ``s`` in the shape's frame (m): a box's ``(+-hx, +-hy, +-hz)``, a hull's vertex, a
    sphere's centre, a capsule's segment's ends ``(0, +-half_height, 0)``."""
    kind = si[s, S_TYPE]
    if kind == BOX:
        return (sf[s, S_PARAMS] * (1.0 if k & 1 else -1.0), sf[s, S_PARAMS + 1] * (1.0 if k & 2 else -1.0),
                sf[s, S_PARAMS + 2] * (1.0 if k & 4 else -1.0))
    if kind == SPHERE:
        return 0.0, 0.0, 0.0
    if kind == CAPSULE:
        return 0.0, sf[s, S_PARAMS + 1] * (1.0 if k & 1 else -1.0), 0.0
    o = si[s, S_OFF_F] + 3 * k
    return geom_f[o], geom_f[o + 1], geom_f[o + 2]


@njit_inline
def edge_count(si, geom_i, s):
    """How many edges of shape row ``s`` meet the cloth's border between their ends: 12 for a box, a hull's edges,
    1 for a capsule (its segment), 0 for the others."""
    kind = si[s, S_TYPE]
    if kind == BOX:
        return 12
    if kind == HULL:
        return counts(geom_i, si[s, S_OFF_I])[2]
    if kind == CAPSULE:
        return 1
    return 0


@njit_inline
def edge_corners(si, geom_i, s, k):
    """The corners (:func:`corner` indices) at the ends of edge ``k`` of shape row ``s``: a capsule's segment, a
    hull's edge, or the box edge along axis ``k // 4`` whose other two coordinates have the signs of the bits of
    ``k % 4``."""
    kind = si[s, S_TYPE]
    if kind == CAPSULE:
        return 0, 1
    if kind == HULL:
        o = edges_start(geom_i, si[s, S_OFF_I]) + EDGE_COLS * k
        return geom_i[o], geom_i[o + 1]
    axis = k // 4
    j0 = ((k & 1) << ((axis + 1) % 3)) | (((k >> 1) & 1) << ((axis + 2) % 3))
    return j0, j0 | (1 << axis)


@njit_inline
def _shape_point(sf, si, geom_f, s, local_q, k):
    """Corner ``k`` of shape row ``s`` in its body's frame (m); ``local_q`` the shape's orientation on the body."""
    r = rotated(local_q, corner(sf, si, geom_f, s, k))
    return sf[s, S_LOCAL_POS] + r[0], sf[s, S_LOCAL_POS + 1] + r[1], sf[s, S_LOCAL_POS + 2] + r[2]


@njit_inline
def _over_triangle(pf, a, b, c, x0, x1):
    """``(lo, k_lo, hi, k_hi)``: the part ``lo <= s <= hi`` of the segment ``x(s) = x0 + s (x1 - x0)``, ``0 <= s <=
    1``, whose foot on the plane of the triangle of particle rows ``a b c`` lies inside it (``lo >= hi``: none), and
    the triangle's edges it leaves it over at each end (the edge opposite corner ``k``; -1: the segment's end).  The
    foot's barycentric weights are linear in ``s``, so each bounds ``s`` on one side where it changes sign."""
    u = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
    v = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
    f0 = foot_weights(u, v, (x0[0] - pf[a, P_POS], x0[1] - pf[a, P_POS + 1], x0[2] - pf[a, P_POS + 2]))
    f1 = foot_weights(u, v, (x1[0] - pf[a, P_POS], x1[1] - pf[a, P_POS + 1], x1[2] - pf[a, P_POS + 2]))
    lo, hi, k_lo, k_hi = 0.0, 1.0, -1, -1
    for k in range(3):
        if f0[k] < 0.0 and f1[k] < 0.0:
            return 1.0, -1, 0.0, -1
        if f0[k] < 0.0 and f0[k] / (f0[k] - f1[k]) > lo:
            lo, k_lo = f0[k] / (f0[k] - f1[k]), k
        elif f1[k] < 0.0 and f0[k] / (f0[k] - f1[k]) < hi:
            hi, k_hi = f0[k] / (f0[k] - f1[k]), k
    return lo, k_lo, hi, k_hi


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
    velocity) comes as near the triangle's box, and a round shape's radius nearer; its side of a triangle: the one
    its centre is on at the step's start."""
    pf, pi, tri, cloth_f, bf, bi = borrow(pf), borrow(pi), borrow(tri), borrow(cloth_f), borrow(bf), borrow(bi)
    sf, si, geom_f, geom_i, out = borrow(sf), borrow(si), borrow(geom_f), borrow(geom_i), borrow(out)
    if n_tri == 0:
        return 0
    lo_all, hi_all = _swept_bounds(pf, tri, n_tri, dt)
    thickest = 0.0
    for t in range(n_tri):
        thickest = max(thickest, 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS])
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
            # (within half the thickest cloth's thickness: a ball resting on a sheet is no nearer)
            if not _overlap(box_lo, box_hi, lo_all, hi_all, thickest):
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
                grow_corner = half + reach + corner_radius(sf, si, s)
                near = False
                for j in range(corner_count(sf, si, geom_i, s)):
                    x0, x1 = _corner_path(sf, si, geom_f, s, j, start, end, q_start, q_end)
                    if _overlap((min(x0[0], x1[0]), min(x0[1], x1[1]), min(x0[2], x1[2])),
                                (max(x0[0], x1[0]), max(x0[1], x1[1]), max(x0[2], x1[2])), lo, hi, grow_corner):
                        near = True
                        break
                # (or, for a triangle on the cloth's border, an edge's path: the box of its ends' paths; a plank lying
                # across a narrow strip has none of its corners over the strip)
                for j in range(edge_count(si, geom_i, s) if tri[t, T_BORDER] != 0 else 0):
                    if near:
                        break
                    j0, j1 = edge_corners(si, geom_i, s, j)
                    x0, x1 = _corner_path(sf, si, geom_f, s, j0, start, end, q_start, q_end)
                    y0, y1 = _corner_path(sf, si, geom_f, s, j1, start, end, q_start, q_end)
                    near = _overlap((min(x0[0], x1[0], y0[0], y1[0]), min(x0[1], x1[1], y0[1], y1[1]),
                                     min(x0[2], x1[2], y0[2], y1[2])),
                                    (max(x0[0], x1[0], y0[0], y1[0]), max(x0[1], x1[1], y0[1], y1[1]),
                                     max(x0[2], x1[2], y0[2], y1[2])), lo, hi, grow_corner)
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
def _corner_path(sf, si, geom_f, s, k, start, end, q_start, q_end):
    """Where corner ``k`` of shape row ``s`` is (m, world) at the step's start and end, the shape's centre at ``start``
    and ``end`` and its orientation ``q_start`` and ``q_end``."""
    local = corner(sf, si, geom_f, s, k)
    r0, r1 = rotated(q_start, local), rotated(q_end, local)
    return (start[0] + r0[0], start[1] + r0[1], start[2] + r0[2]), (end[0] + r1[0], end[1] + r1[1], end[2] + r1[2])


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
def corner_capacity(sf, si, geom_i, tri, pairs, n_pairs):
    """How many corner contacts the candidate pairs can make in a sub-step (each corner against each of its
    shape's candidate triangles, and both ends of the part of each edge over a triangle on the cloth's border)."""
    total = 0
    for k in range(min(n_pairs, pairs.shape[0])):
        s = pairs[k, 0]
        total += corner_count(sf, si, geom_i, s)
        if tri[pairs[k, 1], T_BORDER] != 0:
            total += 2 * edge_count(si, geom_i, s)
    return total


@njit
def corner_contacts(pf, tri, cloth_f, bf, bi, bx, sf, si, geom_f, geom_i, pairs, n_pairs, back, h, ground, slot, cf,
                    ci):
    """The position pass over the candidate ``(shape, triangle, side)`` pairs (module docstring) in the sub-step
    of ``h`` s ending ``back`` s before the step's end, with the particles that the ground holds (``ground``,
    ``particle_contacts.ground_normals``): the corners that touch their triangles are found, recorded in ``cf`` /
    ``ci`` (``C_*`` columns; ``corner_capacity`` rows) and solved in :func:`corner_passes` passes; returns how many
    there are."""
    # (borrowed, _numba/jit.py: each helper inlined in the loops below took and gave back a reference to every
    # array it was handed, two atomic operations an array a call, 15 % of a draped sheet's step)
    pf, tri, cloth_f, bf, bi, bx = borrow(pf), borrow(tri), borrow(cloth_f), borrow(bf), borrow(bi), borrow(bx)
    sf, si, geom_f, geom_i, pairs = borrow(sf), borrow(si), borrow(geom_f), borrow(geom_i), borrow(pairs)
    ground, slot, cf, ci = borrow(ground), borrow(slot), borrow(cf), borrow(ci)
    nc = 0
    # the static and kinematic bodies' contacts first, whose triangles they then hold (:func:`_hold_triangles`),
    # then the movable bodies', which cannot push those triangles into them
    for movable in (False, True):
        if movable:
            _hold_triangles(cf, ci, min(nc, cf.shape[0]), ground)
        nc = _find_contacts(pf, tri, cloth_f, bf, bi, bx, sf, si, geom_f, geom_i, pairs, n_pairs, back, h, ground,
                            slot, cf, ci, nc, movable)
    n_contacts = min(nc, cf.shape[0])
    for _ in range(corner_passes(bf, bi, ci, n_contacts)):
        for c in range(n_contacts):
            _solve(pf, bf, bi, bx, cf, ci, c, back, h)
    return n_contacts


@njit_inline
def _hold_triangles(cf, ci, n_contacts, ground):
    """Count the corners of the triangles touched by the first ``n_contacts`` corner contacts (all of static or
    kinematic bodies) as held by those bodies in ``ground`` (``particle_contacts.ground_normals``: each contact's
    push on its triangle, ``-n``, added to its corners' normals): a triangle squeezed between such a body and a
    movable one is then held, and the movable body takes the push.  Left to share it by inverse masses, a box
    pressing a sheet's triangle into a static ball moved the light triangle back into the ball at each pass, the
    ball's contact pushed it out further, and the two pushes grew by half at every pass (boxes dropped on a sheet
    draped over a ball flew off at up to 1e5 m/s)."""
    for c in range(n_contacts):
        for q in range(3):
            p = ci[c, C_CORNERS + q]
            for k in range(3):
                ground[p, k] -= cf[c, C_NORMAL + k]
            ground[p, 3] += 1.0


@njit_inline
def _find_contacts(pf, tri, cloth_f, bf, bi, bx, sf, si, geom_f, geom_i, pairs, n_pairs, back, h, ground, slot, cf,
                   ci, nc, movable):
    """Record the contacts of the candidate pairs whose body is ``movable`` (``body_motion.pushable``) or not
    after the ``nc`` in ``cf`` / ``ci`` (:func:`corner_contacts`); returns the new count."""
    for k in range(n_pairs):
        s, t, side = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        if slot[tri[t, T_A]] >= 0 or slot[tri[t, T_A + 1]] >= 0 or slot[tri[t, T_A + 2]] >= 0:
            continue
        b = si[s, S_BODY]
        if pushable(bf, bi, b) != movable:
            continue
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        centre = to_world(x_b, q_b, (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]))
        # (no corner of a shape whose ball lies wholly in front of the triangle's slab can touch it)
        a, _, _, normal, ok = _triangle_frame(pf, tri, t)
        height = side * ((centre[0] - pf[a, P_POS]) * normal[0] + (centre[1] - pf[a, P_POS + 1]) * normal[1]
                         + (centre[2] - pf[a, P_POS + 2]) * normal[2])
        if not ok or height >= sf[s, S_RADIUS] + 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]:
            continue
        local_q = (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2], sf[s, S_LOCAL_QUAT + 3])
        radius = corner_radius(sf, si, s)
        for j in range(corner_count(sf, si, geom_i, s)):
            nc = _touch(pf, tri, cloth_f, bf, bi, bx, b, x_b, q_b, _shape_point(sf, si, geom_f, s, local_q, j), radius,
                        t, side, h, ground, cf, ci, nc, 0.0)
        # the points where an edge passes over the cloth's border (module docstring)
        border = tri[t, T_BORDER]
        if border == 0:
            continue
        a, bb, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
        for j in range(edge_count(si, geom_i, s)):
            j0, j1 = edge_corners(si, geom_i, s, j)
            l0, l1 = _shape_point(sf, si, geom_f, s, local_q, j0), _shape_point(sf, si, geom_f, s, local_q, j1)
            lo, k_lo, hi, k_hi = _over_triangle(pf, a, bb, c, to_world(x_b, q_b, l0), to_world(x_b, q_b, l1))
            if lo >= hi:
                continue
            for end, k in ((lo, k_lo), (hi, k_hi)):
                if k >= 0 and (border >> k) & 1:
                    local = (l0[0] + end * (l1[0] - l0[0]), l0[1] + end * (l1[1] - l0[1]),
                             l0[2] + end * (l1[2] - l0[2]))
                    nc = _touch(pf, tri, cloth_f, bf, bi, bx, b, x_b, q_b, local, radius, t, side, h, ground, cf, ci,
                                nc, EDGE_SLACK)
    return nc


@njit_inline
def corner_passes(bf, bi, ci, n_contacts):
    """How many passes the sub-step's corner contacts (rows ``0 .. n_contacts - 1`` of ``ci``) are solved in:
    ``CORNER_PASSES`` when one of their bodies can be moved, else 1.  The passes are for a body turning under its
    corners; against static and kinematic bodies only the cloth moves, and each contact is one more vertex-like
    contact of the sub-step, solved once as the vertices' contacts are."""
    for c in range(n_contacts):
        if pushable(bf, bi, ci[c, C_BODY]):
            return CORNER_PASSES
    return 1


@njit_inline
def _touch(pf, tri, cloth_f, bf, bi, bx, b, x_b, q_b, local, radius, t, side, h, ground, cf, ci, nc, slack):
    """Record in row ``nc`` of ``cf`` / ``ci`` the contact of the corner at ``local`` (m, in the frame of body row
    ``b``, posed ``x_b``, ``q_b``; its surface ``radius`` m out from it) with triangle ``t`` from side ``side``, if
    it touches it (module docstring); returns the new count.  ``slack``: how far outside the triangle (in
    barycentric weight) the corner's foot may lie and still touch it, its weights then taken back onto the triangle
    (``EDGE_SLACK`` for a point of an edge over the triangle's edge, 0 for a corner)."""
    a, bb, c, normal, ok = _triangle_frame(pf, tri, t)
    if not ok or nc >= cf.shape[0]:
        return nc
    n = (side * normal[0], side * normal[1], side * normal[2])
    half = 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]
    x_c = to_world(x_b, q_b, local)
    x_c = (x_c[0] - radius * n[0], x_c[1] - radius * n[1], x_c[2] - radius * n[2])
    w = (x_c[0] - pf[a, P_POS], x_c[1] - pf[a, P_POS + 1], x_c[2] - pf[a, P_POS + 2])
    d = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    if d >= half:
        return nc
    # barycentric weights of the corner's foot on the triangle's plane
    b0, b1, b2 = foot_weights(
        (pf[bb, P_POS] - pf[a, P_POS], pf[bb, P_POS + 1] - pf[a, P_POS + 1], pf[bb, P_POS + 2] - pf[a, P_POS + 2]),
        (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2]), w)
    if b0 < -slack or b1 < -slack or b2 < -slack:
        return nc
    if b0 < 0.0 or b1 < 0.0 or b2 < 0.0:         # (a point of an edge over the triangle's edge, rounded outside)
        b0, b1, b2 = max(b0, 0.0), max(b1, 0.0), max(b2, 0.0)
        total = b0 + b1 + b2
        b0, b1, b2 = b0 / total, b1 / total, b2 / total
    # the corner's motion relative to the triangle's point under it in this sub-step: one that was behind the
    # triangle at the sub-step's start is left alone
    motion = _relative_motion(pf, bf, bi, bx, b, x_b, x_c, (a, bb, c), (b0, b1, b2),
                              (pf[a, P_INV_MASS], pf[bb, P_INV_MASS], pf[c, P_INV_MASS]), h)
    if d - (motion[0] * n[0] + motion[1] * n[1] + motion[2] * n[2]) < -half:
        return nc
    back_n = (-n[0], -n[1], -n[2])
    wc = inverse_mass_along(bf, bi, b, x_b, q_b, x_c, n)
    wa, wb, wcc = held_inverse_mass(pf, ground, a, back_n), held_inverse_mass(pf, ground, bb, back_n), \
        held_inverse_mass(pf, ground, c, back_n)
    u = point_velocity(bf, bi, bx, b, x_b, x_c)
    share = 1.0
    # (a triangle whose free corners carry under a tenth of the contact's point counts as held: pushed through a
    # free corner of weight b alone, that corner moves 1 / b times the push)
    if (b0 if wa > 0.0 else 0.0) + (b1 if wb > 0.0 else 0.0) + (b2 if wcc > 0.0 else 0.0) < 0.1:
        wa = wb = wcc = 0.0
    if b0 * b0 * wa + b1 * b1 * wb + b2 * b2 * wcc <= 0.0:
        if wc > 0.0:
            # (the ground holds the triangle: the body takes the push, as velocity the part its own motion closed in
            # the sub-step)
            closing = -(u[0] * n[0] + u[1] * n[1] + u[2] * n[2]) * h
            share = min(1.0, max(0.0, closing) / (half - d))
        else:
            wa, wb, wcc = pf[a, P_INV_MASS], pf[bb, P_INV_MASS], pf[c, P_INV_MASS]
    vn0 = 0.0
    for k in range(3):
        vn0 += (u[k] - b0 * pf[a, P_VEL0 + k] - b1 * pf[bb, P_VEL0 + k] - b2 * pf[c, P_VEL0 + k]) * n[k]
    for k in range(3):
        cf[nc, C_WEIGHTS + k] = (b0, b1, b2)[k]
        cf[nc, C_NORMAL + k] = n[k]
        cf[nc, C_LOCAL + k] = local[k]
        cf[nc, C_INV_MASS + k] = (wa, wb, wcc)[k]
    cf[nc, C_RADIUS] = radius
    cf[nc, C_DEPTH] = 0.0
    cf[nc, C_VN0] = vn0
    cf[nc, C_SHARE] = share
    cf[nc, C_HALF] = half
    for k in range(3):
        cf[nc, C_FRICTION + k] = 0.0
    ci[nc, C_BODY] = b
    ci[nc, C_CORNERS] = a
    ci[nc, C_CORNERS + 1] = bb
    ci[nc, C_CORNERS + 2] = c
    return nc + 1


@njit_inline
def _contact_point(cf, c, x_b, q_b):
    """The point (m, world) of corner contact ``c``'s body, posed ``x_b``, ``q_b``, that touches the triangle: its
    corner, out by its radius towards the triangle."""
    x = to_world(x_b, q_b, (cf[c, C_LOCAL], cf[c, C_LOCAL + 1], cf[c, C_LOCAL + 2]))
    r = cf[c, C_RADIUS]
    return x[0] - r * cf[c, C_NORMAL], x[1] - r * cf[c, C_NORMAL + 1], x[2] - r * cf[c, C_NORMAL + 2]


@njit_inline
def _solve(pf, bf, bi, bx, cf, ci, c, back, h):
    """One pass over corner contact ``c`` (module docstring): its overlap, as it is now, removed, the push out
    summed over the passes kept ``>= 0``; then its friction, bounded by the pushes so far."""
    b = ci[c, C_BODY]
    x_b, q_b = body_pose(bf, bi, bx, b, back)
    x_c = _contact_point(cf, c, x_b, q_b)
    corners = (ci[c, C_CORNERS], ci[c, C_CORNERS + 1], ci[c, C_CORNERS + 2])
    weights = (cf[c, C_WEIGHTS], cf[c, C_WEIGHTS + 1], cf[c, C_WEIGHTS + 2])
    inverse_masses = (cf[c, C_INV_MASS], cf[c, C_INV_MASS + 1], cf[c, C_INV_MASS + 2])
    n = (cf[c, C_NORMAL], cf[c, C_NORMAL + 1], cf[c, C_NORMAL + 2])
    d = 0.0
    for k in range(3):
        foot = 0.0
        for q in range(3):
            foot += weights[q] * pf[corners[q], P_POS + k]
        d += (x_c[k] - foot) * n[k]
    denominator = inverse_mass_along(bf, bi, b, x_b, q_b, x_c, n)
    for q in range(3):
        denominator += weights[q] * weights[q] * inverse_masses[q]
    if denominator <= 0.0:
        return
    # (the push of this pass: the overlap left, or back by what earlier passes pushed too far, never to a pull)
    push = max(cf[c, C_HALF] - d, -cf[c, C_DEPTH])
    if push != 0.0:
        _move(pf, bf, bi, bx, b, x_b, q_b, x_c, corners, weights, inverse_masses, n, push / denominator, h,
              cf[c, C_SHARE])
        cf[c, C_DEPTH] += push
    _friction(pf, bf, bi, bx, cf, c, b, x_b, q_b, x_c, corners, weights, inverse_masses, n, h)


@njit_inline
def _relative_motion(pf, bf, bi, bx, b, x_b, x_c, corners, weights, movable, h):
    """How far (m, a 3-tuple) the body's point at ``x_c`` moved in the sub-step of ``h`` s relative to the
    triangle's point of barycentric ``weights`` (its ``corners``' rows), counting the motion of the corners whose
    ``movable`` entry is positive (one that the ground holds moves with it)."""
    u = point_velocity(bf, bi, bx, b, x_b, x_c)
    # (three numbers, not a list: a list is allocated on the heap at every call, and this runs for every corner
    # contact in every pass)
    ox, oy, oz = u[0] * h, u[1] * h, u[2] * h
    for q in range(3):
        p = corners[q]
        if movable[q] > 0.0:
            ox -= weights[q] * (pf[p, P_POS] - pf[p, P_PREV])
            oy -= weights[q] * (pf[p, P_POS + 1] - pf[p, P_PREV + 1])
            oz -= weights[q] * (pf[p, P_POS + 2] - pf[p, P_PREV + 2])
    return ox, oy, oz


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
def _friction(pf, bf, bi, bx, cf, c, b, x_b, q_b, x_c, corners, weights, inverse_masses, n, h):
    """Coulomb friction of corner contact ``c`` (module docstring) on the corner's slip ``s`` across ``n`` in the
    sub-step, with ``F`` the sum of the friction's corrections so far and ``D`` the overlap removed so far:

        F' = F - s                            if |F - s| <= mu_s D    (it holds: the slip is undone)
        F' = (F - s) mu_d D / |F - s|         else                    (it slides)

    and the contact moved by ``F' - F``.  (Summed as a vector, a later pass takes back what an earlier one did
    against a slip that the other corners' pushes have since undone: summed as lengths, a cube striking a held
    sheet flat on its corners left it sideways at 2 cm/s.)"""
    # (the motion of every corner counts: the ground holds a corner against the normal only, and a sheet sliding
    # on it carries the body; counting only the movable ones, a box stood still on a sheet sliding down a 30 degree
    # slope under it)
    motion = _relative_motion(pf, bf, bi, bx, b, x_b, x_c, corners, weights,
                              (pf[corners[0], P_INV_MASS], pf[corners[1], P_INV_MASS], pf[corners[2], P_INV_MASS]), h)
    along = motion[0] * n[0] + motion[1] * n[1] + motion[2] * n[2]
    wx = cf[c, C_FRICTION] - (motion[0] - along * n[0])
    wy = cf[c, C_FRICTION + 1] - (motion[1] - along * n[1])
    wz = cf[c, C_FRICTION + 2] - (motion[2] - along * n[2])
    size = math.sqrt(wx ** 2 + wy ** 2 + wz ** 2)
    a = corners[0]
    mu_s = math.sqrt(pf[a, P_STATIC_FRICTION] * bf[b, STATIC_FRICTION])
    if size > mu_s * cf[c, C_DEPTH]:
        scale = math.sqrt(pf[a, P_FRICTION] * bf[b, FRICTION]) * cf[c, C_DEPTH] / size
        wx, wy, wz = wx * scale, wy * scale, wz * scale
    change = (wx - cf[c, C_FRICTION], wy - cf[c, C_FRICTION + 1], wz - cf[c, C_FRICTION + 2])
    length = math.sqrt(change[0] ** 2 + change[1] ** 2 + change[2] ** 2)
    if length <= 0.0:
        return
    unit = (change[0] / length, change[1] / length, change[2] / length)
    denominator = inverse_mass_along(bf, bi, b, x_b, q_b, x_c, unit)
    for q in range(3):
        denominator += weights[q] * weights[q] * inverse_masses[q]
    if denominator > 0.0:
        _move(pf, bf, bi, bx, b, x_b, q_b, x_c, corners, weights, inverse_masses, unit, length / denominator, h, 1.0)
        cf[c, C_FRICTION], cf[c, C_FRICTION + 1], cf[c, C_FRICTION + 2] = wx, wy, wz


@njit
def corner_velocity_pass(pf, bf, bi, bx, cf, ci, n_contacts, back, h, resting_speed):
    """The velocity pass of the sub-step's corner contacts (rows ``0 .. n_contacts - 1`` of ``cf`` / ``ci``), on
    the particles' velocities taken from their positions and the bodies' velocities, at the bodies' poses ``back``
    s before the step's end: sequential impulses, :func:`corner_passes` passes.  With ``v_n`` the normal velocity of
    the corner relative to the triangle's point under it, each contact's is brought to

        v_n' = -e v_n0     if the corner struck at ``v_n0 < -resting_speed``, else 0,

    by impulses whose sum over the passes only pushes: ``dv_n / (w_c + sum_i b_i^2 w_i)`` (the generalised inverse
    masses of the position pass), the body's part at the corner (body_motion.push_body) and ``-w_i b_i`` times it to
    each triangle corner's velocity.  The position pass gives a body only the part of a push that its own motion
    closed as velocity, and what is left of a corner's approach is stopped here.  A box with restitution struck flat
    on its four corners took the whole bounce at the first of them in one pass over them: it spun at 8 rad/s.  No
    friction here: the position pass has both static and dynamic friction, and a second, dynamic friction here kept
    a 1 kg box on the corner-held trampoline bobbing by 3 mm after 12 s, 9 mm higher on the sheet."""
    pf, bf, bi, bx, cf, ci = borrow(pf), borrow(bf), borrow(bi), borrow(bx), borrow(cf), borrow(ci)
    n_contacts = min(n_contacts, cf.shape[0])
    for c in range(n_contacts):
        cf[c, C_DV_N] = 0.0
    for _ in range(corner_passes(bf, bi, ci, n_contacts)):
        for c in range(n_contacts):
            b, a = ci[c, C_BODY], ci[c, C_CORNERS]
            n = (cf[c, C_NORMAL], cf[c, C_NORMAL + 1], cf[c, C_NORMAL + 2])
            v = _corner_velocity(pf, bf, bi, bx, cf, ci, c, back)
            vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2]
            vn0 = cf[c, C_VN0]
            target = -max(pf[a, P_RESTITUTION], bf[b, RESTITUTION]) * vn0 if vn0 < -resting_speed else 0.0
            total = max(cf[c, C_DV_N] + target - vn, 0.0)
            _change_velocity(pf, bf, bi, bx, cf, ci, c, back, n, total - cf[c, C_DV_N])
            cf[c, C_DV_N] = total


@njit_inline
def _corner_velocity(pf, bf, bi, bx, cf, ci, c, back):
    """The velocity (m/s, a 3-tuple) of corner contact ``c``'s corner relative to the triangle's point under it."""
    b = ci[c, C_BODY]
    x_b, q_b = body_pose(bf, bi, bx, b, back)
    u = point_velocity(bf, bi, bx, b, x_b, _contact_point(cf, c, x_b, q_b))
    vx, vy, vz = u[0], u[1], u[2]
    for q in range(3):
        p, weight = ci[c, C_CORNERS + q], cf[c, C_WEIGHTS + q]
        vx -= weight * pf[p, P_VEL]
        vy -= weight * pf[p, P_VEL + 1]
        vz -= weight * pf[p, P_VEL + 2]
    return vx, vy, vz


@njit_inline
def _change_velocity(pf, bf, bi, bx, cf, ci, c, back, along, dv):
    """Change corner contact ``c``'s relative velocity (:func:`_corner_velocity`) by ``dv`` (m/s) along the unit
    ``along`` with an impulse between the body and the triangle's corners (:func:`corner_velocity_pass`)."""
    if dv == 0.0:
        return
    b = ci[c, C_BODY]
    x_b, q_b = body_pose(bf, bi, bx, b, back)
    point = _contact_point(cf, c, x_b, q_b)
    denominator = inverse_mass_along(bf, bi, b, x_b, q_b, point, along)
    for q in range(3):
        weight = cf[c, C_WEIGHTS + q]
        denominator += weight * weight * cf[c, C_INV_MASS + q]
    if denominator <= 0.0:
        return
    dlambda = dv / denominator
    # (an impulse, kg m/s: push_body's positional impulse over a time of 1 s)
    push_body(bf, bi, bx, b, x_b, q_b, point, (dlambda * along[0], dlambda * along[1], dlambda * along[2]), 1.0,
              False, 1.0)
    for q in range(3):
        p = ci[c, C_CORNERS + q]
        for k in range(3):
            pf[p, P_VEL + k] -= cf[c, C_INV_MASS + q] * cf[c, C_WEIGHTS + q] * dlambda * along[k]
