"""The four integrators of the lecture: explicit Euler, semi-implicit Euler, Verlet and RK4.

Each step is split in two stages so that the constraint solver can act between them:

1. ``integrate_velocities``: forces -> new velocities ``V_FREE``, ``W_FREE`` (copied into ``VEL``, ``OMEGA``
   for the solver) and, for the methods whose position update does not follow from the final velocity,
   the predicted pose ``X_PRED``, ``Q_PRED``.
2. ``integrate_positions``: after the solver changed the velocities by ``dv``, the pose moves with them.

Explicit Euler:       x' = x + v h,           v' = v + a(x, v) h                       (first order, gains energy)
Semi-implicit Euler:  v' = v + a(x, v) h,     x' = x + v' h                            (first order, symplectic)
Verlet (positions):   x' = x + (x - x_prev) h / h_prev + a (h + h_prev) / 2 * h         (second order, no velocity state;
                      started with x' = x + v h + a h^2 / 2; the reported velocity is (x' - x) / h)
RK4:                  y' = y + h/6 (k1 + 2 k2 + 2 k3 + k4) on y = (x, q, v, omega)       (fourth order)

Rotation.  Explicit Euler and RK4 integrate Euler's equation ``I_w domega/dt = T - omega x I_w omega``
directly.  Semi-implicit Euler and Verlet keep the world angular momentum ``L = I_w omega`` exactly: the
torque changes ``L``, the orientation advances by the implicit-midpoint rule ``q' = exp(omega_mid h) q`` with
``omega_mid = I_w(q_mid)^-1 L`` and ``q_mid = exp(omega h / 2) q``, and ``omega' = I_w(q')^-1 L``, so a
torque-free body conserves its angular momentum to round-off, even about its unstable intermediate axis.
"""
import numpy as np

from .._jit import njit, njit_inline
from ..layout import (F_ISOTROPIC, F_RESTART, FLAGS, INV_I, INV_MASS, OMEGA, POS, PREV_POS, Q_PRED, QUAT,
                      V_FREE, VEL, W_FREE, X_PRED)
from ..math3d import mat3_vec, quat_integrate, quat_normalize, quat_to_matrix
from .forces import accumulate_forces, is_moving
from .rigid import body_inertia_world, body_inverse_inertia_world

EXPLICIT_EULER = 0
SEMI_IMPLICIT_EULER = 1
VERLET = 2
RK4 = 3
#: Public names of the integrators, in code order.
INTEGRATORS = ("explicit_euler", "semi_implicit_euler", "verlet", "rk4")
#: Scratch the per-sub-step stages work in, allocated once per step by the caller: ``mats`` of shape
#: (SCRATCH_MATS, 3, 3) and ``vecs`` of shape (SCRATCH_VECS, 4).  A kernel that allocates pays Numba's
#: reference counting on every array argument at every call (~16 ns each), so the hot stages do not.
SCRATCH_MATS = 3
SCRATCH_VECS = 8


@njit
def angular_acceleration(bf, i, q, w, torque, rot, iw_inv, iw, lw, rhs, out):
    """Euler's equation in the world frame: ``alpha = I_w^-1 (T - omega x (I_w omega))`` (rad/s^2).

    ``rot``, ``iw_inv``, ``iw`` (3x3) and ``lw``, ``rhs`` (3) are scratch.
    """
    body_inverse_inertia_world(bf, i, q, rot, iw_inv)
    body_inertia_world(bf, i, rot, iw)
    mat3_vec(iw, w, lw)
    rhs[0] = torque[0] - (w[1] * lw[2] - w[2] * lw[1])
    rhs[1] = torque[1] - (w[2] * lw[0] - w[0] * lw[2])
    rhs[2] = torque[2] - (w[0] * lw[1] - w[1] * lw[0])
    mat3_vec(iw_inv, rhs, out)


@njit
def _store_free_velocity(bf, i):
    for k in range(3):
        bf[i, V_FREE + k] = bf[i, VEL + k]
        bf[i, W_FREE + k] = bf[i, OMEGA + k]


@njit
def _explicit_euler_velocities(bf, bi, nb, F, T, h, mats, vecs):
    rot, iw_inv, iw = mats[0], mats[1], mats[2]
    alpha, lw, rhs = vecs[0, :3], vecs[1, :3], vecs[2, :3]
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        # Positions use the velocities at the start of the step.
        for k in range(3):
            bf[i, X_PRED + k] = bf[i, POS + k] + bf[i, VEL + k] * h
        quat_integrate(bf[i, QUAT:QUAT + 4], bf[i, OMEGA:OMEGA + 3], h, bf[i, Q_PRED:Q_PRED + 4])
        angular_acceleration(bf, i, bf[i, QUAT:QUAT + 4], bf[i, OMEGA:OMEGA + 3], T[i], rot, iw_inv, iw,
                             lw, rhs, alpha)
        inv_m = bf[i, INV_MASS]
        for k in range(3):
            bf[i, VEL + k] += F[i, k] * inv_m * h
            bf[i, OMEGA + k] += alpha[k] * h
        _store_free_velocity(bf, i)


