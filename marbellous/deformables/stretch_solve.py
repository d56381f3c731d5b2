"""The cloths' stretch and bending solved over the whole sheet at once: one backward-Euler step of its springs
and flat hinges per sub-step, by local-global passes (projective dynamics: Liu, Bargteil, O'Brien and Kavan 2013;
Bouaziz, Martin, Liu, Kavan and Pauly 2014), ``World.cloth_stretch_passes`` passes.

A cloth edge ``e`` between vertices ``a`` and ``b`` stores the energy of a Hooke spring of stiffness ``k_e``
(N/m) and rest length ``L_e``, which is the least, over the vectors ``p`` of length ``L_e``, of a spring of
zero rest length stretched from ``p``:

    E_e(x) = k_e/2 (|x_a - x_b| - L_e)^2 = min_{|p| = L_e} k_e/2 |S_e x - p|^2,    S_e x = x_a - x_b

A hinge that is flat at rest (two triangles ``x0 x1 x2`` and ``x1 x0 x3``) stores ``|K x|^2 / 2``, ``K x = sum_i
K_i x_i`` with its cotangent weights ``K`` (the quadratic bending model of Bergou, Wardetzky, Harmon, Zorin and
Grinspun 2006: zero however a flat hinge is moved, and ``kappa theta^2 / 2`` for a small fold ``theta`` once
``K`` is scaled to the hinge's stiffness ``kappa``, bend_constraints.py).  A sub-step of ``h`` starts from the
positions ``y`` the integrator predicts (``x + h v``, gravity and forces in ``v``); backward Euler's positions
are the least of

    f(x) = 1/(2 h^2) (x - y)^T M (x - y) + sum_e k_e/2 |S_e x - p_e|^2 + sum_hinges |K x|^2 / 2

taken alternately over the ``p_e`` (local: ``p_e = L_e (x_a - x_b) / |x_a - x_b|``, each edge on its own) and
over ``x`` (global: a linear system, the same for the three coordinates)

    (M / h^2 + sum_e k_e S_e^T S_e + sum_hinges K K^T) x = M y / h^2 + sum_e k_e S_e^T p_e

whose matrix does not change while the cloth does not (its edges, hinges, masses, pins and ``h``): it is
factored once (``StretchSystem``: SuperLU with a minimum-degree ordering, from scipy), and each pass costs two
sparse triangular solves.  Each pass lowers ``f`` from wherever it starts, so no stiffness makes the step blow
up; the first local step starts from ``y - h^2 (g + F / m)`` (the positions without this sub-step's gravity and
forces), so that a sheet at rest under a load rests at its springs' equilibrium (from ``y`` a pass turns the
loaded vertex's springs by ``h^2 F / m``).  Vertices pinned to the world are not unknowns: their terms move to
the right-hand side.  The global solve hands a load across the whole sheet in one pass, where a Gauss-Seidel
pass over the edges (``edge_constraints.py``) hands it on one edge per pass: a fine, stiff sheet (``k_e h^2 /
m`` about 1700 for a 128 x 128 sheet of 0.5 kg at 16 sub-steps of 1/960 s) stretches and shakes under the local
pass and not under the global one.  A cloth pinned to a body, the hinges bent at rest, and the networks' edges
stay on the local passes (they move the body too: two-way coupling); the hinges run before the global solve,
which takes their moves as part of ``y`` (after it, they fed a growing ripple into a 128 x 128 sheet).  Each pass
leaves the edge's tension ``T = k_e (|x_a - x_b| - L_e)`` (N, > 0 pulling the ends together); its mean over the
sub-steps is the edge's force of the step, as for the local pass.
"""
import math

import numpy as np

from .._numba.jit import njit, njit_inline
from .body_motion import body_pose, inverse_mass_along, push_body, pushable
from .particle_contacts import held_by_ground
from .particle_layout import (BN_ANGLE, BN_COMPLIANCE, E_A, E_B, E_COMPLIANCE, E_FLAGS, E_FORCE, E_KIND, E_REST,
                              EB_BROKEN, EK_SPRING, K_DEPTH, K_KIND, K_NORMAL, K_OTHER, K_PARTICLE, K_POINT, KK_BODY,
                              P_CLOTH, P_FLAGS, P_FORCE, P_INV_MASS, P_MASS, P_PIN_BODY, P_POS, P_REST, PP_PINNED)


