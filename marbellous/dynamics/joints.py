"""Rods and cables: distance constraints solved in the same sequential-impulse iterations as contacts.

With world anchors ``p_a = x_a + ra``, ``p_b = x_b + rb``, ``l = |p_b - p_a|`` and ``u = (p_b - p_a) / l``:

    rod     C = l - L = 0        J v = u . ((v_b + w_b x rb) - (v_a + w_a x ra))     lambda free
    cable   C = l - L <= 0       same Jacobian; the cable only pulls (lambda <= 0); while slack
                                 (C < 0) it lets the ends separate by exactly -C in the sub-step

The impulse ``lambda u`` goes to b and ``-lambda u`` to a; both are soft constraints (``soft.py``), so a
rod pendulum keeps its length and its period without adding energy.
"""
import math


from .._jit import njit
from ..layout import (C_CABLE, C_ROD, K_ANCHOR_A, K_ANCHOR_B, K_BODY_A, K_BODY_B, K_FLAGS, K_FORCE,
                      K_IMPULSE, K_LENGTH, K_TYPE, KF_ALIVE, KF_BROKEN, POS, QUAT)
from ..math3d import quat_rotate
from .rigid import apply_impulse_pair, effective_mass, relative_velocity


@njit
def is_active_joint(ki, c):
    t = ki[c, K_TYPE]
    f = ki[c, K_FLAGS]
    return (t == C_ROD or t == C_CABLE) and (f & KF_ALIVE) != 0 and (f & KF_BROKEN) == 0


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
    """The 3-vectors ra, rb, pa, pb, u, dv, p as views of the scratch rows ``vecs[:7]``."""
    return vecs[0, :3], vecs[1, :3], vecs[2, :3], vecs[3, :3], vecs[4, :3], vecs[5, :3], vecs[6, :3]


@njit
def _world_inertia(sb, a, b):
    """Inverse mass and world inverse inertia rows of b; for the world (b < 0) a zero mass and a's row as a
    stand-in (its anchor offset rb is zero, so the inertia term (rb x d) I (rb x d) vanishes anyway)."""
    if b >= 0:
        return sb[b, 0], sb[b, 1:10]
    return 0.0, sb[a, 1:10]


@njit
def warm_start_joints(bf, kf, ki, nk, sb, vecs):
    """Apply each rod's and cable's impulse of the last sub-step along its current axis (``vecs``: scratch
    of at least (7, 3))."""
    ra, rb, pa, pb, u, _, p = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c) or kf[c, K_IMPULSE] == 0.0:
            continue
        if joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u) < 1e-12:
            continue
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        for k in range(3):
            p[k] = kf[c, K_IMPULSE] * u[k]
        inv_mb, iwb = _world_inertia(sb, a, b)
        apply_impulse_pair(bf, a, sb[a, 0], sb[a, 1:10], ra, b, inv_mb, iwb, rb, p)


@njit
def solve_joints(bf, kf, ki, nk, sb, h, use_bias, soft, vecs):
    """One pass over rods and cables (``use_bias``: solve, else relax); returns the largest velocity change.
    ``vecs``: scratch of at least (7, 3)."""
    ra, rb, pa, pb, u, dv, p = _scratch(vecs)
    largest = 0.0
    for c in range(nk):
        if not is_active_joint(ki, c):
            continue
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        if length < 1e-12:
            continue
        inv_mb, iwb = _world_inertia(sb, a, b)
        mass = effective_mass(sb[a, 0], sb[a, 1:10], ra, inv_mb, iwb, rb, u)
        if mass == 0.0:
            continue
        err = length - kf[c, K_LENGTH]
        cable = ki[c, K_TYPE] == C_CABLE
        if cable and err < 0.0:
            bias, mass_scale, impulse_scale = err / h, 1.0, 0.0   # slack: may open up to the full length
        elif use_bias:
            bias, mass_scale, impulse_scale = soft[0] * err, soft[1], soft[2]
        else:
            bias, mass_scale, impulse_scale = 0.0, 1.0, 0.0
        relative_velocity(bf, a, ra, b, rb, dv)
        vu = dv[0] * u[0] + dv[1] * u[1] + dv[2] * u[2]
        old = kf[c, K_IMPULSE]
        new = old - mass * mass_scale * (vu + bias) - impulse_scale * old
        if cable and new > 0.0:
            new = 0.0
        kf[c, K_IMPULSE] = new
        d = new - old
        if d != 0.0:
            for k in range(3):
                p[k] = d * u[k]
            apply_impulse_pair(bf, a, sb[a, 0], sb[a, 1:10], ra, b, inv_mb, iwb, rb, p)
            largest = max(largest, abs(d) / mass)
    return largest


@njit
def record_joint_forces(bf, kf, ki, nk, dt, totals, vecs):
    """Store each rod's and cable's force on body a over the step: ``F = -sum(lambda) u / dt`` (N).

    ``totals`` holds the impulses summed over the step's sub-steps; ``vecs``: scratch of at least (7, 3).
    """
    ra, rb, pa, pb, u, _, _ = _scratch(vecs)
    for c in range(nk):
        if not is_active_joint(ki, c):
            continue
        length = joint_axis(bf, kf, ki, c, ra, rb, pa, pb, u)
        for k in range(3):
            # a received -lambda u
            kf[c, K_FORCE + k] = -totals[c] * u[k] / dt if length >= 1e-12 else 0.0
