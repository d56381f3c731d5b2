"""The spring-based scheme of the lecture: a damped spring at each contact point forces the bodies apart.

At the start of every sub-step each contact point with overlap ``d = -s > 0`` (``s`` the separation
now, updated from the bodies' motion since detection) pushes b along the normal and a against it with

    F_n = max(0, k d - c v_n)                         (never pulls)
    k = m_n omega^2,   c = 2 zeta m_n omega,          omega = 2 pi f

where ``m_n`` is the contact's effective mass along the normal (``1 / (J M^-1 J^T)``), so every contact
is a damped oscillator of frequency ``f`` whatever the masses.  The damping ratio follows from the
coefficient of restitution ``e`` of the pair: the spring lets go with ``e`` times the approach speed
(see :func:`spring_restitution`); below ``e = exp(-2)`` it is critical, 1.

Stability.  The semi-implicit Euler update of a damped oscillator is stable for
``(omega h)^2 + 4 zeta omega h < 4``; a column of contacts has modes up to twice the single-contact
frequency, so ``f`` is capped at ``STABLE_FRACTION / h`` (omega h <= 0.4, i.e. at most 2 omega h = 0.8 in
a stack: 0.64 + 3.2 zeta < 4 for zeta <= 1).  Every force is taken at the sub-step's start (a Jacobi
update), so the dashpots of the contacts on one body add up: their common mode's approach speed is
scaled by ``2 zeta omega h R`` in a sub-step, ``R`` the coupling of :func:`_dashpot_coupling`, and the
damping force of a contact approaching faster than gravity makes in a sub-step (``g h``, at which
restitution starts too) is capped at ``2 m_n omega max(|v_n| / (2 omega h R), zeta g h)`` so that they
never throw a body back by more than that speed (at critical damping a box landing flat on four corners
left at 2.2 times its landing speed).  Resting contacts, slower, keep their full damping.  A resting body sinks
in by ``g / omega^2`` per contact layer (about 1 mm at h = 1/240 s), the price of the method; more
sub-steps make the springs stiffer.

Friction is a tangential spring at the contact (Cundall and Strack 1979), stretched by the sliding of
the contact points and limited by Coulomb's cone, with a critically damped dashpot beside it:

    S  <- S - m_t omega^2 v_t h          (the spring's force follows the tangential displacement)
    F_t = S - 2 m_t omega v_t,   |F_t| <= mu F_n   (scaled back onto the cone, and then S = F_t)

per tangent of the contact basis (``m_t`` the effective mass along it), so a body held by static
friction rests on a stretched spring instead of creeping, and a sliding one feels ``mu F_n`` against
its motion.  The spring force ``S h`` is the contact's friction impulse (C_LAMBDA_T1, C_LAMBDA_T2),
carried from sub-step to sub-step and, matched by feature, from step to step.  A contact sticks
(``mu = mu_s``; a spring pulled past the static cone is held on it, and the contact slips) until the
step ends with every contact of its pair at the cone, its points sliding faster than ``slide_speed`` and
its bodies slipping past each other faster than at the step before (``contact_solver.store_friction_state``,
as for the impulse solvers: the springs start from zero force, so a box set down on a slope slips while
they take its weight, a slip that static friction then stops); then it slides (``mu = mu_d``) until the
spring and dashpot ask for less than ``mu_d F_n`` again.  The uphill corners of a box on a
slope, which carry less weight, reach their share of the static cone first: the box holds while the
others do, and lets go at ``tan(theta) = mu_s``.

Rolling resistance is a torque ``-I_r dw_t / h`` on the relative angular velocity across the normal,
``dw_t = dw - (dw.n) n`` with ``dw = w_b - w_a``, bounded by ``rho F_n`` (``I_r = 1 / (d . (I_a^-1 +
I_b^-1) d)``, ``d = dw_t / |dw_t|``); torsional friction is the same on the spin ``(dw.n) n``, bounded by
``tau F_n``.

The forces are added to the bodies' force and torque accumulators before the integrator runs, so
every integrator sees them; the impulses ``F h`` are stored in the contact rows as the other
solvers' impulses are (reports, sliding state).
"""
import math

import numpy as np

from .._numba.jit import njit
from ..math3d import row3
from ..state.layout import (CP_SENSOR, CP_SLIDING, C_BODY_A, C_BODY_B, C_E, C_FLAGS, C_LAMBDA_N, C_LAMBDA_R,
                            C_LAMBDA_T1, C_LAMBDA_T2, C_MASS_N, C_MASS_T1, C_MASS_T2, C_MAX_N, C_MU_D, C_MU_S, C_NORMAL,
                            C_RA, C_RB, C_ROLL, C_T1, C_T2, C_TORSION, FORCE, OMEGA, SB_INV_I, SB_INV_MASS, SB_ISO,
                            TORQUE)
