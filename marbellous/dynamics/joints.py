"""Rods and cables (and springs too stiff for explicit forces): distance constraints solved in the same
sequential-impulse iterations as contacts.

With world anchors ``p_a = x_a + ra``, ``p_b = x_b + rb``, ``l = |p_b - p_a|`` and ``u = (p_b - p_a) / l``:

    rod     C = l - L = 0        J v = u . ((v_b + w_b x rb) - (v_a + w_a x ra))     lambda free
    cable   C = l - L <= 0       same Jacobian; the cable only pulls (lambda <= 0); while slack
                                 (C < 0) it lets the ends separate by exactly -C in the sub-step
    spring  F = -k C - c dC/dt   same Jacobian, solved implicitly (:func:`spring_softness`) when
                                 ``(k h^2 + c h) / m`` exceeds ``EXPLICIT_LIMIT``

The impulse ``lambda u`` goes to b and ``-lambda u`` to a; rods and cables are soft constraints
(``soft.py``), so a rod pendulum keeps its length and its period without adding energy.  Their position
error is corrected at ``joint_hertz`` but never faster than ``max_push`` (m/s): a 2 m rod made between
bodies 30 m apart pulls them together at that speed (uncapped, its bias ``rate * 28 m`` was about
1,900 m/s per rod, and the soak run's pile of such rods reached 6e17 m/s and NaN).
"""
import math

from .._numba.jit import njit
from ..math3d import quat_rotate
from ..state.layout import (KT_CABLE, KT_ROD, KT_SPRING, K_ANCHOR_A, K_ANCHOR_B, K_BODY_A, K_BODY_B, K_DAMPING,
                            K_FLAGS, K_FORCE, K_IMPULSE, K_LENGTH, K_STIFFNESS, K_TYPE, KF_ALIVE, KF_BROKEN, POS, QUAT)
from .solver_bodies import effective_mass_along, push, relative_velocity_at, set_velocity, velocity


@njit
def is_active_joint(ki, c, implicit):
    """True if constraint ``c`` is alive, unbroken and solved here: a rod, a cable, or a spring that the step
    solves implicitly (``implicit[c] != 0``, :func:`classify_springs`)."""
    t = ki[c, K_TYPE]
    f = ki[c, K_FLAGS]
    if (f & KF_ALIVE) == 0 or (f & KF_BROKEN) != 0:
        return False
    return t == KT_ROD or t == KT_CABLE or (t == KT_SPRING and implicit[c] != 0.0)


#: a spring with ``(k h^2 + c h) / m_eff`` above this is solved implicitly by the constraint solver (``springs.py``)
EXPLICIT_LIMIT = 1.0


@njit
def classify_springs(bf, kf, ki, nk, sb, h, implicit, vecs):
    """For each live spring, ``implicit[c] = 1`` if ``(k h^2 + c h) / m_eff > EXPLICIT_LIMIT`` over the sub-step
    of ``h`` s (``m_eff`` along the spring from the solver bodies ``sb``), else 0; a spring that is explicit
    forgets its solver impulse (no stale warm start if it turns implicit again).  ``vecs``: scratch of at
    least (5, 3)."""
    ra, rb, pa, pb, u = _scratch(vecs)
    for c in range(nk):
        implicit[c] = 0.0
        flags = ki[c, K_FLAGS]
        if ki[c, K_TYPE] != KT_SPRING or (flags & KF_ALIVE) == 0 or (flags & KF_BROKEN) != 0:
            continue
        if joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u) >= 1e-12:
            m = effective_mass_along(sb, ki[c, K_BODY_A], ra, ki[c, K_BODY_B], rb, u)
            if m > 0.0 and kf[c, K_STIFFNESS] * h * h + kf[c, K_DAMPING] * h > EXPLICIT_LIMIT * m:
                implicit[c] = 1.0
        if implicit[c] == 0.0:
            kf[c, K_IMPULSE] = 0.0


@njit
def spring_softness(k, c, m, h):
    """``(bias_rate (1/s), mass_scale, impulse_scale)`` of a spring of stiffness ``k`` (N/m) and damping ``c``
    (N s/m) on the effective mass ``m`` (kg) over a sub-step of ``h`` s, solved as a soft constraint: backward
    Euler on ``m dv/dt = -k C - c dC/dt`` gives the impulse

        P = -m gamma / (m + gamma) (v + k / (k h + c) C),   gamma = h (k h + c)

    which is the soft step's ``-m mass_scale (J v + bias_rate C) - impulse_scale lambda`` at its fixed point
    with ``mass_scale = gamma / (m + gamma)``, ``impulse_scale = m / (m + gamma)`` and
    ``bias_rate = k / (k h + c)`` (Box2D's ``omega / (2 zeta + h omega)``, ``a2 = gamma / m``).  Backward
    Euler is stable for any ``k h^2 / m`` and never adds energy; it damps the oscillation (the spring's
    period is resolved only where it is explicit).
    """
    gamma = h * (k * h + c)
    if gamma <= 0.0 or m <= 0.0:
        return 0.0, 0.0, 1.0
    return k / (k * h + c), gamma / (m + gamma), m / (m + gamma)


