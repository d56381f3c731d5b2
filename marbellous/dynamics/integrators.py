"""The four integrators of the lecture: explicit Euler, semi-implicit Euler, Verlet and RK4.

Each step is split in two stages so that the constraint solver can act between them:

1. ``integrate_velocities``: forces -> new velocities ``V_FREE``, ``W_FREE`` (copied into ``VEL``, ``OMEGA``
   for the solver) and, for the methods whose position update does not follow from the final velocity,
   the predicted pose ``X_PRED``, ``Q_PRED``.
2. ``integrate_positions``: after the solver changed the velocities by ``dv``, the pose moves with them.

Explicit Euler:       x' = x + v h,           v' = v + a(x, v) h                       (first order, gains energy)
Semi-implicit Euler:  v' = v + a(x, v) h,     x' = x + v' h                            (first order, symplectic)
Verlet (positions):   x' = x + (x - x_prev) h / h_prev + a (h + h_prev) / 2 * h        (second order, no velocity state;
                      started with x' = x + v h + a h^2 / 2; the reported velocity is (x' - x) / h)
RK4:                  y' = y + h/6 (k1 + 2 k2 + 2 k3 + k4) on y = (x, q, v, omega)       (fourth order)

Rotation.  Explicit Euler and RK4 integrate Euler's equation ``I_w domega/dt = T - omega x I_w omega``
directly.  Semi-implicit Euler and Verlet keep the world angular momentum ``L = I_w omega`` exactly: the
torque changes ``L``, the orientation advances by the implicit-midpoint rule ``q' = exp(omega_mid h) q`` with
``omega_mid = I_w(q_mid)^-1 L`` and ``q_mid = exp(omega h / 2) q``, and ``omega' = I_w(q')^-1 L``, so a
torque-free body conserves its angular momentum to round-off, even about its unstable intermediate axis.
"""
import numpy as np

from .._numba.jit import njit, njit_inline
from ..math3d import quat_integrate, quat_normalize, quat_step, row3, row4, tensor_vec
from ..state.layout import (F_ISOTROPIC, F_RESTART, FLAGS, INV_I, INV_MASS, OMEGA, POS, PREV_POS, Q_PRED, QUAT, V_FREE,
                            VEL, W_FREE, X_PRED)
from .forces import accumulate_forces, add_applied_forces, is_moving
from .rigid import inertia_world, inverse_inertia_world
from .springs import add_spring_forces

EXPLICIT_EULER = 0
SEMI_IMPLICIT_EULER = 1
VERLET = 2
RK4 = 3
#: Public names of the integrators, in code order.
INTEGRATORS = ("explicit_euler", "semi_implicit_euler", "verlet", "rk4")
#: Scratch vectors the per-sub-step stages work in (springs, joints), allocated once per step by the caller
#: as ``vecs`` of shape (SCRATCH_VECS, 4).  A kernel that allocates, or creates array views, pays Numba's
#: reference counting at every call, so the hot stages do neither: small tensors travel as tuples.
SCRATCH_VECS = 8


@njit
def angular_acceleration(bf, i, q, w, torque):
    """Euler's equation in the world frame: ``alpha = I_w^-1 (T - omega x (I_w omega))`` (rad/s^2), a tuple."""
    lw = tensor_vec(inertia_world(bf, i, q), w)
    return tensor_vec(inverse_inertia_world(bf, i, q), (torque[0] - (w[1] * lw[2] - w[2] * lw[1]),
                                                        torque[1] - (w[2] * lw[0] - w[0] * lw[2]),
                                                        torque[2] - (w[0] * lw[1] - w[1] * lw[0])))


@njit
def _store_free_velocity(bf, i):
    for k in range(3):
        bf[i, V_FREE + k] = bf[i, VEL + k]
        bf[i, W_FREE + k] = bf[i, OMEGA + k]


@njit
def _explicit_euler_velocities(bf, bi, nb, F, T, h):
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        # Positions use the velocities at the start of the step.
        for k in range(3):
            bf[i, X_PRED + k] = bf[i, POS + k] + bf[i, VEL + k] * h
        quat_integrate(bf[i, QUAT:QUAT + 4], bf[i, OMEGA:OMEGA + 3], h, bf[i, Q_PRED:Q_PRED + 4])
        alpha = angular_acceleration(bf, i, bf[i, QUAT:QUAT + 4], bf[i, OMEGA:OMEGA + 3], T[i])
        inv_m = bf[i, INV_MASS]
        for k in range(3):
            bf[i, VEL + k] += F[i, k] * inv_m * h
            bf[i, OMEGA + k] += alpha[k] * h
        _store_free_velocity(bf, i)


