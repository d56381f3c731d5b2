"""Sequential impulses on contact points, as the lecture teaches them, with the overlap pushed out by split
impulses.

For each contact point (normal n from a to b, offsets ra, rb from the centres of mass):

    relative velocity     dv = (v_b + w_b x rb) - (v_a + w_a x ra)
    change per impulse    K_d = m_a^-1 + m_b^-1 + (ra x d) I_a^-1 (ra x d) + (rb x d) I_b^-1 (rb x d)
    normal                lambda_n += -(dv.n + bias) / K_n,  lambda_n >= 0,
                          bias = s / h for a gap s > 0 (speculative: it may close exactly), else 0
                          (touching, soft in the solve passes: see solve_contacts)
    friction (Coulomb)    (lambda_t1, lambda_t2) += -(dv.t1 / K_t1, dv.t2 / K_t2),
                          clamped to the disc |lambda_t| <= mu lambda_n, mu = mu_s while the contact
                          sticks and mu_d once it slides
    rolling, torsion      lambda_r += -(I_a^-1 + I_b^-1)^-1 (w_b - w_a), then split along n:
                          |lambda_r - (lambda_r.n) n| <= rho lambda_n (rolling), |lambda_r.n| <= tau lambda_n
                          (torsional friction, against spinning about the normal)
    restitution           after the solve, dv.n := -e dv.n(before) for contacts that were closing

Impulses accumulate per contact and are warm-started from the last step (matched by feature).

Overlap (separation s < 0) is corrected through the velocities only as deep as ``D = min(max_push / rate,
SOFT_DEPTH)`` (``soft.soft_depth``, 1 cm: softly in the solve passes, the correction's velocity taken out
by the rigid relax pass, handed over to the pushes between D and 2 D: :func:`soft_bias`).  After the
positions moved, the push passes (split impulses, Catto 2006, as in Bullet and Box2D 2.x) solve the same
rows on a second set of pseudo-velocities ``u_p`` (``pb``, zero at the start of each sub-step), which move
the poses by ``h u_p`` and are then dropped:

    push                  lambda_p += K_n^-1 (target - dv_p.n),  lambda_p >= 0,
                          target = min(rate max(-s - D, 0), max_push) for s < 0,
                          -s / h for a gap s >= 0

so each contact opens at no more than ``max_push`` (m/s), and each body's pseudo-velocity is capped at
``max_push`` before it moves the pose (:func:`apply_push`): the pushes that add up along chains of bodies
spawned into one another move no body faster than that, and none of them is ever momentum.  ``rate`` is
the contact's soft-constraint bias rate (``soft.py``: ``omega / (2 zeta + h omega)`` from
``contact_hertz`` and ``contact_damping_ratio``), the overdamped rate at which overlap decays.
(The soft step with a relax pass, used before, put the correction into the velocities and took it out in
one relax pass; along chains it did not take it all out: 1,000 spheres spawned at one point flew apart
at 158 m/s with ``max_push`` at 3 m/s.)
"""
import math


from .._numba.jit import njit, njit_inline
from ..math3d import dot3, quat_step, row3, row4, row9
from ..state.layout import (CP_MATCHED, CP_SENSOR, CP_SLIDING, C_ADJ_SEP, C_BODY_A, C_BODY_B, C_DEPTH, C_E, C_FLAGS,
                            C_LAMBDA_N, C_LAMBDA_R, C_LAMBDA_T1, C_LAMBDA_T2, C_MASS_N, C_MASS_T1, C_MASS_T2, C_MAX_N,
                            C_MU_D, C_MU_S, C_NORMAL, C_PAIR_SLIP, C_POINT, C_RA, C_RB, C_ROLL, C_SUM_N, C_SUM_T, C_T1,
                            C_T2, C_TORSION, C_VN0, DTHETA, F_ISOTROPIC, FLAGS, FRICTION, OMEGA, PB_V, PB_W, POS, QUAT,
                            RESTITUTION, ROLLING, SB_INV_I, SB_INV_MASS, SB_ISO, STATIC_FRICTION, TORSION, VEL)
from .contact_basis import contact_basis
from .forces import is_moving
from .solver_bodies import (effective_mass_along, effective_masses, lighter, motion, push, relative_velocity_at,
                            set_velocity, twist, velocity)


