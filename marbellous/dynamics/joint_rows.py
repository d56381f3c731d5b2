"""Ball, hinge, slider and fixed joints: their constraint rows, solved with the contacts by sequential
impulses (and assembled into the LCP, ``lcp.py``).

Body a and body b (``b < 0``: the world, which never moves) with centres ``x``, orientations ``q`` and the
joint's anchors ``p_a = x_a + r_a``, ``p_b = x_b + r_b`` (``r = R anchor``; the world: ``p_b`` is the
fixed point, ``r_b = 0``).  Every row is a scalar constraint ``C`` whose rate is linear in the velocities,

    dC/dt = J v = l_a . v_a + k_a . w_a + l_b . v_b + k_b . w_b,      J = (l_a, k_a, l_b, k_b)

and an impulse ``lambda`` along the row changes them by ``v += l lambda / m``, ``w += I_w^-1 k lambda``
(per body); its effective mass is ``1 / (J M^-1 J^T)``.  The rows, with ``d = p_a - p_b`` and the joint
axis ``n = R_b axis_b`` (fixed to b):

    point (ball, hinge, fixed)   C = d . e_k             J = (e_k, r_a x e_k, -e_k, -(r_b x e_k))
    across (slider)              C = d . t_i             J = (t_i, r_a x t_i, -t_i, -((r_b + d) x t_i))
    orientation (slider, fixed)  C = theta_k             J = (0, e_k, 0, -e_k)
    hinge axes                   C = (R_a axis_a) . t_i  J = (0, a x t_i, 0, -(a x t_i)),  a = R_a axis_a

``e_k`` are the world axes, ``t_1, t_2`` unit and normal to ``n`` (``contact_basis``).  Across: the rate
of ``d . t`` has the term ``d . (w_b x t)``, which moves b's arm to ``p_a``.  Orientation: ``theta = 2
vec(q_e)`` (``q_e.w >= 0``) for the rotation ``q_e = q_a (q_b q_ref)*`` of a away from the orientation
relative to b it had at creation (``q_ref``); its rate is ``w_a - w_b`` to first order.

The hinge's angle is the rotation of a relative to b about the axis, in b's frame: with ``q_rel = q_b* q_a
q_ref*`` (identity at creation), ``angle = 2 atan2(vec(q_rel) . axis_b, q_rel.w)`` in [-pi, pi]; its rate
``(w_a - w_b) . n`` (``J = (0, n, 0, -n)``).  The slider's position is ``d . n`` (0 at creation), its rate
``J = (n, r_a x n, -n, -((r_b + d) x n))``.  A limit is the row ``C = value - lower >= 0`` with the rate's
J, and ``C = upper - value >= 0`` with -J, and ``lambda >= 0``; while ``C > 0`` it only stops the
value from passing the limit in the sub-step (bias ``C / h``, rigid), so a joint swinging towards its
limit stops there and does not bounce from a spring.  A motor's row has the rate's J and drives ``J v`` to
the motor speed with ``|lambda| <= max torque (force) h``.

The equality rows of the joints that form trees are solved a whole tree at once, exactly and without
position bias (``joint_tree.py``); the pushes take the error out of the poses.  The joints of a loop solve
theirs here: soft constraints (``soft.py``, at ``RIGID_JOINT_RATE`` of the step's sub-step rate, damped by
``joint_damping_ratio``), bias ``bias_rate C``, no faster than ``max_push`` (m/s, or rad/s for the
orientation and hinge-axis rows); what their softness leaves of the error, the pushes take out of the poses
(:func:`push_rigid_joints`).  The three point rows, the two across rows and the orientation or hinge-axis
rows are each solved as one block (``lambda = -mass_scale K^-1 (J v + bias) - impulse_scale lambda_0`` with
``K = J M^-1 J^T``), so that a chain of joints converges like a chain of single rows would not.
"""
import math

from .._numba.jit import njit
from ..collision.adjacency import begin_fill, clear_counts, count_link, end_fill, fill_link, joined
from ..math3d import cross, quat_conj, quat_product, rotated, row3, row4
from ..state.layout import (FLAGS, F_JOINTED, JOINT_ROWS, KF_ALIVE, KF_BROKEN, KF_LIMITS, KF_MOTOR, KT_BALL,
                            KT_HINGE, KT_SLIDER, K_ANCHOR_A, K_ANCHOR_B, K_AXIS_A, K_AXIS_B, K_BODY_A, K_BODY_B,
                            K_FLAGS, K_FORCE, K_IMPULSE, K_LOWER,
                            K_MOTOR_MAX, K_MOTOR_SPEED, K_REF_QUAT, K_ROW_IMPULSE, K_SUM_ANGULAR, K_SUM_LINEAR,
                            K_TORQUE, K_TYPE, K_UPPER, OMEGA, PB_V, PB_W, POS, QUAT, SB_INV_I, SB_INV_MASS, SB_ISO,
                            SB_V, SB_W, VEL)
