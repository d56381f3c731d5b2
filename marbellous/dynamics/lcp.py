"""The constraint-based scheme of the lecture: all contacts and joints of a sub-step as one LCP.

Every contact point, rod, cable and joint adds rows to a constraint vector; row i has a Jacobian
``J_i`` over the two bodies it touches (linear and angular parts), so that ``J_i v`` is the relative
velocity it constrains:

    contact normal      J v = n . ((v_b + w_b x rb) - (v_a + w_a x ra))      lambda >= 0
    friction t1, t2     the same along the tangents                          |lambda_t| <= mu lambda_n (disc)
    rolling x, y, z     J v = (w_b - w_a) . e_k        (when rho > 0)        |lambda_k| <= rho lambda_n (box)
    rod                 J v = u . ((v_b + w_b x rb) - (v_a + w_a x ra))      lambda free
    cable               the same                                             lambda <= 0 (it only pulls)
    ball, hinge,        the rows of ``joint_rows.py``: equalities free, limits lambda >= 0, a motor's
    slider, fixed       |lambda| <= max torque (force) h, with J v -> its speed

With the impulses ``lambda`` the velocities become ``v + M^-1 J^T lambda``, so the constrained
velocities are ``w = A lambda + b`` with the assembled matrix ``A = J M^-1 J^T`` and
``b = J v + bias``: a mixed linear complementarity problem (``lcp_solve.py``).  A contact row keeps the
bodies from closing (a speculative contact with gap ``s > 0`` gets the bias ``s / h``: it may close
exactly); overlap is pushed out afterwards by the split impulses of the sequential-impulse solver
(``contact_solver.push_contacts``), which move the poses and never the velocities.  Rods and cables
correct their length error through soft constraints (``soft.py``): a bias ``bias_rate * C`` (no faster
than ``max_push``) and the regularisation ``shift_i = A_ii impulse_scale / mass_scale`` on the diagonal,
the fixed point of the soft impulse update; a slack cable gets ``C / h`` and no softness.  A spring too
stiff for an explicit force is a row with its own softness (``joints.spring_softness``) in both solves.
The "relax" solve after the positions moved (only in steps with rods, cables or implicit springs) uses
no bias and no softness for rods and cables, which takes their correction velocity out again.

The impulses of the last sub-step (or the matched contacts of the last step) are the starting point:
they have already been applied (warm start), so ``b = J v - A lambda_0 + bias`` and only the change
``lambda - lambda_0`` is applied afterwards.

Scaling: A is assembled in compressed sparse rows; rows i and j couple only when they share a moving
body, so for ``m`` rows and at most ``r`` rows per body the matrix has ``O(m r)`` non-zeros, and each
sweep of the projected Gauss-Seidel solver costs that much (assembly likewise).  A pile where each
body touches a few others stays linear in the number of contacts; a body with hundreds of contacts
(a floor is static, so it does not count) makes it quadratic in them.
"""

import numpy as np

from .._numba.jit import njit
from ..state.layout import (CP_MATCHED, CP_SENSOR, CP_SLIDING, C_BODY_A, C_BODY_B, C_FLAGS, C_LAMBDA_N, C_LAMBDA_R,
                            C_LAMBDA_T1, C_MAX_N, C_MU_D, C_MU_S, C_NORMAL, C_RA, C_RB, C_ROLL, C_T1, C_T2, C_TORSION,
                            C_VN0, JOINT_ROWS, KT_CABLE, KT_SPRING, K_BODY_A, K_BODY_B, K_DAMPING, K_IMPULSE, K_LENGTH,
                            K_MOTOR_MAX, K_MOTOR_SPEED, K_ROW_IMPULSE, K_STIFFNESS, K_SUM_ANGULAR, K_SUM_LINEAR, K_TYPE,
                            OMEGA, SB_INV_I, SB_INV_MASS, VEL)
from .contact_solver import contact_separation
from .joint_rows import LIMIT, MOTOR, OFF, R_C, R_KIND, ROW_COLS, fill_rows, is_rigid_joint
from .joints import is_active_joint, joint_axis, spring_softness
from .lcp_solve import solve_bounded_lcp

# What a row constrains (row_kind)
ROW_NORMAL = 0
ROW_T1 = 1
ROW_T2 = 2
ROW_ROLL = 3        # 3, 4, 5: rolling about the contact's t1 and t2, torsion about its normal
ROW_JOINT = 6
ROW_RIGID_JOINT = 7  # 7 .. 7 + JOINT_ROWS - 1: the slots of a ball, hinge, slider or fixed joint's rows