class StretchSystem:
    """The factored global system of the cloths' stretch for sub-steps of ``h`` s (module docstring), over the
    particles and edges as they are; ``arrays`` are the kernel's arguments (:func:`solve_stretch`):

    - ``solved`` (ne,): whether each edge is solved here (the local pass leaves it), ``edges`` (m,): those
      edges' rows; ``slot`` (n,): each particle's unknown, -1 if none;
    - ``rows`` (u,): each unknown's particle row; ``mass_h2`` (u,): ``m / h^2`` (kg/s^2);
    - ``perm_r``, ``perm_c`` (u,): the factor's row and column orders, ``A = Pr^T L U Pc^T``;
    - ``l_start``, ``l_row``, ``l_value``: the strictly lower part of ``L`` by columns (its diagonal is 1);
    - ``u_start``, ``u_row``, ``u_value``, ``u_diagonal``: the strictly upper part of ``U`` by columns and its
      diagonal;
    - ``y``, ``b``, ``x`` (u, 3): scratch (the predicted positions, the right-hand side, the solve's work);
    - ``columns`` (u, MAX_HELD): columns of ``A^-1`` kept for :func:`hold_bodies` and
      ``layer_contacts.hold_layers``, ``column_of`` (u,): each unknown's column there, -1 if none,
      ``column_unknown`` (MAX_HELD,): each column's unknown, -1 if none,
      ``column_used`` (MAX_HELD + 1,): when each column was last used, and the clock.
    """

    __slots__ = ("arrays",)

    def __init__(self, pf, pi, n, ef, ei, ne, bend_f, bend_i, h, whole=True):
        """The system of the particles ``0 .. n - 1``, edges ``0 .. ne - 1`` and hinges ``bend_f`` / ``bend_i``;
        ``whole`` False: of no edge and no hinge (the local passes solve them all)."""
        from scipy.sparse import coo_matrix, tril, triu  # (imported here: only worlds with cloth need them)
        from scipy.sparse.linalg import splu
        a, b = ei[:ne, E_A], ei[:ne, E_B]
        on_body = ((pi[:n, P_FLAGS] & PP_PINNED) != 0) & (pi[:n, P_PIN_BODY] >= 0)
        held = np.unique(pi[:n, P_CLOTH][on_body & (pi[:n, P_CLOTH] >= 0)])
        ours = (pi[:n, P_CLOTH] >= 0) & ~np.isin(pi[:n, P_CLOTH], held) & whole
        edges = np.flatnonzero(ours[a] & ours[b] & (ei[:ne, E_KIND] == EK_SPRING)
                               & ((ei[:ne, E_FLAGS] & EB_BROKEN) == 0) & (ef[:ne, E_COMPLIANCE] > 0.0))
        solved = np.zeros(ne, dtype=np.bool_)
        solved[edges] = True
        a, b = a[edges], b[edges]
        free = pf[:n, P_INV_MASS] > 0.0
        rows = np.unique(np.concatenate([a[free[a]], b[free[b]]]))
        slot = np.full(n, -1, dtype=np.int64)
        slot[rows] = np.arange(rows.size)
        u = rows.size
        mass_h2 = pf[rows, P_MASS] / (h * h)
        k = 1.0 / ef[edges, E_COMPLIANCE]
        flat, hinges, weights = _flat_hinges(pf, bend_f, bend_i, ours)
        # A = M / h^2 + sum_e k_e S_e^T S_e + sum_hinges K K^T over the unknowns
        i, j, v = [np.arange(u)], [np.arange(u)], [mass_h2]
        for ends, sign in (((a, a), 1.0), ((b, b), 1.0), ((a, b), -1.0), ((b, a), -1.0)):
            _add_terms(i, j, v, slot[ends[0]], slot[ends[1]], sign * k)
        for r in range(4):
            for c in range(4):
                _add_terms(i, j, v, slot[hinges[:, r]], slot[hinges[:, c]], weights[:, r] * weights[:, c])
        matrix = coo_matrix((np.concatenate(v), (np.concatenate(i), np.concatenate(j))), shape=(u, u)).tocsc()
        factors = _factored(matrix, splu, tril, triu) if u else _EMPTY
        self.arrays = (solved, edges.astype(np.int64), flat, hinges, weights, slot, rows.astype(np.int64),
                       mass_h2) + factors + (np.zeros((u, 3)), np.zeros((u, 3)), np.zeros((u, 3))) \
            + (np.zeros((u, MAX_HELD)), np.full(u, -1, np.int64), np.full(MAX_HELD, -1, np.int64),
               np.zeros(MAX_HELD + 1, np.int64))


