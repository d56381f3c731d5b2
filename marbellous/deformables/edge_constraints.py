"""The networks' edges as compliant distance constraints (XPBD), one Gauss-Seidel pass per sub-step.

An edge between particles a and b keeps their distance ``l = |x_a - x_b|`` at its length ``L``:

    C = l - L,    grad_a C = n = (x_a - x_b) / l,    grad_b C = -n

a rod always, a cable only when stretched (``C > 0``), a spring softly, with compliance ``alpha = 1/k`` (m/N)
and damping coefficient ``c`` (N s/m).  Extended position-based dynamics (Macklin, Mueller and Chentanez 2016)
moves the particles by ``dx_a = w_a dlambda n``, ``dx_b = -w_b dlambda n`` with

    alpha~ = alpha / h^2,    gamma = alpha c / h
    dlambda = (-C - alpha~ lambda - gamma n . (dx_a - dx_b)) / ((1 + gamma) (w_a + w_b) + alpha~),
    lambda += dlambda

where ``w`` are the inverse masses, ``dx`` each end's motion in this sub-step so far, and ``lambda`` the
multiplier the edge has gathered over the sub-step's earlier passes (0 in the first).  An end pinned to a
body is a point of that body: its ``w`` is the body's generalised inverse mass at that point along ``n``
(``body_motion.inverse_mass_along``), and its share of the correction moves the body (``push_body``).

With ``alpha = 0`` (rods, cables) the constraint is exact after the pass; with ``alpha > 0`` the spring's
force is ``-C / alpha``, as Hooke's law says, whatever the sub-step: the stiffness does not depend on the step,
and the pass cannot blow up however stiff the spring (the lecture's "stiff constraints").  Over a sub-step the
edge pulls with the tension ``T = -dlambda / h^2`` (N, > 0 pulling the ends together); the edge's force of the
step is the mean of its sub-steps' (its impulse over the step divided by ``dt``), and an edge whose force passes
its breaking force, or a cloth's edge longer than its tearing length, breaks at the step's end and acts no more.
"""
import math

from .._numba.jit import njit
from .body_motion import body_pose, inverse_mass_along, push_body
from .particle_layout import (E_A, E_B, E_BREAKING, E_COMPLIANCE, E_DAMPING, E_FLAGS, E_FORCE, E_KIND, E_LAMBDA,
                              E_REST, E_TEAR,
                              EB_BROKEN, EK_CABLE, EK_SPRING, P_CLOTH, P_FLAGS, P_INV_MASS, P_PIN_BODY, P_POS, P_PREV,
                              PP_PINNED)


@njit
def end_mass(pf, pi, bf, bi, bx, p, back, n):
    """Inverse mass of edge end ``p`` along ``n``: the particle's, or its body's at its place when it is
    pinned to one."""
    b = pi[p, P_PIN_BODY]
    if (pi[p, P_FLAGS] & PP_PINNED) == 0 or b < 0:
        return pf[p, P_INV_MASS]
    x_b, q_b = body_pose(bf, bi, bx, b, back)
    return inverse_mass_along(bf, bi, b, x_b, q_b, (pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2]), n)


@njit
def move_end(pf, pi, bf, bi, bx, p, back, w, dlambda, n, h):
    """Move edge end ``p`` by ``w dlambda n`` (m), and its body with it when it is pinned to one."""
    for k in range(3):
        pf[p, P_POS + k] += w * dlambda * n[k]
    b = pi[p, P_PIN_BODY]
    if (pi[p, P_FLAGS] & PP_PINNED) != 0 and b >= 0:
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        point = (pf[p, P_POS], pf[p, P_POS + 1], pf[p, P_POS + 2])
        push_body(bf, bi, bx, b, x_b, q_b, point, (dlambda * n[0], dlambda * n[1], dlambda * n[2]), h, True, 1.0)


