"""The four integrators of the lecture: explicit Euler, semi-implicit Euler, Verlet and RK4.

Each step is split in two stages so that the constraint solver can act between them:

1. ``integrate_velocities``: forces -> new velocities ``V_FREE``, ``W_FREE`` (copied into ``VEL``, ``OMEGA``
   for the solver) and, for the methods whose position update does not follow from the final velocity,
   the predicted position ``X_PRED``.
2. ``integrate_positions``: after the solver changed the velocities by ``dv``, the pose moves with them.

Explicit Euler:       x' = x + v h,           v' = v + a(x, v) h                       (first order, gains energy)
Semi-implicit Euler:  v' = v + a(x, v) h,     x' = x + v' h                            (first order, symplectic)
Verlet (positions):   x' = x + (x - x_prev) h / h_prev + a (h + h_prev) / 2 * h        (second order, no velocity state;
                      started with x' = x + v h + a h^2 / 2; the reported velocity is (x' - x) / h)
RK4:                  y' = y + h/6 (k1 + 2 k2 + 2 k3 + k4) on y = (x, q, v, L)    (fourth order in x, v)

Damping (``linear_damping``, ``angular_damping``: ``dv/dt = -c v``) is split off and solved exactly before
the forces act, for every method: ``v := v exp(-c h)``, ``omega := omega exp(-c h)``.  So it is stable at
any rate, a free body's speed decays exactly as ``exp(-c t)``, and under a constant force the split's
terminal speed is ``F h / (m (1 - exp(-c h)))``, within ``c h / 2`` of the exact ``F / (m c)``.

Speed limit.  A dynamic body's speeds are held to SPEED_LIMIT (1e9 m/s and rad/s, the most the API accepts)
after the forces and after the solve (:func:`limit_speeds`; and where each interval of a step begins, before
its boxes are swept: ``pipeline/collide.update_aabbs``); a speed that is not finite becomes 0 there, so
that a diverging solve never carries NaN into a pose.

Explicit Euler multiplies the energy of an undamped oscillator of angular frequency omega (a mass on a
spring) by exactly ``1 + (omega h)^2`` per step: that is its nature, kept and tested.

Rotation.  Every method changes the world angular momentum ``L = I_w omega`` by the torque impulse (RK4:
by the weighted torques of its four stages) and then turns the body at constant ``L`` by the implicit
midpoint rule on Euler's equation (``rotate_at_constant_momentum``), with ``omega' = I_w(q')^-1 L``.  That
rule keeps ``L`` to round-off and the kinetic energy ``L . I_w^-1 L / 2`` to 1e-10 of itself for any
``|omega| h``, even about the unstable intermediate axis.  Euler's equation ``I_w domega/dt = T - omega x
I_w omega`` is not integrated explicitly by any method: on a body of very unequal moments (a thin rod
spinning even slowly about its long axis) its gyroscopic term is stiff, and an explicit rule (Euler,
RK4, or an explicit midpoint orientation) gains energy without limit there, up to ``I_max / I_min`` per
turn: the 8 m x 4 cm x 2.4 cm rod of the "energy from nowhere" report flew off at 63,000 rad/s.
"""
import math

import numpy as np

from .._numba.jit import njit, njit_inline
from .._validate import MAX_SPEED
from ..math3d import quat_normalize, quat_step, row3, row4, tensor_vec
from ..state.layout import (ANGULAR_DAMPING, F_ISOTROPIC, F_RESTART, FLAGS, INV_I, INV_MASS, LINEAR_DAMPING,
                            OMEGA, POS, PREV_POS, QUAT, V_FREE, VEL, W_FREE, X_PRED)
from .forces import accumulate_forces, add_applied_forces, free_acceleration, is_driven, is_moving
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


#: Largest linear (m/s) and angular (rad/s) speed a body keeps: the bound the API accepts for a speed.
SPEED_LIMIT = MAX_SPEED