@njit_inline
def _momentum_velocities(bf, bi, nb, F, T, h, verlet, prev_h):
    """Semi-implicit Euler (and Verlet's linear part): kick velocities, change L by the torque impulse."""
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
        q = row4(bf, i, QUAT)
        lw = tensor_vec(inertia_world(bf, i, q), row3(bf, i, OMEGA))
        w = tensor_vec(inverse_inertia_world(bf, i, q), (lw[0] + T[i, 0] * h, lw[1] + T[i, 1] * h,
                                                          lw[2] + T[i, 2] * h))
        for k in range(3):
            bf[i, OMEGA + k] = w[k]
        _store_free_velocity(bf, i)


@njit
def _rk4_derivative(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, dX, dQ, dV, dW, record):
    """The right-hand side ``dy/dt = (v, omega (x) q / 2, F/m, alpha)`` at the state (X, Q, V, W)."""
    vecs = np.empty((SCRATCH_VECS, 4))
    accumulate_forces(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, record, vecs)
    qn = np.empty(4)
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
        alpha = angular_acceleration(bf, i, qn, W[i], T[i])
        for k in range(3):
            dW[i, k] = alpha[k]
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
def integrate_velocities(method, bf, bi, kf, ki, nb, nk, gravity, F, T, h, prev_h, record, vecs):
    """Stage "integrate velocities": apply all forces over ``h`` seconds with the chosen ``method``.

    ``F``, ``T`` are scratch (nb, 3) tables, ``vecs`` the stages' scratch (see SCRATCH_VECS); the springs'
    forces at the sub-step's start are added to their recorded mean with weight ``record``.
    """
    if method == RK4:
        _rk4_velocities(bf, bi, kf, ki, nb, nk, gravity, F, T, h, record)
        return
    # accumulate_forces on the body table's own state (its column views made only when springs need them)
    add_applied_forces(bf, bi, nb, gravity, F, T)
    if nk > 0:
        add_spring_forces(kf, ki, nk, bf[:, POS:POS + 3], bf[:, QUAT:QUAT + 4], bf[:, VEL:VEL + 3],
                          bf[:, OMEGA:OMEGA + 3], F, T, record, vecs)
    if method == EXPLICIT_EULER:
        _explicit_euler_velocities(bf, bi, nb, F, T, h)
    else:
        _momentum_velocities(bf, bi, nb, F, T, h, method == VERLET, prev_h)


@njit
def _setrow4(bf, i, col, q):
    for k in range(4):
        bf[i, col + k] = q[k]


@njit
def _rotate_conserving_momentum(bf, i, h):
    """Advance body ``i``'s orientation by the implicit-midpoint rule at constant world angular momentum:

        L = I_w(q) omega,  q_mid = exp(omega h / 2) q,  q' = exp(I_w(q_mid)^-1 L h) q,  omega' = I_w(q')^-1 L
    """
    q = row4(bf, i, QUAT)
    w = row3(bf, i, OMEGA)
    lw = tensor_vec(inertia_world(bf, i, q), w)
    w_mid = tensor_vec(inverse_inertia_world(bf, i, quat_step(q, w, 0.5 * h)), lw)
    q_new = quat_step(q, w_mid, h)
    _setrow4(bf, i, QUAT, q_new)
    w_new = tensor_vec(inverse_inertia_world(bf, i, q_new), lw)
    for k in range(3):
        bf[i, OMEGA + k] = w_new[k]


@njit_inline
def integrate_positions(method, bf, bi, nb, h):
    """Stage "integrate positions": move every awake dynamic body over ``h`` seconds.

    The solver's velocity change ``dv = v - v_free`` is added to the integrator's own prediction for
    explicit Euler and RK4; semi-implicit Euler and Verlet move with the final velocity directly.
    """
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        if method == EXPLICIT_EULER or method == RK4:
            for k in range(3):
                bf[i, POS + k] = bf[i, X_PRED + k] + (bf[i, VEL + k] - bf[i, V_FREE + k]) * h
            dw = (bf[i, OMEGA] - bf[i, W_FREE], bf[i, OMEGA + 1] - bf[i, W_FREE + 1],
                  bf[i, OMEGA + 2] - bf[i, W_FREE + 2])
            _setrow4(bf, i, QUAT, quat_step(row4(bf, i, Q_PRED), dw, h))
        else:
            for k in range(3):
                bf[i, PREV_POS + k] = bf[i, POS + k]
                bf[i, POS + k] += bf[i, VEL + k] * h
            if (bi[i, FLAGS] & F_ISOTROPIC) != 0:
                # omega is constant under torque-free rotation of an isotropic body.
                _setrow4(bf, i, QUAT, quat_step(row4(bf, i, QUAT), row3(bf, i, OMEGA), h))
            else:
                _rotate_conserving_momentum(bf, i, h)