@njit_inline
def prepare_contacts(bf, cf, ci, nc, sb, slide_speed):
    """Stage "prepare": offsets, contact basis, effective masses, combined materials, approach speed.

    A contact kept from the last step slides (dynamic friction) as :func:`store_friction_state` decided
    then; a new one slides if its tangential speed exceeds ``slide_speed`` (m/s) (a box thrown onto the
    floor sliding); otherwise it sticks (static friction).
    """
    for c in range(nc):
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        for k in range(3):
            cf[c, C_RA + k] = cf[c, C_POINT + k] - bf[a, POS + k]
            cf[c, C_RB + k] = cf[c, C_POINT + k] - bf[b, POS + k]
        ra = row3(cf, c, C_RA)
        rb = row3(cf, c, C_RB)
        n = row3(cf, c, C_NORMAL)
        t1, t2 = contact_basis(n)
        for k in range(3):
            cf[c, C_T1 + k] = t1[k]
            cf[c, C_T2 + k] = t2[k]
        if (ci[c, C_FLAGS] & CP_MATCHED) != 0 and (sb[a, SB_ISO] < 0.0 or sb[b, SB_ISO] < 0.0):
            # warm-started on a body whose inertia turned since: as refresh_turning_masses
            _refresh_contact_masses(cf, ci, c, sb)
        else:
            cf[c, C_MASS_N], cf[c, C_MASS_T1], cf[c, C_MASS_T2] = effective_masses(sb, a, ra, b, rb, n, t1, t2)
        # Materials: friction by geometric mean, restitution, rolling and torsional friction by maximum.
        cf[c, C_MU_D] = math.sqrt(bf[a, FRICTION] * bf[b, FRICTION])
        cf[c, C_MU_S] = math.sqrt(bf[a, STATIC_FRICTION] * bf[b, STATIC_FRICTION])
        cf[c, C_E] = max(bf[a, RESTITUTION], bf[b, RESTITUTION])
        cf[c, C_ROLL] = max(bf[a, ROLLING], bf[b, ROLLING])
        cf[c, C_TORSION] = max(bf[a, TORSION], bf[b, TORSION])
        _drop_unbounded_angular_impulse(cf, c, n)
        dv = relative_velocity_at(velocity(sb, a), ra, velocity(sb, b), rb)
        cf[c, C_VN0] = dot3(dv, n)
        vt1 = dot3(dv, t1)
        vt2 = dot3(dv, t2)
        if (ci[c, C_FLAGS] & CP_MATCHED) != 0:
            sliding = (ci[c, C_FLAGS] & CP_SLIDING) != 0
        else:
            sliding = math.sqrt(vt1 * vt1 + vt2 * vt2) > slide_speed
            cf[c, C_PAIR_SLIP] = _pair_slip(bf, cf, ci, c)
        if sliding:
            ci[c, C_FLAGS] |= CP_SLIDING
        else:
            ci[c, C_FLAGS] &= ~CP_SLIDING
        cf[c, C_ADJ_SEP] = -cf[c, C_DEPTH]
        cf[c, C_MAX_N] = 0.0
        cf[c, C_SUM_N] = 0.0
        for k in range(3):
            cf[c, C_SUM_T + k] = 0.0


@njit_inline
def has_turning_contacts(ci, nc, sb):
    """True if some contact touches a body whose world inverse inertia turns with it (``SB_ISO < 0``): only
    those contacts' effective masses change within a step (see :func:`refresh_turning_masses`)."""
    for c in range(nc):
        if sb[ci[c, C_BODY_A], SB_ISO] < 0.0 or sb[ci[c, C_BODY_B], SB_ISO] < 0.0:
            return True
    return False


@njit
def _refresh_contact_masses(cf, ci, c, sb):
    """Effective masses of contact ``c`` along its normal and tangents from the solver bodies ``sb`` now."""
    a = ci[c, C_BODY_A]
    b = ci[c, C_BODY_B]
    if sb[a, SB_ISO] >= 0.0 and sb[b, SB_ISO] >= 0.0:
        return
    ra = row3(cf, c, C_RA)
    rb = row3(cf, c, C_RB)
    m = effective_mass_along(sb, a, ra, b, rb, row3(cf, c, C_NORMAL))
    cf[c, C_LAMBDA_N] *= lighter(m, cf[c, C_MASS_N])
    cf[c, C_MASS_N] = m
    m = effective_mass_along(sb, a, ra, b, rb, row3(cf, c, C_T1))
    cf[c, C_LAMBDA_T1] *= lighter(m, cf[c, C_MASS_T1])
    cf[c, C_MASS_T1] = m
    m = effective_mass_along(sb, a, ra, b, rb, row3(cf, c, C_T2))
    cf[c, C_LAMBDA_T2] *= lighter(m, cf[c, C_MASS_T2])
    cf[c, C_MASS_T2] = m


@njit
def refresh_turning_masses(cf, ci, order, n, sb):
    """After the bodies turned (each sub-step's position update): recompute the effective masses

        m_d = 1 / (m_a^-1 + m_b^-1 + (ra x d) I_a^-1 (ra x d) + (rb x d) I_b^-1 (rb x d))

    of the contacts ``order[:n]`` (``order`` None: the first ``n``) that touch a body whose world inverse
    inertia ``R I^-1 R^T`` turned with it.  A sequential impulse ``-m (J v)`` with a mass from the step's
    start over-shoots when the body has turned a lever arm onto a small moment since: by the factor
    ``m_stale / m_now``, and above 2 every pass adds energy (a thin rod turning about its long axis,
    whose moment there is 1e-4 of the others', took 1.7 MJ in one relax pass of the "energy from
    nowhere" report).  The accumulated impulses are scaled by :func:`lighter`: the next sub-step's warm
    start re-applies them, and the same impulse on a lever arm that has turned onto a small moment gave a
    spinning 3.6 m capsule 0.3 MJ where it had 300 J.
    """
    for k in range(n):
        _refresh_contact_masses(cf, ci, k if order is None else order[k], sb)


@njit_inline
def _warm_start_contact(cf, ci, c, sb):
    """Apply contact ``c``'s accumulated impulses (normal, friction, rolling) to its two bodies."""
    if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
        return
    a = ci[c, C_BODY_A]
    b = ci[c, C_BODY_B]
    ln, l1, l2 = cf[c, C_LAMBDA_N], cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
    px = ln * cf[c, C_NORMAL] + l1 * cf[c, C_T1] + l2 * cf[c, C_T2]
    py = ln * cf[c, C_NORMAL + 1] + l1 * cf[c, C_T1 + 1] + l2 * cf[c, C_T2 + 1]
    pz = ln * cf[c, C_NORMAL + 2] + l1 * cf[c, C_T1 + 2] + l2 * cf[c, C_T2 + 2]
    ua = push(sb, a, velocity(sb, a), row3(cf, c, C_RA), px, py, pz, -1.0)
    ub = push(sb, b, velocity(sb, b), row3(cf, c, C_RB), px, py, pz, 1.0)
    lr = row3(cf, c, C_LAMBDA_R)
    if lr[0] != 0.0 or lr[1] != 0.0 or lr[2] != 0.0:
        ua = twist(ua, row9(sb, a, SB_INV_I), lr, -1.0)
        ub = twist(ub, row9(sb, b, SB_INV_I), lr, 1.0)
    set_velocity(sb, a, ua)
    set_velocity(sb, b, ub)


