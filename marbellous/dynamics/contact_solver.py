"""Sequential impulses on contact points, as the lecture teaches them, made stable by soft constraints.

For each contact point (normal n from a to b, offsets ra, rb from the centres of mass):

    relative velocity     dv = (v_b + w_b x rb) - (v_a + w_a x ra)
    change per impulse    K_d = m_a^-1 + m_b^-1 + (ra x d) I_a^-1 (ra x d) + (rb x d) I_b^-1 (rb x d)
    normal                lambda_n += -(dv.n + bias) / K_n,  lambda_n >= 0   (separation, soft)
    friction (Coulomb)    (lambda_t1, lambda_t2) += -(dv.t1 / K_t1, dv.t2 / K_t2),
                          clamped to the disc |lambda_t| <= mu lambda_n, mu = mu_s while the contact
                          sticks and mu_d once it slides
    rolling resistance    lambda_r += -(I_a^-1 + I_b^-1)^-1 (w_b - w_a), |lambda_r| <= rho lambda_n
    restitution           after the solve, dv.n := -e dv.n(before) for contacts that were closing

Impulses accumulate per contact and are warm-started from the last step (matched by feature).
A speculative contact (separation s > 0) lets the bodies approach by exactly s in the sub-step.
"""
import math

import numpy as np

from .._jit import njit
from ..layout import (C_ADJ_SEP, C_BODY_A, C_BODY_B, C_DEPTH, C_E, C_FLAGS, C_LAMBDA_N, C_LAMBDA_R,
                      C_LAMBDA_T1, C_LAMBDA_T2, C_MASS_N, C_MASS_T1, C_MASS_T2, C_MAX_N, C_MU_D, C_MU_S,
                      C_NORMAL, C_POINT, C_RA, C_RB, C_ROLL, C_SUM_N, C_SUM_T, C_T1, C_T2, C_VN0,
                      CP_MATCHED, CP_SENSOR, CP_SLIDING, DTHETA, FRICTION, OMEGA, POS, POS0, RESTITUTION, ROLLING,
                      STATIC_FRICTION)
from .contact_basis import contact_basis
from .rigid import apply_impulse_pair, effective_mass, relative_velocity


@njit
def prepare_contacts(bf, cf, ci, nc, sb, slide_speed):
    """Stage "prepare": offsets, contact basis, effective masses, combined materials, approach speed.

    A contact slides (dynamic friction) if its tangential speed exceeds ``slide_speed`` (m/s) or its
    friction was saturated in the last step; otherwise it sticks (static friction).
    """
    if nc == 0:
        return
    dv = np.empty(3)
    for c in range(nc):
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        n = cf[c, C_NORMAL:C_NORMAL + 3]
        for k in range(3):
            cf[c, C_RA + k] = cf[c, C_POINT + k] - bf[a, POS + k]
            cf[c, C_RB + k] = cf[c, C_POINT + k] - bf[b, POS + k]
        ra = cf[c, C_RA:C_RA + 3]
        rb = cf[c, C_RB:C_RB + 3]
        t1 = cf[c, C_T1:C_T1 + 3]
        t2 = cf[c, C_T2:C_T2 + 3]
        contact_basis(n, t1, t2)
        cf[c, C_MASS_N] = effective_mass(sb[a, 0], sb[a, 1:10], ra, sb[b, 0], sb[b, 1:10], rb, n)
        cf[c, C_MASS_T1] = effective_mass(sb[a, 0], sb[a, 1:10], ra, sb[b, 0], sb[b, 1:10], rb, t1)
        cf[c, C_MASS_T2] = effective_mass(sb[a, 0], sb[a, 1:10], ra, sb[b, 0], sb[b, 1:10], rb, t2)
        # Materials: friction by geometric mean, restitution and rolling friction by maximum.
        cf[c, C_MU_D] = math.sqrt(bf[a, FRICTION] * bf[b, FRICTION])
        cf[c, C_MU_S] = math.sqrt(bf[a, STATIC_FRICTION] * bf[b, STATIC_FRICTION])
        cf[c, C_E] = max(bf[a, RESTITUTION], bf[b, RESTITUTION])
        cf[c, C_ROLL] = max(bf[a, ROLLING], bf[b, ROLLING])
        relative_velocity(bf, a, ra, b, rb, dv)
        vn = dv[0] * n[0] + dv[1] * n[1] + dv[2] * n[2]
        cf[c, C_VN0] = vn
        vt1 = dv[0] * t1[0] + dv[1] * t1[1] + dv[2] * t1[2]
        vt2 = dv[0] * t2[0] + dv[1] * t2[1] + dv[2] * t2[2]
        sliding = math.sqrt(vt1 * vt1 + vt2 * vt2) > slide_speed
        if (ci[c, C_FLAGS] & CP_MATCHED) != 0 and (ci[c, C_FLAGS] & CP_SLIDING) != 0:
            sliding = True
        if sliding:
            ci[c, C_FLAGS] |= CP_SLIDING
        else:
            ci[c, C_FLAGS] &= ~CP_SLIDING
        cf[c, C_ADJ_SEP] = -cf[c, C_DEPTH]
        cf[c, C_MAX_N] = 0.0
        cf[c, C_SUM_N] = 0.0
        for k in range(3):
            cf[c, C_SUM_T + k] = 0.0


