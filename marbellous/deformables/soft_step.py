"""The soft bodies' step: linearised backward Euler over the corotated elements, solved by conjugate gradients.

Once per sub-step of ``h`` seconds of the particles' step, before it moves the soft bodies' nodes with the
velocity found here and resolves their contacts (``particle_step.py``), in order:

    rotations    each element's R from its deformation gradient F (soft_elements.py)
    right side   b = M v + h (f_el(x) + f_user + M g)
    solve        A v+ = b,  A = M + sum_e (h^2 + h beta_e) K_e     (conjugate gradients, Jacobi preconditioner)
    velocities   v = v+

A node that touched a static or kinematic body in the last sub-step keeps its velocity along the contact's
normal through the solve (the residual and search directions of that node are projected onto the contact's
plane: Baraff and Witkin's filtered conjugate gradients), unless the elastic forces would pull it off the
contact; the normal impulse the contact had to give, ``J = -n . (b - A v+)``, is kept for the contact's
friction (``P_SUPPORT``, ``particle_contacts.py``).  Without this the nodes next to a contact only learn of
it one sub-step late, and a block resting on the ground settles lower than its stiffness implies (by 10% for
a block two elements high at 16 sub-steps).

This is backward Euler, ``M (v+ - v) = h (f(x + h v+) + f_user + M g - beta K v+)``, with the elastic force
linearised at ``x`` with the rotations held, ``f(x + h v+) ~ f(x) - h K v+``.  ``A`` is symmetric positive
definite, so the step is stable however stiff the material: a vibration of angular frequency ``w`` keeps
``1 / sqrt(1 + (w h)^2)`` of its amplitude per step and its period lengthens by about ``(w h)^2 / 3``.  The
stiffness-proportional (Rayleigh) damping ``beta`` (s) makes a mode of angular frequency ``w`` decay at the rate
``beta w^2 / 2``.  A pinned node keeps the velocity it has: its row is left out of the system, its value
enters the rows of its neighbours.  A node pinned to a body pulls the body back with the impulse the pin gave
it, ``J = (A v+ - b)_p`` (its weight and the elastic pull of its neighbours), at the node, over the sub-step
(``body_motion.push_body``): the body carries the soft body and is held by it.
"""
import math

import numpy as np

from .._numba.jit import njit
from ..state.layout import INV_MASS
from .body_motion import body_pose, push_body
from .particle_layout import (K_KIND, K_NORMAL, K_OTHER, K_PARTICLE, KK_BODY, P_CONTACT, P_FLAGS, P_FORCE,
                              P_INV_MASS, P_MASS, P_PIN_BODY, P_POS, P_SUPPORT, P_VEL, PP_PINNED, PP_SOFT, Q_GRAVITY,
                              S_DAMPING)
from .soft_elements import add_element_forces, add_stiffness_diagonal, deformation_gradient, update_rotation


@njit
def _free(pf, pi, p):
    """Whether particle row ``p`` is a soft body's node that the solve moves (not pinned)."""
    return (pi[p, P_FLAGS] & PP_SOFT) != 0 and (pi[p, P_FLAGS] & PP_PINNED) == 0 and pf[p, P_INV_MASS] > 0.0


@njit
def record_contact_normals(pf, pi, n_particles, bf, kf, ki, nk):
    """Note, on each soft body's node, the normal (towards the node) of its first contact with a body that
    nothing moves (static or kinematic) among the sub-step's contacts ``0 .. nk - 1`` (``P_CONTACT``; zero:
    none).  (Against a body that the node pushes, a held normal velocity would not let the body's mass
    count: those contacts stay with the position pass alone.)"""
    for p in range(n_particles):
        if (pi[p, P_FLAGS] & PP_SOFT) != 0:
            for k in range(3):
                pf[p, P_CONTACT + k] = 0.0
    for c in range(min(nk, kf.shape[0])):
        p = ki[c, K_PARTICLE]
        if ki[c, K_KIND] != KK_BODY or bf[ki[c, K_OTHER], INV_MASS] != 0.0 or (pi[p, P_FLAGS] & PP_SOFT) == 0:
            continue
        if pf[p, P_CONTACT] == 0.0 and pf[p, P_CONTACT + 1] == 0.0 and pf[p, P_CONTACT + 2] == 0.0:
            for k in range(3):
                pf[p, P_CONTACT + k] = kf[c, K_NORMAL + k]