from .contact_basis import contact_basis
from .forces import is_moving

#: the joints' stiffness as a fraction of the step's sub-step rate: ``hertz = RIGID_JOINT_RATE substeps / dt``
#: (120 Hz at 60 Hz with 4 sub-steps), the stiffest soft constraint the sub-steps resolve; an interval of
#: the step cut short at a time of impact keeps it (rods and cables use ``joint_hertz``, capped there too)
RIGID_JOINT_RATE = 0.5
#: ``det K`` below this fraction of the product of its diagonal: the block's rows are treated as dependent
SINGULAR = 1e-6
# columns of a row in the rows scratch: the Jacobian (l_a, k_a, l_b, k_b), C, the row's kind, its line of its
# block's solve matrix (``x = S rhs``, :func:`_block_inverse`) and its effective mass's inverse ``K_rr``
R_LA, R_KA, R_LB, R_KB, R_C, R_KIND, R_S, R_K = 0, 3, 6, 9, 12, 13, 14, 17
ROW_COLS = 18
# kinds of row
OFF = 0         # not used by this joint (its stored impulse is dropped)
EQUAL = 1       # C = 0 (soft)
LIMIT = 2       # C >= 0, lambda >= 0
MOTOR = 3       # J v = motor speed, |lambda| <= most
# the rows' slots (K_ROW_IMPULSE + slot)
LINEAR, ANGULAR, LOWER, UPPER, DRIVE = 0, 3, 6, 7, 8


@njit
def is_rigid_joint(ki, c):
    """True if constraint ``c`` is a live, unbroken ball, hinge, slider or fixed joint."""
    f = ki[c, K_FLAGS]
    return ki[c, K_TYPE] >= KT_BALL and (f & KF_ALIVE) != 0 and (f & KF_BROKEN) == 0


@njit
def _set_row(rows, r, la, ka, lb, kb, value, kind):
    for k in range(3):
        rows[r, R_LA + k] = la[k]
        rows[r, R_KA + k] = ka[k]
        rows[r, R_LB + k] = lb[k]
        rows[r, R_KB + k] = kb[k]
    rows[r, R_C] = value
    rows[r, R_KIND] = kind


@njit
def _neg(v):
    return -v[0], -v[1], -v[2]


@njit
def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@njit
def joint_frames(bf, kf, ki, c):
    """``(q_a, q_b, r_a, r_b, d, n)`` of joint ``c``: the orientations (the world: identity), the anchors'
    arms (m), ``d = p_a - p_b`` (m) and the axis ``n = R_b axis_b`` (module docstring)."""
    a = ki[c, K_BODY_A]
    b = ki[c, K_BODY_B]
    qa = row4(bf, a, QUAT)
    ra = rotated(qa, row3(kf, c, K_ANCHOR_A))
    if b >= 0:
        qb = row4(bf, b, QUAT)
        rb = rotated(qb, row3(kf, c, K_ANCHOR_B))
        pb = (bf[b, POS] + rb[0], bf[b, POS + 1] + rb[1], bf[b, POS + 2] + rb[2])
    else:
        qb = (1.0, 0.0, 0.0, 0.0)
        rb = (0.0, 0.0, 0.0)
        pb = row3(kf, c, K_ANCHOR_B)
    d = (bf[a, POS] + ra[0] - pb[0], bf[a, POS + 1] + ra[1] - pb[1], bf[a, POS + 2] + ra[2] - pb[2])
    return qa, qb, ra, rb, d, rotated(qb, row3(kf, c, K_AXIS_B))


@njit
def hinge_angle(kf, c, qa, qb):
    """The rotation (rad, in [-pi, pi]) of a relative to b about the hinge's axis since creation."""
    q = quat_product(quat_product(quat_conj(qb), qa), quat_conj(row4(kf, c, K_REF_QUAT)))
    s = q[1] * kf[c, K_AXIS_B] + q[2] * kf[c, K_AXIS_B + 1] + q[3] * kf[c, K_AXIS_B + 2]
    if q[0] < 0.0:
        return 2.0 * math.atan2(-s, -q[0])
    return 2.0 * math.atan2(s, q[0])


@njit
def _rate_jacobian(t, ra, rb, d, n):
    """``(l_a, k_a, l_b, k_b)`` of the hinge's angle or the slider's position (``t``: KT_HINGE, KT_SLIDER)."""
    zero = (0.0, 0.0, 0.0)
    if t == KT_HINGE:
        return zero, n, zero, _neg(n)
    rb_at_a = (rb[0] + d[0], rb[1] + d[1], rb[2] + d[2])
    return n, cross(ra, n), _neg(n), _neg(cross(rb_at_a, n))