@njit
def warm_start_contacts(bf, cf, ci, nc, sb):
    """Stage "warm start": apply the impulses accumulated last sub-step (or matched from last step)."""
    if nc == 0:
        return
    p = np.empty(3)
    for c in range(nc):
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ln, l1, l2 = cf[c, C_LAMBDA_N], cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
        for k in range(3):
            p[k] = ln * cf[c, C_NORMAL + k] + l1 * cf[c, C_T1 + k] + l2 * cf[c, C_T2 + k]
        apply_impulse_pair(bf, a, sb[a, 0], sb[a, 1:10], cf[c, C_RA:C_RA + 3],
                           b, sb[b, 0], sb[b, 1:10], cf[c, C_RB:C_RB + 3], p)
        _apply_angular(bf, sb, a, b, cf[c, C_LAMBDA_R:C_LAMBDA_R + 3])


@njit
def _apply_angular(bf, sb, a, b, l):
    """Apply the angular impulse ``l`` (N m s) to b and ``-l`` to a."""
    if l[0] == 0.0 and l[1] == 0.0 and l[2] == 0.0:
        return
    for k in range(3):
        bf[a, OMEGA + k] -= sb[a, 1 + 3 * k] * l[0] + sb[a, 2 + 3 * k] * l[1] + sb[a, 3 + 3 * k] * l[2]
        bf[b, OMEGA + k] += sb[b, 1 + 3 * k] * l[0] + sb[b, 2 + 3 * k] * l[1] + sb[b, 3 + 3 * k] * l[2]


@njit
def contact_separation(bf, cf, c, a, b):
    """Current separation (m): the one at detection plus the normal part of the contact points' motion,

        s = s0 + n . ((dx_b + dtheta_b x rb) - (dx_a + dtheta_a x ra))

    with dx, dtheta the bodies' displacement and rotation since the step began (first order in the
    rotation, so a rolling ball's contact stays at its lowest point).
    """
    s = cf[c, C_ADJ_SEP]
    for sign, body, r0 in ((1.0, b, C_RB), (-1.0, a, C_RA)):
        t0, t1, t2 = bf[body, DTHETA], bf[body, DTHETA + 1], bf[body, DTHETA + 2]
        r = cf[c, r0:r0 + 3]
        mx = bf[body, POS] - bf[body, POS0] + t1 * r[2] - t2 * r[1]
        my = bf[body, POS + 1] - bf[body, POS0 + 1] + t2 * r[0] - t0 * r[2]
        mz = bf[body, POS + 2] - bf[body, POS0 + 2] + t0 * r[1] - t1 * r[0]
        s += sign * (cf[c, C_NORMAL] * mx + cf[c, C_NORMAL + 1] * my + cf[c, C_NORMAL + 2] * mz)
    return s