@njit
def _filter(normals, p, vec):
    """Project ``vec[p]`` onto the plane of node ``p``'s contact normal (unchanged without one); returns the
    component taken away."""
    along = vec[p, 0] * normals[p, 0] + vec[p, 1] * normals[p, 1] + vec[p, 2] * normals[p, 2]
    for k in range(3):
        vec[p, k] -= along * normals[p, k]
    return along


@njit
def _apply_system(pf, nodes, tf, ti, elements, rot, h, w, out):
    """``out = A w = M w + sum_e (h^2 + h beta_e) K_e w`` over the node rows ``nodes`` and element rows
    ``elements`` (ranges) of one soft body."""
    for p in nodes:
        for k in range(3):
            out[p, k] = pf[p, P_MASS] * w[p, k]
    for e in elements:
        add_element_forces(w, tf, ti, e, rot, False, h * h + h * tf[e, S_DAMPING], out)


@njit
def _restore_momentum(pf, pi, nodes, x, r, normals):
    """Give a soft body that no pin or contact held in its solve the momentum its residual ``r`` holds: the
    elastic forces of a body sum to zero, so ``sum (A x) = sum M x`` over its nodes and the exact solution
    changes its momentum by ``h (f_user + M g)`` alone; a solve stopped at a tolerance is off by ``-sum r``,
    which is spread over the body as one velocity."""
    mass = 0.0
    missing = [0.0, 0.0, 0.0]
    for p in nodes:
        if not _free(pf, pi, p) or normals[p, 0] != 0.0 or normals[p, 1] != 0.0 or normals[p, 2] != 0.0:
            return
        mass += pf[p, P_MASS]
        for k in range(3):
            missing[k] += r[p, k]
    for p in nodes:
        for k in range(3):
            x[p, k] += missing[k] / mass


@njit
def step_soft_bodies(params, pf, pi, bodies, n_bodies, tf, ti, h, tolerance, max_iterations, rot, work, bf, bi, bx,
                     back):
    """The soft bodies' step (module docstring), body by body: their free nodes' velocities ``P_VEL`` for the
    next ``h`` seconds, the elements' rotations updated.  ``bodies`` (``n_bodies`` rows): each soft body's
    first node row, node count, first element row and element count.  Each solve starts from the velocities
    the nodes have and stops when the residual's norm is below ``tolerance`` times the first residual's, or
    after ``max_iterations``.  Scratch: ``rot`` (elements, 9), ``work`` (9, particles, 3).  ``bf``, ``bi``,
    ``bx``, ``back``: the rigid bodies and the sub-step's time before the step's end, for the nodes pinned to
    bodies.  Returns ``(most iterations of a body, its largest residual / first residual)``."""
    most, worst = 0, 0.0
    for s in range(n_bodies):
        nodes = range(bodies[s, 0], bodies[s, 0] + bodies[s, 1])
        elements = range(bodies[s, 2], bodies[s, 2] + bodies[s, 3])
        used, residual = _solve_body(params, pf, pi, nodes, tf, ti, elements, h, tolerance, max_iterations, rot,
                                     work)
        _pull_pinning_bodies(pf, pi, nodes, tf, ti, elements, rot, h, work, bf, bi, bx, back)
        most = max(most, used)
        worst = max(worst, residual)
    return most, worst


@njit
def _pull_pinning_bodies(pf, pi, nodes, tf, ti, elements, rot, h, work, bf, bi, bx, back):
    """Give each body that a node of this soft body is pinned to the node's pull, ``-J = b_p - (A v+)_p`` (N s)
    at the node (module docstring), as the positional impulse ``-J h`` over the sub-step."""
    pinned_to_body = False
    for p in nodes:
        pinned_to_body = pinned_to_body or ((pi[p, P_FLAGS] & PP_PINNED) != 0 and pi[p, P_PIN_BODY] >= 0)
    if not pinned_to_body:
        return
    x, b, ap = work[0], work[1], work[5]
    _apply_system(pf, nodes, tf, ti, elements, rot, h, x, ap)
    for p in nodes:
        body = pi[p, P_PIN_BODY]
        if (pi[p, P_FLAGS] & PP_PINNED) == 0 or body < 0:
            continue
        x_b, q_b = body_pose(bf, bi, bx, body, back)
        point = (pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2])
        pull = ((b[p, 0] - ap[p, 0]) * h, (b[p, 1] - ap[p, 1]) * h, (b[p, 2] - ap[p, 2]) * h)
        push_body(bf, bi, bx, body, x_b, q_b, point, pull, h, True, 1.0)


