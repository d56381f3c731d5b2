"""The bodies as the particles see them during their sub-steps, and the particles' push back on them.

The particles take their sub-steps after the rigid bodies' step, so a body's pose at time ``t`` of the step
(``0 <= t <= dt``) is taken back from its pose at the end along its velocities:

    x(t) = x_end - v (dt - t) + D          q(t) = exp(Theta) exp(-omega (dt - t) / 2) q_end

where ``D`` and ``Theta`` are what the particles have moved and turned it by so far.  A particle's push on a
body is a positional impulse ``P`` (kg m) at a point ``p``, split as in position-based dynamics:

    D += P / m        Theta += I^-1 (r x P)        dv += P / (m h)        domega += I^-1 (r x P) / h

(``r = p - x(t)``, ``I^-1 = R I_body^-1 R^T`` the world inverse inertia, ``h`` the sub-step; the velocities get
less of it where a push takes the body out of an overlap it did not close in that sub-step,
``particle_contacts._shape_pair``), and the body goes on moving with its extra velocity ``dv, domega`` in the
later sub-steps.  At the end of the step the pose and the
velocities are written back, so that momentum is conserved: what a particle gains the body loses.

A body in free fall in the bodies' step (its velocity changed as gravity, its user force and its linear
damping ``c`` alone would change it, give or take a quarter of ``g dt``: no contact or joint took its weight)
falls in the particles' sub-steps as a particle does, from where it was at the start of the step (``dv`` starts
at ``v_start - v_end``, ``D`` at ``x_start - (x_end - v_end dt)``), each sub-step

    v_k = v_(k-1) exp(-c h) + a h        x_k = x_(k-1) + v_k h        (a = g + F / m)

Taking its weight's velocity ``g dt`` at once instead (and starting from ``x_end - v_end dt``, which the
bodies' own sub-steps put ``g dt^2 / 4`` below ``x_start``), a body hanging from particles dipped within each
step while its particles pulled it back over the sub-steps: at rest on a spring it reported 2 cm/s upward at
60 Hz (``0.13 g dt``); and its damping, acting on the velocity its weight gave it within the step, took up to
1 % of its weight.  Bodies held by contacts or joints in their own step move at ``v_end`` throughout.

The table ``bx`` holds, per body row: ``D`` (3), ``Theta`` (3), ``dv`` (3), ``domega`` (3), whether it was
touched (pushed bodies that were asleep wake), ``a`` (3), whether it falls freely, and its load in the sub-step:
the overlaps it was pushed out of by particles that the ground holds (m; ``particle_contacts._shape_pair``).
Static and kinematic bodies are never pushed: they move the particles and take nothing back.
"""
import math

from .._numba.jit import njit, njit_inline
from ..dynamics.forces import is_dynamic
from ..math3d import quat_step, rotate_tensor, rotation_of, rotated, tensor_vec
from ..state.layout import (F_RESTART, F_SLEEPING, F_STATIC, FLAGS, INV_I, INV_MASS, LINEAR_DAMPING, OMEGA, POS, QUAT,
                            SLEEP_TIME, VEL)

BX_D = 0
BX_THETA = 3
BX_DV = 6
BX_DW = 9
BX_TOUCHED = 12
BX_ACCEL = 13
BX_FALLING = 16
BX_LOAD = 17
BX_COLS = 18

#: how far a body's velocity after its step may be from free fall's (as a fraction of ``|a| dt``) for the
#: body to count as falling freely (a contact that holds it takes it all)
FREE_FALL_TOLERANCE = 0.25


@njit
def clear_motion(bx, nb):
    """No push on any body yet."""
    for i in range(nb):
        for k in range(BX_COLS):
            bx[i, k] = 0.0


