"""Particles against the bodies' shapes (every shape: planes, boxes, spheres, capsules, hulls, meshes, height
fields), and the contacts' friction and restitution, two ways with the bodies.

A particle is a sphere of its radius: its contacts with a shape are the narrow phase's sphere pair tests
(``collide_pair``), ghost-free on meshes as for bodies, compiled for the kinds of shape the world has (its
coverage, ``shape_types.COVER_*``: the sphere-primitive tests alone, meshes too, or height fields and hulls
too).  Once per step, the shapes whose boxes the particle's swept box meets are listed as candidates; in each
sub-step, each candidate is tested at the poses the bodies have then (``body_motion``), and every overlap
``d`` along the unit normal ``n`` (from the shape to the particle) is removed in position, split by the
generalised inverse masses:

    dlambda = d / (w_p + w_b),     x_p += w_p dlambda n,    the body gets the positional impulse -dlambda n

Static friction (Coulomb's cone in position, Mueller et al. 2020): the particle's motion across the surface
in this sub-step, relative to the surface, is undone when it is shorter than ``mu_s d``.  After the
velocities are taken from the positions, the velocity pass applies dynamic friction to the contacts that
slid, a change of at most ``mu_d d / h`` against the sliding velocity (the same impulse bound as
Coulomb's law, ``|f_t| <= mu_d f_n``), and restitution: a contact that approached faster than gravity
makes in a sub-step leaves with ``-e`` times its approach speed; any other leaves no faster than it came
(an overlap, say of particles made overlapping a shape, is removed in position but launches nothing).
Materials combine as for bodies: friction by geometric mean, restitution by maximum.
"""
import math

from .._numba.jit import borrow, njit, njit_inline
from ..collision.pairs.dispatch import collide_sphere_shape
from ..collision.shape_types import COVER_GROUND, COVER_MESHES, COVER_SPHERES, N_SHAPE_PARAMS
from ..math3d import quat_product, quat_to_matrix
from ..state.layout import (F_ALIVE, F_SENSOR, FLAGS, FRICTION, OMEGA, RESTITUTION, S_BODY, S_LOCAL_POS,
                            S_LOCAL_QUAT, S_OFF_F, S_OFF_I, S_PARAMS, S_RADIUS, S_TYPE, SHAPE_COUNT, SHAPE_START,
                            STATIC_FRICTION, VEL)
from .body_motion import BX_LOAD, body_pose, inverse_mass_along, point_velocity, push_body, pushable, to_world
from .particle_layout import (K_DEPTH, K_E, K_KIND, K_MU, K_NORMAL, K_OTHER, K_PARTICLE, K_POINT, K_STUCK, K_VN0,
                              KK_BODY, KK_PARTICLE, P_FLAGS, P_FORCE, P_FRICTION, P_INV_MASS, P_PIN_BODY, P_POS,
                              P_PREV, P_RADIUS, P_RESTITUTION, P_STATIC_FRICTION, P_SUPPORT, P_VEL, P_VEL0, PP_PINNED,
                              PP_SOFT)

#: a soft body's node touches a shape within this fraction of its radius (shape_contacts)
SOFT_TOUCH = 1e-3


@njit
def _swept_box(pf, p, dt, grow):
    """``(lo, hi)`` tuples: the box particle row ``p`` sweeps in a step of ``dt`` s at its velocity, grown by
    ``grow`` (m)."""
    x0, x1, x2 = pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2]
    y0, y1, y2 = x0 + pf[p, P_VEL] * dt, x1 + pf[p, P_VEL + 1] * dt, x2 + pf[p, P_VEL + 2] * dt
    return ((min(x0, y0) - grow, min(x1, y1) - grow, min(x2, y2) - grow),
            (max(x0, y0) + grow, max(x1, y1) + grow, max(x2, y2) + grow))


