"""Impacts resolved at the moment they happen: the lecture's "go to the time of impact, resolve there".

An interval that ends at a time of impact leaves the bodies touching and still closing.  The next
interval begins by resolving those impacts before anything moves, with sequential impulses on the solver
bodies (``solver_bodies``) over the listed contacts:

    approach     v_n- = (v_b + w_b x rb - v_a - w_a x ra) . n  at the start  (< 0: closing)
    normal       d lambda_n = m_n (-e v_n- - v_n),  lambda_n >= 0 accumulated
                 (Newton's law of restitution, e = max(e_a, e_b), m_n the effective mass along n)
    friction     (lambda_t1, lambda_t2) += -(m_t1 v_t1, m_t2 v_t2), clamped to |lambda_t| <= mu_d lambda_n
                 (Coulomb, sliding coefficient mu_d = sqrt(mu_a mu_b))
    passes       until no velocity changes by more than the tolerance, at most MAX_PASSES

For a single contact the normal impulse is exact: the bodies leave at ``-e`` times their approach speed
(e = 1 keeps the kinetic energy).  The solved velocities are written back to the body table; each
contact's total impulse goes to ``impact_f`` (``IMP_N``, ``IMP_T``) for the step's contact report, and its
approach speed ``max(0, -v_n-)`` to ``IMP_APPROACH`` (the step's contact events).  The
contact table's solver columns serve as scratch: the step's match and prepare stages write them all again.
"""
import math

from .._numba.jit import njit
from ..math3d import dot3, row3
from ..state.layout import (C_BODY_A, C_BODY_B, C_E, C_LAMBDA_N, C_LAMBDA_T1, C_LAMBDA_T2, C_MASS_N, C_MASS_T1,
                            C_MASS_T2, C_MU_D, C_NORMAL, C_POINT, C_RA, C_RB, C_T1, C_T2, C_VN0, FRICTION, IMP_APPROACH,
                            IMP_N, IMP_T, OMEGA, POS, RESTITUTION, VEL)
from .contact_basis import contact_basis
from .forces import is_moving
from .solver_bodies import (effective_masses, prepare_solver_bodies, push, relative_velocity_at, set_velocity,
                            store_velocities, velocity)

#: most passes over the impacts of one instant
MAX_PASSES = 32


@njit
def _point_velocity(bf, bi, i, r):
    """``v + omega x r`` (m/s) of body row ``i`` (zero for a static or sleeping body)."""
    if not is_moving(bi, i):
        return 0.0, 0.0, 0.0
    w0, w1, w2 = bf[i, OMEGA], bf[i, OMEGA + 1], bf[i, OMEGA + 2]
    return (bf[i, VEL] + w1 * r[2] - w2 * r[1], bf[i, VEL + 1] + w2 * r[0] - w0 * r[2],
            bf[i, VEL + 2] + w0 * r[1] - w1 * r[0])


@njit
def closing_speed(bf, bi, cf, ci, c):
    """``-(v_b + w_b x rb - v_a - w_a x ra) . n`` (m/s) of contact ``c`` from the body table: > 0 when its
    bodies approach at its point."""
    a = ci[c, C_BODY_A]
    b = ci[c, C_BODY_B]
    p = row3(cf, c, C_POINT)
    pa = _point_velocity(bf, bi, a, (p[0] - bf[a, POS], p[1] - bf[a, POS + 1], p[2] - bf[a, POS + 2]))
    pb = _point_velocity(bf, bi, b, (p[0] - bf[b, POS], p[1] - bf[b, POS + 1], p[2] - bf[b, POS + 2]))
    return -((pb[0] - pa[0]) * cf[c, C_NORMAL] + (pb[1] - pa[1]) * cf[c, C_NORMAL + 1]
             + (pb[2] - pa[2]) * cf[c, C_NORMAL + 2])


@njit
def resolve_impacts(bf, bi, nb, cf, ci, listed, m, sb, impact_f, tolerance):
    """Resolve the impacts ``listed[:m]`` (contact rows) at once (module docstring); ``sb`` is scratch for the
    solver bodies, ``tolerance`` (m/s) the convergence test.  Adds each contact's impulses to its row of
    ``impact_f``."""
    prepare_solver_bodies(bf, bi, nb, sb)
    for k in range(m):
        c = listed[k]
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        for j in range(3):
            cf[c, C_RA + j] = cf[c, C_POINT + j] - bf[a, POS + j]
            cf[c, C_RB + j] = cf[c, C_POINT + j] - bf[b, POS + j]
        ra, rb, n = row3(cf, c, C_RA), row3(cf, c, C_RB), row3(cf, c, C_NORMAL)
        t1, t2 = contact_basis(n)
        for j in range(3):
            cf[c, C_T1 + j] = t1[j]
            cf[c, C_T2 + j] = t2[j]
        cf[c, C_MASS_N], cf[c, C_MASS_T1], cf[c, C_MASS_T2] = effective_masses(sb, a, ra, b, rb, n, t1, t2)
        cf[c, C_E] = max(bf[a, RESTITUTION], bf[b, RESTITUTION])
        cf[c, C_MU_D] = math.sqrt(bf[a, FRICTION] * bf[b, FRICTION])
        cf[c, C_VN0] = dot3(relative_velocity_at(velocity(sb, a), ra, velocity(sb, b), rb), n)
        impact_f[c, IMP_APPROACH] = max(impact_f[c, IMP_APPROACH], -cf[c, C_VN0])
        cf[c, C_LAMBDA_N] = 0.0
        cf[c, C_LAMBDA_T1] = 0.0
        cf[c, C_LAMBDA_T2] = 0.0
    for _ in range(MAX_PASSES):
        largest = 0.0
        for k in range(m):
            c = listed[k]
            a = ci[c, C_BODY_A]
            b = ci[c, C_BODY_B]
            ra, rb, n = row3(cf, c, C_RA), row3(cf, c, C_RB), row3(cf, c, C_NORMAL)
            ua = velocity(sb, a)
            ub = velocity(sb, b)
            vn = dot3(relative_velocity_at(ua, ra, ub, rb), n)
            old = cf[c, C_LAMBDA_N]
            new = max(old + cf[c, C_MASS_N] * (-cf[c, C_E] * cf[c, C_VN0] - vn), 0.0)
            d = new - old
            cf[c, C_LAMBDA_N] = new
            if d != 0.0:
                ua = push(sb, a, ua, ra, d * n[0], d * n[1], d * n[2], -1.0)
                ub = push(sb, b, ub, rb, d * n[0], d * n[1], d * n[2], 1.0)
                if cf[c, C_MASS_N] > 0.0:
                    largest = max(largest, abs(d) / cf[c, C_MASS_N])
            t1, t2 = row3(cf, c, C_T1), row3(cf, c, C_T2)
            dv = relative_velocity_at(ua, ra, ub, rb)
            o1, o2 = cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
            n1 = o1 - cf[c, C_MASS_T1] * dot3(dv, t1)
            n2 = o2 - cf[c, C_MASS_T2] * dot3(dv, t2)
            bound = cf[c, C_MU_D] * new
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
            set_velocity(sb, a, ua)
            set_velocity(sb, b, ub)
        if largest <= tolerance:
            break
    store_velocities(bf, bi, nb, sb)
    for k in range(m):
        c = listed[k]
        impact_f[c, IMP_N] += cf[c, C_LAMBDA_N]
        for j in range(3):
            impact_f[c, IMP_T + j] += cf[c, C_LAMBDA_T1] * cf[c, C_T1 + j] + cf[c, C_LAMBDA_T2] * cf[c, C_T2 + j]