@njit
def scale_contact_impulses(cf, nc, scale):
    """Multiply the impulses every contact starts its next sub-step from (normal, friction, rolling) by
    ``scale``."""
    for c in range(nc):
        for k in range(C_LAMBDA_N, C_LAMBDA_R + 3):
            cf[c, k] *= scale


@njit_inline
def warm_start_contacts(cf, ci, nc, sb):
    """Stage "warm start": apply the impulses accumulated last sub-step (or matched from last step)."""
    for c in range(nc):
        _warm_start_contact(cf, ci, c, sb)


@njit
def warm_start_listed(cf, ci, order, n, sb):
    """Stage "warm start" for the contacts ``order[:n]`` only."""
    for k in range(n):
        _warm_start_contact(cf, ci, order[k], sb)


@njit
def contact_separation(sb, cf, c, a, b):
    """Current separation (m): the one at detection plus the normal part of the contact points' motion,

        s = s0 + n . ((dx_b + dtheta_b x rb) - (dx_a + dtheta_a x ra))

    with dx, dtheta the bodies' displacement and rotation since the step began, read from the solver
    bodies ``sb``.  The rotation's term is the part of Rodrigues' formula normal to the rotation axis,
    ``sin(theta) / theta (dtheta x r)`` (``prepare_solver_bodies`` scales dtheta): a rolling ball's contact
    stays at its lowest point, and a body turning fast does not see a corner move further than its
    distance from the centre, ``theta |r|`` where it moves ``|r| sin(theta)`` (the first-order term made
    fake overlap, centimetres deep on a spinning stick, that the contact springs and the position
    correction then pushed out: energy from nowhere).  The term towards the axis,
    ``(1 - cos theta) r_perp``, is left out (a ball's contact point does not lift as it rolls).
    """
    return cf[c, C_ADJ_SEP] + dot3(relative_velocity_at(motion(sb, a), row3(cf, c, C_RA), motion(sb, b),
                                                        row3(cf, c, C_RB)), row3(cf, c, C_NORMAL))


@njit_inline
def soft_bias(s, rate, max_bias):
    """The velocity bias (m/s) of a contact of overlap ``d = -s >= 0`` (m) in the soft solve passes, with
    ``max_bias = rate D`` (m/s, ``D`` from ``soft.soft_depth``):

        bias = -rate d                        for d <= D
        bias = -(2 max_bias - rate d)         for D <= d <= 2 D,   0 beyond

    so the velocities open shallow overlap softly (a resting contact's) and hand deep overlap over to the
    pushes (:func:`push_target`), whose ``rate (d - D)`` grows as this falls: together they open it at
    ``rate D`` from ``D`` on, and faster as the pushes take over.  (Deep overlap opened through the
    velocities of every contact of a heap spawned at one point, and the relax pass did not take it all out
    again: 258 m/s.)"""
    r = rate * (0.0 - s)
    return 0.0 - max(min(r, 2.0 * max_bias - r), 0.0)