def _add_terms(i, j, v, si, sj, values):
    """Append the matrix terms ``values`` at ``(si, sj)`` where both are unknowns (>= 0)."""
    both = (si >= 0) & (sj >= 0)
    i.append(si[both])
    j.append(sj[both])
    v.append(values[both])


#: the fold (rad) at which a hinge's weights are scaled to its stiffness (small: the bending model's limit)
_FOLD = 1e-4


def _flat_hinges(pf, bend_f, bend_i, ours):
    """``(flat, hinges, weights)``: whether each hinge is solved globally (flat at rest, its four corners
    unknowns or fixed in a cloth of ours), their rows ``(H, 4)``, and their weights ``(H, 4)`` (module
    docstring): the quadratic bending model's cotangent weights, scaled so that a small fold ``theta`` of the rest
    hinge stores ``kappa theta^2 / 2``."""
    angle, compliance = bend_f[:, BN_ANGLE], bend_f[:, BN_COMPLIANCE]
    flat = np.all(ours[bend_i], axis=1) & (np.abs(angle) < 1e-9) if bend_i.size else np.zeros(0, np.bool_)
    hinges = bend_i[flat].astype(np.int64)
    x = pf[hinges][:, :, P_REST:P_REST + 3]
    weights = _cotangent_weights(x)
    # fold the second far corner about the hinge's edge by _FOLD (Rodrigues) and scale: c |K x|^2 = kappa theta^2
    axis = x[:, 1] - x[:, 0]
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    arm = x[:, 3] - x[:, 0]
    folded = x.copy()
    folded[:, 3] = x[:, 0] + arm * np.cos(_FOLD) + np.cross(axis, arm) * np.sin(_FOLD) \
        + axis * np.sum(axis * arm, axis=1)[:, None] * (1.0 - np.cos(_FOLD))
    curvature = np.einsum("hi,hik->hk", weights, folded)
    stiffness = 1.0 / compliance[flat]
    scale = np.sqrt(stiffness * _FOLD ** 2 / np.maximum(np.sum(curvature ** 2, axis=1), 1e-300))
    return flat, hinges, weights * scale[:, None]


def _cotangent_weights(x):
    """The cotangent weights ``(H, 4)`` of the hinges with corners ``x`` ``(H, 4, 3)`` (edge ``x0 x1``, far
    corners ``x2``, ``x3``): ``K = (c03 + c04, c01 + c02, -c01 - c03, -c02 - c04)``, ``c0j`` the cotangent of the
    angle at ``x0`` or ``x1`` between the edge and the side to ``xj`` (Bergou, Wardetzky, Harmon, Zorin and
    Grinspun 2006); ``K x = 0`` for a flat hinge however it is moved, turned or stretched in its plane."""
    def cot(p, q):
        return np.sum(p * q, axis=1) / np.maximum(np.linalg.norm(np.cross(p, q), axis=1), 1e-300)
    e0, e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    e3, e4 = x[:, 2] - x[:, 1], x[:, 3] - x[:, 1]
    c01, c02, c03, c04 = cot(e0, e1), cot(e0, e2), cot(-e0, e3), cot(-e0, e4)
    return np.stack([c03 + c04, c01 + c02, -c01 - c03, -c02 - c04], axis=1)