@njit_inline
def limit_speeds(bf, i):
    """Hold body ``i``'s velocity and angular velocity to SPEED_LIMIT in magnitude, ``v := v min(1, v_max /
    |v|)``; a speed that is not finite (a diverged solve) becomes 0.

    No step of a sane scene comes near the limit (1e9 m/s).  A scene driven to diverge (stiff springs under
    explicit Euler, a solver fed a broken Jacobian) would otherwise carry speeds of 1e15 and up, then NaN,
    into the poses, and its sweeps, impact intervals and rotation pieces would grow with them until one step
    took minutes."""
    for col in (VEL, OMEGA):
        x, y, z = bf[i, col], bf[i, col + 1], bf[i, col + 2]
        if not (abs(x) < math.inf and abs(y) < math.inf and abs(z) < math.inf):     # (NaN compares False)
            for k in range(3):
                bf[i, col + k] = 0.0
            continue
        # |v| = m |v / m| with m the largest component: no square overflows, however large v is
        m = max(abs(x), abs(y), abs(z))
        if m <= SPEED_LIMIT / 2.0:        # (|v| <= sqrt(3) m: within the limit)
            continue
        speed = m * math.sqrt((x / m) ** 2 + (y / m) ** 2 + (z / m) ** 2)
        if speed > SPEED_LIMIT:
            scale = SPEED_LIMIT / speed
            for k in range(3):
                bf[i, col + k] *= scale


@njit
def _store_free_velocity(bf, i):
    """The velocities the forces gave body ``i`` (held to the speed limit: :func:`limit_speeds`) kept as its
    free velocities ``V_FREE``, ``W_FREE``, the solver's reference."""
    limit_speeds(bf, i)
    for k in range(3):
        bf[i, V_FREE + k] = bf[i, VEL + k]
        bf[i, W_FREE + k] = bf[i, OMEGA + k]


@njit
def _angular_kick(bf, bi, i, T, h):
    """Change body ``i``'s world angular momentum by the torque impulse ``T h`` (N m s) at the current
    orientation: ``omega := I_w^-1 (I_w omega + T h)`` (for an isotropic body ``omega += T h / I``).  The
    torque-free turning follows in ``integrate_positions`` (energy-conserving, at constant ``L``)."""
    if (bi[i, FLAGS] & F_ISOTROPIC) != 0:
        for k in range(3):
            bf[i, OMEGA + k] += bf[i, INV_I] * T[k] * h
        return
    q = row4(bf, i, QUAT)
    lw = tensor_vec(inertia_world(bf, i, q), row3(bf, i, OMEGA))
    w = tensor_vec(inverse_inertia_world(bf, i, q), (lw[0] + T[0] * h, lw[1] + T[1] * h, lw[2] + T[2] * h))
    for k in range(3):
        bf[i, OMEGA + k] = w[k]


@njit
def _explicit_euler_velocities(bf, bi, nb, F, T, h):
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        # Positions use the velocities at the start of the step.
        for k in range(3):
            bf[i, X_PRED + k] = bf[i, POS + k] + bf[i, VEL + k] * h
        inv_m = bf[i, INV_MASS]
        for k in range(3):
            bf[i, VEL + k] += F[i, k] * inv_m * h
        _angular_kick(bf, bi, i, T[i], h)
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
                # x' - x = (x - x_prev) h / h_prev + a (h + h_prev) / 2 * h, with (x - x_prev) / h_prev the
                # velocity the last sub-step ended with: the same sequence of positions while nothing acts
                # on the body, and the constraints' velocity changes after the last position update (the
                # relax pass takes the position correction's velocity out again, restitution) are kept:
                # recomputed from the positions, the correction's push stayed in Verlet's velocity and
                # a tall box landing on its end gained energy.
                for k in range(3):
                    bf[i, VEL + k] += F[i, k] * inv_m * 0.5 * (h + prev_h)
        else:
            for k in range(3):
                bf[i, VEL + k] += F[i, k] * inv_m * h
        # L = I_w omega + T h, omega = I_w^-1 L  (I = I E: omega += T h / I)
        _angular_kick(bf, bi, i, T[i], h)
        _store_free_velocity(bf, i)


@njit
def velocity_at_end(bf, bi, i, gravity, lead):
    """The velocity (m/s) of moving body row ``i`` at the end of its last sub-step, as a tuple: its stored
    velocity, which Verlet keeps as the mean over that sub-step of ``h'`` s, plus ``a lead`` with ``lead =
    h' / 2`` (0 for the other integrators), ``a = g + F_user / m``:

        v(t) = (x(t) - x(t - h')) / h' + a h' / 2

    exact under a constant acceleration (the mean velocity over a sub-step is the one at its middle).  A body
    that restarts (new, or its velocity set by hand) holds its velocity at the end already."""
    v = (bf[i, VEL], bf[i, VEL + 1], bf[i, VEL + 2])
    if lead == 0.0 or (bi[i, FLAGS] & F_RESTART) != 0:
        return v
    a = free_acceleration(bf, i, gravity)
    return v[0] + a[0] * lead, v[1] + a[1] * lead, v[2] + a[2] * lead