@njit
def hinge_or_slider_state(bf, kf, ki, c):
    """``(value, rate)``: the hinge's angle (rad) and angular speed (rad/s), or the slider's position (m) and
    speed (m/s), of joint ``c`` at the bodies' poses and velocities in the body table."""
    t = ki[c, K_TYPE]
    qa, qb, ra, rb, d, n = joint_frames(bf, kf, ki, c)
    value = hinge_angle(kf, c, qa, qb) if t == KT_HINGE else _dot(d, n)
    la, ka, lb, kb = _rate_jacobian(t, ra, rb, d, n)
    a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
    rate = _dot(la, row3(bf, a, VEL)) + _dot(ka, row3(bf, a, OMEGA))
    if b >= 0:
        rate += _dot(lb, row3(bf, b, VEL)) + _dot(kb, row3(bf, b, OMEGA))
    return value, rate


@njit
def fill_rows(bf, kf, ki, c, rows):
    """The rows of joint ``c`` at the bodies' current poses into ``rows`` (``JOINT_ROWS`` x ``ROW_COLS``; slots
    as ``LINEAR`` .. ``DRIVE``, ``R_KIND`` OFF where unused).  Returns the hinge's angle or the slider's
    position (0 for the others)."""
    t = ki[c, K_TYPE]
    qa, qb, ra, rb, d, n = joint_frames(bf, kf, ki, c)
    zero = (0.0, 0.0, 0.0)
    for r in range(JOINT_ROWS):
        rows[r, R_KIND] = OFF
    rb_at_a = (rb[0] + d[0], rb[1] + d[1], rb[2] + d[2])
    if t == KT_SLIDER:
        t1, t2 = contact_basis(n)
        for i, ti in enumerate((t1, t2)):
            _set_row(rows, LINEAR + i, ti, cross(ra, ti), _neg(ti), _neg(cross(rb_at_a, ti)), _dot(d, ti), EQUAL)
    else:
        for k in range(3):
            e = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
            _set_row(rows, LINEAR + k, e, cross(ra, e), _neg(e), _neg(cross(rb, e)), d[k], EQUAL)
    value = 0.0
    if t == KT_HINGE:
        axis_a = rotated(qa, row3(kf, c, K_AXIS_A))
        t1, t2 = contact_basis(n)
        for i, ti in enumerate((t1, t2)):
            k_a = cross(axis_a, ti)
            _set_row(rows, ANGULAR + i, zero, k_a, zero, _neg(k_a), _dot(axis_a, ti), EQUAL)
        value = hinge_angle(kf, c, qa, qb)
    elif t != KT_BALL:
        qe = quat_product(qa, quat_conj(quat_product(qb, row4(kf, c, K_REF_QUAT))))
        s = 2.0 if qe[0] >= 0.0 else -2.0
        for k in range(3):
            e = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
            _set_row(rows, ANGULAR + k, zero, e, zero, _neg(e), s * qe[1 + k], EQUAL)
        value = _dot(d, n)
    if t == KT_HINGE or t == KT_SLIDER:
        la, ka, lb, kb = _rate_jacobian(t, ra, rb, d, n)
        f = ki[c, K_FLAGS]
        if (f & KF_LIMITS) != 0:
            _set_row(rows, LOWER, la, ka, lb, kb, value - kf[c, K_LOWER], LIMIT)
            _set_row(rows, UPPER, _neg(la), _neg(ka), _neg(lb), _neg(kb), kf[c, K_UPPER] - value, LIMIT)
        if (f & KF_MOTOR) != 0:
            _set_row(rows, DRIVE, la, ka, lb, kb, 0.0, MOTOR)
    return value


@njit
def _body(sb, i):
    """``(inverse mass, I_w^-1 as a 9-tuple)`` of solver body ``i`` (zeros for the world and resting bodies)."""
    if i < 0:
        return 0.0, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return sb[i, SB_INV_MASS], (sb[i, SB_INV_I], sb[i, SB_INV_I + 1], sb[i, SB_INV_I + 2], sb[i, SB_INV_I + 3],
                                sb[i, SB_INV_I + 4], sb[i, SB_INV_I + 5], sb[i, SB_INV_I + 6],
                                sb[i, SB_INV_I + 7], sb[i, SB_INV_I + 8])


@njit
def _mass_term(rows, r, s, col_l, col_k, im, ii):
    """One body's ``l_r . l_s / m + k_r . I_w^-1 k_s`` (1/kg)."""
    t = im * (rows[r, col_l] * rows[s, col_l] + rows[r, col_l + 1] * rows[s, col_l + 1]
              + rows[r, col_l + 2] * rows[s, col_l + 2])
    for i in range(3):
        t += rows[r, col_k + i] * (ii[3 * i] * rows[s, col_k] + ii[3 * i + 1] * rows[s, col_k + 1]
                                   + ii[3 * i + 2] * rows[s, col_k + 2])
    return t


@njit
def coupling(sb, a, b, rows, r, s):
    """``J_r M^-1 J_s^T`` of rows ``r`` and ``s`` (1/kg, or its angular kin)."""
    im_a, ii_a = _body(sb, a)
    im_b, ii_b = _body(sb, b)
    return _mass_term(rows, r, s, R_LA, R_KA, im_a, ii_a) + _mass_term(rows, r, s, R_LB, R_KB, im_b, ii_b)