@njit
def _solve_body(params, pf, pi, nodes, tf, ti, elements, h, tolerance, max_iterations, rot, work):
    """One soft body's step (:func:`step_soft_bodies`) over its node and element rows (ranges); returns
    ``(iterations, residual / first residual)``."""
    gravity = (params[Q_GRAVITY], params[Q_GRAVITY + 1], params[Q_GRAVITY + 2])
    x, b, r, z, d, ap, normals, pressed = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7]
    pos = pf[:, P_POS:P_POS + 3]
    grad = np.empty((3, 3))
    scratch = np.empty((3, 3))
    # right side b = M v + h (f_user + M g) + h f_el, the preconditioner d = diag(A)
    for p in nodes:
        m = pf[p, P_MASS]
        for k in range(3):
            x[p, k] = pf[p, P_VEL + k]
            b[p, k] = m * x[p, k] + h * (pf[p, P_FORCE + k] + m * gravity[k])
            d[p, k] = m
    for e in elements:
        deformation_gradient(pos, tf, ti, e, grad)
        update_rotation(tf, e, grad, scratch, rot)
        add_element_forces(pos, tf, ti, e, rot, True, -h, b)
        add_stiffness_diagonal(tf, ti, e, rot, h * h + h * tf[e, S_DAMPING], d)
    # preconditioned conjugate gradients on the free rows, from v
    _apply_system(pf, nodes, tf, ti, elements, rot, h, x, ap)
    rz = 0.0
    for p in nodes:
        free = _free(pf, pi, p)
        for k in range(3):
            r[p, k] = b[p, k] - ap[p, k] if free else 0.0
            normals[p, k] = pf[p, P_CONTACT + k] if free else 0.0
        # a node that the residual force pulls off its contact (along the normal) is let go
        if r[p, 0] * normals[p, 0] + r[p, 1] * normals[p, 1] + r[p, 2] * normals[p, 2] > 0.0:
            for k in range(3):
                normals[p, k] = 0.0
        pressed[p, 0] = _filter(normals, p, r)          # n . (b - A x): minus the contact's impulse
        for k in range(3):
            z[p, k] = r[p, k] / d[p, k]
        _filter(normals, p, z)
        for k in range(3):
            rz += r[p, k] * z[p, k]
    direction = work[8]
    for p in nodes:
        for k in range(3):
            direction[p, k] = z[p, k]
    first = -1.0
    iterations = 0
    rr = 0.0
    for iterations in range(max_iterations + 1):
        rr = 0.0
        for p in nodes:
            for k in range(3):
                rr += r[p, k] * r[p, k]
        if first < 0.0:
            first = rr
        if rr <= tolerance * tolerance * first or iterations == max_iterations:
            break
        _apply_system(pf, nodes, tf, ti, elements, rot, h, direction, ap)
        pap = 0.0
        for p in nodes:
            if _free(pf, pi, p):
                for k in range(3):
                    pap += direction[p, k] * ap[p, k]
        if pap <= 0.0:
            break
        alpha = rz / pap
        rz_next = 0.0
        for p in nodes:
            if _free(pf, pi, p):
                pressed[p, 0] -= alpha * _filter(normals, p, ap)
                for k in range(3):
                    x[p, k] += alpha * direction[p, k]
                    r[p, k] -= alpha * ap[p, k]
                    z[p, k] = r[p, k] / d[p, k]
                _filter(normals, p, z)
                for k in range(3):
                    rz_next += r[p, k] * z[p, k]
        beta = rz_next / rz
        rz = rz_next
        for p in nodes:
            for k in range(3):
                direction[p, k] = z[p, k] + beta * direction[p, k]
    _restore_momentum(pf, pi, nodes, x, r, normals)
    for p in nodes:
        if _free(pf, pi, p):
            for k in range(3):
                pf[p, P_VEL + k] = x[p, k]
            pf[p, P_SUPPORT] = max(0.0, -pressed[p, 0])
    return iterations, math.sqrt(rr / first) if first > 0.0 else 0.0
