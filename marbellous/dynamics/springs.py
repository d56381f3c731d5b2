"""Hooke springs as force generators (D'Alembert: their forces join the accumulators).

For anchors ``p_a`` and ``p_b`` (world points), ``d = p_b - p_a``, ``l = |d|``, ``u = d / l``:

    F_a = (k (l - l0) + c dl/dt) u,   F_b = -F_a,   dl/dt = (v_pb - v_pa) . u

so a stretched spring pulls a towards b.  The torque on each body is ``r x F`` with ``r`` the anchor's
offset from the centre of mass.  Evaluated at every stage of the integrator.

An explicit force is stable only while the spring is slow next to the sub-step: semi-implicit Euler and
Verlet need ``omega h < 2`` (``omega^2 = k / m``), RK4 ``omega h < 2.8``, and the damping ``c h / m < 2``;
beyond, each sub-step multiplies the motion (a 1e15 N/m spring between 1 g bodies reached inf, then a
ZeroDivisionError, within a few steps).  So each step, ``joints.classify_springs`` hands every spring with

    (k h^2 + c h) / m_eff > joints.EXPLICIT_LIMIT     (m_eff: the two bodies' effective mass along the spring)

to the constraint solver, which solves it implicitly with its own k and c (``joints.spring_softness``:
backward Euler, stable for any k and never adding energy), and its force is left out here.  Below the
limit (``omega h < 1``, with a factor 4 of margin for springs sharing a body) a spring stays an explicit
force, integrated by the chosen integrator with its order and period.
"""
import math

from .._numba.jit import njit
from ..math3d import quat_rotate
from ..state.layout import (K_ANCHOR_A, K_ANCHOR_B, K_BODY_A, K_BODY_B, K_DAMPING, K_FLAGS, K_FORCE, K_LENGTH,
                            K_STIFFNESS, K_TYPE, KF_ALIVE, KF_BROKEN, KT_SPRING)



@njit
def anchor_world(X, Q, V, W, body, local, p_out, v_out, r):
    """World position and velocity of an anchor given in ``body``'s frame (``body < 0``: a fixed world point).

    ``r`` (3) is scratch; it receives the anchor's offset from the centre of mass.
    """
    if body < 0:
        for k in range(3):
            p_out[k] = local[k]
            v_out[k] = 0.0
        return
    quat_rotate(Q[body], local, r)
    w = W[body]
    for k in range(3):
        p_out[k] = X[body, k] + r[k]
    v_out[0] = V[body, 0] + w[1] * r[2] - w[2] * r[1]
    v_out[1] = V[body, 1] + w[2] * r[0] - w[0] * r[2]
    v_out[2] = V[body, 2] + w[0] * r[1] - w[1] * r[0]


@njit
def add_force_at(X, F, T, body, point, f, sign):
    """Add ``sign * f`` at world ``point`` to body's force and its torque ``(point - x) x f``."""
    rx = point[0] - X[body, 0]
    ry = point[1] - X[body, 1]
    rz = point[2] - X[body, 2]
    fx, fy, fz = sign * f[0], sign * f[1], sign * f[2]
    F[body, 0] += fx
    F[body, 1] += fy
    F[body, 2] += fz
    T[body, 0] += ry * fz - rz * fy
    T[body, 1] += rz * fx - rx * fz
    T[body, 2] += rx * fy - ry * fx


@njit
def add_spring_forces(kf, ki, nk, X, Q, V, W, F, T, record, implicit, vecs):
    """Accumulate the force and torque of every live, unbroken spring that is not solved implicitly
    (``implicit[c] != 0``: ``joints.classify_springs``).

    ``record`` (a weight, 0: none) adds ``record * F`` to each spring's K_FORCE: with weight h / dt at
    each sub-step, K_FORCE ends up as the step's mean force.  ``vecs``: scratch of at least (6, 3).
    """
    pa, pb, va, vb, f, r = vecs[0, :3], vecs[1, :3], vecs[2, :3], vecs[3, :3], vecs[4, :3], vecs[5, :3]
    for c in range(nk):
        flags = ki[c, K_FLAGS]
        if (ki[c, K_TYPE] != KT_SPRING or (flags & KF_ALIVE) == 0 or (flags & KF_BROKEN) != 0
                or implicit[c] != 0.0):
            continue
        a = ki[c, K_BODY_A]
        b = ki[c, K_BODY_B]
        anchor_world(X, Q, V, W, a, kf[c, K_ANCHOR_A:K_ANCHOR_A + 3], pa, va, r)
        anchor_world(X, Q, V, W, b, kf[c, K_ANCHOR_B:K_ANCHOR_B + 3], pb, vb, r)
        dx, dy, dz = pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        if length < 1e-12:
            # Direction undefined when the anchors coincide: no force.
            f[0] = 0.0
            f[1] = 0.0
            f[2] = 0.0
        else:
            ux, uy, uz = dx / length, dy / length, dz / length
            rate = (vb[0] - va[0]) * ux + (vb[1] - va[1]) * uy + (vb[2] - va[2]) * uz
            mag = kf[c, K_STIFFNESS] * (length - kf[c, K_LENGTH]) + kf[c, K_DAMPING] * rate
            f[0] = mag * ux
            f[1] = mag * uy
            f[2] = mag * uz
        add_force_at(X, F, T, a, pa, f, 1.0)
        if b >= 0:
            add_force_at(X, F, T, b, pb, f, -1.0)
        if record != 0.0:
            kf[c, K_FORCE] += record * f[0]
            kf[c, K_FORCE + 1] += record * f[1]
            kf[c, K_FORCE + 2] += record * f[2]


@njit
def clear_spring_forces(kf, ki, nk):
    """Zero the recorded force of every spring before a step accumulates its mean."""
    for c in range(nk):
        if ki[c, K_TYPE] == KT_SPRING:
            kf[c, K_FORCE] = 0.0
            kf[c, K_FORCE + 1] = 0.0
            kf[c, K_FORCE + 2] = 0.0
