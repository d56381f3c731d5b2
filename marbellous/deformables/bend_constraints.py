"""Cloth bending: each hinge (two triangles that share an edge) resists turning about its edge, as a compliant
constraint on the dihedral angle (XPBD), one pass per sub-step.

The hinge's edge runs from ``x0`` to ``x1``, ``e = x1 - x0``; its triangles' far corners are ``x2`` and ``x3``.
With the triangles' normals ``n1 = e x (x2 - x0) / |...|`` and ``n2 = (x3 - x0) x e / |...|`` (equal while the
hinge is flat), the dihedral angle and its gradients (Bridson et al. 2003; ``h2``, ``h3`` the far corners'
distances from the edge's line, ``t2``, ``t3`` where their feet lie along the edge, 0 at ``x0`` and 1 at ``x1``):

    theta = atan2((n1 x n2) . e / |e|, n1 . n2)
    grad_2 = -n1 / h2,    grad_3 = -n2 / h3
    grad_0 = -(1 - t2) grad_2 - (1 - t3) grad_3,    grad_1 = -t2 grad_2 - t3 grad_3

The constraint ``C = theta - theta_0`` (wrapped into (-pi, pi]) with the hinge's stiffness ``kappa`` (N m per
rad^2, energy ``kappa C^2 / 2``) moves each corner by ``w_i dlambda grad_i`` with

    dlambda = -C / (sum_i w_i |grad_i|^2 + 1 / (kappa h^2))

The stiffness of a hinge from the cloth's bending stiffness ``D`` (N m): ``kappa = D |e|^2 / A``, ``A`` the two
triangles' rest area (Grinspun et al. 2003), which gives a sheet of right triangles bent along its grid lines
the bending energy of a plate, ``D / 2`` times its curvature squared per unit area.
"""
import math

import numpy as np

from .._numba.jit import njit
from .particle_layout import BN_A, BN_ANGLE, BN_COMPLIANCE, P_INV_MASS, P_POS


@njit
def hinge_angle(x0, x1, x2, x3):
    """The signed dihedral angle (rad) of the hinge with edge ``x0 x1`` and far corners ``x2``, ``x3`` (module
    docstring; 3-tuples or arrays), 0 when flat."""
    e = (x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2])
    a = (x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2])
    b = (x3[0] - x0[0], x3[1] - x0[1], x3[2] - x0[2])
    c1 = (e[1] * a[2] - e[2] * a[1], e[2] * a[0] - e[0] * a[2], e[0] * a[1] - e[1] * a[0])
    c2 = (b[1] * e[2] - b[2] * e[1], b[2] * e[0] - b[0] * e[2], b[0] * e[1] - b[1] * e[0])
    cross = (c1[1] * c2[2] - c1[2] * c2[1], c1[2] * c2[0] - c1[0] * c2[2], c1[0] * c2[1] - c1[1] * c2[0])
    length = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    if length < 1e-15:
        return 0.0
    sine = (cross[0] * e[0] + cross[1] * e[1] + cross[2] * e[2]) / length
    cosine = c1[0] * c2[0] + c1[1] * c2[1] + c1[2] * c2[2]
    return math.atan2(sine, cosine)


@njit
def solve_bends(pf, bend_f, bend_i, n_bends, solved, h):
    """One pass over the hinges ``0 .. n_bends - 1`` but those the global solve takes (``solved``,
    stretch_solve.py) (module docstring) in a sub-step of ``h`` s."""
    g = np.zeros((4, 3))
    for k in range(n_bends):
        if solved[k]:
            continue
        r0, r1, r2, r3 = bend_i[k, BN_A], bend_i[k, BN_A + 1], bend_i[k, BN_A + 2], bend_i[k, BN_A + 3]
        e0, e1, e2 = pf[r1, P_POS] - pf[r0, P_POS], pf[r1, P_POS + 1] - pf[r0, P_POS + 1], \
            pf[r1, P_POS + 2] - pf[r0, P_POS + 2]
        a0, a1, a2 = pf[r2, P_POS] - pf[r0, P_POS], pf[r2, P_POS + 1] - pf[r0, P_POS + 1], \
            pf[r2, P_POS + 2] - pf[r0, P_POS + 2]
        b0, b1, b2 = pf[r3, P_POS] - pf[r0, P_POS], pf[r3, P_POS + 1] - pf[r0, P_POS + 1], \
            pf[r3, P_POS + 2] - pf[r0, P_POS + 2]
        length2 = e0 * e0 + e1 * e1 + e2 * e2
        c10, c11, c12 = e1 * a2 - e2 * a1, e2 * a0 - e0 * a2, e0 * a1 - e1 * a0
        c20, c21, c22 = b1 * e2 - b2 * e1, b2 * e0 - b0 * e2, b0 * e1 - b1 * e0
        area1 = math.sqrt(c10 * c10 + c11 * c11 + c12 * c12)      # |e| h2
        area2 = math.sqrt(c20 * c20 + c21 * c21 + c22 * c22)      # |e| h3
        if length2 < 1e-24 or area1 < 1e-24 or area2 < 1e-24:
            continue
        length = math.sqrt(length2)
        x0 = (pf[r0, P_POS], pf[r0, P_POS + 1], pf[r0, P_POS + 2])
        theta = hinge_angle(x0, (pf[r1, P_POS], pf[r1, P_POS + 1], pf[r1, P_POS + 2]),
                            (pf[r2, P_POS], pf[r2, P_POS + 1], pf[r2, P_POS + 2]),
                            (pf[r3, P_POS], pf[r3, P_POS + 1], pf[r3, P_POS + 2]))
        c = theta - bend_f[k, BN_ANGLE]
        if c > math.pi:
            c -= 2.0 * math.pi
        elif c <= -math.pi:
            c += 2.0 * math.pi
        # grad_2 = -n1 / h2 = -c1 |e| / area1^2;  grad_3 = -n2 / h3 = -c2 |e| / area2^2
        s1 = -length / (area1 * area1)
        s2 = -length / (area2 * area2)
        t2 = (a0 * e0 + a1 * e1 + a2 * e2) / length2
        t3 = (b0 * e0 + b1 * e1 + b2 * e2) / length2
        for j in range(3):
            g2 = s1 * (c10, c11, c12)[j]
            g3 = s2 * (c20, c21, c22)[j]
            g[2, j] = g2
            g[3, j] = g3
            g[0, j] = -(1.0 - t2) * g2 - (1.0 - t3) * g3
            g[1, j] = -t2 * g2 - t3 * g3
        rows = (r0, r1, r2, r3)
        denominator = bend_f[k, BN_COMPLIANCE] / (h * h)
        for i in range(4):
            denominator += pf[rows[i], P_INV_MASS] * (g[i, 0] ** 2 + g[i, 1] ** 2 + g[i, 2] ** 2)
        if denominator <= 0.0:
            continue
        dlambda = -c / denominator
        for i in range(4):
            w = pf[rows[i], P_INV_MASS] * dlambda
            for j in range(3):
                pf[rows[i], P_POS + j] += w * g[i, j]