@njit
def start_motion(bf, bi, bx, nb, start, dt, gravity):
    """No push on any body yet; the bodies that fell freely in their step fall again in the sub-steps
    (module docstring; ``start`` (nb, 9): each body's position, m, velocity, m/s, and user force, N, before its
    step; ``gravity`` m/s^2)."""
    clear_motion(bx, nb)
    for b in range(min(nb, start.shape[0])):
        if not pushable(bf, bi, b) or (bi[b, FLAGS] & F_SLEEPING) != 0:
            continue
        a = (gravity[0] + start[b, 6] * bf[b, INV_MASS], gravity[1] + start[b, 7] * bf[b, INV_MASS],
             gravity[2] + start[b, 8] * bf[b, INV_MASS])
        a_dt = math.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2) * dt
        keep = math.exp(-bf[b, LINEAR_DAMPING] * dt)
        off = 0.0
        for k in range(3):
            off += (bf[b, VEL + k] - (start[b, 3 + k] * keep + a[k] * dt)) ** 2
        if a_dt > 0.0 and math.sqrt(off) <= FREE_FALL_TOLERANCE * a_dt:
            for k in range(3):
                bx[b, BX_ACCEL + k] = a[k]
                bx[b, BX_DV + k] = start[b, 3 + k] - bf[b, VEL + k]
                bx[b, BX_D + k] = start[b, k] - (bf[b, POS + k] - bf[b, VEL + k] * dt)
            bx[b, BX_FALLING] = 1.0


@njit
def drift(bf, bx, nb, h):
    """The pushed and the falling bodies go on moving with their extra velocities for a sub-step of ``h``
    seconds, the falling ones damped and accelerated first (module docstring); no load yet in the sub-step."""
    for i in range(nb):
        bx[i, BX_LOAD] = 0.0
        if bx[i, BX_FALLING] != 0.0:
            keep = math.exp(-bf[i, LINEAR_DAMPING] * h)
            for k in range(3):
                v = (bf[i, VEL + k] + bx[i, BX_DV + k]) * keep + bx[i, BX_ACCEL + k] * h
                bx[i, BX_DV + k] = v - bf[i, VEL + k]
        if bx[i, BX_TOUCHED] != 0.0 or bx[i, BX_FALLING] != 0.0:
            for k in range(3):
                bx[i, BX_D + k] += bx[i, BX_DV + k] * h
                bx[i, BX_THETA + k] += bx[i, BX_DW + k] * h


@njit_inline
def body_pose(bf, bi, bx, b, back):
    """Body row ``b``'s ``(position, orientation)`` ``back`` seconds before the end of the step (tuples)."""
    q = (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3])
    x = (bf[b, POS], bf[b, POS + 1], bf[b, POS + 2])
    if (bi[b, FLAGS] & (F_STATIC | F_SLEEPING)) == 0:
        x = (x[0] - bf[b, VEL] * back, x[1] - bf[b, VEL + 1] * back, x[2] - bf[b, VEL + 2] * back)
        q = quat_step(q, (bf[b, OMEGA], bf[b, OMEGA + 1], bf[b, OMEGA + 2]), -back)
    if bx[b, BX_TOUCHED] != 0.0 or bx[b, BX_FALLING] != 0.0:
        x = (x[0] + bx[b, BX_D], x[1] + bx[b, BX_D + 1], x[2] + bx[b, BX_D + 2])
        q = quat_step(q, (bx[b, BX_THETA], bx[b, BX_THETA + 1], bx[b, BX_THETA + 2]), 1.0)
    return x, q


@njit_inline
def point_velocity(bf, bi, bx, b, x_b, p):
    """Velocity (m/s) of body row ``b``'s material point at ``p`` (its centre at ``x_b``)."""
    if (bi[b, FLAGS] & F_STATIC) != 0:
        return 0.0, 0.0, 0.0
    v = (bf[b, VEL] + bx[b, BX_DV], bf[b, VEL + 1] + bx[b, BX_DV + 1], bf[b, VEL + 2] + bx[b, BX_DV + 2])
    w = (bf[b, OMEGA] + bx[b, BX_DW], bf[b, OMEGA + 1] + bx[b, BX_DW + 1], bf[b, OMEGA + 2] + bx[b, BX_DW + 2])
    r = (p[0] - x_b[0], p[1] - x_b[1], p[2] - x_b[2])
    return (v[0] + w[1] * r[2] - w[2] * r[1], v[1] + w[2] * r[0] - w[0] * r[2], v[2] + w[0] * r[1] - w[1] * r[0])