@njit
def solve_contacts(cf, ci, order, first, last, sb, h, soft):
    """Stage "solve" (``soft`` = (bias_rate, mass_scale, impulse_scale, max_bias) of ``soft.py``, ``max_bias``
    as in :func:`soft_bias`) or "relax" (rigid: ``soft`` = (0, 1, 0, 0)): one pass of sequential impulses
    over the contacts ``order[first:last]``, in that order, on the velocities of the solver bodies ``sb``.

    A contact keeps its bodies from closing by more than its gap ``s > 0`` in the sub-step of ``h`` s
    (speculative: exactly), and a touching one (``s <= 0``) opens its overlap softly, at ``bias_rate (-s)``
    up to ``max_bias`` (the soft step of ``soft.py``, Box2D 3's, which keeps tall stacks standing: with
    rigid passes and the overlap left to the pushes alone a 20-box tower tilted until it fell); the rigid
    relax pass after the positions moved takes the correction's velocity out again.  Overlap deeper than
    ``D = max_bias / bias_rate`` (``soft.soft_depth``, 1 cm) is handed over to :func:`push_contacts`
    (:func:`soft_bias`).  Returns the largest velocity change made (m/s), for the adaptive
    iteration count.  Each contact's two bodies are read once, updated in registers through the normal,
    friction and rolling impulses, and written back once; bodies that cannot move are never written, so
    passes over contacts that share no movable body may run at the same time.
    """
    bias_rate, mass_scale, impulse_scale, max_bias = soft
    largest = 0.0
    for k in range(first, last):
        c = order[k]
        flags = ci[c, C_FLAGS]
        if (flags & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = row3(cf, c, C_RA)
        rb = row3(cf, c, C_RB)
        n = row3(cf, c, C_NORMAL)
        ua = velocity(sb, a)
        ub = velocity(sb, b)
        # --- normal: non-penetration -------------------------------------------------------------
        s = contact_separation(sb, cf, c, a, b)
        if s > 0.0:
            bias, soft_mass, soft_impulse = s / h, 1.0, 0.0        # speculative: close the gap exactly
        else:
            bias, soft_mass, soft_impulse = soft_bias(s, bias_rate, max_bias), mass_scale, impulse_scale
        vn = dot3(relative_velocity_at(ua, ra, ub, rb), n)
        mass_n = cf[c, C_MASS_N]
        old = cf[c, C_LAMBDA_N]
        new = max(old - mass_n * soft_mass * (vn + bias) - soft_impulse * old, 0.0)
        cf[c, C_LAMBDA_N] = new
        if new > 0.0 and cf[c, C_MAX_N] == 0.0 and (flags & CP_MATCHED) == 0:
            # A new contact engages: the approach speed at impact, gravity of earlier sub-steps included.
            cf[c, C_VN0] = min(vn, cf[c, C_VN0])
        if new > cf[c, C_MAX_N]:
            cf[c, C_MAX_N] = new
        d = new - old
        if d != 0.0:
            ua = push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0)
            ub = push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0)
            if mass_n > 0.0:
                largest = max(largest, abs(d) / mass_n)
        # --- friction: Coulomb disc on the tangent plane -------------------------------------------
        mu = cf[c, C_MU_D] if (flags & CP_SLIDING) != 0 else cf[c, C_MU_S]
        bound = mu * new
        t1 = row3(cf, c, C_T1)
        t2 = row3(cf, c, C_T2)
        dv = relative_velocity_at(ua, ra, ub, rb)
        o1, o2 = cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
        n1 = o1 - cf[c, C_MASS_T1] * dot3(dv, t1)
        n2 = o2 - cf[c, C_MASS_T2] * dot3(dv, t2)
        length = math.sqrt(n1 * n1 + n2 * n2)
        if length > bound:
            scale = bound / length if length > 0.0 else 0.0
            n1 *= scale
            n2 *= scale
        cf[c, C_LAMBDA_T1] = n1
        cf[c, C_LAMBDA_T2] = n2
        d1, d2 = n1 - o1, n2 - o2
        if d1 != 0.0 or d2 != 0.0:
            px = d1 * t1[0] + d2 * t2[0]
            py = d1 * t1[1] + d2 * t2[1]
            pz = d1 * t1[2] + d2 * t2[2]
            ua = push(sb, a, ua, ra, px, py, pz, -1.0)
            ub = push(sb, b, ub, rb, px, py, pz, 1.0)
        # --- rolling and torsional friction: an angular impulse bounded by rho and tau times lambda_n ----
        if cf[c, C_ROLL] > 0.0 or cf[c, C_TORSION] > 0.0:
            ua, ub = _solve_rolling(cf, c, sb, a, b, ua, ub, cf[c, C_ROLL] * new, cf[c, C_TORSION] * new)
        if sb[a, SB_ISO] != 0.0:
            set_velocity(sb, a, ua)
        if sb[b, SB_ISO] != 0.0:
            set_velocity(sb, b, ub)
    return largest


@njit
def pseudo_velocity(pb, i):
    """``u_p = (v_p, omega_p)`` of body ``i``: its push pseudo-velocity (m/s, rad/s)."""
    return (pb[i, PB_V], pb[i, PB_V + 1], pb[i, PB_V + 2], pb[i, PB_W], pb[i, PB_W + 1], pb[i, PB_W + 2])


@njit
def set_pseudo_velocity(pb, i, u):
    """Write ``u_p = (v_p, omega_p)`` to body ``i``."""
    for k in range(3):
        pb[i, PB_V + k] = u[k]
        pb[i, PB_W + k] = u[3 + k]


@njit_inline
def push_target(s, h, rate, max_push, depth):
    """The relative normal pseudo-velocity a contact of separation ``s`` (m) asks for (m/s): overlap deeper
    than ``depth`` (``soft.soft_depth`` for sequential impulses, whose velocity passes open shallower
    overlap; 0 for the LCP) opens at ``rate (-s - depth)``, no faster than ``max_push``; a gap ``s >= 0``
    may close by ``s`` in the sub-step of ``h`` s and no more (as a speculative contact)."""
    return (0.0 - s) / h if s >= 0.0 else min(rate * max((0.0 - s) - depth, 0.0), max_push)


@njit
def push_contacts(cf, ci, order, first, last, sb, pb, lam_p, h, rate, max_push, depth, first_pass):
    """Stage "relax", contacts: one pass of split impulses over the contacts ``order[first:last]`` on the
    pseudo-velocities ``pb`` (see the module's docstring):

        lambda_p := max(lambda_p + m_n (target - dv_p . n), 0),   target = push_target(s)

    with the separation ``s`` the poses have now (``depth``: :func:`push_target`), the accumulated ``lambda_p``
    in ``lam_p[c]`` (taken as 0 on
    the ``first_pass`` of a sub-step) and the inverse masses of ``sb``.  Returns the largest pseudo-velocity
    change made (m/s).  The arithmetic is ``contact_bundles.push_bundles``' term for term.
    """
    largest = 0.0
    for k in range(first, last):
        c = order[k]
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = row3(cf, c, C_RA)
        rb = row3(cf, c, C_RB)
        n = row3(cf, c, C_NORMAL)
        target = push_target(contact_separation(sb, cf, c, a, b), h, rate, max_push, depth)
        ua = pseudo_velocity(pb, a)
        ub = pseudo_velocity(pb, b)
        vn = dot3(relative_velocity_at(ua, ra, ub, rb), n)
        mass_n = cf[c, C_MASS_N]
        old = 0.0 if first_pass else lam_p[c]
        new = max(old + mass_n * (target - vn), 0.0)
        lam_p[c] = new
        d = new - old
        if d != 0.0:
            if sb[a, SB_ISO] != 0.0:
                set_pseudo_velocity(pb, a, push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0))
            if sb[b, SB_ISO] != 0.0:
                set_pseudo_velocity(pb, b, push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0))
            if mass_n > 0.0:
                largest = max(largest, abs(d) / mass_n)
    return largest