@njit
def row_rate(u, cv, cw, a, b, rows, r):
    """``J_r v`` on the velocities in columns ``cv`` (linear) and ``cw`` (angular) of table ``u`` (the solver
    bodies' velocities, or the pseudo-velocities of the pushes)."""
    v = 0.0
    for k in range(3):
        v += rows[r, R_LA + k] * u[a, cv + k] + rows[r, R_KA + k] * u[a, cw + k]
        if b >= 0:
            v += rows[r, R_LB + k] * u[b, cv + k] + rows[r, R_KB + k] * u[b, cw + k]
    return v


@njit
def _kick(sb, u, cv, cw, i, rows, r, col_l, col_k, lam):
    """Body ``i``'s velocities in ``u`` (as :func:`row_rate`) after the impulse ``lam`` along row ``r`` (its
    columns ``col_l``, ``col_k``), with the inverse mass and inertia of the solver bodies ``sb``."""
    if i < 0 or sb[i, SB_ISO] == 0.0:
        return
    im = sb[i, SB_INV_MASS] * lam
    lx, ly, lz = rows[r, col_k] * lam, rows[r, col_k + 1] * lam, rows[r, col_k + 2] * lam
    for k in range(3):
        u[i, cv + k] += im * rows[r, col_l + k]
        u[i, cw + k] += sb[i, SB_INV_I + 3 * k] * lx + sb[i, SB_INV_I + 3 * k + 1] * ly \
            + sb[i, SB_INV_I + 3 * k + 2] * lz


@njit
def _kick_both(sb, u, cv, cw, a, b, rows, r, lam):
    _kick(sb, u, cv, cw, a, rows, r, R_LA, R_KA, lam)
    _kick(sb, u, cv, cw, b, rows, r, R_LB, R_KB, lam)


@njit
def apply_row(sb, kf, c, a, b, rows, r, lam):
    """Apply the impulse ``lam`` (N s, or N m s) along row ``r`` of joint ``c`` to its solver bodies and add
    what a received to the step's sums (``K_SUM_LINEAR``, ``K_SUM_ANGULAR``)."""
    _kick_both(sb, sb, SB_V, SB_W, a, b, rows, r, lam)
    for k in range(3):
        kf[c, K_SUM_LINEAR + k] += rows[r, R_LA + k] * lam
        kf[c, K_SUM_ANGULAR + k] += rows[r, R_KA + k] * lam


@njit
def fill_joint_rows(bf, kf, ki, nk, sb, cache):
    """Every ball, hinge, slider and fixed joint's rows at the bodies' current poses into ``cache[c]`` (``nk``
    x ``JOINT_ROWS`` x ``ROW_COLS``), with their blocks' solve matrices and effective masses on the solver bodies
    ``sb`` (:func:`_fill_masses`).  A joint's rows depend on the poses only, which no velocity pass moves, and
    its masses on the solver bodies' inertia, which only a position update turns: filled once where the poses
    change (the warm start, after the position update), they serve every pass until then."""
    for c in range(nk):
        if is_rigid_joint(ki, c):
            rows = cache[c]
            fill_rows(bf, kf, ki, c, rows)
            _fill_masses(sb, ki[c, K_BODY_A], ki[c, K_BODY_B], rows)


@njit
def warm_start_rigid_joints(bf, kf, ki, nk, sb, cache):
    """The rows at the poses of the sub-step's start into ``cache`` (:func:`fill_joint_rows`), and each joint
    row's impulse of the last sub-step applied along its Jacobian (a row the joint no longer uses forgets its
    impulse)."""
    fill_joint_rows(bf, kf, ki, nk, sb, cache)
    for c in range(nk):
        if not is_rigid_joint(ki, c):
            continue
        rows = cache[c]
        a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
        for r in range(JOINT_ROWS):
            if rows[r, R_KIND] == OFF:
                kf[c, K_ROW_IMPULSE + r] = 0.0
        for r in (DRIVE, LOWER, UPPER):
            lam = kf[c, K_ROW_IMPULSE + r]
            if lam != 0.0:
                apply_row(sb, kf, c, a, b, rows, r, lam)
        for r0 in (ANGULAR, LINEAR):
            if rows[r0, R_KIND] != OFF:
                lam = (kf[c, K_ROW_IMPULSE + r0], kf[c, K_ROW_IMPULSE + r0 + 1], kf[c, K_ROW_IMPULSE + r0 + 2])
                _apply_block(sb, kf, c, a, b, rows, r0, 3 if rows[r0 + 2, R_KIND] != OFF else 2, lam)


@njit
def scale_joint_impulses(kf, ki, nk, scale):
    """Multiply the impulses every joint, rod, cable and spring starts its next sub-step from by ``scale``."""
    for c in range(nk):
        if ki[c, K_TYPE] >= KT_BALL:
            for r in range(JOINT_ROWS):
                kf[c, K_ROW_IMPULSE + r] *= scale
        else:
            kf[c, K_IMPULSE] *= scale