@njit
def restart_at_end(bf, bi, i, gravity, lead):
    """Store :func:`velocity_at_end` of moving body row ``i`` and restart Verlet from it (``F_RESTART``): for
    an impact resolved at its time, which must reflect the velocity the body meets the surface with."""
    if not is_moving(bi, i):
        return
    v = velocity_at_end(bf, bi, i, gravity, lead)
    for k in range(3):
        bf[i, VEL + k] = v[k]
    bi[i, FLAGS] |= F_RESTART


@njit
def _rk4_derivative(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, Lw, W, F, T, dX, dQ, dV, dL, record, implicit):
    """The right-hand side ``dy/dt = (v, omega (x) q / 2, F/m, T)`` at the state (X, Q, V, L), with the
    stage's angular velocity ``omega = I_w(q)^-1 L`` written to ``W`` (the springs read it)."""
    vecs = np.empty((SCRATCH_VECS, 4))
    qn = np.empty(4)
    for i in range(nb):
        if not is_moving(bi, i):
            for k in range(3):
                W[i, k] = 0.0
            continue
        for k in range(4):
            qn[k] = Q[i, k]
        quat_normalize(qn)
        w = tensor_vec(inverse_inertia_world(bf, i, (qn[0], qn[1], qn[2], qn[3])), (Lw[i, 0], Lw[i, 1], Lw[i, 2]))
        for k in range(3):
            W[i, k] = w[k]
    accumulate_forces(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, record, implicit, vecs)
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        inv_m = bf[i, INV_MASS]
        for k in range(3):
            dX[i, k] = V[i, k]
            dV[i, k] = F[i, k] * inv_m
            dL[i, k] = T[i, k]
        for k in range(4):
            qn[k] = Q[i, k]
        quat_normalize(qn)
        # dq/dt = 1/2 (0, omega) * q
        wx, wy, wz = W[i, 0], W[i, 1], W[i, 2]
        dQ[i, 0] = 0.5 * (-wx * qn[1] - wy * qn[2] - wz * qn[3])
        dQ[i, 1] = 0.5 * (wx * qn[0] + wy * qn[3] - wz * qn[2])
        dQ[i, 2] = 0.5 * (-wx * qn[3] + wy * qn[0] + wz * qn[1])
        dQ[i, 3] = 0.5 * (wx * qn[2] - wy * qn[1] + wz * qn[0])


@njit
def _rk4_velocities(bf, bi, kf, ki, nb, nk, gravity, F, T, h, record, implicit):
    """RK4 on ``y = (x, q, v, L)`` (world angular momentum ``L``, so the stiff gyroscopic term of Euler's
    equation never enters an explicit stage): ``X_PRED`` and ``v`` are RK4's, and the angular velocity
    becomes ``I_w(q)^-1 (L + h/6 (T1 + 2 T2 + 2 T3 + T4))``, the torque impulse of the four stages; the
    orientation then turns at that ``L`` in ``integrate_positions`` (energy-conserving midpoint rule)."""
    # y = (X, Q, V, L) as column blocks of one scratch table; k1..k4 likewise.
    y0 = np.empty((nb, 13))
    ys = np.empty((nb, 13))
    acc = np.zeros((nb, 13))
    kk = np.zeros((nb, 13))
    ws = np.zeros((nb, 3))
    for i in range(nb):
        for k in range(10):
            y0[i, k] = bf[i, POS + k]  # POS, QUAT, VEL are contiguous columns 0..9
        for k in range(3):
            y0[i, 10 + k] = 0.0
        if is_moving(bi, i):
            lw = tensor_vec(inertia_world(bf, i, row4(bf, i, QUAT)), row3(bf, i, OMEGA))
            for k in range(3):
                y0[i, 10 + k] = lw[k]
    weights = (1.0, 2.0, 2.0, 1.0)
    offsets = (0.0, 0.5, 0.5, 1.0)
    for stage in range(4):
        for i in range(nb):
            for k in range(13):
                ys[i, k] = y0[i, k] + offsets[stage] * h * kk[i, k]
        _rk4_derivative(bf, bi, kf, ki, nb, nk, gravity,
                        ys[:, 0:3], ys[:, 3:7], ys[:, 7:10], ys[:, 10:13], ws, F, T,
                        kk[:, 0:3], kk[:, 3:7], kk[:, 7:10], kk[:, 10:13], record if stage == 0 else 0.0,
                        implicit)
        for i in range(nb):
            for k in range(13):
                acc[i, k] += weights[stage] * kk[i, k]
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        for k in range(3):
            bf[i, X_PRED + k] = y0[i, k] + h / 6.0 * acc[i, k]
            bf[i, VEL + k] = y0[i, 7 + k] + h / 6.0 * acc[i, 7 + k]
        # omega := I_w^-1 (I_w omega + T_mean h)
        _angular_kick(bf, bi, i, (acc[i, 10] / 6.0, acc[i, 11] / 6.0, acc[i, 12] / 6.0), h)
        _store_free_velocity(bf, i)