@njit
def joint_anchors(bf, kf, ki, c, ra, rb, pa, pb):
    """Offsets ``ra``, ``rb`` of the anchors from the centres of mass and the world anchors ``pa``, ``pb``."""
    a = ki[c, K_BODY_A]
    b = ki[c, K_BODY_B]
    quat_rotate(bf[a, QUAT:QUAT + 4], kf[c, K_ANCHOR_A:K_ANCHOR_A + 3], ra)
    for k in range(3):
        pa[k] = bf[a, POS + k] + ra[k]
    if b >= 0:
        quat_rotate(bf[b, QUAT:QUAT + 4], kf[c, K_ANCHOR_B:K_ANCHOR_B + 3], rb)
        for k in range(3):
            pb[k] = bf[b, POS + k] + rb[k]
    else:
        for k in range(3):
            rb[k] = 0.0
            pb[k] = kf[c, K_ANCHOR_B + k]


@njit
def joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u):
    """Anchors of constraint ``c`` (as ``joint_anchors``) and the unit axis ``u = (p_b - p_a) / l``.

    Returns the distance ``l`` between the anchors (m); ``u`` is left alone when ``l < 1e-12``.
    """
    joint_anchors(bf, kf, ki, c, ra, rb, pa, pb)
    length = math.sqrt((pb[0] - pa[0]) ** 2 + (pb[1] - pa[1]) ** 2 + (pb[2] - pa[2]) ** 2)
    if length >= 1e-12:
        for k in range(3):
            u[k] = (pb[k] - pa[k]) / length
    return length


@njit
def _scratch(vecs):
    """The 3-vectors ra, rb, pa, pb, u as views of the scratch rows ``vecs[:5]``."""
    return vecs[0, :3], vecs[1, :3], vecs[2, :3], vecs[3, :3], vecs[4, :3]


@njit
def _velocity(sb, b):
    """``(v, omega)`` of solver body ``b``, or rest for the world (``b < 0``)."""
    if b >= 0:
        return velocity(sb, b)
    return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit
def _apply(sb, a, ra, b, rb, px, py, pz):
    """Apply the impulse ``p`` (N s) to b at ``rb`` and ``-p`` to a at ``ra`` (``b < 0``: the world)."""
    set_velocity(sb, a, push(sb, a, velocity(sb, a), ra, px, py, pz, -1.0))
    if b >= 0:
        set_velocity(sb, b, push(sb, b, velocity(sb, b), rb, px, py, pz, 1.0))


@njit
def warm_start_joints(bf, kf, ki, nk, sb, implicit, vecs):
    """Apply each rod's, cable's and implicit spring's impulse of the last sub-step along its current axis to
    the solver bodies ``sb`` (``vecs``: scratch of at least (5, 3))."""
    ra, rb, pa, pb, u = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c, implicit) or kf[c, K_IMPULSE] == 0.0:
            continue
        if joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u) < 1e-12:
            continue
        lam = kf[c, K_IMPULSE]
        _apply(sb, ki[c, K_BODY_A], ra, ki[c, K_BODY_B], rb, lam * u[0], lam * u[1], lam * u[2])


@njit
def solve_joints(bf, kf, ki, nk, sb, h, use_bias, soft, max_push, implicit, vecs):
    """One pass over rods, cables and implicit springs on the solver bodies ``sb`` (``use_bias``: solve, else
    relax); returns the largest velocity change (m/s).  A rod's or cable's position error is corrected at
    ``soft[0] C`` but no faster than ``max_push`` (m/s); a spring is solved with its own stiffness and
    damping (:func:`spring_softness`) in both passes, as its force is physics, not a correction.
    ``vecs``: scratch of at least (5, 3)."""
    ra, rb, pa, pb, u = _scratch(vecs)
    largest = 0.0
    for c in range(nk):
        if not is_active_joint(ki, c, implicit):
            continue
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        if length < 1e-12:
            continue
        mass = effective_mass_along(sb, a, ra, b, rb, u)
        if mass == 0.0:
            continue
        err = length - kf[c, K_LENGTH]
        cable = ki[c, K_TYPE] == KT_CABLE
        if ki[c, K_TYPE] == KT_SPRING:
            rate, mass_scale, impulse_scale = spring_softness(kf[c, K_STIFFNESS], kf[c, K_DAMPING], mass, h)
            bias = rate * err
        elif cable and err < 0.0:
            bias, mass_scale, impulse_scale = err / h, 1.0, 0.0   # slack: may open up to the full length
        elif use_bias:
            bias = min(max(soft[0] * err, -max_push), max_push)
            mass_scale, impulse_scale = soft[1], soft[2]
        else:
            bias, mass_scale, impulse_scale = 0.0, 1.0, 0.0
        dv = relative_velocity_at(velocity(sb, a), ra, _velocity(sb, b), rb)
        vu = dv[0] * u[0] + dv[1] * u[1] + dv[2] * u[2]
        old = kf[c, K_IMPULSE]
        new = old - mass * mass_scale * (vu + bias) - impulse_scale * old
        if cable and new > 0.0:
            new = 0.0
        kf[c, K_IMPULSE] = new
        d = new - old
        if d != 0.0:
            _apply(sb, a, ra, b, rb, d * u[0], d * u[1], d * u[2])
            largest = max(largest, abs(d) / mass)
    return largest


@njit
def record_joint_forces(bf, kf, ki, nk, dt, totals, implicit, vecs):
    """Store each rod's, cable's and implicit spring's force on body a over the step:
    ``F = -sum(lambda) u / dt`` (N).

    ``totals`` holds the impulses summed over the step's sub-steps; ``vecs``: scratch of at least (7, 3).
    """
    ra, rb, pa, pb, u = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c, implicit):
            continue
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        for k in range(3):
            # a received -lambda u
            kf[c, K_FORCE + k] = -totals[c] * u[k] / dt if length >= 1e-12 else 0.0