@njit
def _jacobian_side(rows, r, present, col_l, col_k):
    """``(l, k)`` of row ``r`` in columns ``col_l``, ``col_k`` (zeros unless ``present``)."""
    if not present:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return ((rows[r, col_l], rows[r, col_l + 1], rows[r, col_l + 2]),
            (rows[r, col_k], rows[r, col_k + 1], rows[r, col_k + 2]))


@njit
def _tensor_times(ii, k):
    """``I_w^-1 k`` (``ii``: the 3 x 3 as a 9-tuple by rows)."""
    return (ii[0] * k[0] + ii[1] * k[1] + ii[2] * k[2], ii[3] * k[0] + ii[4] * k[1] + ii[5] * k[2],
            ii[6] * k[0] + ii[7] * k[1] + ii[8] * k[2])


@njit
def _body_block(body, rows, r0, n, col_l, col_k):
    """One body's part ``(K_00, K_11, K_22, K_01, K_02, K_12)`` of the block's ``K``, ``l_r . l_s / m + k_r .
    I_w^-1 k_s`` (``body``: its :func:`_body`; its Jacobian in columns ``col_l``, ``col_k``; 0 past ``n``)."""
    im, ii = body
    l0, k0 = _jacobian_side(rows, r0, True, col_l, col_k)
    l1, k1 = _jacobian_side(rows, r0 + 1, True, col_l, col_k)
    l2, k2 = _jacobian_side(rows, r0 + 2, n == 3, col_l, col_k)
    ik0, ik1, ik2 = _tensor_times(ii, k0), _tensor_times(ii, k1), _tensor_times(ii, k2)
    return (im * _dot(l0, l0) + _dot(k0, ik0), im * _dot(l1, l1) + _dot(k1, ik1), im * _dot(l2, l2) + _dot(k2, ik2),
            im * _dot(l0, l1) + _dot(k0, ik1), im * _dot(l0, l2) + _dot(k0, ik2), im * _dot(l1, l2) + _dot(k1, ik2))


@njit
def _set_solve_line(rows, r, s0, s1, s2, k):
    rows[r, R_S] = s0
    rows[r, R_S + 1] = s1
    rows[r, R_S + 2] = s2
    rows[r, R_K] = k


@njit
def _block_inverse(sb, a, b, rows, r0, n):
    """The solve matrix ``S`` of the block of rows ``r0 .. r0 + n - 1`` (n = 2 or 3) into their ``R_S`` columns,
    and ``K``'s diagonal into ``R_K``: ``S = K^-1`` (the adjugate over the determinant) of the symmetric positive
    (semi)definite ``K = J M^-1 J^T``, padded with the identity to 3 x 3 when ``n`` is 2.  When ``det K`` is below
    ``SINGULAR`` times the product of the diagonal (Hadamard's bound, reached by orthogonal rows), the rows are
    solved each alone: ``S = diag(1 / K_ii)``, 0 for a row no body can move."""
    ka = _body_block(_body(sb, a), rows, r0, n, R_LA, R_KA)
    kb = _body_block(_body(sb, b), rows, r0, n, R_LB, R_KB)
    k00, k11, k01 = ka[0] + kb[0], ka[1] + kb[1], ka[3] + kb[3]
    k22, k02, k12 = (ka[2] + kb[2], ka[4] + kb[4], ka[5] + kb[5]) if n == 3 else (1.0, 0.0, 0.0)
    c00, c01, c02 = k11 * k22 - k12 * k12, k12 * k02 - k01 * k22, k01 * k12 - k11 * k02
    det = k00 * c00 + k01 * c01 + k02 * c02
    if not det > SINGULAR * k00 * k11 * k22:
        # (nearly) dependent rows, e.g. a hinge turned a quarter turn off its axis: each row alone, and a
        # row whose Jacobian has (nearly) vanished (K_ii below SINGULAR of the block's largest) not at all
        big = SINGULAR * max(k00, k11, k22 if n == 3 else 0.0)
        _set_solve_line(rows, r0, 1.0 / k00 if k00 > big else 0.0, 0.0, 0.0, k00)
        _set_solve_line(rows, r0 + 1, 0.0, 1.0 / k11 if k11 > big else 0.0, 0.0, k11)
        if n == 3:
            _set_solve_line(rows, r0 + 2, 0.0, 0.0, 1.0 / k22 if k22 > big else 0.0, k22)
        return
    inv = 1.0 / det
    s01 = inv * (k02 * k12 - k01 * k22)
    s02 = inv * (k01 * k12 - k02 * k11)
    s12 = inv * (k02 * k01 - k00 * k12)
    _set_solve_line(rows, r0, inv * c00, s01, s02, k00)
    _set_solve_line(rows, r0 + 1, s01, inv * (k00 * k22 - k02 * k02), s12, k11)
    if n == 3:
        _set_solve_line(rows, r0 + 2, s02, s12, inv * (k00 * k11 - k01 * k01), k22)