@njit_inline
def _damp_velocities(bf, bi, nb, h):
    """``v := v exp(-c_v h)``, ``omega := omega exp(-c_w h)``: the exact decay of ``dv/dt = -c v`` over ``h``."""
    for i in range(nb):
        cv = bf[i, LINEAR_DAMPING]
        cw = bf[i, ANGULAR_DAMPING]
        if (cv == 0.0 and cw == 0.0) or not is_moving(bi, i):
            continue
        fv = math.exp(-cv * h)
        fw = math.exp(-cw * h)
        for k in range(3):
            bf[i, VEL + k] *= fv
            bf[i, OMEGA + k] *= fw


@njit_inline
def integrate_velocities(method, bf, bi, kf, ki, nb, nk, gravity, F, T, h, prev_h, record, implicit, vecs):
    """Stage "integrate velocities": apply all forces over ``h`` seconds with the chosen ``method``.

    ``F``, ``T`` are scratch (nb, 3) tables, ``vecs`` the stages' scratch (see SCRATCH_VECS); the springs'
    forces at the sub-step's start are added to their recorded mean with weight ``record``; the springs
    flagged in ``implicit`` are left to the constraint solver (``springs.classify_springs``).  Damping acts
    first (:func:`_damp_velocities`).
    """
    _damp_velocities(bf, bi, nb, h)
    if method == RK4:
        _rk4_velocities(bf, bi, kf, ki, nb, nk, gravity, F, T, h, record, implicit)
        return
    # accumulate_forces on the body table's own state (its column views made only when springs need them)
    add_applied_forces(bf, bi, nb, gravity, F, T)
    if nk > 0:
        add_spring_forces(kf, ki, nk, bf[:, POS:POS + 3], bf[:, QUAT:QUAT + 4], bf[:, VEL:VEL + 3],
                          bf[:, OMEGA:OMEGA + 3], F, T, record, implicit, vecs)
    if method == EXPLICIT_EULER:
        _explicit_euler_velocities(bf, bi, nb, F, T, h)
    else:
        _momentum_velocities(bf, bi, nb, F, T, h, method == VERLET, prev_h)


@njit
def _setrow4(bf, i, col, q):
    for k in range(4):
        bf[i, col + k] = q[k]


#: Largest rotation (rad) of one implicit-midpoint piece: larger sub-steps are cut into pieces this short
#: (Newton's method on the midpoint equation converges from the start value well within it).
ROTATION_PIECE = 1.0
#: Most pieces a sub-step's rotation is cut into; beyond (|omega| h > 4096 rad) the kinetic energy is capped.
MAX_ROTATION_PIECES = 4096
#: Newton iterations of one piece, and the relative energy error at which a piece is accepted.
ROTATION_NEWTON = 10
ROTATION_ENERGY_TOLERANCE = 1e-10


@njit
def _solve_3x3(j, f):
    """``J^-1 f`` for a row-major 9-tuple ``J`` (Cramer's rule), a 3-tuple; zeros if J is singular."""
    c0 = j[4] * j[8] - j[5] * j[7]
    c1 = j[5] * j[6] - j[3] * j[8]
    c2 = j[3] * j[7] - j[4] * j[6]
    det = j[0] * c0 + j[1] * c1 + j[2] * c2
    if det == 0.0:
        return 0.0, 0.0, 0.0
    # adj(J) f / det, adj(J) = cofactor matrix transposed
    x = (c0 * f[0] + (j[2] * j[7] - j[1] * j[8]) * f[1] + (j[1] * j[5] - j[2] * j[4]) * f[2]) / det
    y = (c1 * f[0] + (j[0] * j[8] - j[2] * j[6]) * f[1] + (j[2] * j[3] - j[0] * j[5]) * f[2]) / det
    z = (c2 * f[0] + (j[1] * j[6] - j[0] * j[7]) * f[1] + (j[0] * j[4] - j[1] * j[3]) * f[2]) / det
    return x, y, z