@njit
def solve_contacts(bf, cf, ci, nc, sb, h, use_bias, soft, max_push):
    """Stage "solve" (``use_bias``) or "relax" (not): one pass of sequential impulses over all contacts.

    ``soft`` = (bias_rate, mass_scale, impulse_scale) of the contact softness; ``max_push`` (m/s) caps
    the speed at which overlap is removed.  Returns the largest velocity change made (m/s), for the
    adaptive iteration count.
    """
    if nc == 0:
        return 0.0
    dv = np.empty(3)
    p = np.empty(3)
    largest = 0.0
    for c in range(nc):
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = cf[c, C_RA:C_RA + 3]
        rb = cf[c, C_RB:C_RB + 3]
        n = cf[c, C_NORMAL:C_NORMAL + 3]
        iwa = sb[a, 1:10]
        iwb = sb[b, 1:10]
        # --- normal: non-penetration -------------------------------------------------------------
        s = contact_separation(bf, cf, c, a, b)
        if s > 0.0:
            bias, mass_scale, impulse_scale = s / h, 1.0, 0.0      # speculative: close the gap exactly
        elif use_bias:
            bias = max(soft[0] * s, -max_push)
            mass_scale, impulse_scale = soft[1], soft[2]
        else:
            bias, mass_scale, impulse_scale = 0.0, 1.0, 0.0
        relative_velocity(bf, a, ra, b, rb, dv)
        vn = dv[0] * n[0] + dv[1] * n[1] + dv[2] * n[2]
        old = cf[c, C_LAMBDA_N]
        new = max(old - cf[c, C_MASS_N] * mass_scale * (vn + bias) - impulse_scale * old, 0.0)
        cf[c, C_LAMBDA_N] = new
        if new > 0.0 and cf[c, C_MAX_N] == 0.0 and (ci[c, C_FLAGS] & CP_MATCHED) == 0:
            # A new contact engages: the approach speed at impact, gravity of earlier sub-steps included.
            cf[c, C_VN0] = min(vn, cf[c, C_VN0])
        if new > cf[c, C_MAX_N]:
            cf[c, C_MAX_N] = new
        d = new - old
        if d != 0.0:
            for k in range(3):
                p[k] = d * n[k]
            apply_impulse_pair(bf, a, sb[a, 0], iwa, ra, b, sb[b, 0], iwb, rb, p)
            change = abs(d) / cf[c, C_MASS_N] if cf[c, C_MASS_N] > 0.0 else 0.0
            largest = max(largest, change)
        # --- friction: Coulomb disc on the tangent plane -------------------------------------------
        mu = cf[c, C_MU_D] if (ci[c, C_FLAGS] & CP_SLIDING) != 0 else cf[c, C_MU_S]
        bound = mu * new
        relative_velocity(bf, a, ra, b, rb, dv)
        t1 = cf[c, C_T1:C_T1 + 3]
        t2 = cf[c, C_T2:C_T2 + 3]
        vt1 = dv[0] * t1[0] + dv[1] * t1[1] + dv[2] * t1[2]
        vt2 = dv[0] * t2[0] + dv[1] * t2[1] + dv[2] * t2[2]
        o1, o2 = cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
        n1 = o1 - cf[c, C_MASS_T1] * vt1
        n2 = o2 - cf[c, C_MASS_T2] * vt2
        length = math.sqrt(n1 * n1 + n2 * n2)
        if length > bound:
            scale = bound / length if length > 0.0 else 0.0
            n1 *= scale
            n2 *= scale
        cf[c, C_LAMBDA_T1] = n1
        cf[c, C_LAMBDA_T2] = n2
        d1, d2 = n1 - o1, n2 - o2
        if d1 != 0.0 or d2 != 0.0:
            for k in range(3):
                p[k] = d1 * t1[k] + d2 * t2[k]
            apply_impulse_pair(bf, a, sb[a, 0], iwa, ra, b, sb[b, 0], iwb, rb, p)
        # --- rolling resistance: an angular impulse bounded by rho * lambda_n -------------------------
        rho = cf[c, C_ROLL]
        if rho > 0.0:
            _solve_rolling(bf, cf, c, sb, a, b, rho * new)
    return largest


