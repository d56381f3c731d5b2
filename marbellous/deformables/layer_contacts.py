"""The contacts of cloth with cloth (a point on a triangle, an edge on an edge: triangle_contacts.py,
edge_contacts.py) solved with the whole-cloth solve's step (stretch_solve.py).

The position pass pushes a contact's three or four corners apart along its normal ``n``, split by their inverse
masses, until the contact's distance

    d = n . sum_j c_j x_j        (a point on a triangle: c = (1, -b_0, -b_1, -b_2); edges: (1 - u, u, -(1 - v), -v))

reaches its target ``d*``.  On a stiff sheet that is far from what the sheet would do: a push ``f`` on one
vertex moves it, within the sub-step, by ``Z f`` (``Z = A^-1``, ``A = M / h^2 + K`` the solve's matrix), its
neighbours with it; moved alone by ``delta``, the vertex stores about ``k delta^2 / 2`` in its springs, ``k h^2 / m``
times the kinetic energy ``m (delta / h)^2 / 2`` the push takes away (74 to 99 for a strip with 2 cm edges at
16 sub-steps of 1/60 s), and the next solve turns it into motion: a roll of cloth whose turns press on each other
blew up.  So, as for the bodies (``stretch_solve.hold_bodies``), the pushes that moved only unknowns of the solve
are taken back, and forces ``mu_i >= 0`` (N) along each contact's normal, with the backward-Euler step's answer

    dx = Z C^T mu,    (C^T mu)_j = sum_i mu_i c_ij n_i,

close each contact's distance to its target, or are zero and leave it open (a linear complementarity problem,
``stretch_solve.pushing_forces``):

    sum_k (sum_{j in i, l in k} c_ij c_kl Z_{jl}) (n_i . n_k) mu_k - (d*_i - d_i) = g_i,  mu, g >= 0,  mu . g = 0

A backward-Euler step with its contacts as constraints only loses energy.  The columns of ``Z`` are the
bodies' (``stretch_solve.columns_of``, ``MAX_HELD`` of them): the contacts pushed hardest whose corners fit in them
are solved this way, the others keep their pushes, and so do the contacts with a corner on a shape the particles
cannot move (the ground): that contact is not in the problem, and a layer pressed onto the ground by the forces
of another, then pushed back up by position, fed it (a folded strip lying on the ground slid apart and flew off).
Friction stays with the position pass.
"""
import numpy as np

from .._numba.jit import njit
from .particle_layout import L_CORNER, L_NORMAL, L_PUSH, L_TARGET, L_WEIGHT, P_INV_MASS, P_POS
from .stretch_solve import MAX_HELD, columns_of, pushing_forces


@njit
def record_push(lf, li, n_rec, corners, weights, n, push, target):
    """Append to ``lf``/``li`` (rows past their end are dropped) that the position pass pushed a contact
    (module docstring; ``corners`` its four particle rows, -1 for none, ``weights`` their ``c_j``) by the
    positional impulse ``push`` (kg m) along the unit normal ``n`` out to the distance ``target`` (m); returns the
    new count."""
    if n_rec >= lf.shape[0]:
        return n_rec
    for k in range(3):
        lf[n_rec, L_NORMAL + k] = n[k]
    for j in range(4):
        lf[n_rec, L_WEIGHT + j] = weights[j]
        li[n_rec, L_CORNER + j] = corners[j]
    lf[n_rec, L_PUSH] = push
    lf[n_rec, L_TARGET] = target
    return n_rec + 1


@njit
def _held(pf, slot, lf, li, n_rec, ground):
    """``(rows, corners)``: the records of the contacts to solve with the sheet (module docstring; one per contact:
    the first pass's) and the distinct unknowns of their corners.  A contact is solved when all its moving corners
    are unknowns of the solve and none is held by the ground (``ground``: touches a shape the particles cannot
    move); the hardest pushed first while their corners fit in ``MAX_HELD`` columns."""
    rows = np.empty(n_rec, np.int64)
    corners = np.empty(MAX_HELD, np.int64)
    n_rows = n_corners = 0
    for r in np.argsort(-lf[:n_rec, L_PUSH]):
        ok = True
        extra = 0
        for j in range(4):
            q = li[r, L_CORNER + j]
            if q >= 0 and pf[q, P_INV_MASS] > 0.0:
                if slot[q] < 0 or ground[q, 3] > 0.0:
                    ok = False
                elif not _listed(corners, n_corners, slot[q]):
                    extra += 1
        if not ok or n_corners + extra > MAX_HELD:
            continue
        for j in range(4):
            q = li[r, L_CORNER + j]
            if q >= 0 and pf[q, P_INV_MASS] > 0.0 and not _listed(corners, n_corners, slot[q]):
                corners[n_corners] = slot[q]
                n_corners += 1
        rows[n_rows] = r
        n_rows += 1
    return rows[:n_rows], corners[:n_corners]