@njit
def _linear_row(J, MJ, i, sb, a, ra, b, rb, d):
    """Jacobian of the relative velocity of the points ``ra``, ``rb`` along ``d``, and ``M^-1 J^T``."""
    ca = (ra[1] * d[2] - ra[2] * d[1], ra[2] * d[0] - ra[0] * d[2], ra[0] * d[1] - ra[1] * d[0])
    cb = (rb[1] * d[2] - rb[2] * d[1], rb[2] * d[0] - rb[0] * d[2], rb[0] * d[1] - rb[1] * d[0])
    for k in range(3):
        J[i, k] = -d[k]
        J[i, 3 + k] = -ca[k]
        J[i, 6 + k] = d[k]
        J[i, 9 + k] = cb[k]
    _inverse_mass_times(J, MJ, i, sb, a, b)


@njit
def _angular_row(J, MJ, i, sb, a, b, d):
    """Jacobian of the relative angular velocity ``(w_b - w_a) . d`` about the unit vector ``d``."""
    for k in range(3):
        J[i, k] = 0.0
        J[i, 6 + k] = 0.0
        J[i, 3 + k] = -d[k]
        J[i, 9 + k] = d[k]
    _inverse_mass_times(J, MJ, i, sb, a, b)


@njit
def _inverse_mass_times(J, MJ, i, sb, a, b):
    """``MJ_i = M^-1 J_i^T``: inverse mass on the linear parts, world inverse inertia on the angular."""
    for side in range(2):
        body = a if side == 0 else b
        o = 6 * side
        if body < 0:
            for k in range(6):
                MJ[i, o + k] = 0.0
            continue
        for k in range(3):
            MJ[i, o + k] = sb[body, SB_INV_MASS] * J[i, o + k]
            MJ[i, o + 3 + k] = (sb[body, SB_INV_I + 3 * k] * J[i, o + 3] + sb[body, SB_INV_I + 1 + 3 * k] * J[i, o + 4]
                                + sb[body, SB_INV_I + 2 + 3 * k] * J[i, o + 5])


@njit
def _row_dot(J, i, MJ, j, side_i, side_j):
    """``J_i(side_i) . MJ_j(side_j)``: the coupling of rows i and j through one shared body."""
    s = 0.0
    for k in range(6):
        s += J[i, 6 * side_i + k] * MJ[j, 6 * side_j + k]
    return s


@njit
def _row_velocity(bf, J, i, a, b):
    """``J_i v``: the constrained relative velocity of row i (m/s or rad/s)."""
    s = 0.0
    for side in range(2):
        body = a if side == 0 else b
        if body < 0:
            continue
        for k in range(3):
            s += J[i, 6 * side + k] * bf[body, VEL + k] + J[i, 6 * side + 3 + k] * bf[body, OMEGA + k]
    return s


@njit
def _apply_row(bf, MJ, i, a, b, d):
    """``v += M^-1 J_i^T d``: apply a change ``d`` of row i's impulse to its bodies."""
    if d == 0.0:
        return
    for side in range(2):
        body = a if side == 0 else b
        if body < 0:
            continue
        for k in range(3):
            bf[body, VEL + k] += MJ[i, 6 * side + k] * d
            bf[body, OMEGA + k] += MJ[i, 6 * side + 3 + k] * d


@njit
def assemble_matrix(rows, J, MJ, m, sb, nb):
    """``A = J M^-1 J^T`` of the first ``m`` rows in compressed sparse rows: ``(ptr, col, val)``.

    ``rows`` (m, 2) holds each row's bodies (-1: the world).  Only bodies that move (inverse mass > 0)
    couple rows; each row's entries are in the order their neighbours were found.
    """
    count = np.zeros(nb + 1, dtype=np.int64)
    for i in range(m):
        for side in range(2):
            k = rows[i, side]
            if k >= 0 and sb[k, SB_INV_MASS] > 0.0:
                count[k + 1] += 1
    for k in range(nb):
        count[k + 1] += count[k]
    start = count.copy()
    members = np.empty(max(count[nb], 1), dtype=np.int64)
    for i in range(m):
        for side in range(2):
            k = rows[i, side]
            if k >= 0 and sb[k, SB_INV_MASS] > 0.0:
                members[start[k]] = i
                start[k] += 1
    bound = 0
    for i in range(m):
        for side in range(2):
            k = rows[i, side]
            if k >= 0 and sb[k, SB_INV_MASS] > 0.0:
                bound += count[k + 1] - count[k]
    ptr = np.zeros(m + 1, dtype=np.int64)
    col = np.empty(max(bound, 1), dtype=np.int64)
    val = np.empty(max(bound, 1))
    where = np.full(m, -1, dtype=np.int64)   # position of column j in the row being built
    nnz = 0
    for i in range(m):
        row_start = nnz
        for side in range(2):
            k = rows[i, side]
            if k < 0 or sb[k, SB_INV_MASS] <= 0.0:
                continue
            for q in range(count[k], count[k + 1]):
                j = members[q]
                other = 0 if rows[j, 0] == k else 1
                v = _row_dot(J, i, MJ, j, side, other)
                p = where[j]
                if p < row_start:
                    p = nnz
                    where[j] = p
                    col[p] = j
                    val[p] = 0.0
                    nnz += 1
                val[p] += v
        ptr[i + 1] = nnz
    return ptr, col, val