from .contact_solver import contact_separation
from .rigid import relative_velocity

#: The contact frequency is at most this fraction of the sub-step rate (omega h <= 2 pi * 0.064 = 0.4).
STABLE_FRACTION = 0.4 / (2.0 * math.pi)
#: The friction springs' frequency relative to the normal springs'.
TANGENT_FRACTION = 0.5


@njit
def spring_restitution(zeta):
    """Coefficient of restitution of a contact spring with damping ratio ``zeta`` in [0, 1] that never pulls.

    With overlap ``d`` (``d(0) = 0``, ``d'(0) = v0``), ``d'' + 2 zeta w0 d' + w0^2 d = 0`` and the contact
    ends when the force ``w0^2 d + 2 zeta w0 d'`` (that is ``-d''``) reaches zero, before d does.  With
    ``w = w0 sqrt(1 - zeta^2)`` and the phase ``phi = atan2(2 zeta w0 w, (zeta w0)^2 - w^2)`` at which
    ``d'' = 0``:

        e = -d'(phi / w) / v0 = exp(-zeta w0 phi / w) ((zeta w0 / w) sin phi - cos phi)

    (``e = 1`` at zeta = 0, ``e = exp(-2)`` at critical damping; Schwager and Poeschel, Phys. Rev. E 2007).
    """
    if zeta >= 1.0:
        return math.exp(-2.0)
    w = math.sqrt(1.0 - zeta * zeta)
    phi = math.atan2(2.0 * zeta * w, zeta * zeta - w * w)
    return math.exp(-zeta * phi / w) * ((zeta / w) * math.sin(phi) - math.cos(phi))