@njit
def list_static_contacts(ci, nc, sb, out):
    """Write the contacts (not sensors) between a movable body and one that cannot move (static or sleeping)
    to ``out``; returns how many."""
    count = 0
    for c in range(nc):
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        if (sb[ci[c, C_BODY_A], SB_ISO] == 0.0) != (sb[ci[c, C_BODY_B], SB_ISO] == 0.0):
            out[count] = c
            count += 1
    return count


@njit
def push_static(cf, ci, listed, sb, pb, h, rate, max_push, depth):
    """After the push passes: each contact ``listed`` of a movable body with one that cannot move raises the
    movable body's pseudo-velocity along the normal to the contact's ``push_target`` if it is below:

        d lambda = max(m_n (target - dv_p . n), 0)

    Sequential impulses converge slowly in a heap of bodies spawned into one another, and the pushes of the
    bodies above could leave one at the bottom moving into the floor (a column of 300 spheres spawned at
    one point pressed the lowest 0.39 m into the ground); the static world is then visited last, and no
    push moves a body into it.  (The per-body cap of :func:`apply_push` scales the pseudo-velocity, so it
    keeps its sign along every normal.)"""
    for k in range(listed.shape[0]):
        c = listed[k]
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = row3(cf, c, C_RA)
        rb = row3(cf, c, C_RB)
        n = row3(cf, c, C_NORMAL)
        target = push_target(contact_separation(sb, cf, c, a, b), h, rate, max_push, depth)
        ua = pseudo_velocity(pb, a)
        ub = pseudo_velocity(pb, b)
        d = max(cf[c, C_MASS_N] * (target - dot3(relative_velocity_at(ua, ra, ub, rb), n)), 0.0)
        if d > 0.0:
            if sb[a, SB_ISO] != 0.0:
                set_pseudo_velocity(pb, a, push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0))
            else:
                set_pseudo_velocity(pb, b, push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0))


@njit
def clear_push(pb, nb):
    """Zero the pseudo-velocities of the body rows ``0 .. nb - 1`` (the start of each sub-step's pushes)."""
    for i in range(nb):
        for k in range(6):
            pb[i, k] = 0.0


@njit
def apply_push(bf, bi, nb, pb, h, max_push):
    """Move every awake dynamic body by its pseudo-velocity over the sub-step of ``h`` s, then forget it:

        v_p := v_p min(1, max_push / |v_p|),   x += v_p h,   q := exp(omega_p h / 2) q,   dtheta += omega_p h

    The cap makes ``max_push`` (m/s) the fastest any body is pushed, however many contacts push it along
    a chain.  A body whose inertia is not isotropic also turns its angular velocity with the push,
    ``omega := R omega`` (``R`` the push's rotation): ``omega . I_w omega / 2`` is then unchanged, as
    ``I_w`` turns with the body (``R I_w R^T``), so the push moves the body without changing its kinetic
    energy (the velocities are never touched otherwise).
    """
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        vx, vy, vz = pb[i, PB_V], pb[i, PB_V + 1], pb[i, PB_V + 2]
        speed = math.sqrt(vx * vx + vy * vy + vz * vz)
        if speed > max_push:
            scale = max_push / speed
            vx, vy, vz = vx * scale, vy * scale, vz * scale
        bf[i, POS] += vx * h
        bf[i, POS + 1] += vy * h
        bf[i, POS + 2] += vz * h
        wp = (pb[i, PB_W], pb[i, PB_W + 1], pb[i, PB_W + 2])
        if wp[0] == 0.0 and wp[1] == 0.0 and wp[2] == 0.0:
            continue
        q = quat_step(row4(bf, i, QUAT), wp, h)
        for k in range(4):
            bf[i, QUAT + k] = q[k]
        for k in range(3):
            bf[i, DTHETA + k] += wp[k] * h
        if (bi[i, FLAGS] & F_ISOTROPIC) == 0:
            # omega := R omega, R the rotation by phi = omega_p h (Rodrigues)
            p0, p1, p2 = wp[0] * h, wp[1] * h, wp[2] * h
            angle = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
            if angle == 0.0:
                continue
            e0, e1, e2 = p0 / angle, p1 / angle, p2 / angle
            w0, w1, w2 = bf[i, OMEGA], bf[i, OMEGA + 1], bf[i, OMEGA + 2]
            cos_a, sin_a = math.cos(angle), math.sin(angle)
            along = (e0 * w0 + e1 * w1 + e2 * w2) * (1.0 - cos_a)
            bf[i, OMEGA] = w0 * cos_a + (e1 * w2 - e2 * w1) * sin_a + e0 * along
            bf[i, OMEGA + 1] = w1 * cos_a + (e2 * w0 - e0 * w2) * sin_a + e1 * along
            bf[i, OMEGA + 2] = w2 * cos_a + (e0 * w1 - e1 * w0) * sin_a + e2 * along


#: A contact is "heavy on light" when the body above (along -g) is at least this many times heavier than
#: the movable body below it (see :func:`solve_supported`).
HEAVY_ON_LIGHT = 10.0