@njit
def solve_lcp(bf, cf, ci, nc, kf, ki, nk, sb, nb, h, use_bias, joint_soft, rigid_soft, max_push, implicit,
              sweeps, omega, tolerance):
    """Stage "solve" (``use_bias``) or "relax" (not) of the LCP scheme over one sub-step of ``h`` s.

    Assembles the rows of every contact, rod and cable, solves the bounded LCP by projected Gauss-Seidel
    with over-relaxation ``omega`` (at most ``sweeps`` sweeps, stopping below ``tolerance`` m/s),
    applies the change of the impulses and stores them (C_LAMBDA_*, K_IMPULSE) for the next warm start.
    ``joint_soft`` (rods, cables) and ``rigid_soft`` (ball, hinge, slider and fixed joints) as in ``soft.py``;
    ``implicit`` flags the springs solved here.  Returns the number of
    sweeps made.
    """
    cap = 6 * nc + JOINT_ROWS * nk
    rows = np.empty((cap, 2), dtype=np.int64)
    kind = np.empty(cap, dtype=np.int64)
    source = np.empty(cap, dtype=np.int64)
    J = np.empty((cap, 12))
    MJ = np.empty((cap, 12))
    bias = np.zeros(cap)
    shift = np.zeros(cap)
    lo = np.full(cap, -np.inf)
    hi = np.full(cap, np.inf)
    link = np.full(cap, -1, dtype=np.int64)
    partner = np.full(cap, -1, dtype=np.int64)
    mu = np.zeros(cap)
    lam = np.zeros(cap)
    ra = np.empty(3)
    rb = np.empty(3)
    pa = np.empty(3)
    pb = np.empty(3)
    u = np.empty(3)
    m = 0
    # --- contact rows: normal, two tangents, rolling --------------------------------------------------
    for c in range(nc):
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        n_row = m
        _linear_row(J, MJ, m, sb, a, cf[c, C_RA:C_RA + 3], b, cf[c, C_RB:C_RB + 3], cf[c, C_NORMAL:C_NORMAL + 3])
        s = contact_separation(sb, cf, c, a, b)
        if s > 0.0:
            bias[m] = s / h                     # speculative: close the gap exactly (overlap: stop closing)
        lo[m] = 0.0
        kind[m] = ROW_NORMAL
        lam[m] = cf[c, C_LAMBDA_N]
        m += 1
        sliding = (ci[c, C_FLAGS] & CP_SLIDING) != 0
        friction = cf[c, C_MU_D] if sliding else cf[c, C_MU_S]
        for t in range(2):
            col0 = C_T1 if t == 0 else C_T2
            _linear_row(J, MJ, m, sb, a, cf[c, C_RA:C_RA + 3], b, cf[c, C_RB:C_RB + 3], cf[c, col0:col0 + 3])
            link[m] = n_row
            mu[m] = friction
            partner[m] = m + 1 if t == 0 else m - 1
            kind[m] = ROW_T1 + t
            lam[m] = cf[c, C_LAMBDA_T1 + t]
            m += 1
        # Rolling about t1 and t2 (bound rho lambda_n), torsion about n (bound tau lambda_n); the impulses are
        # kept as one world vector, lambda_r = sum of lambda_d d.
        for axis in range(3):
            col = C_T1 if axis == 0 else (C_T2 if axis == 1 else C_NORMAL)
            bound = cf[c, C_TORSION] if axis == 2 else cf[c, C_ROLL]
            if bound > 0.0:
                d = cf[c, col:col + 3]
                _angular_row(J, MJ, m, sb, a, b, d)
                link[m] = n_row
                mu[m] = bound
                kind[m] = ROW_ROLL + axis
                lam[m] = cf[c, C_LAMBDA_R] * d[0] + cf[c, C_LAMBDA_R + 1] * d[1] + cf[c, C_LAMBDA_R + 2] * d[2]
                m += 1
        for i in range(n_row, m):
            rows[i, 0] = a
            rows[i, 1] = b
            source[i] = c
    # --- rod and cable rows ---------------------------------------------------------------------------
    for c in range(nk):
        if not is_active_joint(ki, c, implicit):
            continue
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        if length < 1e-12:
            continue
        _linear_row(J, MJ, m, sb, a, ra, b, rb, u)
        a_ii = _row_dot(J, m, MJ, m, 0, 0) + _row_dot(J, m, MJ, m, 1, 1)
        err = length - kf[c, K_LENGTH]
        cable = ki[c, K_TYPE] == KT_CABLE
        if cable:
            hi[m] = 0.0
        if ki[c, K_TYPE] == KT_SPRING:
            rate, mass_scale, impulse_scale = spring_softness(kf[c, K_STIFFNESS], kf[c, K_DAMPING],
                                                              1.0 / a_ii if a_ii > 0.0 else 0.0, h)
            bias[m] = rate * err
            shift[m] = a_ii * impulse_scale / mass_scale if mass_scale > 0.0 else 0.0
        elif cable and err < 0.0:
            bias[m] = err / h                   # slack: may open up to the full length
        elif use_bias:
            bias[m] = min(max(joint_soft[0] * err, -max_push), max_push)
            shift[m] = a_ii * joint_soft[2] / joint_soft[1]
        rows[m, 0] = a
        rows[m, 1] = b
        kind[m] = ROW_JOINT
        source[m] = c
        lam[m] = kf[c, K_IMPULSE]
        m += 1
    # --- ball, hinge, slider and fixed joint rows (joint_rows.py) --------------------------------------------
    joint = np.empty((JOINT_ROWS, ROW_COLS))
    for c in range(nk):
        if not is_rigid_joint(ki, c):
            continue
        fill_rows(bf, kf, ki, c, joint)
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        for r in range(JOINT_ROWS):
            row_kind = joint[r, R_KIND]
            if row_kind == OFF:
                continue
            for k in range(12):
                J[m, k] = joint[r, k]
            _inverse_mass_times(J, MJ, m, sb, a, b)
            a_ii = _row_dot(J, m, MJ, m, 0, 0) + _row_dot(J, m, MJ, m, 1, 1)
            err = joint[r, R_C]
            if row_kind == MOTOR:
                most = kf[c, K_MOTOR_MAX] * h
                lo[m] = -most
                hi[m] = most
                bias[m] = -kf[c, K_MOTOR_SPEED]
            elif row_kind == LIMIT and err > 0.0:
                lo[m] = 0.0
                bias[m] = err / h               # not at the limit yet: may close the gap exactly
            else:
                if row_kind == LIMIT:
                    lo[m] = 0.0
                if use_bias:
                    bias[m] = min(max(rigid_soft[0] * err, -max_push), max_push)
                    shift[m] = a_ii * rigid_soft[2] / rigid_soft[1]
            rows[m, 0] = a
            rows[m, 1] = b
            kind[m] = ROW_RIGID_JOINT + r
            source[m] = c
            lam[m] = kf[c, K_ROW_IMPULSE + r]
            m += 1
    # --- assemble and solve ---------------------------------------------------------------------------------
    ptr, col, val = assemble_matrix(rows, J, MJ, m, sb, nb)
    lam0 = lam[:m].copy()
    b_vec = np.empty(m)
    vel = np.empty(m)
    for i in range(m):
        vel[i] = _row_velocity(bf, J, i, rows[i, 0], rows[i, 1])
        b_vec[i] = vel[i] + bias[i]
        for p in range(ptr[i], ptr[i + 1]):
            b_vec[i] -= val[p] * lam0[col[p]]
    used = solve_bounded_lcp(ptr, col, val, shift, b_vec, lo, hi, link, mu, partner, lam, m, sweeps, omega,
                             tolerance)
    # --- apply and store ------------------------------------------------------------------------------------
    for c in range(nc):
        for k in range(3):
            cf[c, C_LAMBDA_R + k] = 0.0
    for i in range(m):
        _apply_row(bf, MJ, i, rows[i, 0], rows[i, 1], lam[i] - lam0[i])
        c = source[i]
        r = kind[i]
        if r == ROW_JOINT:
            kf[c, K_IMPULSE] = lam[i]
        elif r >= ROW_RIGID_JOINT:
            kf[c, K_ROW_IMPULSE + r - ROW_RIGID_JOINT] = lam[i]
            for k in range(3):
                kf[c, K_SUM_LINEAR + k] += J[i, k] * (lam[i] - lam0[i])
                kf[c, K_SUM_ANGULAR + k] += J[i, 3 + k] * (lam[i] - lam0[i])
        elif r == ROW_NORMAL:
            cf[c, C_LAMBDA_N] = lam[i]
            if lam[i] > 0.0 and cf[c, C_MAX_N] == 0.0 and (ci[c, C_FLAGS] & CP_MATCHED) == 0:
                # A new contact engages: its approach speed, for restitution.
                cf[c, C_VN0] = min(vel[i], cf[c, C_VN0])
            cf[c, C_MAX_N] = max(cf[c, C_MAX_N], lam[i])
        elif r == ROW_T1 or r == ROW_T2:
            cf[c, C_LAMBDA_T1 + r - ROW_T1] = lam[i]
        else:
            for k in range(3):
                cf[c, C_LAMBDA_R + k] += lam[i] * J[i, 9 + k]
    return used