@njit
def damping_ratio(e):
    """Damping ratio in [0, 1] of the contact spring that rebounds with restitution ``e`` (bisection of
    :func:`spring_restitution`); restitutions below ``exp(-2) = 0.135``, which would need an over-damped
    spring (unstable at the sub-step), get critical damping."""
    if e >= 1.0:
        return 0.0
    if e <= math.exp(-2.0):
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if spring_restitution(mid) > e:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit
def add_penalty_forces(bf, cf, ci, nc, sb, nb, h, hertz, saved, rest_speed=0.0):
    """Stage "penalty forces": add every contact spring's force and torque to the accumulators.

    ``hertz`` (Hz) is the contact frequency (capped for stability, see above), ``h`` (s) the sub-step.
    The accumulators' previous contents (the user's forces) are kept in ``saved`` (nb, 6) for
    :func:`restore_user_forces`.  Contacts approaching faster than ``rest_speed`` (m/s; the step passes
    the speed gravity gives in a sub-step) have their dashpots capped so that those of one body cannot
    throw it back (:func:`_dashpot_coupling`); slower ones, resting contacts, are damped in full.
    """
    for i in range(nb):
        for k in range(6):
            saved[i, k] = bf[i, FORCE + k]
    omega = 2.0 * math.pi * min(hertz, STABLE_FRACTION / h)
    omega_t = TANGENT_FRACTION * omega
    F = bf[:, FORCE:FORCE + 3]
    T = bf[:, TORQUE:TORQUE + 3]
    dv = np.empty(3)
    f = np.empty(3)
    dw_roll = np.empty(3)    # relative angular velocity across the normal (rad/s)
    dw_spin = np.empty(3)    # and along it
    coupling = _dashpot_coupling(cf, ci, nc, sb, nb)
    for c in range(nc):
        for k in range(3):
            cf[c, C_LAMBDA_R + k] = 0.0
        cf[c, C_LAMBDA_N] = 0.0
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        depth = -contact_separation(sb, cf, c, a, b)
        m_n = cf[c, C_MASS_N]
        if depth <= 0.0 or m_n == 0.0 or (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            cf[c, C_LAMBDA_T1] = 0.0      # out of touch: the friction spring lets go
            cf[c, C_LAMBDA_T2] = 0.0
            continue
        n = cf[c, C_NORMAL:C_NORMAL + 3]
        relative_velocity(bf, a, cf[c, C_RA:C_RA + 3], b, cf[c, C_RB:C_RB + 3], dv)
        vn = dv[0] * n[0] + dv[1] * n[1] + dv[2] * n[2]
        # Sliding (dynamic friction) as the step began (contact_solver.store_friction_state), until the spring
        # holds again within the dynamic cone.
        mu = cf[c, C_MU_D] if (ci[c, C_FLAGS] & CP_SLIDING) != 0 else cf[c, C_MU_S]
        # n dashpots on one body act at once (all from the sub-step's start): above the speed gravity gives in
        # a sub-step, at most 2 zeta omega h R <= 1 (see _dashpot_coupling)
        zeta = damping_ratio(cf[c, C_E])
        speed = abs(vn)
        if speed > rest_speed:
            zeta = max(min(zeta, 1.0 / (2.0 * omega * h * coupling[c])), zeta * rest_speed / speed)
        fn = max(m_n * omega * (omega * depth - 2.0 * zeta * vn), 0.0)
        if fn == 0.0:
            cf[c, C_LAMBDA_T1] = 0.0
            cf[c, C_LAMBDA_T2] = 0.0
            continue
        # Friction: tangential spring S (stored as the impulse S h) and dashpot, within the Coulomb disc.
        t1 = cf[c, C_T1:C_T1 + 3]
        t2 = cf[c, C_T2:C_T2 + 3]
        v1 = dv[0] * t1[0] + dv[1] * t1[1] + dv[2] * t1[2]
        v2 = dv[0] * t2[0] + dv[1] * t2[1] + dv[2] * t2[2]
        s1 = cf[c, C_LAMBDA_T1] / h - cf[c, C_MASS_T1] * omega_t * omega_t * v1 * h
        s2 = cf[c, C_LAMBDA_T2] / h - cf[c, C_MASS_T2] * omega_t * omega_t * v2 * h
        f1 = s1 - 2.0 * cf[c, C_MASS_T1] * omega_t * v1
        f2 = s2 - 2.0 * cf[c, C_MASS_T2] * omega_t * v2
        length = math.sqrt(f1 * f1 + f2 * f2)
        if length > mu * fn:
            scale = mu * fn / length
            f1 *= scale
            f2 *= scale
            s1, s2 = f1, f2
        else:
            ci[c, C_FLAGS] &= ~CP_SLIDING       # the spring holds: the contact sticks again
        for k in range(3):
            f[k] = fn * n[k] + f1 * t1[k] + f2 * t2[k]
        # f acts on b and -f on a, at the contact's offsets of the step's start (as the impulse solvers).
        _push(F, T, b, cf[c, C_RB:C_RB + 3], f, 1.0)
        _push(F, T, a, cf[c, C_RA:C_RA + 3], f, -1.0)
        cf[c, C_LAMBDA_N] = fn * h
        cf[c, C_LAMBDA_T1] = s1 * h
        cf[c, C_LAMBDA_T2] = s2 * h
        cf[c, C_MAX_N] = max(cf[c, C_MAX_N], fn * h)
        if cf[c, C_ROLL] > 0.0 or cf[c, C_TORSION] > 0.0:
            spin = 0.0
            for k in range(3):
                dw_roll[k] = bf[b, OMEGA + k] - bf[a, OMEGA + k]
                spin += dw_roll[k] * n[k]
            for k in range(3):
                dw_spin[k] = spin * n[k]
                dw_roll[k] -= dw_spin[k]
            _rolling_torque(cf, c, sb, a, b, dw_roll, cf[c, C_ROLL] * fn, h, T)
            _rolling_torque(cf, c, sb, a, b, dw_spin, cf[c, C_TORSION] * fn, h, T)


@njit
def _dashpot_coupling(cf, ci, nc, sb, nb):
    """For each touching contact ``i``, a bound ``R_i >= 1`` on how many times over the dashpots of all the
    contacts on its bodies, each evaluated at the sub-step's start, stop their common motion: the
    Gershgorin row sum of the contacts' normal coupling scaled by the contact's effective mass,

        R_i = m_i sum_j |J_i M_b^-1 J_j^T|,
        J_i M_b^-1 J_j^T = s_i s_j (n_i . n_j / m_b + (r_i x n_i) . I_b^-1 (r_j x n_j))

    over the contacts ``j`` touching body ``b`` (each movable body of ``i``, counted apart; ``s`` = -1 on a,
    +1 on b).  It bounds the largest eigenvalue of ``D J M^-1 J^T`` (``D`` the effective masses), the factor
    by which a common mode's approach speed is scaled by the dashpots: ``2 zeta omega h R``, kept <= 1 so
    they never throw a body back (at critical damping, four of them threw a box landing flat on its
    corners off at 2.2 times its landing speed).  A cube resting on four corners has R = 2 on the ground,
    4 in a tower.  Contacts not touching get 1.
    """
    touching = np.zeros(nc, dtype=np.bool_)
    start = np.zeros(nb + 1, dtype=np.int64)
    for c in range(nc):
        a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
        if (ci[c, C_FLAGS] & CP_SENSOR) == 0 and cf[c, C_MASS_N] > 0.0 and contact_separation(sb, cf, c, a, b) < 0.0:
            touching[c] = True
            for body in (a, b):
                if sb[body, SB_ISO] != 0.0:
                    start[body + 1] += 1
    for i in range(nb):
        start[i + 1] += start[i]
    fill = start.copy()
    members = np.empty(max(start[nb], 1), dtype=np.int64)
    for c in range(nc):
        if touching[c]:
            for body in (ci[c, C_BODY_A], ci[c, C_BODY_B]):
                if sb[body, SB_ISO] != 0.0:
                    members[fill[body]] = c
                    fill[body] += 1
    out = np.ones(nc)
    for c in range(nc):
        if not touching[c]:
            continue
        n = row3(cf, c, C_NORMAL)
        total = 0.0
        for side in range(2):
            body = ci[c, C_BODY_A + side]
            if sb[body, SB_ISO] == 0.0:
                continue
            r = row3(cf, c, C_RA + 3 * side)
            u = (r[1] * n[2] - r[2] * n[1], r[2] * n[0] - r[0] * n[2], r[0] * n[1] - r[1] * n[0])
            w = (sb[body, SB_INV_I] * u[0] + sb[body, SB_INV_I + 1] * u[1] + sb[body, SB_INV_I + 2] * u[2],
                 sb[body, SB_INV_I + 3] * u[0] + sb[body, SB_INV_I + 4] * u[1] + sb[body, SB_INV_I + 5] * u[2],
                 sb[body, SB_INV_I + 6] * u[0] + sb[body, SB_INV_I + 7] * u[1] + sb[body, SB_INV_I + 8] * u[2])
            sign = -1.0 if side == 0 else 1.0
            for q in range(start[body], start[body + 1]):
                j = members[q]
                nj = row3(cf, j, C_NORMAL)
                sj = -1.0 if ci[j, C_BODY_A] == body else 1.0
                rj = row3(cf, j, C_RA) if sj < 0.0 else row3(cf, j, C_RB)
                uj = (rj[1] * nj[2] - rj[2] * nj[1], rj[2] * nj[0] - rj[0] * nj[2], rj[0] * nj[1] - rj[1] * nj[0])
                entry = (sb[body, SB_INV_MASS] * (n[0] * nj[0] + n[1] * nj[1] + n[2] * nj[2])
                         + w[0] * uj[0] + w[1] * uj[1] + w[2] * uj[2])
                total += abs(sign * sj * entry)
        out[c] = max(cf[c, C_MASS_N] * total, 1.0)
    return out


@njit
def _push(F, T, body, r, f, sign):
    """Add the force ``sign f`` (N) at offset ``r`` (m) from ``body``'s centre of mass, and its torque."""
    for k in range(3):
        F[body, k] += sign * f[k]
    T[body, 0] += sign * (r[1] * f[2] - r[2] * f[1])
    T[body, 1] += sign * (r[2] * f[0] - r[0] * f[2])
    T[body, 2] += sign * (r[0] * f[1] - r[1] * f[0])


@njit
def _rolling_torque(cf, c, sb, a, b, dw, bound, h, T):
    """Torque opposing the relative angular velocity ``dw`` (a part of ``w_b - w_a``), the one that stops it
    in ``h``, at most ``bound`` (N m); its impulse is added to the contact's ``lambda_r``."""
    speed = math.sqrt(dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2])
    if speed == 0.0 or bound <= 0.0:
        return
    inv_i = 0.0
    for r in range(3):
        for q in range(3):
            inv_i += dw[r] * (sb[a, SB_INV_I + 3 * r + q] + sb[b, SB_INV_I + 3 * r + q]) * dw[q]
    inv_i /= speed * speed
    if inv_i <= 0.0:
        return
    tau = min(speed / (inv_i * h), bound)
    for k in range(3):
        t = -tau * dw[k] / speed
        T[b, k] += t
        T[a, k] -= t
        cf[c, C_LAMBDA_R + k] += t * h


@njit
def restore_user_forces(bf, nb, saved):
    """Put the user's forces and torques back into the accumulators after the integrator used them."""
    for i in range(nb):
        for k in range(6):
            bf[i, FORCE + k] = saved[i, k]