@njit
def _above_below(cf, ci, c, gravity, g):
    """``(upper, lower)`` bodies of contact ``c`` if its normal is within 60 degrees of ``-gravity``, else
    ``(-1, -1)``."""
    up = -(cf[c, C_NORMAL] * gravity[0] + cf[c, C_NORMAL + 1] * gravity[1] + cf[c, C_NORMAL + 2] * gravity[2]) / g
    if abs(up) < 0.5:
        return -1, -1
    # n points from a to b: b is above when n points up
    if up > 0.0:
        return ci[c, C_BODY_B], ci[c, C_BODY_A]
    return ci[c, C_BODY_A], ci[c, C_BODY_B]


@njit
def heavy_on_light(cf, ci, nc, sb, gravity, light, heavy, found):
    """The contacts whose body above, along the contact normal within 60 degrees of ``-gravity``, is at least
    HEAVY_ON_LIGHT times heavier than the movable body below, after the contacts on which those light
    bodies rest themselves (bottom up), written to ``found`` (rows: the contact's row, and room for its
    :func:`solve_supported` impulse); returns how many (0 in most scenes: then nothing else is done).
    ``light`` (one flag per solver-body row), ``heavy`` (one per contact) and ``found`` are scratch."""
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    if g == 0.0:
        return 0
    count = 0
    for c in range(nc):
        heavy[c] = False
        high, low = -1, -1
        if (ci[c, C_FLAGS] & CP_SENSOR) == 0:
            high, low = _above_below(cf, ci, c, gravity, g)
        if high >= 0:
            m_low, m_high = sb[low, SB_INV_MASS], sb[high, SB_INV_MASS]
            if m_low > 0.0 and m_high > 0.0 and m_low >= HEAVY_ON_LIGHT * m_high:
                if count == 0:
                    for i in range(sb.shape[0]):
                        light[i] = False
                heavy[c] = True
                light[low] = True
                count += 1
    if count == 0:
        return 0
    count = 0
    for c in range(nc):                 # the light bodies' own supports first
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0 or heavy[c]:
            continue
        high, low = _above_below(cf, ci, c, gravity, g)
        if high >= 0 and light[high]:
            found[count, 0] = c
            count += 1
    for c in range(nc):
        if heavy[c]:
            found[count, 0] = c
            count += 1
    return count


#: Passes of :func:`solve_supported` over its contacts (a body above rests on several points of one below).
SUPPORTED_PASSES = 4


@njit
def solve_supported(cf, ci, supported, sb, pb, h, pushing, rate, max_push, depth, gravity):
    """Passes over the heavy-on-light contacts ``supported`` (:func:`heavy_on_light`) with the light body
    below held still (shock propagation, Guendelman, Bridson and Fedkiw 2003): the normal impulse

        d lambda_s = -m_up (v_n + bias),   m_up = 1 / (m_up^-1 + (r x n) . I_up^-1 (r x n))

    with the effective mass of the body above alone, applied to that body alone, its own accumulated
    ``lambda_s >= 0`` (``supported[:, 1]``, from zero at each call).  The light body never feels these
    impulses, so nothing is warm-started from them.  Without ``pushing`` they act on the velocities of
    ``sb`` (after the solve passes, ``bias`` as in :func:`solve_contacts` with the bias rate ``rate``;
    after the relax pass with ``rate`` 0); with it, on the pseudo-velocities ``pb`` (after the push
    passes; ``v_n + bias`` is ``dv_p . n - push_target(s)``, ``rate`` the push's); ``depth`` as in
    :func:`push_target`.

    Sequential impulses move momentum between two bodies by about the lighter one's mass times their
    relative speed per pass, so a 1e4 kg box on a 1 kg box needs thousands of passes to stop, and pushing
    it out of the light one moves the light one rather than the heavy one: at 1:1000 the heavy box ended
    inside the light one, at 1:1e4 it pressed the light one through the floor.  Bottom up, the light body
    first stopped (or pushed) on its own supports, then the heavy one held on it, the heavy one stops
    within these passes.
    """
    g = math.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    for k in range(supported.shape[0]):
        supported[k, 1] = 0.0
    for _ in range(SUPPORTED_PASSES):
        for k in range(supported.shape[0]):
            c = int(supported[k, 0])
            a = ci[c, C_BODY_A]
            b = ci[c, C_BODY_B]
            n = row3(cf, c, C_NORMAL)
            up = -(n[0] * gravity[0] + n[1] * gravity[1] + n[2] * gravity[2]) / g
            ra = row3(cf, c, C_RA)
            rb = row3(cf, c, C_RB)
            s = contact_separation(sb, cf, c, a, b)
            if pushing:
                ua = pseudo_velocity(pb, a)
                ub = pseudo_velocity(pb, b)
                bias = 0.0 - push_target(s, h, rate, max_push, depth)
            else:
                ua = velocity(sb, a)
                ub = velocity(sb, b)
                bias = s / h if s > 0.0 else soft_bias(s, rate, rate * depth)
            vn = dot3(relative_velocity_at(ua, ra, ub, rb), n)
            # the effective mass of the body above alone (the one below held)
            if up > 0.0:
                m_up = effective_mass_along(sb, b, rb, -1, rb, n)
            else:
                m_up = effective_mass_along(sb, a, ra, -1, ra, n)
            old = supported[k, 1]
            new = max(old - m_up * (vn + bias), 0.0)
            d = new - old
            if d == 0.0:
                continue
            supported[k, 1] = new
            if up > 0.0:
                ub = push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0)
                if pushing:
                    set_pseudo_velocity(pb, b, ub)
                else:
                    set_velocity(sb, b, ub)
            else:
                ua = push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0)
                if pushing:
                    set_pseudo_velocity(pb, a, ua)
                else:
                    set_velocity(sb, a, ua)