@njit
def solve_edges(pf, pi, ef, ei, ne, solved, bf, bi, bx, back, h, share, first):
    """One pass over the edges ``0 .. ne - 1`` but those the whole-cloth solve takes (``solved``,
    stretch_solve.py) (module docstring), in the sub-step that ends ``back`` s before the step's end;
    ``first``: the sub-step's first pass, the multipliers start from 0 (else a second pass over the cloths' edges
    only, going on from them).  Each edge's force gets ``share`` (1 / sub-steps) of this sub-step's tension."""
    for e in range(ne):
        if solved[e]:
            continue
        if first:
            ef[e, E_LAMBDA] = 0.0
        elif pi[ei[e, E_A], P_CLOTH] < 0:
            continue
        if (ei[e, E_FLAGS] & EB_BROKEN) != 0:
            continue
        a, b = ei[e, E_A], ei[e, E_B]
        d0 = pf[a, P_POS] - pf[b, P_POS]
        d1 = pf[a, P_POS + 1] - pf[b, P_POS + 1]
        d2 = pf[a, P_POS + 2] - pf[b, P_POS + 2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        c = length - ef[e, E_REST]
        kind = ei[e, E_KIND]
        if length < 1e-12 or (kind == EK_CABLE and c <= 0.0):
            continue
        n0, n1, n2 = d0 / length, d1 / length, d2 / length
        # (the calls for ends on bodies only: every call passes and reference-counts the tables again)
        on_a = (pi[a, P_FLAGS] & PP_PINNED) != 0 and pi[a, P_PIN_BODY] >= 0
        on_b = (pi[b, P_FLAGS] & PP_PINNED) != 0 and pi[b, P_PIN_BODY] >= 0
        wa = end_mass(pf, pi, bf, bi, bx, a, back, (n0, n1, n2)) if on_a else pf[a, P_INV_MASS]
        wb = end_mass(pf, pi, bf, bi, bx, b, back, (-n0, -n1, -n2)) if on_b else pf[b, P_INV_MASS]
        alpha = ef[e, E_COMPLIANCE] / (h * h) if kind == EK_SPRING else 0.0
        gamma = ef[e, E_COMPLIANCE] * ef[e, E_DAMPING] / h if kind == EK_SPRING else 0.0
        denominator = (1.0 + gamma) * (wa + wb) + alpha
        if denominator <= 0.0:
            continue
        closing = 0.0
        if gamma > 0.0:
            closing = (n0 * ((pf[a, P_POS] - pf[a, P_PREV]) - (pf[b, P_POS] - pf[b, P_PREV]))
                       + n1 * ((pf[a, P_POS + 1] - pf[a, P_PREV + 1]) - (pf[b, P_POS + 1] - pf[b, P_PREV + 1]))
                       + n2 * ((pf[a, P_POS + 2] - pf[a, P_PREV + 2]) - (pf[b, P_POS + 2] - pf[b, P_PREV + 2])))
        dlambda = (-c - alpha * ef[e, E_LAMBDA] - gamma * closing) / denominator
        ef[e, E_LAMBDA] += dlambda
        ef[e, E_FORCE] -= share * dlambda / (h * h)
        if on_a:
            move_end(pf, pi, bf, bi, bx, a, back, wa, dlambda, (n0, n1, n2), h)
        else:
            pf[a, P_POS] += wa * dlambda * n0
            pf[a, P_POS + 1] += wa * dlambda * n1
            pf[a, P_POS + 2] += wa * dlambda * n2
        if on_b:
            move_end(pf, pi, bf, bi, bx, b, back, wb, dlambda, (-n0, -n1, -n2), h)
        else:
            pf[b, P_POS] -= wb * dlambda * n0
            pf[b, P_POS + 1] -= wb * dlambda * n1
            pf[b, P_POS + 2] -= wb * dlambda * n2


@njit
def clear_edge_forces(ef, ei, ne):
    """The forces of the step start from 0."""
    for e in range(ne):
        ef[e, E_FORCE] = 0.0


@njit
def break_edges(pf, ef, ei, ne):
    """Break the edges whose force of the step passed their breaking force, and tear those stretched past
    their tearing length; returns how many broke or tore."""
    broke = 0
    for e in range(ne):
        if (ei[e, E_FLAGS] & EB_BROKEN) != 0:
            continue
        a, b = ei[e, E_A], ei[e, E_B]
        length = math.sqrt((pf[a, P_POS] - pf[b, P_POS]) ** 2 + (pf[a, P_POS + 1] - pf[b, P_POS + 1]) ** 2
                           + (pf[a, P_POS + 2] - pf[b, P_POS + 2]) ** 2)
        if ef[e, E_FORCE] > ef[e, E_BREAKING] or length > ef[e, E_TEAR]:
            ei[e, E_FLAGS] |= EB_BROKEN
            broke += 1
    return broke