@njit
def _solve_rolling(bf, cf, c, sb, a, b, bound):
    """Drive the relative angular velocity ``w_b - w_a`` to zero with ``|lambda_r| <= bound``."""
    k = np.empty((3, 3))
    for r in range(3):
        for q in range(3):
            k[r, q] = sb[a, 1 + 3 * r + q] + sb[b, 1 + 3 * r + q]
    det = (k[0, 0] * (k[1, 1] * k[2, 2] - k[1, 2] * k[2, 1]) - k[0, 1] * (k[1, 0] * k[2, 2] - k[1, 2] * k[2, 0])
           + k[0, 2] * (k[1, 0] * k[2, 1] - k[1, 1] * k[2, 0]))
    if det <= 0.0:
        return
    dw = np.empty(3)
    for q in range(3):
        dw[q] = bf[b, OMEGA + q] - bf[a, OMEGA + q]
    # K^-1 dw by Cramer's rule
    x = np.empty(3)
    for col in range(3):
        m = k.copy()
        for r in range(3):
            m[r, col] = dw[r]
        x[col] = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]) - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
                  + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0])) / det
    old = cf[c, C_LAMBDA_R:C_LAMBDA_R + 3].copy()
    new = old - x
    length = math.sqrt(new[0] * new[0] + new[1] * new[1] + new[2] * new[2])
    if length > bound:
        new *= bound / length if length > 0.0 else 0.0
    for q in range(3):
        cf[c, C_LAMBDA_R + q] = new[q]
    _apply_angular(bf, sb, a, b, new - old)


@njit
def apply_restitution(bf, cf, ci, nc, sb, threshold):
    """Stage "restitution": contacts that closed faster than ``threshold`` (m/s) separate at ``-e vn0``."""
    if nc == 0:
        return
    dv = np.empty(3)
    p = np.empty(3)
    for c in range(nc):
        e = cf[c, C_E]
        if e == 0.0 or (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        if cf[c, C_VN0] > -threshold or cf[c, C_MAX_N] == 0.0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        ra = cf[c, C_RA:C_RA + 3]
        rb = cf[c, C_RB:C_RB + 3]
        n = cf[c, C_NORMAL:C_NORMAL + 3]
        relative_velocity(bf, a, ra, b, rb, dv)
        vn = dv[0] * n[0] + dv[1] * n[1] + dv[2] * n[2]
        old = cf[c, C_LAMBDA_N]
        new = max(old - cf[c, C_MASS_N] * (vn + e * cf[c, C_VN0]), 0.0)
        cf[c, C_LAMBDA_N] = new
        d = new - old
        for k in range(3):
            p[k] = d * n[k]
        apply_impulse_pair(bf, a, sb[a, 0], sb[a, 1:10], ra, b, sb[b, 0], sb[b, 1:10], rb, p)
        cf[c, C_SUM_N] += d


@njit
def accumulate_applied(cf, ci, nc):
    """After each sub-step: add the impulses that sub-step applied to the step's totals (for reports)."""
    for c in range(nc):
        cf[c, C_SUM_N] += cf[c, C_LAMBDA_N]
        for k in range(3):
            cf[c, C_SUM_T + k] += cf[c, C_LAMBDA_T1] * cf[c, C_T1 + k] + cf[c, C_LAMBDA_T2] * cf[c, C_T2 + k]


@njit
def store_friction_state(cf, ci, nc):
    """Stage "store impulses": a contact whose friction reached the cone slides in the next step."""
    for c in range(nc):
        bound = cf[c, C_LAMBDA_N] * (cf[c, C_MU_D] if (ci[c, C_FLAGS] & CP_SLIDING) != 0 else cf[c, C_MU_S])
        l1, l2 = cf[c, C_LAMBDA_T1], cf[c, C_LAMBDA_T2]
        if bound > 0.0 and math.sqrt(l1 * l1 + l2 * l2) >= bound * (1.0 - 1e-9):
            ci[c, C_FLAGS] |= CP_SLIDING
        else:
            ci[c, C_FLAGS] &= ~CP_SLIDING