@njit_inline
def world_inverse_inertia(bf, b, q):
    """``R I_body^-1 R^T`` of body row ``b`` at orientation ``q`` (row-major 9-tuple, 1/(kg m^2))."""
    m = (bf[b, INV_I], bf[b, INV_I + 1], bf[b, INV_I + 2], bf[b, INV_I + 3], bf[b, INV_I + 4], bf[b, INV_I + 5],
         bf[b, INV_I + 6], bf[b, INV_I + 7], bf[b, INV_I + 8])
    return rotate_tensor(rotation_of(q), m)


@njit_inline
def pushable(bf, bi, b):
    """Whether the particles can move body row ``b`` (dynamic, awake or asleep; not static or kinematic)."""
    return bf[b, INV_MASS] > 0.0 and is_dynamic(bi, b)


@njit_inline
def inverse_mass_along(bf, bi, b, x_b, q, p, n):
    """Generalised inverse mass of body row ``b`` at point ``p`` along the unit direction ``n``:
    ``1/m + (r x n) . I^-1 (r x n)`` (0 for a body the particles cannot move)."""
    if not pushable(bf, bi, b):
        return 0.0
    r = (p[0] - x_b[0], p[1] - x_b[1], p[2] - x_b[2])
    rn = (r[1] * n[2] - r[2] * n[1], r[2] * n[0] - r[0] * n[2], r[0] * n[1] - r[1] * n[0])
    irn = tensor_vec(world_inverse_inertia(bf, b, q), rn)
    return bf[b, INV_MASS] + rn[0] * irn[0] + rn[1] * irn[1] + rn[2] * irn[2]


@njit_inline
def push_body(bf, bi, bx, b, x_b, q, p, impulse, h, move, share):
    """Give body row ``b`` the positional impulse ``impulse`` (kg m, a 3-tuple) at ``p``: a velocity change of
    ``share impulse / h`` (kg m/s; ``share`` 1 but where a push takes a body out of an overlap it did not close in
    the sub-step), and, when ``move``, the position change too (see the module docstring)."""
    if not pushable(bf, bi, b):
        return
    r = (p[0] - x_b[0], p[1] - x_b[1], p[2] - x_b[2])
    torque = (r[1] * impulse[2] - r[2] * impulse[1], r[2] * impulse[0] - r[0] * impulse[2],
              r[0] * impulse[1] - r[1] * impulse[0])
    turn = tensor_vec(world_inverse_inertia(bf, b, q), torque)
    inv_m = bf[b, INV_MASS]
    for k in range(3):
        if move:
            bx[b, BX_D + k] += inv_m * impulse[k]
            bx[b, BX_THETA + k] += turn[k]
        bx[b, BX_DV + k] += share * inv_m * impulse[k] / h
        bx[b, BX_DW + k] += share * turn[k] / h
    bx[b, BX_TOUCHED] = 1.0


@njit
def write_back(bf, bi, bx, nb):
    """The pushed bodies' poses and velocities at the end of the step; a pushed body that slept wakes."""
    for b in range(nb):
        if bx[b, BX_TOUCHED] == 0.0:
            continue
        x, q = body_pose(bf, bi, bx, b, 0.0)
        n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        for k in range(3):
            bf[b, POS + k] = x[k]
            bf[b, VEL + k] += bx[b, BX_DV + k]
            bf[b, OMEGA + k] += bx[b, BX_DW + k]
        for k in range(4):
            bf[b, QUAT + k] = q[k] / n
        bi[b, FLAGS] &= ~F_SLEEPING
        bi[b, FLAGS] |= F_RESTART           # (moved outside its integrator: Verlet starts again from here)
        bf[b, SLEEP_TIME] = 0.0


@njit
def to_world(x, q, local):
    """The body-frame point ``local`` at pose ``(x, q)``, in the world (tuple)."""
    r = rotated(q, local)
    return x[0] + r[0], x[1] + r[1], x[2] + r[2]