@njit_inline
def shape_query(coverage, pf, bf, bi, bx, sf, si, geom_f, geom_i, p, s, back, prediction, scratch_f, scratch_i,
                sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """The contact rows of particle row ``p`` (a sphere of its radius) with shape row ``s``, its body posed
    ``back`` s before the step's end, gaps up to ``prediction`` (m) included: ``(rows, x_b, q_b)``, the rows in
    ``scratch_f`` / ``scratch_i`` (``collide_pair``'s layout, normals from the particle to the shape) and the
    body's pose.  Scratch: ``sphere`` (N_SHAPE_PARAMS), ``pos_a``, ``pos_s`` (3), ``rot_a`` (the identity),
    ``rot_s`` (3, 3), ``q_s`` (4).  ``coverage``: the world's (a constant where this is inlined)."""
    b = si[s, S_BODY]
    x_b, q_b = body_pose(bf, bi, bx, b, back)
    centre = to_world(x_b, q_b, (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]))
    quat_product_into(q_b, sf, s, q_s)
    quat_to_matrix(q_s, rot_s)
    for k in range(3):
        pos_s[k] = centre[k]
        pos_a[k] = pf[p, P_POS + k]
    sphere[0] = pf[p, P_RADIUS]
    m = collide_sphere_shape(coverage, pos_a, rot_a, sphere, si[s, S_TYPE], pos_s, rot_s,
                             sf[s, S_PARAMS:S_PARAMS + N_SHAPE_PARAMS], geom_f, geom_i, si[s, S_OFF_F], si[s, S_OFF_I],
                             prediction, scratch_f, scratch_i, 0)
    return min(m, scratch_f.shape[0]), x_b, q_b