#: the factor of a system with no unknowns
_EMPTY = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros(0),
          np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros(0))


def _factored(matrix, splu, tril, triu):
    """``(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal)`` of the symmetric positive
    definite ``matrix`` (``StretchSystem``): SuperLU with a minimum-degree ordering of ``A + A^T`` and no pivoting
    off the diagonal, which for such a matrix is a Cholesky factor's sparsity."""
    lu = splu(matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    lower = tril(lu.L, k=-1, format="csc")
    upper = triu(lu.U, k=1, format="csc")
    return (lu.perm_r.astype(np.int64), lu.perm_c.astype(np.int64), lower.indptr.astype(np.int64),
            lower.indices.astype(np.int64), lower.data.copy(), upper.indptr.astype(np.int64),
            upper.indices.astype(np.int64), upper.data.copy(), lu.U.diagonal().copy())


@njit
def _solve_factored(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, b, x):
    """``x`` (u, 3) with ``A x = b`` for the factored ``A = Pr^T L U Pc^T``: ``z = Pr b``, ``L w = z`` forward by
    columns, ``U v = w`` back by columns, ``x = Pc v``; ``b`` is overwritten with ``v``."""
    u = b.shape[0]
    for i in range(u):
        for k in range(3):
            x[perm_r[i], k] = b[i, k]
    for j in range(u):
        for s in range(l_start[j], l_start[j + 1]):
            r, value = l_row[s], l_value[s]
            for k in range(3):
                x[r, k] -= value * x[j, k]
    for j in range(u - 1, -1, -1):
        for k in range(3):
            x[j, k] /= u_diagonal[j]
        for s in range(u_start[j], u_start[j + 1]):
            r, value = u_row[s], u_value[s]
            for k in range(3):
                x[r, k] -= value * x[j, k]
    for i in range(u):
        for k in range(3):
            b[i, k] = x[perm_c[i], k]


@njit_inline
def _separation(pf, pa, pb):
    """``(x_a - x_b, |x_a - x_b|)`` of particle rows ``pa`` and ``pb`` (m): the vector's three components, then
    its length."""
    d0 = pf[pa, P_POS] - pf[pb, P_POS]
    d1 = pf[pa, P_POS + 1] - pf[pb, P_POS + 1]
    d2 = pf[pa, P_POS + 2] - pf[pb, P_POS + 2]
    return d0, d1, d2, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit
def solve_stretch(pf, ef, ei, solved, edges, flat, hinges, weights, slot, rows, mass_h2, perm_r, perm_c, l_start,
                  l_row, l_value, u_start, u_row, u_value, u_diagonal, y, b, x, passes, h, gravity, share):
    """``passes`` local-global passes of the sub-step over the edges ``edges`` (module docstring), from the
    positions in ``pf`` (the integrator's prediction), which they are replaced by; each edge's force gets ``share``
    (1 / sub-steps) of its tension after them (``solved`` and ``flat`` are for the local passes,
    ``edge_constraints.py`` and ``bend_constraints.py``)."""
    u = rows.shape[0]
    # the first local step from y - h^2 (g + F / m), the positions without this sub-step's gravity and forces:
    # from y, the first pass would turn the springs by the load's h^2 F / m (13 mm for a 2 kg load on a 1.6 g
    # vertex at 1/960 s), and a sheet at rest would rest where that turn balances the load, not at equilibrium
    # (any first guess keeps each pass lowering the objective)
    for i in range(u):
        p = rows[i]
        for k in range(3):
            y[i, k] = pf[p, P_POS + k]
            pf[p, P_POS + k] -= h * h * (gravity[k] + pf[p, P_FORCE + k] * pf[p, P_INV_MASS])
    for _ in range(passes):
        # right-hand side: M y / h^2 + sum_e k_e S_e^T p_e, and an end pinned to the world as a known term
        for i in range(u):
            for k in range(3):
                b[i, k] = mass_h2[i] * y[i, k]
        for j in range(edges.shape[0]):
            e = edges[j]
            pa, pb = ei[e, E_A], ei[e, E_B]
            d0, d1, d2, length = _separation(pf, pa, pb)
            scale = ef[e, E_REST] / length if length > 1e-12 else 0.0
            k_e = 1.0 / ef[e, E_COMPLIANCE]
            p = (k_e * scale * d0, k_e * scale * d1, k_e * scale * d2)
            sa, sb = slot[pa], slot[pb]
            if sa >= 0:
                for k in range(3):
                    b[sa, k] += p[k] + (k_e * pf[pb, P_POS + k] if sb < 0 else 0.0)
            if sb >= 0:
                for k in range(3):
                    b[sb, k] += -p[k] + (k_e * pf[pa, P_POS + k] if sa < 0 else 0.0)
        # a hinge's corner fixed in the world: -K_i sum_{j fixed} K_j x_j on the others
        for t in range(hinges.shape[0]):
            k0 = k1 = k2 = 0.0
            unknowns = 0
            for c in range(4):
                q = hinges[t, c]
                if slot[q] < 0:
                    k0 += weights[t, c] * pf[q, P_POS]
                    k1 += weights[t, c] * pf[q, P_POS + 1]
                    k2 += weights[t, c] * pf[q, P_POS + 2]
                else:
                    unknowns += 1
            if unknowns < 4:
                for c in range(4):
                    s = slot[hinges[t, c]]
                    if s >= 0:
                        b[s, 0] -= weights[t, c] * k0
                        b[s, 1] -= weights[t, c] * k1
                        b[s, 2] -= weights[t, c] * k2
        _solve_factored(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, b, x)
        for i in range(u):
            for k in range(3):
                pf[rows[i], P_POS + k] = b[i, k]
    for j in range(edges.shape[0]):
        e = edges[j]
        pa, pb = ei[e, E_A], ei[e, E_B]
        length = math.sqrt((pf[pa, P_POS] - pf[pb, P_POS]) ** 2 + (pf[pa, P_POS + 1] - pf[pb, P_POS + 1]) ** 2
                           + (pf[pa, P_POS + 2] - pf[pb, P_POS + 2]) ** 2)
        ef[e, E_FORCE] += share * (length - ef[e, E_REST]) / ef[e, E_COMPLIANCE]


@njit
def hold_bodies(pf, slot, rows, perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, work,
                columns, column_of, column_unknown, column_used, kf, ki, nk, bf, bi, bx, back, h, ground):
    """The sub-step's contacts of bodies with the vertices of the whole-cloth solve, solved with it: after the
    contact pass, each vertex and body moved to where the sub-step's backward-Euler step puts them with the
    contacts as constraints (``work`` (u, 3) scratch).  The global solve's matrix ``A`` (module docstring) is the
    objective's curvature, so a force ``mu_i`` (N) along the unit normal ``n_i`` (from the body to the vertex)
    of contact ``i`` on unknown ``s_i`` moves every vertex by

        dx = Z C^T mu,    C^T mu = sum_i mu_i n_i e_{s_i},    Z = A^-1

    (the sheet answers a push as a whole, within the sub-step), and the body, pushed by ``-mu_i n_i``, by ``h^2
    w_i mu_i`` along ``-n_i`` at the point (``w_i`` its inverse mass along ``n_i`` there).  The forces close
    each contact's overlap ``d_i`` as the contact pass found it (``K_DEPTH``), or are zero and leave it open:

        sum_j (Z_{s_i s_j} n_i . n_j + h^2 w_i [i = j]) mu_j - d_i = g_i,    mu >= 0,  g >= 0,  mu . g = 0

    (a linear complementarity problem, :func:`pushing_forces`; the columns of ``Z`` are kept while their vertices
    stay held, :func:`columns_of`).  The contact pass had moved the vertex by its
    share of ``d_i`` alone and the body by the rest (``particle_contacts.separate``): the vertex goes back, every
    vertex moves by ``dx``, and the body gets what it lacks of ``mu_i h^2``.  Taken at the one vertex the contact
    pass moved while its neighbours stayed, a stiff sheet's pull on a body is many times its force (before this,
    ``(m (x - y) / h^2 - F) . n`` there: a 2 kg box resting on a 21 x 21 sheet pinned all round floated 6 cm
    above its rest and shook it at 0.5 m/s; now within 1 % of the sheet's and box's equilibrium).  Only contacts
    with bodies the particles can move are solved here (the static ones need no force), but those that pushed a
    vertex the ground holds (``ground``, ``particle_contacts.ground_normals``: the body took those pushes whole),
    the ``MAX_HELD`` deepest of them."""
    held = _held_contacts(pf, slot, kf, ki, nk, bf, bi, ground)
    m = held.shape[0]
    if m == 0:
        return
    u = work.shape[0]
    unknowns = np.empty(m, np.int64)
    for i in range(m):
        unknowns[i] = slot[ki[held[i], K_PARTICLE]]
    z = columns_of(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, work, columns,
                   column_of, column_unknown, column_used, unknowns)
    normal = np.empty((m, 3))
    given = np.empty(m)             # dlambda_i, the positional impulse (kg m) the contact pass gave the body
    system = np.empty((m, m))
    delta = np.empty(m)
    for i in range(m):
        for k in range(3):
            normal[i, k] = kf[held[i], K_NORMAL + k]
    for i in range(m):
        c = held[i]
        p, b = ki[c, K_PARTICLE], ki[c, K_OTHER]
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        point = (kf[c, K_POINT], kf[c, K_POINT + 1], kf[c, K_POINT + 2])
        w_b = inverse_mass_along(bf, bi, b, x_b, q_b, point, (normal[i, 0], normal[i, 1], normal[i, 2]))
        given[i] = kf[c, K_DEPTH] / (pf[p, P_INV_MASS] + w_b)
        delta[i] = kf[c, K_DEPTH]
        for j in range(m):
            alike = normal[i, 0] * normal[j, 0] + normal[i, 1] * normal[j, 1] + normal[i, 2] * normal[j, 2]
            system[i, j] = columns[slot[ki[held[j], K_PARTICLE]], z[i]] * alike
        system[i, i] += h * h * w_b
    mu = pushing_forces(system, delta)
    # each held vertex back to where it was before the contact pass, then every vertex by Z C^T mu
    for i in range(m):
        p = ki[held[i], K_PARTICLE]
        for k in range(3):
            pf[p, P_POS + k] -= pf[p, P_INV_MASS] * given[i] * normal[i, k]
    for j in range(u):
        for i in range(m):
            if mu[i] > 0.0:
                for k in range(3):
                    pf[rows[j], P_POS + k] += mu[i] * columns[j, z[i]] * normal[i, k]
    for i in range(m):
        c = held[i]
        b = ki[c, K_OTHER]
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        point = (kf[c, K_POINT], kf[c, K_POINT + 1], kf[c, K_POINT + 2])
        push = mu[i] * h * h - given[i]
        push_body(bf, bi, bx, b, x_b, q_b, point, (-push * normal[i, 0], -push * normal[i, 1], -push * normal[i, 2]),
                  h, True, 1.0)


@njit
def columns_of(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, work, columns, column_of,
               column_unknown, column_used, unknowns):
    """Which of ``columns`` holds ``Z e_s`` (``Z = A^-1``) for each unknown ``s`` of ``unknowns`` (at most
    ``MAX_HELD`` distinct), solving for those not kept (three to a solve) into the columns least recently used by
    others."""
    m = unknowns.shape[0]
    clock = column_used[-1] + 1
    column_used[-1] = clock
    z = np.empty(m, np.int64)
    missing = np.empty(m, np.int64)
    n_missing = 0
    for i in range(m):
        s = unknowns[i]
        if column_of[s] < 0:
            # a free column: never used, or the one used longest ago (not in this call: m <= MAX_HELD)
            c = np.argmin(column_used[:-1])
            if column_unknown[c] >= 0:
                column_of[column_unknown[c]] = -1
            column_unknown[c] = s
            column_of[s] = c
            missing[n_missing] = c
            n_missing += 1
        z[i] = column_of[s]
        column_used[z[i]] = clock
    rhs = np.empty((columns.shape[0], 3))
    for first in range(0, n_missing, 3):
        rhs[:] = 0.0
        for k in range(min(3, n_missing - first)):
            rhs[column_unknown[missing[first + k]], k] = 1.0
        _solve_factored(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, rhs, work)
        for k in range(min(3, n_missing - first)):
            columns[:, missing[first + k]] = rhs[:, k]
    return z


#: the most contacts of bodies with the whole-cloth solve's vertices solved with it in a sub-step (the deepest;
#: each vertex newly held costs a third of a solve of the factored system, and the forces a dense solve of their
#: number; a 2 kg box resting on a 50 x 50 sheet: 34 ms a step, 14 ms with none solved), and the most vertices of
#: its contacts with cloth solved with it (layer_contacts.py)
MAX_HELD = 96


@njit
def _held_contacts(pf, slot, kf, ki, nk, bf, bi, ground):
    """The rows of the sub-step's contacts that :func:`hold_bodies` solves: of bodies the particles can move
    with vertices of the whole-cloth solve, that removed an overlap without pushing the vertex into what holds it
    (``ground``: the body took that push whole, ``particle_contacts.separate``); the ``MAX_HELD`` deepest."""
    rows = []
    depth = []
    for c in range(min(nk, kf.shape[0])):
        p = ki[c, K_PARTICLE]
        n = (kf[c, K_NORMAL], kf[c, K_NORMAL + 1], kf[c, K_NORMAL + 2])
        if ki[c, K_KIND] == KK_BODY and slot[p] >= 0 and kf[c, K_DEPTH] > 0.0 \
                and pushable(bf, bi, ki[c, K_OTHER]) and not held_by_ground(pf, ground, p, n):
            rows.append(c)
            depth.append(kf[c, K_DEPTH])
    held = np.array(rows, dtype=np.int64) if rows else np.zeros(0, np.int64)
    if held.shape[0] > MAX_HELD:
        held = held[np.argsort(-np.array(depth))[:MAX_HELD]]
    return held


@njit
def pushing_forces(system, delta):
    """The forces ``mu`` of the linear complementarity problem ``w = system mu - delta``, ``mu >= 0``, ``w >= 0``,
    ``mu . w = 0`` (each contact pushes, and then closes its overlap exactly, or does not push and is left
    open), ``system`` symmetric positive definite: block principal pivoting (Judice and Pires 1994), every
    contact in the wrong set moved at once while that lowers their number, else the first of them alone
    (Murty's rule, which ends for such a matrix)."""
    m = delta.shape[0]
    active = delta > 0.0
    mu = np.zeros(m)
    best, tries = m + 1, 0
    for _ in range(10 * m + 10):
        index = np.flatnonzero(active)
        mu[:] = 0.0
        if index.size:
            sub = np.empty((index.size, index.size))
            for a in range(index.size):
                for c in range(index.size):
                    sub[a, c] = system[index[a], index[c]]
            solved = np.linalg.solve(sub, delta[index])
            for a in range(index.size):
                mu[index[a]] = solved[a]
        wrong = np.zeros(m, np.bool_)
        for i in range(m):
            if active[i]:
                wrong[i] = mu[i] < 0.0
            else:
                gap = -delta[i]
                for j in range(m):
                    gap += system[i, j] * mu[j]
                wrong[i] = gap < -1e-12 * max(abs(delta[i]), 1e-12)
        count = int(np.count_nonzero(wrong))
        if count == 0:
            break
        if count < best:
            best, tries = count, 0
        else:
            tries += 1
        if tries < 3:
            active ^= wrong
        else:
            first = np.flatnonzero(wrong)[0]
            active[first] = not active[first]
    for i in range(m):
        mu[i] = max(mu[i], 0.0)
    return mu