@njit
def _fill_masses(sb, a, b, rows):
    """The solve matrices of the orientation or hinge-axis block and the point or across block
    (:func:`_block_inverse`), and each limit's and motor's ``K_rr``, on the solver bodies ``sb``."""
    for r0 in (ANGULAR, LINEAR):
        if rows[r0, R_KIND] != OFF:
            _block_inverse(sb, a, b, rows, r0, 3 if rows[r0 + 2, R_KIND] != OFF else 2)
    for r in (DRIVE, LOWER, UPPER):
        if rows[r, R_KIND] != OFF:
            rows[r, R_K] = coupling(sb, a, b, rows, r, r)


@njit
def _block_solution(rows, r0, n, rhs):
    """``x = S rhs`` for the block of rows ``r0 .. r0 + n - 1`` (``S`` from :func:`_block_inverse`; 0 past
    ``n``)."""
    x0 = rows[r0, R_S] * rhs[0] + rows[r0, R_S + 1] * rhs[1] + rows[r0, R_S + 2] * rhs[2]
    x1 = rows[r0 + 1, R_S] * rhs[0] + rows[r0 + 1, R_S + 1] * rhs[1] + rows[r0 + 1, R_S + 2] * rhs[2]
    if n < 3:
        return x0, x1, 0.0
    r2 = r0 + 2
    return x0, x1, rows[r2, R_S] * rhs[0] + rows[r2, R_S + 1] * rhs[1] + rows[r2, R_S + 2] * rhs[2]


@njit
def _block_kick(sb, u, cv, cw, i, rows, r0, n, col_l, col_k, x):
    """Body ``i``'s velocities in ``u`` (as :func:`row_rate`) after the impulses ``x`` along the block's rows: one
    linear and one angular impulse, ``sum_j x_j l_j`` and ``sum_j x_j k_j``, each applied once; returns them."""
    lx = ly = lz = kx = ky = kz = 0.0
    for j in range(n):
        r = r0 + j
        lx += x[j] * rows[r, col_l]
        ly += x[j] * rows[r, col_l + 1]
        lz += x[j] * rows[r, col_l + 2]
        kx += x[j] * rows[r, col_k]
        ky += x[j] * rows[r, col_k + 1]
        kz += x[j] * rows[r, col_k + 2]
    if i >= 0 and sb[i, SB_ISO] != 0.0:
        im = sb[i, SB_INV_MASS]
        u[i, cv] += im * lx
        u[i, cv + 1] += im * ly
        u[i, cv + 2] += im * lz
        for k in range(3):
            u[i, cw + k] += sb[i, SB_INV_I + 3 * k] * kx + sb[i, SB_INV_I + 3 * k + 1] * ky \
                + sb[i, SB_INV_I + 3 * k + 2] * kz
    return (lx, ly, lz), (kx, ky, kz)


@njit
def _apply_block(sb, kf, c, a, b, rows, r0, n, lam):
    """Apply the impulses ``lam`` along the block's rows (as :func:`apply_row` does one row's)."""
    linear, angular = _block_kick(sb, sb, SB_V, SB_W, a, rows, r0, n, R_LA, R_KA, lam)
    _block_kick(sb, sb, SB_V, SB_W, b, rows, r0, n, R_LB, R_KB, lam)
    for k in range(3):
        kf[c, K_SUM_LINEAR + k] += linear[k]
        kf[c, K_SUM_ANGULAR + k] += angular[k]


@njit
def _block_rhs(u, cv, cw, a, b, rows, r0, n, i, bias):
    """``-(J v + bias)`` of the block's row ``i`` on the velocities in ``u`` (0 past ``n``)."""
    if i >= n:
        return 0.0
    return -(row_rate(u, cv, cw, a, b, rows, r0 + i) + bias)


@njit
def _solve_bias(rows, r, use_bias, soft, max_push):
    """The solve passes' bias of equality row ``r``: ``bias_rate C`` within +-``max_push`` when ``use_bias``."""
    return min(max(soft[0] * rows[r, R_C], -max_push), max_push) if use_bias else 0.0


@njit
def _block_delta(kf, c, r, x, mass_scale, impulse_scale):
    """Row ``r``'s impulse change ``mass_scale x - impulse_scale lambda``, added to its ``lambda``."""
    slot = K_ROW_IMPULSE + r
    delta = mass_scale * x - impulse_scale * kf[c, slot]
    kf[c, slot] += delta
    return delta