@njit
def _midpoint_piece(bf, i, q, lw, h):
    """One implicit-midpoint rotation of body ``i`` over ``h`` s at constant world angular momentum ``lw``.

    In the frame of the piece's start (``W = I_w(q)^-1``) the body-frame angular momentum obeys Euler's
    equation ``dy/dt = y x W y`` with ``y(0) = L``; the implicit midpoint rule

        y' = L + h (m x W m),   m = (L + y') / 2

    keeps both quadratic invariants, ``|y|`` and the energy ``y . W y / 2``, exactly.  ``m`` solves
    ``m - L - h/2 (m x W m) = 0`` by Newton's method (Jacobian ``E - h/2 ([m]x W - [W m]x)``), and the
    orientation consistent with ``y'`` is the Cayley rotation about ``omega_mid = W m``:

        q' = normalise((1, h omega_mid / 2) * q)      (angle 2 atan(h |omega_mid| / 2))

    so that ``I_w(q')^-1 L`` has the energy ``L . W L / 2`` (to the tolerance of the solve).  Returns
    ``(q', ok)``: ``ok`` is False if the energy moved by more than ROTATION_ENERGY_TOLERANCE (Newton did
    not converge: the caller cuts the piece shorter).
    """
    w = inverse_inertia_world(bf, i, q)
    l0, l1, l2 = lw[0], lw[1], lw[2]
    m0, m1, m2 = l0, l1, l2
    hh = 0.5 * h
    for _ in range(ROTATION_NEWTON):
        u0, u1, u2 = tensor_vec(w, (m0, m1, m2))
        f = (m0 - l0 - hh * (m1 * u2 - m2 * u1), m1 - l1 - hh * (m2 * u0 - m0 * u2),
             m2 - l2 - hh * (m0 * u1 - m1 * u0))
        # [m]x W - [u]x, row-major
        a = (m1 * w[6] - m2 * w[3], m1 * w[7] - m2 * w[4] + u2, m1 * w[8] - m2 * w[5] - u1,
             m2 * w[0] - m0 * w[6] - u2, m2 * w[1] - m0 * w[7], m2 * w[2] - m0 * w[8] + u0,
             m0 * w[3] - m1 * w[0] + u1, m0 * w[4] - m1 * w[1] - u0, m0 * w[5] - m1 * w[2])
        jac = (1.0 - hh * a[0], -hh * a[1], -hh * a[2], -hh * a[3], 1.0 - hh * a[4], -hh * a[5],
               -hh * a[6], -hh * a[7], 1.0 - hh * a[8])
        d0, d1, d2 = _solve_3x3(jac, f)
        m0, m1, m2 = m0 - d0, m1 - d1, m2 - d2
        if d0 * d0 + d1 * d1 + d2 * d2 <= 1e-28 * (m0 * m0 + m1 * m1 + m2 * m2):
            break
    u0, u1, u2 = tensor_vec(w, (m0, m1, m2))
    c0, c1, c2, c3 = 1.0, hh * u0, hh * u1, hh * u2
    r0 = c0 * q[0] - c1 * q[1] - c2 * q[2] - c3 * q[3]
    r1 = c0 * q[1] + c1 * q[0] + c2 * q[3] - c3 * q[2]
    r2 = c0 * q[2] - c1 * q[3] + c2 * q[0] + c3 * q[1]
    r3 = c0 * q[3] + c1 * q[2] - c2 * q[1] + c3 * q[0]
    n = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    q_new = (r0 / n, r1 / n, r2 / n, r3 / n)
    e0 = _dot3(lw, tensor_vec(w, lw))
    e1 = _dot3(lw, tensor_vec(inverse_inertia_world(bf, i, q_new), lw))
    ok = math.isfinite(e1) and abs(e1 - e0) <= ROTATION_ENERGY_TOLERANCE * e0
    return q_new, ok