@njit_inline
def _momentum_velocities(bf, bi, nb, F, T, h, verlet, prev_h, mats, vecs):
    """Semi-implicit Euler (and Verlet's linear part): kick velocities, change L by the torque impulse."""
    rot, iw_inv, iw = mats[0], mats[1], mats[2]
    lw = vecs[0, :3]
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        inv_m = bf[i, INV_MASS]
        if verlet:
            if (bi[i, FLAGS] & F_RESTART) != 0 or prev_h <= 0.0:
                # Start: x1 = x0 + v0 h + a h^2 / 2, i.e. a mean velocity of v0 + a h / 2.
                for k in range(3):
                    bf[i, VEL + k] += 0.5 * F[i, k] * inv_m * h
                bi[i, FLAGS] &= ~F_RESTART
            else:
                # x' - x = (x - x_prev) h / h_prev + a (h + h_prev) / 2 * h
                for k in range(3):
                    bf[i, VEL + k] = ((bf[i, POS + k] - bf[i, PREV_POS + k]) / prev_h
                                      + F[i, k] * inv_m * 0.5 * (h + prev_h))
        else:
            for k in range(3):
                bf[i, VEL + k] += F[i, k] * inv_m * h
        if (bi[i, FLAGS] & F_ISOTROPIC) != 0:
            # I = I E: omega += T h / I
            for k in range(3):
                bf[i, OMEGA + k] += bf[i, INV_I] * T[i, k] * h
            _store_free_velocity(bf, i)
            continue
        # L = I_w omega + T h, omega = I_w^-1 L
        q = bf[i, QUAT:QUAT + 4]
        body_inverse_inertia_world(bf, i, q, rot, iw_inv)
        body_inertia_world(bf, i, rot, iw)
        mat3_vec(iw, bf[i, OMEGA:OMEGA + 3], lw)
        for k in range(3):
            lw[k] += T[i, k] * h
        mat3_vec(iw_inv, lw, bf[i, OMEGA:OMEGA + 3])
        _store_free_velocity(bf, i)


@njit
def _rk4_derivative(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, dX, dQ, dV, dW, record):
    """The right-hand side ``dy/dt = (v, omega (x) q / 2, F/m, alpha)`` at the state (X, Q, V, W)."""
    vecs = np.empty((SCRATCH_VECS, 4))
    accumulate_forces(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, record, vecs)
    rot = np.empty((3, 3))
    iw_inv = np.empty((3, 3))
    iw = np.empty((3, 3))
    qn = np.empty(4)
    lw = np.empty(3)
    rhs = np.empty(3)
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        inv_m = bf[i, INV_MASS]
        for k in range(3):
            dX[i, k] = V[i, k]
            dV[i, k] = F[i, k] * inv_m
        for k in range(4):
            qn[k] = Q[i, k]
        quat_normalize(qn)
        angular_acceleration(bf, i, qn, W[i], T[i], rot, iw_inv, iw, lw, rhs, dW[i])
        # dq/dt = 1/2 (0, omega) * q
        wx, wy, wz = W[i, 0], W[i, 1], W[i, 2]
        dQ[i, 0] = 0.5 * (-wx * qn[1] - wy * qn[2] - wz * qn[3])
        dQ[i, 1] = 0.5 * (wx * qn[0] + wy * qn[3] - wz * qn[2])
        dQ[i, 2] = 0.5 * (-wx * qn[3] + wy * qn[0] + wz * qn[1])
        dQ[i, 3] = 0.5 * (wx * qn[2] - wy * qn[1] + wz * qn[0])


@njit
def _rk4_velocities(bf, bi, kf, ki, nb, nk, gravity, F, T, h, record):
    # y = (X, Q, V, W) as column blocks of one scratch table; k1..k4 likewise.
    y0 = np.empty((nb, 13))
    ys = np.empty((nb, 13))
    acc = np.zeros((nb, 13))
    kk = np.zeros((nb, 13))
    for i in range(nb):
        for k in range(13):
            y0[i, k] = bf[i, POS + k]  # POS, QUAT, VEL, OMEGA are contiguous columns 0..12
    weights = (1.0, 2.0, 2.0, 1.0)
    offsets = (0.0, 0.5, 0.5, 1.0)
    for stage in range(4):
        for i in range(nb):
            for k in range(13):
                ys[i, k] = y0[i, k] + offsets[stage] * h * kk[i, k]
        _rk4_derivative(bf, bi, kf, ki, nb, nk, gravity,
                        ys[:, 0:3], ys[:, 3:7], ys[:, 7:10], ys[:, 10:13], F, T,
                        kk[:, 0:3], kk[:, 3:7], kk[:, 7:10], kk[:, 10:13], record if stage == 0 else 0.0)
        for i in range(nb):
            for k in range(13):
                acc[i, k] += weights[stage] * kk[i, k]
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        for k in range(3):
            bf[i, X_PRED + k] = y0[i, k] + h / 6.0 * acc[i, k]
            bf[i, VEL + k] = y0[i, 7 + k] + h / 6.0 * acc[i, 7 + k]
            bf[i, OMEGA + k] = y0[i, 10 + k] + h / 6.0 * acc[i, 10 + k]
        for k in range(4):
            bf[i, Q_PRED + k] = y0[i, 3 + k] + h / 6.0 * acc[i, 3 + k]
        quat_normalize(bf[i, Q_PRED:Q_PRED + 4])
        _store_free_velocity(bf, i)