@njit
def _listed(values, count, value):
    """Whether ``value`` is among ``values[:count]``."""
    return _index(values[:count], value) >= 0


@njit
def _index(values, value):
    """Where ``value`` is in ``values``, -1 if it is not."""
    for i in range(values.shape[0]):
        if values[i] == value:
            return i
    return -1


@njit
def hold_layers(pf, slot, rows, perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, work,
                columns, column_of, column_unknown, column_used, lf, li, n_rec, ground):
    """Solve the sub-step's recorded cloth-on-cloth pushes (``lf``/``li``, ``n_rec`` of them, pushed with no
    particle held by the ground) with the whole-cloth solve's step (module docstring; ``work`` (u, 3) scratch),
    after the shapes' contact pass (``ground``: what it found holding each particle,
    ``particle_contacts.ground_normals``)."""
    if n_rec == 0:
        return
    held, corners = _held(pf, slot, lf, li, n_rec, ground)
    m = held.shape[0]
    if m == 0:
        return
    columns_of(perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, work, columns, column_of,
               column_unknown, column_used, corners)
    # take the pushes back: each moving corner by its share w_j c_j push of the contact's total push
    for i in range(m):
        r = held[i]
        for j in range(4):
            q = li[r, L_CORNER + j]
            if q >= 0:
                share = pf[q, P_INV_MASS] * lf[r, L_WEIGHT + j] * lf[r, L_PUSH]
                for k in range(3):
                    pf[q, P_POS + k] -= share * lf[r, L_NORMAL + k]
    # the contacts' system and how far each is from its target
    system = np.zeros((m, m))
    delta = np.empty(m)
    for i in range(m):
        r = held[i]
        d = 0.0
        for j in range(4):
            q = li[r, L_CORNER + j]
            if q >= 0:
                for k in range(3):
                    d += lf[r, L_WEIGHT + j] * pf[q, P_POS + k] * lf[r, L_NORMAL + k]
        delta[i] = lf[r, L_TARGET] - d
        for i2 in range(m):
            r2 = held[i2]
            alike = lf[r, L_NORMAL] * lf[r2, L_NORMAL] + lf[r, L_NORMAL + 1] * lf[r2, L_NORMAL + 1] \
                + lf[r, L_NORMAL + 2] * lf[r2, L_NORMAL + 2]
            total = 0.0
            for j in range(4):
                q = li[r, L_CORNER + j]
                if q < 0 or pf[q, P_INV_MASS] == 0.0:
                    continue
                for j2 in range(4):
                    q2 = li[r2, L_CORNER + j2]
                    if q2 < 0 or pf[q2, P_INV_MASS] == 0.0:
                        continue
                    total += lf[r, L_WEIGHT + j] * lf[r2, L_WEIGHT + j2] * columns[slot[q], column_of[slot[q2]]]
            system[i, i2] = total * alike
    # two contacts can push alike (a point over the edge two flat triangles share: its contacts with both have
    # the same corners, weights and normal), which makes the system singular: a compliance of a millionth of
    # the mean point's keeps it definite, changing the forces by about as much
    soft = 0.0
    for i in range(m):
        soft += system[i, i]
    for i in range(m):
        system[i, i] += 1e-6 * soft / m
    mu = pushing_forces(system, delta)
    # every unknown by Z C^T mu: the force on each held corner (C^T mu), then its column times it
    force = np.zeros((corners.shape[0], 3))
    for i in range(m):
        r = held[i]
        for j in range(4):
            q = li[r, L_CORNER + j]
            if q < 0 or pf[q, P_INV_MASS] == 0.0:
                continue
            a = _index(corners, slot[q])
            for k in range(3):
                force[a, k] += mu[i] * lf[r, L_WEIGHT + j] * lf[r, L_NORMAL + k]
    for a in range(corners.shape[0]):
        c = column_of[corners[a]]
        for s in range(rows.shape[0]):
            for k in range(3):
                pf[rows[s], P_POS + k] += columns[s, c] * force[a, k]