@njit
def _dot3(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def rotate_at_constant_momentum(bf, i, q, lw, h):
    """Orientation of body ``i`` after ``h`` s of torque-free rotation from ``q`` with world angular
    momentum ``lw`` (a 4-tuple), by :func:`_midpoint_piece`: ``L`` is kept exactly and the kinetic energy
    ``L . I_w^-1 L / 2`` to 1e-10 of itself, for any ``|omega| h``.

    The sub-step is cut into ``n = ceil(|omega| h / ROTATION_PIECE)`` pieces (more, by fours, if a piece
    does not converge).  Returns ``(q', capped)``: ``capped`` is True in the one case left (no piece count
    up to MAX_ROTATION_PIECES converges, ``|omega| h`` of thousands of radians), where the caller scales
    the angular velocity back to the energy it had.
    """
    w = tensor_vec(inverse_inertia_world(bf, i, q), lw)
    speed = math.sqrt(_dot3(w, w))
    n = max(1, int(math.ceil(min(speed * h / ROTATION_PIECE, float(MAX_ROTATION_PIECES)))))
    while True:
        piece = h / n
        qp = q
        ok = True
        for _ in range(n):
            qp, ok = _midpoint_piece(bf, i, qp, lw, piece)
            if not ok:
                break
        if ok:
            return qp, False
        if n >= MAX_ROTATION_PIECES:
            return qp, True
        n = min(4 * n, MAX_ROTATION_PIECES)


@njit
def _rotate_conserving_momentum(bf, i, h):
    """Advance body ``i``'s orientation over ``h`` at constant world angular momentum ``L = I_w(q) omega``
    (:func:`rotate_at_constant_momentum`: energy-conserving implicit midpoint), then ``omega' = I_w(q')^-1 L``.

    The kinetic energy ``omega . L / 2`` is conserved for any step: an explicit rule (such as the
    midpoint ``q_mid = exp(omega h / 2) q`` it replaces) turns a body whose inertia is very unequal
    (a thin rod spinning about its long axis, ``|omega| h`` of radians per sub-step) by the wrong angle,
    and at constant ``L`` its energy ``L . I_w(q')^-1 L / 2`` then grows by up to ``I_max / I_min``.
    """
    q = row4(bf, i, QUAT)
    w = row3(bf, i, OMEGA)
    lw = tensor_vec(inertia_world(bf, i, q), w)
    q_new, capped = rotate_at_constant_momentum(bf, i, q, lw, h)
    _setrow4(bf, i, QUAT, q_new)
    w_new = tensor_vec(inverse_inertia_world(bf, i, q_new), lw)
    if capped:
        # (|omega| h of thousands of radians: keep the energy, not L)
        scale = math.sqrt(max(_dot3(w, lw), 0.0) / max(_dot3(w_new, lw), 1e-300))
        w_new = (w_new[0] * scale, w_new[1] * scale, w_new[2] * scale)
    for k in range(3):
        bf[i, OMEGA + k] = w_new[k]


@njit_inline
def integrate_positions(method, bf, bi, nb, h):
    """Stage "integrate positions": move every awake dynamic body over ``h`` seconds.

    The solver's velocity change ``dv = v - v_free`` is added to the integrator's own prediction for
    explicit Euler and RK4; semi-implicit Euler and Verlet move with the final velocity directly.
    Kinematic bodies move by their own velocities, ``x += v h``, ``q := exp(omega h / 2) q``.  Every dynamic
    body's speeds after the solve are held to the speed limit first (:func:`limit_speeds`), as the forces'
    were before it.
    """
    for i in range(nb):
        if not is_moving(bi, i):
            if is_driven(bf, bi, i):
                for k in range(3):
                    bf[i, POS + k] += bf[i, VEL + k] * h
                _setrow4(bf, i, QUAT, quat_step(row4(bf, i, QUAT), row3(bf, i, OMEGA), h))
            continue
        limit_speeds(bf, i)
        if method == EXPLICIT_EULER or method == RK4:
            for k in range(3):
                bf[i, POS + k] = bf[i, X_PRED + k] + (bf[i, VEL + k] - bf[i, V_FREE + k]) * h
        else:
            for k in range(3):
                bf[i, PREV_POS + k] = bf[i, POS + k]
                bf[i, POS + k] += bf[i, VEL + k] * h
        if (bi[i, FLAGS] & F_ISOTROPIC) != 0:
            # omega is constant under torque-free rotation of an isotropic body.
            _setrow4(bf, i, QUAT, quat_step(row4(bf, i, QUAT), row3(bf, i, OMEGA), h))
        else:
            _rotate_conserving_momentum(bf, i, h)