@njit_inline
def integrate_velocities(method, bf, bi, kf, ki, nb, nk, gravity, F, T, h, prev_h, record, mats, vecs):
    """Stage "integrate velocities": apply all forces over ``h`` seconds with the chosen ``method``.

    ``F``, ``T`` are scratch (nb, 3) tables, ``mats``, ``vecs`` the stages' scratch (see SCRATCH_MATS); the
    springs' forces at the sub-step's start are added to their recorded mean with weight ``record``.
    """
    if method == RK4:
        _rk4_velocities(bf, bi, kf, ki, nb, nk, gravity, F, T, h, record)
        return
    accumulate_forces(bf, bi, kf, ki, nb, nk, gravity, bf[:, POS:POS + 3], bf[:, QUAT:QUAT + 4],
                      bf[:, VEL:VEL + 3], bf[:, OMEGA:OMEGA + 3], F, T, record, vecs)
    if method == EXPLICIT_EULER:
        _explicit_euler_velocities(bf, bi, nb, F, T, h, mats, vecs)
    else:
        _momentum_velocities(bf, bi, nb, F, T, h, method == VERLET, prev_h, mats, vecs)


@njit
def _rotate_conserving_momentum(bf, i, h, rot, iw_inv, iw, lw, q_mid, w_mid, q_new):
    """Advance the orientation by the implicit-midpoint rule at constant world angular momentum.

    The remaining arguments are scratch arrays (3x3, 3x3, 3x3, 3, 4, 3, 4).
    """
    q = bf[i, QUAT:QUAT + 4]
    w = bf[i, OMEGA:OMEGA + 3]
    body_inverse_inertia_world(bf, i, q, rot, iw_inv)
    body_inertia_world(bf, i, rot, iw)
    mat3_vec(iw, w, lw)
    quat_integrate(q, w, 0.5 * h, q_mid)
    body_inverse_inertia_world(bf, i, q_mid, rot, iw_inv)
    mat3_vec(iw_inv, lw, w_mid)
    quat_integrate(q, w_mid, h, q_new)
    for k in range(4):
        q[k] = q_new[k]
    body_inverse_inertia_world(bf, i, q, rot, iw_inv)
    mat3_vec(iw_inv, lw, w)


@njit_inline
def integrate_positions(method, bf, bi, nb, h, mats, vecs):
    """Stage "integrate positions": move every awake dynamic body over ``h`` seconds.

    The solver's velocity change ``dv = v - v_free`` is added to the integrator's own prediction for
    explicit Euler and RK4; semi-implicit Euler and Verlet move with the final velocity directly.
    ``mats``, ``vecs``: the stages' scratch.
    """
    rot, iw_inv, iw = mats[0], mats[1], mats[2]
    dw, dq, q_mid, w_mid = vecs[0, :3], vecs[1], vecs[2], vecs[3, :3]
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        if method == EXPLICIT_EULER or method == RK4:
            for k in range(3):
                bf[i, POS + k] = bf[i, X_PRED + k] + (bf[i, VEL + k] - bf[i, V_FREE + k]) * h
                dw[k] = bf[i, OMEGA + k] - bf[i, W_FREE + k]
            quat_integrate(bf[i, Q_PRED:Q_PRED + 4], dw, h, dq)
            for k in range(4):
                bf[i, QUAT + k] = dq[k]
        else:
            for k in range(3):
                bf[i, PREV_POS + k] = bf[i, POS + k]
                bf[i, POS + k] += bf[i, VEL + k] * h
            if (bi[i, FLAGS] & F_ISOTROPIC) != 0:
                # omega is constant under torque-free rotation of an isotropic body.
                quat_integrate(bf[i, QUAT:QUAT + 4], bf[i, OMEGA:OMEGA + 3], h, dq)
                for k in range(4):
                    bf[i, QUAT + k] = dq[k]
            else:
                _rotate_conserving_momentum(bf, i, h, rot, iw_inv, iw, dw, q_mid, w_mid, dq)