@njit_inline
def angular_cofactors(inv_i_a, inv_i_b):
    """The cofactors ``(c0, .., c8)`` and the determinant of the angular effective mass's inverse

        K = I_a^-1 + I_b^-1,   K^-1 = adj(K) / det K,   adj(K) = the cofactors' transpose

    from the bodies' world inverse inertias (row-major 9-tuples).  Plain arithmetic, so the wide floats of
    ``contact_bundles`` take it too, lane by lane with the same rounding."""
    k0, k1, k2 = inv_i_a[0] + inv_i_b[0], inv_i_a[1] + inv_i_b[1], inv_i_a[2] + inv_i_b[2]
    k3, k4, k5 = inv_i_a[3] + inv_i_b[3], inv_i_a[4] + inv_i_b[4], inv_i_a[5] + inv_i_b[5]
    k6, k7, k8 = inv_i_a[6] + inv_i_b[6], inv_i_a[7] + inv_i_b[7], inv_i_a[8] + inv_i_b[8]
    c0, c1, c2 = k4 * k8 - k5 * k7, k5 * k6 - k3 * k8, k3 * k7 - k4 * k6
    c3, c4, c5 = k2 * k7 - k1 * k8, k0 * k8 - k2 * k6, k1 * k6 - k0 * k7
    c6, c7, c8 = k1 * k5 - k2 * k4, k2 * k3 - k0 * k5, k0 * k4 - k1 * k3
    return (c0, c1, c2, c3, c4, c5, c6, c7, c8), k0 * c0 + k1 * c1 + k2 * c2


@njit_inline
def rolling_split(cofactors, det, w, old, n):
    """The angular impulse that stops the relative angular velocity ``w = w_b - w_a``, before its bounds,

        lambda_r = old - K^-1 w,   K^-1 w = adj(K) w / det K  (:func:`angular_cofactors`),

    split along the unit normal ``n``: its part across ``n`` (rolling) and its component along ``n``
    (torsion).  Plain arithmetic, as :func:`angular_cofactors`."""
    c0, c1, c2, c3, c4, c5, c6, c7, c8 = cofactors
    r0 = old[0] - (c0 * w[0] + c3 * w[1] + c6 * w[2]) / det
    r1 = old[1] - (c1 * w[0] + c4 * w[1] + c7 * w[2]) / det
    r2 = old[2] - (c2 * w[0] + c5 * w[1] + c8 * w[2]) / det
    spin = r0 * n[0] + r1 * n[1] + r2 * n[2]
    return (r0 - spin * n[0], r1 - spin * n[1], r2 - spin * n[2]), spin


@njit_inline
def _drop_unbounded_angular_impulse(cf, c, n):
    """The warm-start angular impulse ``lambda_r`` of contact ``c`` keeps only the parts a friction still
    bounds: across the normal ``n`` if rolling friction is on, along it if torsional friction is on,

        lambda_r := [rho > 0] (lambda_r - (lambda_r.n) n) + [tau > 0] (lambda_r.n) n

    (a pair whose friction was set to zero while it touched would otherwise have the impulse applied at
    every warm start and never solved again)."""
    roll, torsion = cf[c, C_ROLL] > 0.0, cf[c, C_TORSION] > 0.0
    if roll and torsion:
        return
    spin = cf[c, C_LAMBDA_R] * n[0] + cf[c, C_LAMBDA_R + 1] * n[1] + cf[c, C_LAMBDA_R + 2] * n[2]
    for k in range(3):
        along = spin * n[k]
        across = cf[c, C_LAMBDA_R + k] - along
        cf[c, C_LAMBDA_R + k] = (across if roll else 0.0) + (along if torsion else 0.0)


@njit
def _solve_rolling(cf, c, sb, a, b, ua, ub, rolling_bound, torsion_bound):
    """Drive the relative angular velocity ``w_b - w_a`` to zero with the impulse's part across the normal
    ``n`` at most ``rolling_bound`` and its part along ``n`` at most ``torsion_bound`` (N m s):

        K = I_a^-1 + I_b^-1,   lambda_r := lambda_r - K^-1 (w_b - w_a),   K^-1 = adj(K) / det K,
        lambda_r := clamp(lambda_r - (lambda_r.n) n, rolling_bound) + clamp(lambda_r.n, torsion_bound) n

    Returns the bodies' updated ``(v, omega)``.  (``contact_bundles`` solves it lane by lane with the same
    arithmetic.)
    """
    inv_i_a, inv_i_b = row9(sb, a, SB_INV_I), row9(sb, b, SB_INV_I)
    cofactors, det = angular_cofactors(inv_i_a, inv_i_b)
    if det <= 0.0:
        return ua, ub
    old = row3(cf, c, C_LAMBDA_R)
    n = row3(cf, c, C_NORMAL)
    across, spin = rolling_split(cofactors, det, (ub[3] - ua[3], ub[4] - ua[4], ub[5] - ua[5]), old, n)
    r0, r1, r2 = across
    length = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    if length > rolling_bound:
        scale = rolling_bound / length if length > 0.0 else 0.0
        r0 *= scale
        r1 *= scale
        r2 *= scale
    spin = min(max(spin, -torsion_bound), torsion_bound)
    new = (r0 + spin * n[0], r1 + spin * n[1], r2 + spin * n[2])
    for k in range(3):
        cf[c, C_LAMBDA_R + k] = new[k]
    change = (new[0] - old[0], new[1] - old[1], new[2] - old[2])
    return twist(ua, inv_i_a, change, -1.0), twist(ub, inv_i_b, change, 1.0)