@njit
def _solve_block(sb, kf, c, a, b, rows, r0, n, use_bias, soft, max_push):
    """Rows ``r0 .. r0 + n - 1`` (n = 2 or 3, all EQUAL) as one block:
    ``delta = -mass_scale K^-1 (J v + bias) - impulse_scale lambda``; returns the largest velocity change."""
    rhs = (_block_rhs(sb, SB_V, SB_W, a, b, rows, r0, n, 0, _solve_bias(rows, r0, use_bias, soft, max_push)),
           _block_rhs(sb, SB_V, SB_W, a, b, rows, r0, n, 1, _solve_bias(rows, r0 + 1, use_bias, soft, max_push)),
           _block_rhs(sb, SB_V, SB_W, a, b, rows, r0, n, 2,
                      _solve_bias(rows, r0 + 2, use_bias, soft, max_push) if n == 3 else 0.0))
    x = _block_solution(rows, r0, n, rhs)
    mass_scale, impulse_scale = (soft[1], soft[2]) if use_bias else (1.0, 0.0)
    delta = (_block_delta(kf, c, r0, x[0], mass_scale, impulse_scale),
             _block_delta(kf, c, r0 + 1, x[1], mass_scale, impulse_scale),
             _block_delta(kf, c, r0 + 2, x[2], mass_scale, impulse_scale) if n == 3 else 0.0)
    largest = 0.0
    for i in range(n):
        largest = max(largest, abs(delta[i]) * rows[r0 + i, R_K])
    _apply_block(sb, kf, c, a, b, rows, r0, n, delta)
    return largest


@njit
def _solve_bounded(sb, kf, c, a, b, rows, r, h, use_bias, soft, max_push):
    """A LIMIT or MOTOR row alone; returns the velocity change along it."""
    k = rows[r, R_K]
    if not k > 0.0:
        return 0.0
    slot = K_ROW_IMPULSE + r
    old = kf[c, slot]
    if rows[r, R_KIND] == MOTOR:
        most = kf[c, K_MOTOR_MAX] * h
        new = min(max(old - (row_rate(sb, SB_V, SB_W, a, b, rows, r) - kf[c, K_MOTOR_SPEED]) / k, -most), most)
    else:
        gap = rows[r, R_C]
        if gap > 0.0:                       # not at the limit yet: may close the gap exactly
            bias, mass_scale, impulse_scale = gap / h, 1.0, 0.0
        elif use_bias:
            bias = max(soft[0] * gap, -max_push)
            mass_scale, impulse_scale = soft[1], soft[2]
        else:
            bias, mass_scale, impulse_scale = 0.0, 1.0, 0.0
        new = max(old - mass_scale * (row_rate(sb, SB_V, SB_W, a, b, rows, r) + bias) / k - impulse_scale * old, 0.0)
    kf[c, slot] = new
    if new != old:
        apply_row(sb, kf, c, a, b, rows, r, new - old)
    return abs(new - old) * k


@njit
def solve_rigid_joints(kf, ki, nk, sb, h, use_bias, soft, max_push, cache, in_tree):
    """One pass over the ball, hinge, slider and fixed joints on the solver bodies ``sb`` (``use_bias``:
    solve, else relax), with their rows in ``cache`` (:func:`fill_joint_rows`): motor, limits, then the
    orientation or hinge-axis block and the point or across block (the most important last), but not the
    equality blocks of the joints ``in_tree`` (``in_tree[c] != 0``: solved with their tree,
    ``joint_tree.py``).  Returns the largest velocity change (m/s or rad/s)."""
    largest = 0.0
    for c in range(nk):
        if not is_rigid_joint(ki, c):
            continue
        rows = cache[c]
        a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
        for r in (DRIVE, LOWER, UPPER):
            if rows[r, R_KIND] != OFF:
                largest = max(largest, _solve_bounded(sb, kf, c, a, b, rows, r, h, use_bias, soft, max_push))
        if in_tree[c] != 0:
            continue
        angular = 3 if rows[ANGULAR + 2, R_KIND] != OFF else 2
        if rows[ANGULAR, R_KIND] != OFF:
            largest = max(largest, _solve_block(sb, kf, c, a, b, rows, ANGULAR, angular, use_bias, soft, max_push))
        linear = 3 if rows[LINEAR + 2, R_KIND] != OFF else 2
        largest = max(largest, _solve_block(sb, kf, c, a, b, rows, LINEAR, linear, use_bias, soft, max_push))
    return largest


@njit
def closing_speed(rows, r, h, max_push):
    """``C / h`` of row ``r``, no faster than ``max_push`` (m/s, or rad/s)."""
    return min(max(rows[r, R_C] / h, -max_push), max_push)