@njit_inline
def _shape_candidates(coverage, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up,
                      out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """List ``(particle, shape, under)`` rows into ``out`` for every particle and shape that may touch in the step (a
    pinned particle: the shapes of bodies it can push, other than the one it is pinned to; none for a soft
    body's): the particle's swept box meets the body's box (sensors left out), and the shape lies within the
    particle's and its body's reach of the particle at the poses of the step's end (one exact query per pair and
    step; the sub-steps query only these).  Returns how many there are (rows past ``out``'s end are not written).
    ``reach`` (m): how far a particle may fall in the step beyond its velocity's sweep (its user force adds
    :func:`forced_reach`).  ``under`` is 1 where the particle may hold the shape up, against gravity: the normal of
    one of their contacts from the particle to the shape, the body at its pose at the step's start, within
    ``UNDER_ANGLE`` of ``up`` (the unit vector against gravity; zero: not asked, all 0), load_substeps.py."""
    n = 0
    for p in range(n_particles):
        # (a pinned particle, held by the world or as a point of a body, still pushes the other bodies it meets: a
        # ball dropped on a sheet held at every vertex fell through it; not a soft body's pinned node, whose body
        # meets the bodies through its free nodes' implicit step: pushing rigidly, the game's bumper, pinned at its
        # base, threw the marble back at 0.29 m/s instead of 0.5)
        pinned = (pi[p, P_FLAGS] & PP_PINNED) != 0
        if pinned and (pi[p, P_FLAGS] & PP_SOFT) != 0:
            continue
        own = reach + forced_reach(pf, p, dt)
        lo, hi = _swept_box(pf, p, dt, pf[p, P_RADIUS] + own)
        travel = math.sqrt(pf[p, P_VEL] ** 2 + pf[p, P_VEL + 1] ** 2 + pf[p, P_VEL + 2] ** 2) * dt + own
        for b in range(nb):
            f = bi[b, FLAGS]
            if (f & F_ALIVE) == 0 or (f & F_SENSOR) != 0:
                continue
            if pinned and (pi[p, P_PIN_BODY] == b or not pushable(bf, bi, b)):
                continue
            if aabbs[b, 0] > hi[0] or aabbs[b, 1] > hi[1] or aabbs[b, 2] > hi[2] \
                    or aabbs[b, 3] < lo[0] or aabbs[b, 4] < lo[1] or aabbs[b, 5] < lo[2]:
                continue
            v_b = math.sqrt(bf[b, VEL] ** 2 + bf[b, VEL + 1] ** 2 + bf[b, VEL + 2] ** 2)
            w_b = math.sqrt(bf[b, OMEGA] ** 2 + bf[b, OMEGA + 1] ** 2 + bf[b, OMEGA + 2] ** 2)
            s0 = bi[b, SHAPE_START]
            for s in range(s0, s0 + bi[b, SHAPE_COUNT]):
                turn = w_b * min(sf[s, S_RADIUS] + 1e-12, 1e12) * dt if w_b > 0.0 else 0.0
                rows, _, _ = shape_query(coverage, pf, bf, bi, bx, sf, si, geom_f, geom_i, p, s, 0.0,
                                         travel + v_b * dt + turn, scratch_f, scratch_i, sphere, pos_a, rot_a,
                                         pos_s, rot_s, q_s)
                if rows > 0:
                    if n < out.shape[0]:
                        # (under: seen from the body's pose at the step's start, before the bodies' step moved it
                        # through what it lands on; only a body the particles can move lies on them)
                        out[n, 2] = 0
                        if pushable(bf, bi, b) and (up[0] != 0.0 or up[1] != 0.0 or up[2] != 0.0):
                            rows, _, _ = shape_query(coverage, pf, bf, bi, bx, sf, si, geom_f, geom_i, p, s, dt,
                                                     travel + v_b * dt + turn, scratch_f, scratch_i, sphere, pos_a,
                                                     rot_a, pos_s, rot_s, q_s)
                            for j in range(rows):
                                if scratch_f[j, 3] * up[0] + scratch_f[j, 4] * up[1] + scratch_f[j, 5] * up[2] \
                                        > UNDER_COS:
                                    out[n, 2] = 1
                    n = append_pair(out, n, p, s)
    return n


#: how far (rad) from straight up the normal from a particle to a shape may turn for the particle to be under the
#: shape, holding it up (``_shape_candidates``): a box tilted by 60 degrees on a sheet still lies on it
UNDER_ANGLE = math.radians(60.0)
UNDER_COS = math.cos(UNDER_ANGLE)


@njit_inline
def forced_reach(pf, p, dt):
    """How far (m) particle row ``p``'s user force ``F`` can move it in a step of ``dt`` s from rest, ``w |F|
    dt^2`` (``w`` its inverse mass; the sub-steps' semi-implicit Euler moves it ``(1 + 1/n) / 2`` of that): a
    particle pressed at 100 g from rest onto the ground, boxed by its velocity and gravity alone, ended the step
    10 cm under the plane."""
    return pf[p, P_INV_MASS] * math.sqrt(pf[p, P_FORCE] ** 2 + pf[p, P_FORCE + 1] ** 2
                                         + pf[p, P_FORCE + 2] ** 2) * dt * dt


@njit_inline
def append_pair(out, n, a, b):
    """Write the candidate ``(a, b)`` into row ``n`` of ``out`` if there is room; returns ``n + 1`` either way."""
    if n < out.shape[0]:
        out[n, 0] = a
        out[n, 1] = b
    return n + 1


@njit_inline
def relative_velocity(pf, bf, bi, bx, kind, p, other, x_b, point):
    """Velocity (m/s) of particle row ``p`` relative to the other side at ``point`` (a body's material point,
    the body's centre at ``x_b``; or another particle)."""
    if kind == KK_PARTICLE:
        return (pf[p, P_VEL] - pf[other, P_VEL], pf[p, P_VEL + 1] - pf[other, P_VEL + 1],
                pf[p, P_VEL + 2] - pf[other, P_VEL + 2])
    u = point_velocity(bf, bi, bx, other, x_b, point)
    return pf[p, P_VEL] - u[0], pf[p, P_VEL + 1] - u[1], pf[p, P_VEL + 2] - u[2]


@njit
def ground_normals(pf, bf, bi, kf, ki, nk, ground):
    """Fill ``ground`` (n, 5) with what holds each particle in this sub-step: the sum of the unit
    normals of its contacts (``kf``/``ki``, ``nk`` of them) with shapes and bodies the particles cannot move
    (static, kinematic), their count (0: nothing holds it), and the largest static friction coefficient of
    those whose static friction held it in place (0: none did; :func:`anchored_by_ground`)."""
    ground[:] = 0.0
    for c in range(min(nk, kf.shape[0])):
        b = ki[c, K_OTHER]
        if ki[c, K_KIND] == KK_BODY and not pushable(bf, bi, b):
            p = ki[c, K_PARTICLE]
            for k in range(3):
                ground[p, k] += kf[c, K_NORMAL + k]
            ground[p, 3] += 1.0
            if kf[c, K_STUCK] != 0.0:
                ground[p, 4] = max(ground[p, 4], math.sqrt(pf[p, P_STATIC_FRICTION] * bf[b, STATIC_FRICTION]))


@njit_inline
def held_by_ground(pf, ground, p, along):
    """Whether a push along ``along`` (a unit 3-tuple) would move particle ``p`` (not pinned) into what holds it
    (:func:`ground_normals`)."""
    return pf[p, P_INV_MASS] > 0.0 and ground[p, 3] > 0.0 \
        and ground[p, 0] * along[0] + ground[p, 1] * along[1] + ground[p, 2] * along[2] < 0.0


@njit_inline
def anchored_by_ground(pf, ground, p, along):
    """The static friction coefficient with which the ground anchors particle ``p`` under a body whose push
    along ``along`` (a unit 3-tuple) it holds (:func:`held_by_ground`), if the ground's static friction held the
    particle in place in this sub-step; 0.0 if not."""
    return ground[p, 4] if held_by_ground(pf, ground, p, along) else 0.0


@njit_inline
def held_inverse_mass(pf, ground, p, along):
    """Particle ``p``'s inverse mass (1/kg) for a push along ``along`` (a unit 3-tuple) by a contact of cloth
    with cloth: 0 when it would push the particle into what holds it (:func:`held_by_ground`), which takes the
    push whole (a layer pressed onto one lying on the ground is pushed up by the ground, not the lower layer down
    into it)."""
    return 0.0 if held_by_ground(pf, ground, p, along) else pf[p, P_INV_MASS]


@njit_inline
def pinned_to(pi, p):
    """The body row particle row ``p`` is pinned to (a point of it), or -1."""
    return pi[p, P_PIN_BODY] if (pi[p, P_FLAGS] & PP_PINNED) != 0 else -1


@njit_inline
def separate(pf, bf, bi, bx, kind, p, other, x_b, q_b, point, u, amount, h, move, held, share, carrier, back):
    """Move particle row ``p`` and the other side apart by ``amount`` along the unit ``u`` (positions and
    velocities when ``move``, velocities only (``amount`` a velocity, m/s) otherwise), split by their
    generalised inverse masses (the particle's taken as 0 when ``held`` and the other side can move; a particle
    pinned to body row ``carrier`` (>= 0) is a part of that body, which it moves, pushed at the contact's
    ``point`` with the body's generalised inverse mass there, at its pose ``back`` s before the step's end); a body
    pushed by position gets ``share`` of the push as velocity (``body_motion.push_body``).  Returns what the
    particle moved (m or m/s)."""
    wp = pf[p, P_INV_MASS]
    x_c, q_c = x_b, q_b
    if carrier >= 0:
        x_c, q_c = body_pose(bf, bi, bx, carrier, back)
        wp = inverse_mass_along(bf, bi, carrier, x_c, q_c, point, u)
    if kind == KK_PARTICLE:
        wo = pf[other, P_INV_MASS]
    else:
        wo = inverse_mass_along(bf, bi, other, x_b, q_b, point, u)
    if held and wo > 0.0:
        wp = 0.0
    w = wp + wo
    if w <= 0.0:
        return 0.0
    dlambda = amount / w
    column = P_POS if move else P_VEL
    for k in range(3):
        pf[p, column + k] += wp * dlambda * u[k]
    scale = 1.0 if move else h      # (push_body takes positional impulses)
    if carrier >= 0 and wp > 0.0:
        push_body(bf, bi, bx, carrier, x_c, q_c, point, (dlambda * u[0] * scale, dlambda * u[1] * scale,
                                                          dlambda * u[2] * scale), h, move, 1.0)
    if kind == KK_PARTICLE:
        for k in range(3):
            pf[other, column + k] -= wo * dlambda * u[k]
    else:
        push_body(bf, bi, bx, other, x_b, q_b, point,
                  (-dlambda * u[0] * scale, -dlambda * u[1] * scale, -dlambda * u[2] * scale), h, move,
                  share if move else 1.0)
    return wp * dlambda


@njit_inline
def hold_or_slip(pf, bf, bi, bx, kind, p, other, x_b, q_b, point, n, depth, mu_s, h, anchored, carrier, back):
    """Static friction of a contact whose overlap ``depth`` (m) was just removed along ``n``: undo the
    particle's motion across the surface in this sub-step if it is shorter than ``mu_s depth`` (the other side
    moving the whole way when ``anchored``: the ground holds the particle in place, :func:`anchored_by_ground`;
    ``carrier``, ``back`` as for :func:`separate`); returns 1.0 if it held."""
    if kind == KK_PARTICLE:
        u = ((pf[other, P_POS] - pf[other, P_PREV]) / h, (pf[other, P_POS + 1] - pf[other, P_PREV + 1]) / h,
             (pf[other, P_POS + 2] - pf[other, P_PREV + 2]) / h)
    else:
        u = point_velocity(bf, bi, bx, other, x_b, point)
    dx = (pf[p, P_POS] - pf[p, P_PREV] - u[0] * h, pf[p, P_POS + 1] - pf[p, P_PREV + 1] - u[1] * h,
          pf[p, P_POS + 2] - pf[p, P_PREV + 2] - u[2] * h)
    along = dx[0] * n[0] + dx[1] * n[1] + dx[2] * n[2]
    t = (dx[0] - along * n[0], dx[1] - along * n[1], dx[2] - along * n[2])
    slip = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    if slip >= mu_s * depth:
        return 0.0
    if slip > 0.0:
        separate(pf, bf, bi, bx, kind, p, other, x_b, q_b, point, (-t[0] / slip, -t[1] / slip, -t[2] / slip),
                 slip, h, True, anchored, 1.0, carrier, back)
    return 1.0


@njit_inline
def record_contact(kf, ki, nk, p, other, kind, n, point, depth, vn0, mu, e, stuck):
    """Append a contact of the sub-step to ``kf`` / ``ki`` (if there is room); returns the new count."""
    if nk < kf.shape[0]:
        for k in range(3):
            kf[nk, K_NORMAL + k] = n[k]
            kf[nk, K_POINT + k] = point[k]
        kf[nk, K_DEPTH] = depth
        kf[nk, K_VN0] = vn0
        kf[nk, K_MU] = mu
        kf[nk, K_E] = e
        kf[nk, K_STUCK] = stuck
        ki[nk, K_PARTICLE] = p
        ki[nk, K_OTHER] = other
        ki[nk, K_KIND] = kind
    return nk + 1


@njit_inline
def _shape_contacts(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf, ki, nk,
                    scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """The position pass of the sub-step ending ``back`` s before the step's end over the candidate pairs:
    overlaps removed, static friction; the contacts appended to ``kf`` / ``ki`` from row ``nk``.  First the
    shapes the particles cannot move (static and kinematic), whose contacts then fill ``ground``
    (:func:`ground_normals`); then the bodies they can move, which take the whole of a push that would move the
    particle into what holds it, as velocity only what closes in the sub-step (the bodies' step, which does not
    see the particles, stops a box landing on a cloth that lies on the ground on the ground itself: split by the
    inverse masses, the box pushed the vertices under it into the ground, 7 mm at 10 kg, 1 cm at 100 kg; given
    whole with its velocity, the push out threw a 10 kg box up at 15 m/s).  A soft body's node also records the
    contacts it merely touches (within ``SOFT_TOUCH`` of its radius: the implicit step held it on the surface), and
    its friction counts the normal impulse that step gave it (``P_SUPPORT``) as well as its overlap.  Returns the
    new count.  Scratch: ``scratch_f`` (m, 7) and ``scratch_i`` (m,) rows of pair-test output, ``sphere``
    (N_SHAPE_PARAMS), ``pos_a``, ``pos_s`` (3), ``rot_a``, ``rot_s`` (3, 3), ``q_s`` (4)."""
    # (borrowed, as corner_contacts.py's: no reference counting in the loops' inlined helpers)
    pf, pi, bf, bi, bx, sf, si = borrow(pf), borrow(pi), borrow(bf), borrow(bi), borrow(bx), borrow(sf), borrow(si)
    geom_f, geom_i, candidates, kf, ki = borrow(geom_f), borrow(geom_i), borrow(candidates), borrow(kf), borrow(ki)
    scratch_f, scratch_i, ground = borrow(scratch_f), borrow(scratch_i), borrow(ground)
    sphere, pos_a, rot_a = borrow(sphere), borrow(pos_a), borrow(rot_a)
    pos_s, rot_s, q_s = borrow(pos_s), borrow(rot_s), borrow(q_s)
    for movable in (False, True):
        if movable:
            ground_normals(pf, bf, bi, kf, ki, nk, ground)
        for c in range(n_candidates):
            p, s = candidates[c, 0], candidates[c, 1]
            b = si[s, S_BODY]
            if pushable(bf, bi, b) == movable:
                nk = _shape_pair(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, p, s, b, back, h, kf, ki, nk,
                                 scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)
    return nk


@njit_inline
def _shape_pair(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, p, s, b, back, h, kf, ki, nk, scratch_f,
                scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """:func:`_shape_contacts` of particle ``p`` and shape row ``s`` (of body row ``b``); returns the new count."""
    soft = (pi[p, P_FLAGS] & PP_SOFT) != 0
    touch = SOFT_TOUCH * pf[p, P_RADIUS] if soft else 0.0
    carrier = pinned_to(pi, p)
    m, x_b, q_b = shape_query(coverage, pf, bf, bi, bx, sf, si, geom_f, geom_i, p, s, back, touch, scratch_f,
                              scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)
    moved0, moved1, moved2 = 0.0, 0.0, 0.0
    for j in range(m):
        # the normal from the shape to the particle, and the overlap left after this pair's earlier rows
        n = (-scratch_f[j, 3], -scratch_f[j, 4], -scratch_f[j, 5])
        depth = scratch_f[j, 6] - (moved0 * n[0] + moved1 * n[1] + moved2 * n[2])
        if depth <= -touch or (depth <= 0.0 and not soft):
            continue
        # (a soft body's node: the overlap that its support would have made, for friction)
        grip = max(depth, pf[p, P_SUPPORT] * pf[p, P_INV_MASS] * h) if soft else depth
        half = 0.5 * scratch_f[j, 6]
        point = (scratch_f[j, 0] + n[0] * half, scratch_f[j, 1] + n[1] * half, scratch_f[j, 2] + n[2] * half)
        before = (pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2])
        u = point_velocity(bf, bi, bx, b, x_b, point)
        vn0 = (pf[p, P_VEL0] - u[0]) * n[0] + (pf[p, P_VEL0 + 1] - u[1]) * n[1] + (pf[p, P_VEL0 + 2] - u[2]) * n[2]
        if depth > 0.0:
            # held: the body takes the push, as velocity the part its approach closed in the sub-step
            held = held_by_ground(pf, ground, p, n)
            share = min(1.0, max(0.0, -vn0) * h / depth) if held else 1.0
            separate(pf, bf, bi, bx, KK_BODY, p, b, x_b, q_b, point, n, depth, h, True, held, share, carrier, back)
            if held:
                bx[b, BX_LOAD] += depth
        mu_s = math.sqrt(pf[p, P_STATIC_FRICTION] * bf[b, STATIC_FRICTION])
        # a particle the ground holds in place holds the body as well as the ground holds the particle: the body
        # takes the whole of its static friction (split by the inverse masses, a box on a cloth lying on a slope
        # dragged the light vertices under it down the slope and the ground pulled them back, each sub-step, and
        # the cloth slid down a 20 degree slope at 2 mm/s under a 2 kg box, mu_s 0.5).  Its bound is the body's
        # load on all the particles under it: its approach in the sub-step, or the overlaps they have pushed it out
        # of so far (BX_LOAD), if more.  Each particle takes only a sliver of the load (the first one's push lifts
        # the body off the others), and with each one's own sliver as its bound none held: the box crept down a
        # 10 degree slope at 2 mm/s.  (Once one of them holds, little is left to slip for the others.)
        ground_mu = anchored_by_ground(pf, ground, p, n)
        anchored = ground_mu > 0.0
        hold = grip
        if anchored:
            mu_s = min(mu_s, ground_mu)
            hold = max(grip, -vn0 * h, bx[b, BX_LOAD])
        stuck = hold_or_slip(pf, bf, bi, bx, KK_BODY, p, b, x_b, q_b, point, n, hold, mu_s, h, anchored, carrier,
                             back)
        moved0 += pf[p, P_POS] - before[0]
        moved1 += pf[p, P_POS + 1] - before[1]
        moved2 += pf[p, P_POS + 2] - before[2]
        nk = record_contact(kf, ki, nk, p, b, KK_BODY, n, point, grip, vn0,
                            math.sqrt(pf[p, P_FRICTION] * bf[b, FRICTION]),
                            max(pf[p, P_RESTITUTION], bf[b, RESTITUTION]), stuck)
    return nk


# --- the shape passes of each coverage: a world compiles the ones of its own ------------------------------------
@njit
def shape_candidates_spheres(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up, out,
                             scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """:func:`shape_candidates` of a world of coverage ``COVER_SPHERES``."""
    return _shape_candidates(COVER_SPHERES, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt,
                             reach, up, out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)


@njit
def shape_candidates_meshes(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up, out,
                            scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """:func:`shape_candidates` of a world of coverage ``COVER_MESHES``."""
    return _shape_candidates(COVER_MESHES, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt,
                             reach, up, out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)


@njit
def shape_candidates_ground(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up, out,
                            scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """:func:`shape_candidates` with every sphere pair test (height fields and hulls too)."""
    return _shape_candidates(COVER_GROUND, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt,
                             reach, up, out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)


@njit_inline
def shape_candidates(coverage, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up, out,
                     scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s):
    """:func:`_shape_candidates` compiled for ``coverage`` (``COVER_SPHERES``, ``COVER_MESHES`` or ``COVER_GROUND``,
    a constant where this is inlined)."""
    if coverage == COVER_SPHERES:
        return shape_candidates_spheres(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach,
                                        up, out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)
    if coverage == COVER_MESHES:
        return shape_candidates_meshes(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach,
                                       up, out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)
    return shape_candidates_ground(pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt, reach, up,
                                   out, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s)


@njit
def shape_contacts_spheres(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf, ki, nk,
                           scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """:func:`shape_contacts` of a world of coverage ``COVER_SPHERES``."""
    return _shape_contacts(COVER_SPHERES, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back,
                           h, kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)


@njit
def shape_contacts_meshes(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf, ki, nk,
                          scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """:func:`shape_contacts` of a world of coverage ``COVER_MESHES``."""
    return _shape_contacts(COVER_MESHES, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back,
                           h, kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)


@njit
def shape_contacts_ground(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf, ki, nk,
                          scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """:func:`shape_contacts` with every sphere pair test (height fields and hulls too)."""
    return _shape_contacts(COVER_GROUND, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back,
                           h, kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)


@njit_inline
def shape_contacts(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf, ki, nk,
                   scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground):
    """:func:`_shape_contacts` compiled for ``coverage`` (``COVER_SPHERES``, ``COVER_MESHES`` or ``COVER_GROUND``, a
    constant where this is inlined)."""
    if coverage == COVER_SPHERES:
        return shape_contacts_spheres(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h,
                                      kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s,
                                      ground)
    if coverage == COVER_MESHES:
        return shape_contacts_meshes(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h,
                                     kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)
    return shape_contacts_ground(pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, candidates, n_candidates, back, h, kf,
                                 ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)


@njit_inline
def quat_product_into(q_b, sf, s, out):
    """``out = q_b q_local``: the world orientation of shape row ``s`` on a body at orientation ``q_b``."""
    r = quat_product(q_b, (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2],
                           sf[s, S_LOCAL_QUAT + 3]))
    for k in range(4):
        out[k] = r[k]


@njit
def velocity_pass(pf, pi, bf, bi, bx, kf, ki, nk, back, h, resting_speed, ground):
    """Dynamic friction and restitution of the sub-step's contacts ``0 .. nk - 1`` (module docstring), on
    the velocities taken from the positions (a body takes the whole of a contact's change where the position
    pass gave it the push: ``ground``; a particle pinned to a body moves that body)."""
    pf, pi, bf, bi, bx, kf, ki = borrow(pf), borrow(pi), borrow(bf), borrow(bi), borrow(bx), borrow(kf), borrow(ki)
    ground = borrow(ground)
    for c in range(min(nk, kf.shape[0])):
        p, other, kind = ki[c, K_PARTICLE], ki[c, K_OTHER], ki[c, K_KIND]
        n = (kf[c, K_NORMAL], kf[c, K_NORMAL + 1], kf[c, K_NORMAL + 2])
        point = (kf[c, K_POINT], kf[c, K_POINT + 1], kf[c, K_POINT + 2])
        x_b, q_b = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)
        if kind == KK_BODY:
            x_b, q_b = body_pose(bf, bi, bx, other, back)
        v = relative_velocity(pf, bf, bi, bx, kind, p, other, x_b, point)
        vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2]
        cut = 0.0
        t = (v[0] - vn * n[0], v[1] - vn * n[1], v[2] - vn * n[2])
        vt = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
        if kf[c, K_STUCK] == 0.0 and vt > 0.0:
            cut = min(kf[c, K_MU] * kf[c, K_DEPTH] / h, vt) / vt
        vn0 = kf[c, K_VN0]
        if vn0 < -resting_speed:
            dvn = -kf[c, K_E] * vn0 - vn
        else:
            dvn = min(0.0, max(vn0, 0.0) - vn)
        dv = (dvn * n[0] - cut * t[0], dvn * n[1] - cut * t[1], dvn * n[2] - cut * t[2])
        size = math.sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2])
        if size > 0.0:
            held = kind == KK_BODY and held_by_ground(pf, ground, p, n)
            separate(pf, bf, bi, bx, kind, p, other, x_b, q_b, point, (dv[0] / size, dv[1] / size, dv[2] / size),
                     size, h, False, held, 1.0, pinned_to(pi, p) if kind == KK_BODY else -1, back)
