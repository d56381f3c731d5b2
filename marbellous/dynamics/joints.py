"""Rods and cables: distance constraints solved in the same sequential-impulse iterations as contacts.

With world anchors ``p_a = x_a + ra``, ``p_b = x_b + rb``, ``l = |p_b - p_a|`` and ``u = (p_b - p_a) / l``:

    rod     C = l - L = 0        J v = u . ((v_b + w_b x rb) - (v_a + w_a x ra))     lambda free
    cable   C = l - L <= 0       same Jacobian; the cable only pulls (lambda <= 0); while slack
                                 (C < 0) it lets the ends separate by exactly -C in the sub-step

The impulse ``lambda u`` goes to b and ``-lambda u`` to a; both are soft constraints (``soft.py``), so a
rod pendulum keeps its length and its period without adding energy.
"""
import math

from .._numba.jit import njit
from ..math3d import quat_rotate
from ..state.layout import (KT_CABLE, KT_ROD, K_ANCHOR_A, K_ANCHOR_B, K_BODY_A, K_BODY_B, K_FLAGS, K_FORCE, K_IMPULSE,
                            K_LENGTH, K_TYPE, KF_ALIVE, KF_BROKEN, POS, QUAT)
from .solver_bodies import effective_mass_along, push, relative_velocity_at, set_velocity, velocity


@njit
def is_active_joint(ki, c):
    t = ki[c, K_TYPE]
    f = ki[c, K_FLAGS]
    return (t == KT_ROD or t == KT_CABLE) and (f & KF_ALIVE) != 0 and (f & KF_BROKEN) == 0


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
def warm_start_joints(bf, kf, ki, nk, sb, vecs):
    """Apply each rod's and cable's impulse of the last sub-step along its current axis to the solver bodies
    ``sb`` (``vecs``: scratch of at least (5, 3))."""
    ra, rb, pa, pb, u = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c) or kf[c, K_IMPULSE] == 0.0:
            continue
        if joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u) < 1e-12:
            continue
        lam = kf[c, K_IMPULSE]
        _apply(sb, ki[c, K_BODY_A], ra, ki[c, K_BODY_B], rb, lam * u[0], lam * u[1], lam * u[2])


@njit
def solve_joints(bf, kf, ki, nk, sb, h, use_bias, soft, vecs):
    """One pass over rods and cables on the solver bodies ``sb`` (``use_bias``: solve, else relax); returns the
    largest velocity change (m/s).  ``vecs``: scratch of at least (5, 3)."""
    ra, rb, pa, pb, u = _scratch(vecs)
    largest = 0.0
    for c in range(nk):
        if not is_active_joint(ki, c):
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
        if cable and err < 0.0:
            bias, mass_scale, impulse_scale = err / h, 1.0, 0.0   # slack: may open up to the full length
        elif use_bias:
            bias, mass_scale, impulse_scale = soft[0] * err, soft[1], soft[2]
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
def record_joint_forces(bf, kf, ki, nk, dt, totals, vecs):
    """Store each rod's and cable's force on body a over the step: ``F = -sum(lambda) u / dt`` (N).

    ``totals`` holds the impulses summed over the step's sub-steps; ``vecs``: scratch of at least (7, 3).
    """
    ra, rb, pa, pb, u = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c):
            continue
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        for k in range(3):
            # a received -lambda u
            kf[c, K_FORCE + k] = -totals[c] * u[k] / dt if length >= 1e-12 else 0.0