@njit
def push_rigid_joints(kf, ki, nk, sb, pb, h, max_push, cache, in_tree):
    """One pass of the joints' position correction on the pseudo-velocities ``pb`` of the contacts' split
    impulses (``contact_solver.push_contacts``), at the poses just integrated: each block of equality rows
    gets the pseudo-velocity that closes its error ``C`` in the sub-step of ``h`` s (``J v_p = -C / h``, no
    faster than ``max_push``), and a limit past its bound one that brings it back (``J v_p >= -C / h``).
    ``apply_push`` then moves the bodies (no faster than ``max_push``) and the velocities never see it, so
    a joint holds its anchors together however soft its velocity rows are, without adding energy.  The rows
    come from ``cache`` (:func:`fill_joint_rows`); the equality blocks of the joints ``in_tree`` are pushed with
    their tree (``joint_tree.py``).  Returns the largest pseudo-velocity change (m/s or rad/s)."""
    largest = 0.0
    for c in range(nk):
        if not is_rigid_joint(ki, c):
            continue
        rows = cache[c]
        a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
        for r in (LOWER, UPPER):
            if rows[r, R_KIND] == LIMIT and rows[r, R_C] < 0.0:
                k = rows[r, R_K]
                if k > 0.0:
                    d = max(-(row_rate(pb, PB_V, PB_W, a, b, rows, r) + max(rows[r, R_C] / h, -max_push)) / k, 0.0)
                    _kick_both(sb, pb, PB_V, PB_W, a, b, rows, r, d)
                    largest = max(largest, d * k)
        if in_tree[c] != 0:
            continue
        for r0 in (ANGULAR, LINEAR):
            if rows[r0, R_KIND] == OFF:
                continue
            n = 3 if rows[r0 + 2, R_KIND] != OFF else 2
            rhs = (_block_rhs(pb, PB_V, PB_W, a, b, rows, r0, n, 0, closing_speed(rows, r0, h, max_push)),
                   _block_rhs(pb, PB_V, PB_W, a, b, rows, r0, n, 1, closing_speed(rows, r0 + 1, h, max_push)),
                   _block_rhs(pb, PB_V, PB_W, a, b, rows, r0, n, 2,
                              closing_speed(rows, r0 + 2, h, max_push) if n == 3 else 0.0))
            x = _block_solution(rows, r0, n, rhs)
            _block_kick(sb, pb, PB_V, PB_W, a, rows, r0, n, R_LA, R_KA, x)
            _block_kick(sb, pb, PB_V, PB_W, b, rows, r0, n, R_LB, R_KB, x)
            for i in range(n):
                largest = max(largest, abs(x[i]) * rows[r0 + i, R_K])
    return largest


@njit
def clear_joint_sums(kf, ki, nk):
    """Start the step's sums of the joints' impulses from zero."""
    for c in range(nk):
        if ki[c, K_TYPE] >= KT_BALL:
            for k in range(6):
                kf[c, K_SUM_LINEAR + k] = 0.0


@njit
def record_rigid_joint_forces(bf, bi, kf, ki, nk, dt):
    """Each joint's force on a over the step, ``F = sum(impulses) / dt`` (N), and its torque about the anchor,
    ``T = (L - r_a x P) / dt`` (N m), with ``P`` and ``L`` the linear and angular impulses a received.  A
    joint whose bodies sleep (or are static) keeps the force and torque it had when they fell asleep: it
    still holds them."""
    for c in range(nk):
        if not is_rigid_joint(ki, c):
            continue
        b = ki[c, K_BODY_B]
        if not is_moving(bi, ki[c, K_BODY_A]) and (b < 0 or not is_moving(bi, b)):
            continue
        _, _, ra, _, _, _ = joint_frames(bf, kf, ki, c)
        p = row3(kf, c, K_SUM_LINEAR)
        m = cross(ra, p)
        for k in range(3):
            kf[c, K_FORCE + k] = p[k] / dt
            kf[c, K_TORQUE + k] = (kf[c, K_SUM_ANGULAR + k] - m[k]) / dt


@njit
def _joint_adjacency(ki, nk, nb, start, other):
    """The bodies each body row is joined to by a live ball, hinge, slider or fixed joint (not the world), as
    ``other[start[i]:start[i + 1]]`` for body ``i`` (``collision/adjacency.py``).  ``start``: >= nb + 1 ints;
    ``other``: >= 2 nk."""
    clear_counts(start, nb)
    for c in range(nk):
        if is_rigid_joint(ki, c) and ki[c, K_BODY_B] >= 0:
            count_link(start, ki[c, K_BODY_A], ki[c, K_BODY_B])
    begin_fill(start, nb)
    for c in range(nk):
        if is_rigid_joint(ki, c) and ki[c, K_BODY_B] >= 0:
            fill_link(start, other, ki[c, K_BODY_A], ki[c, K_BODY_B])
    end_fill(start, nb)


@njit
def drop_joined_pairs(pairs, n_pairs, bi, ki, nk, nb, start, other):
    """Remove the pairs of bodies that a joint joins from ``pairs[:n_pairs]`` (only bodies flagged
    ``F_JOINTED`` are looked up, in the joints' adjacency, :func:`_joint_adjacency`, built here in ``start``
    and ``other``); returns the number kept."""
    _joint_adjacency(ki, nk, nb, start, other)
    kept = 0
    for p in range(n_pairs):
        i, j = pairs[p, 0], pairs[p, 1]
        if (bi[i, FLAGS] & F_JOINTED) != 0 and (bi[j, FLAGS] & F_JOINTED) != 0 and joined(start, other, i, j):
            continue
        pairs[kept, 0] = i
        pairs[kept, 1] = j
        kept += 1
    return kept