@njit_inline
def apply_restitution(cf, ci, nc, sb, threshold):
    """Stage "restitution", on the solver bodies ``sb``: contacts that closed faster than ``threshold``
    (m/s) separate at ``-e vn0``."""
    for c in range(nc):
        e = cf[c, C_E]
        if e == 0.0 or (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        if cf[c, C_VN0] > -threshold or cf[c, C_MAX_N] == 0.0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = row3(cf, c, C_RA)
        rb = row3(cf, c, C_RB)
        n = row3(cf, c, C_NORMAL)
        ua = velocity(sb, a)
        ub = velocity(sb, b)
        vn = dot3(relative_velocity_at(ua, ra, ub, rb), n)
        old = cf[c, C_LAMBDA_N]
        new = max(old - cf[c, C_MASS_N] * (vn + e * cf[c, C_VN0]), 0.0)
        cf[c, C_LAMBDA_N] = new
        d = new - old
        set_velocity(sb, a, push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0))
        set_velocity(sb, b, push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0))
        cf[c, C_SUM_N] += d


@njit_inline
def _accumulate_contact(cf, c):
    """Add contact ``c``'s sub-step impulses to its step totals."""
    cf[c, C_SUM_N] += cf[c, C_LAMBDA_N]
    for k in range(3):
        cf[c, C_SUM_T + k] += cf[c, C_LAMBDA_T1] * cf[c, C_T1 + k] + cf[c, C_LAMBDA_T2] * cf[c, C_T2 + k]


@njit_inline
def accumulate_applied(cf, ci, nc):
    """After each sub-step: add the impulses that sub-step applied to the step's totals (for reports)."""
    for c in range(nc):
        _accumulate_contact(cf, c)


@njit
def accumulate_listed(cf, order, n):
    """:func:`accumulate_applied` for the contacts ``order[:n]`` only."""
    for k in range(n):
        _accumulate_contact(cf, order[k])


@njit
def _at_cone(cf, ci, c):
    """True if contact ``c``'s friction impulse has reached its cone (static or dynamic, as it is flagged)."""
    bound = cf[c, C_LAMBDA_N] * (cf[c, C_MU_D] if (ci[c, C_FLAGS] & CP_SLIDING) != 0 else cf[c, C_MU_S])
    l1, l2 = cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
    return bound > 0.0 and math.sqrt(l1 * l1 + l2 * l2) >= bound * (1.0 - 1e-9)


@njit
def _slides(bf, cf, ci, c, slide_speed):
    """True if contact ``c``'s points slide past each other faster than ``slide_speed`` (m/s)."""
    a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
    dv = relative_velocity_at((bf[a, VEL], bf[a, VEL + 1], bf[a, VEL + 2], bf[a, OMEGA], bf[a, OMEGA + 1],
                               bf[a, OMEGA + 2]), row3(cf, c, C_RA),
                              (bf[b, VEL], bf[b, VEL + 1], bf[b, VEL + 2], bf[b, OMEGA], bf[b, OMEGA + 1],
                               bf[b, OMEGA + 2]), row3(cf, c, C_RB))
    vn = dot3(dv, row3(cf, c, C_NORMAL))
    return dot3(dv, dv) - vn * vn > slide_speed * slide_speed


@njit
def _pair_slip(bf, cf, ci, c):
    """How fast the centres of contact ``c``'s two bodies move past each other across its normal (m/s)."""
    a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
    dv = (bf[b, VEL] - bf[a, VEL], bf[b, VEL + 1] - bf[a, VEL + 1], bf[b, VEL + 2] - bf[a, VEL + 2])
    vn = dot3(dv, row3(cf, c, C_NORMAL))
    return math.sqrt(max(dot3(dv, dv) - vn * vn, 0.0))


@njit_inline
def store_friction_state(bf, cf, ci, nc, slide_speed):
    """Stage "store impulses": the contacts of a pair of bodies slide in the next step (dynamic friction) if
    every one of them reached its cone in this one, and each whose points slide past each other faster
    than ``slide_speed`` (m/s) at the step's end does -- unless the pair sticks and its bodies slip past each
    other (their centres, across the normal: ``C_PAIR_SLIP``) no faster than at the last step's end: static
    friction lets go of a slip it cannot stop, not of one it is stopping (penalty springs start from zero
    force, and a box set down on a slope slips while they take its weight).  Some points of a pair at their
    cone do not make it slide: the uphill corners of a box on a slope carry less weight and reach their share
    of the cone first, while the others still hold it; the box lets go at ``tan(theta) = mu_s`` as a whole.
    (A pair's contacts are consecutive rows of the table.)"""
    first = 0
    while first < nc:
        a, b = ci[first, C_BODY_A], ci[first, C_BODY_B]
        last = first + 1
        while last < nc and ci[last, C_BODY_A] == a and ci[last, C_BODY_B] == b:
            last += 1
        held = False
        for c in range(first, last):
            held = held or not _at_cone(cf, ci, c)
        # a sticking pair lets go only of a slip it cannot stop: one that grew over the step
        slip = _pair_slip(bf, cf, ci, first)
        for c in range(first, last):
            stopping = (ci[c, C_FLAGS] & CP_SLIDING) == 0 and slip <= cf[c, C_PAIR_SLIP]
            if not held and not stopping and _slides(bf, cf, ci, c, slide_speed):
                ci[c, C_FLAGS] |= CP_SLIDING
            else:
                ci[c, C_FLAGS] &= ~CP_SLIDING
            cf[c, C_PAIR_SLIP] = slip
        first = last
