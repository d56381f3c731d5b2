"""Joint trees solved exactly: every equality row of a tree of joints (a chain, a ragdoll, a rope) in one
linear solve, in time linear in the joints (Baraff, "Linear-time dynamics using Lagrange multipliers", 1996).

Gauss-Seidel passes over a chain of n joints take out its errors one joint at a time, and the slowest of
them, the whole chain stretching under its own weight, shrinks by only ~1/n^2 of itself per pass: a chain
of twenty links held by its top opens a little more every step that the passes do not converge.  Solved
exactly, the impulses ``lambda`` of the tree's equality rows (``joint_rows``: a joint's point or across
rows and its orientation or hinge-axis rows, up to six) satisfy all the rows at once,

    K lambda = r,        K = J M^-1 J^T,

with ``J`` the rows' Jacobians and ``M`` the bodies' mass matrices (6 x 6: ``m E`` and the world inertia).
``K`` couples two joints only if they share a body.  Root each tree (at the joint to the world, if one
holds it, else at any body) so that every joint ``j`` joins a child body ``c`` to its parent ``p`` (or the
world), and eliminate the joints children first.  Eliminating ``j`` couples the joints still left at ``p``
through ``p``'s effective inverse mass ``W_p`` (6 x 6, ``M_p^-1`` at first), which it lowers:

    A_p = J_jp W_p,   K_j = J_jc W_c J_jc^T + A_p J_jp^T,   W_p <- W_p - A_p^T K_j^-1 A_p

(``W_c`` already has every joint below ``c`` folded in, and ``j`` is the last joint left at ``c``).  The
solve runs down the same order and back up, with a 6-vector per body, ``g`` down and ``h`` up:

    forward    z_j = K_j^-1 (r_j - J_jc g_c - J_jp g_p),   g_p += A_p^T z_j
    backward   lambda_j = z_j - K_j^-1 A_p h_p,            h_p += J_jp^T lambda_j,  h_c += J_jc^T lambda_j

and ``h_b`` is then the impulse the tree's joints give body ``b`` (``v_b += M_b^-1 h_b``).  ``K_j`` is
factored as ``L D L^T``; a row whose pivot falls below ``SINGULAR`` of its diagonal depends on the rows
before it (a hinge turned a quarter turn off its axis) and gets no impulse.

Only trees: where the joints close a loop (two paths between two bodies, or two holds on the world, as a
bridge hung at both ends), every joint of those bodies keeps its per-joint block passes.  A spanning tree
solved exactly with the loop's last joint taking turns with it converges slowly: a bridge of thirty hinged
planks hung at both ends opened 12 mm that way under a 5 kg marble; joint by joint it stays under 1 cm.
Bodies that cannot move (static, kinematic, asleep) count as the world: a joint to one holds its tree.
"""
from .._numba.jit import njit
from ..collision.adjacency import begin_fill, clear_counts, count_end, end_fill, fill_end
from ..state.layout import (K_BODY_A, K_BODY_B, K_FLAGS, K_ROW_IMPULSE, K_SUM_ANGULAR, K_SUM_LINEAR, KF_ALIVE,
                            KF_BROKEN, KF_LIMITS, KF_MOTOR, PB_V, PB_W, SB_INV_I, SB_INV_MASS, SB_ISO, SB_V, SB_W)
from .joint_rows import (ANGULAR, EQUAL, LINEAR, R_K, R_KA, R_KB, R_KIND, R_LA, R_LB, SINGULAR, closing_speed,
                         is_rigid_joint, row_rate)

#: most equality rows of a joint in a tree (three point and three orientation rows of a fixed joint)
TREE_ROWS = 6
# a joint's integer columns: in a tree (1) or not (0), its child and parent body (-1: the world), whether the
# child is the joint's body a (1) or b (0), its equality rows' count and their slots in the joint's rows
T_MEMBER, T_CHILD, T_PARENT, T_CHILD_IS_A, T_N, T_ROW = 0, 1, 2, 3, 4, 5
TREE_INT_COLS = T_ROW + TREE_ROWS
# a joint's float columns: L (unit lower triangle, by rows), 1 / D (0 for a dependent row), A_p (by rows)
F_L, F_DINV, F_A = 0, 36, 42
TREE_FLOAT_COLS = F_A + 36
# a body's float columns: W, its effective inverse mass (by rows), and the solve's g and h
B_W, B_G, B_H = 0, 36, 42
TREE_BODY_COLS = B_H + 6
# the build's scratch per body: union-find link, whether its set is held by the world, whether its set has a
# loop, the joint to its parent (-2: not reached yet, -1: a root), the breadth-first queue
S_LINK, S_HELD, S_LOOP, S_UP, S_QUEUE = 0, 1, 2, 3, 4
TREE_SCRATCH_COLS = 5


@njit
def _is_world(sb, i):
    """True if body ``i`` cannot move in this step (the world, static, kinematic or resting)."""
    return i < 0 or sb[i, SB_ISO] == 0.0


@njit
def _root(scratch, i):
    """The representative of body ``i``'s set (union-find, path halving)."""
    while scratch[i, S_LINK] != i:
        scratch[i, S_LINK] = scratch[scratch[i, S_LINK], S_LINK]
        i = scratch[i, S_LINK]
    return i


@njit
def _link(ki, c, sb, scratch):
    """Joint ``c`` into the sets of bodies: merges its bodies' sets, or marks the loop it closes; False for a
    joint between two bodies that cannot move."""
    a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
    wa, wb = _is_world(sb, a), _is_world(sb, b)
    if wa and wb:
        return False
    if wa or wb:
        r = _root(scratch, b if wa else a)
        if scratch[r, S_HELD] != 0:
            scratch[r, S_LOOP] = 1
        scratch[r, S_HELD] = 1
        return True
    ra, rb = _root(scratch, a), _root(scratch, b)
    if ra == rb:
        scratch[ra, S_LOOP] = 1
        return True
    scratch[ra, S_LINK] = rb
    if scratch[ra, S_HELD] != 0 and scratch[rb, S_HELD] != 0:
        scratch[rb, S_LOOP] = 1
    scratch[rb, S_HELD] |= scratch[ra, S_HELD]
    scratch[rb, S_LOOP] |= scratch[ra, S_LOOP]
    return True


@njit
def _moving_ends(ki, c, sb):
    """Joint ``c``'s bodies that can move, as ``(a or -1, b or -1)``."""
    a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
    return (-1 if _is_world(sb, a) else a), (-1 if _is_world(sb, b) else b)


@njit
def _grow(ki, tree_i, start, joints, scratch, head, tail):
    """Breadth-first from the queue's ``head`` to ``tail``: each joint met below a body becomes the joint to
    its parent of the body on its other end; returns the new tail."""
    while head < tail:
        u = scratch[head, S_QUEUE]
        head += 1
        for k in range(start[u], start[u + 1]):
            c = joints[k]
            if c == scratch[u, S_UP]:
                continue
            o = ki[c, K_BODY_B] if ki[c, K_BODY_A] == u else ki[c, K_BODY_A]
            scratch[o, S_UP] = c
            tree_i[c, T_CHILD] = o
            tree_i[c, T_PARENT] = u
            tree_i[c, T_CHILD_IS_A] = 1 if ki[c, K_BODY_A] == o else 0
            scratch[tail, S_QUEUE] = o
            tail += 1
    return tail


@njit
def build_joint_trees(ki, nk, sb, nb, order, tree_i, start, joints, scratch):
    """The forest of the live ball, hinge, slider and fixed joints on the solver bodies ``sb``: each member
    joint's child and parent body in ``tree_i``, and the joints children first in ``order``.  Returns their
    count, and whether they are all the live constraints and have no limit or motor rows (then one exact
    pass over the trees solves every constraint row).  Scratch: ``start`` (nb + 1 ints), ``joints`` (2 nk
    ints), ``scratch`` (nb x TREE_SCRATCH_COLS).  A world whose constraints are all springs, rods and cables
    costs one scan of the constraints."""
    rigid = False
    for c in range(nk):
        tree_i[c, T_MEMBER] = 0
        rigid = rigid or is_rigid_joint(ki, c)
    if not rigid:
        return 0, False
    for i in range(nb):
        scratch[i, S_LINK] = i
        scratch[i, S_HELD] = 0
        scratch[i, S_LOOP] = 0
        scratch[i, S_UP] = -2
    for c in range(nk):
        tree_i[c, T_MEMBER] = 1 if is_rigid_joint(ki, c) and _link(ki, c, sb, scratch) else 0
    clear_counts(start, nb)
    alone = True
    for c in range(nk):
        if tree_i[c, T_MEMBER] != 0:
            a, b = _moving_ends(ki, c, sb)
            if scratch[_root(scratch, a if a >= 0 else b), S_LOOP] != 0:
                tree_i[c, T_MEMBER] = 0
        if tree_i[c, T_MEMBER] != 0:
            for e in (a, b):
                if e >= 0:
                    count_end(start, e)
            alone = alone and (ki[c, K_FLAGS] & (KF_LIMITS | KF_MOTOR)) == 0
        elif (ki[c, K_FLAGS] & KF_ALIVE) != 0 and (ki[c, K_FLAGS] & KF_BROKEN) == 0:
            alone = False
    begin_fill(start, nb)
    for c in range(nk):
        if tree_i[c, T_MEMBER] != 0:
            a, b = _moving_ends(ki, c, sb)
            for e in (a, b):
                if e >= 0:
                    fill_end(start, joints, e, c)
    end_fill(start, nb)
    tail = 0
    for c in range(nk):        # the trees held by the world, from the body the hold holds
        if tree_i[c, T_MEMBER] != 0:
            a, b = _moving_ends(ki, c, sb)
            if a < 0 or b < 0:
                u = b if a < 0 else a
                scratch[u, S_UP] = c
                tree_i[c, T_CHILD] = u
                tree_i[c, T_PARENT] = -1
                tree_i[c, T_CHILD_IS_A] = 1 if ki[c, K_BODY_A] == u else 0
                scratch[tail, S_QUEUE] = u
                tail = _grow(ki, tree_i, start, joints, scratch, tail, tail + 1)
    for i in range(nb):        # the free trees, from any body
        if start[i + 1] > start[i] and scratch[i, S_UP] == -2:
            scratch[i, S_UP] = -1
            scratch[tail, S_QUEUE] = i
            tail = _grow(ki, tree_i, start, joints, scratch, tail, tail + 1)
    n = 0
    for q in range(tail - 1, -1, -1):
        up = scratch[scratch[q, S_QUEUE], S_UP]
        if up >= 0:
            order[n] = up
            n += 1
    return n, alone


@njit
def _side_columns(tree_i, c, child):
    """The rows' columns ``(l, k)`` of joint ``c``'s child (``child``) or parent side."""
    if (tree_i[c, T_CHILD_IS_A] != 0) == child:
        return R_LA, R_KA
    return R_LB, R_KB


@njit
def _load_inverse_mass(sb, i, body):
    """``W_i = M_i^-1`` (inverse mass on the linear diagonal, ``I_w^-1`` the angular block)."""
    for k in range(36):
        body[i, B_W + k] = 0.0
    im = sb[i, SB_INV_MASS]
    for k in range(3):
        body[i, B_W + 7 * k] = im
        for m in range(3):
            body[i, B_W + 6 * (3 + k) + 3 + m] = sb[i, SB_INV_I + 3 * k + m]


@njit
def _jacobian(rows, tree_i, c, n, col_l, col_k, out):
    """Joint ``c``'s ``n`` tree rows on one side (columns ``col_l``, ``col_k``) into ``out`` (n x 6)."""
    for i in range(n):
        r = tree_i[c, T_ROW + i]
        for k in range(3):
            out[i, k] = rows[r, col_l + k]
            out[i, 3 + k] = rows[r, col_k + k]


@njit
def _times_w(jac, n, w, out):
    """``out = jac W`` (n x 6; ``w``: W's 36 entries by rows)."""
    for r in range(n):
        for k in range(6):
            out[r, k] = 0.0
        for m in range(6):
            f = jac[r, m]
            for k in range(6):
                out[r, k] += f * w[6 * m + k]


@njit
def _add_gram(a, jac, n, kmat):
    """``K += a jac^T`` (n x n, from n x 6 ``a`` and ``jac``)."""
    for i in range(n):
        for j in range(n):
            s = 0.0
            for m in range(6):
                s += a[i, m] * jac[j, m]
            kmat[i, j] += s


@njit
def _ldl(kmat, n, lf, pivot):
    """``K_j = L D L^T`` into a joint's float columns ``lf`` (``pivot``: scratch for ``D``); a pivot under
    ``SINGULAR`` of its diagonal drops its row (``D = 1 / D = 0``, its column of ``L`` zero)."""
    for i in range(n):
        d = kmat[i, i]
        for k in range(i):
            d -= lf[F_L + 6 * i + k] ** 2 * pivot[k]
        lf[F_L + 7 * i] = 1.0
        if not (kmat[i, i] > 0.0 and d > SINGULAR * kmat[i, i]):
            pivot[i] = 0.0
            lf[F_DINV + i] = 0.0
            for j in range(i + 1, n):
                lf[F_L + 6 * j + i] = 0.0
            continue
        pivot[i] = d
        lf[F_DINV + i] = 1.0 / d
        for j in range(i + 1, n):
            s = kmat[j, i]
            for k in range(i):
                s -= lf[F_L + 6 * j + k] * lf[F_L + 6 * i + k] * pivot[k]
            lf[F_L + 6 * j + i] = s / d


@njit
def _ldl_solve(lf, n, x):
    """``x <- K_j^+ x`` from a joint's ``L D L^T`` (float columns ``lf``; a dropped row's entry 0)."""
    for i in range(n):
        for k in range(i):
            x[i] -= lf[F_L + 6 * i + k] * x[k]
    for i in range(n):
        x[i] *= lf[F_DINV + i]
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            x[i] -= lf[F_L + 6 * k + i] * x[k]


@njit
def _ldl_solve_rows(lf, n, x):
    """``x <- K_j^+ x`` for the n x 6 ``x``, its six columns at once."""
    for i in range(n):
        for k in range(i):
            f = lf[F_L + 6 * i + k]
            for m in range(6):
                x[i, m] -= f * x[k, m]
    for i in range(n):
        f = lf[F_DINV + i]
        for m in range(6):
            x[i, m] *= f
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            f = lf[F_L + 6 * k + i]
            for m in range(6):
                x[i, m] -= f * x[k, m]


@njit
def factor_joint_trees(sb, order, n_tree, tree_i, tree_f, cache, body, work):
    """Each tree joint's ``L D L^T`` of ``K_j`` and its ``A_p``, joints children first (``order``), from the
    rows in ``cache`` (``joint_rows.fill_joint_rows``) and the solver bodies ``sb``; ``body``: the bodies'
    effective inverse masses (scratch, nb x TREE_BODY_COLS); ``work``: 4 x 6 x 6 scratch."""
    for t in range(n_tree):
        c = order[t]
        _load_inverse_mass(sb, tree_i[c, T_CHILD], body)
        if tree_i[c, T_PARENT] >= 0:
            _load_inverse_mass(sb, tree_i[c, T_PARENT], body)
    jac, ap, x, kmat = work[0], work[1], work[2], work[3]
    pivot = jac[0]          # (the Jacobians are read by the time the pivots are written)
    for t in range(n_tree):
        c = order[t]
        rows, lf = cache[c], tree_f[c]
        n = 0
        for r in (LINEAR, LINEAR + 1, LINEAR + 2, ANGULAR, ANGULAR + 1, ANGULAR + 2):
            if rows[r, R_KIND] == EQUAL:
                tree_i[c, T_ROW + n] = r
                n += 1
        tree_i[c, T_N] = n
        child, parent = tree_i[c, T_CHILD], tree_i[c, T_PARENT]
        for i in range(n):
            for j in range(n):
                kmat[i, j] = 0.0
        cl, ck = _side_columns(tree_i, c, True)
        _jacobian(rows, tree_i, c, n, cl, ck, jac)
        _times_w(jac, n, body[child, B_W:B_W + 36], x)
        _add_gram(x, jac, n, kmat)
        if parent >= 0:
            pl, pk = _side_columns(tree_i, c, False)
            _jacobian(rows, tree_i, c, n, pl, pk, jac)
            _times_w(jac, n, body[parent, B_W:B_W + 36], ap)
            _add_gram(ap, jac, n, kmat)
        _ldl(kmat, n, lf, pivot)
        for i in range(n):
            for k in range(6):
                lf[F_A + 6 * i + k] = ap[i, k] if parent >= 0 else 0.0
        if parent >= 0:
            # W_p -= A_p^T K_j^-1 A_p
            for i in range(n):
                for k in range(6):
                    x[i, k] = ap[i, k]
            _ldl_solve_rows(lf, n, x)
            wp = body[parent, B_W:B_W + 36]
            for i in range(n):
                for m in range(6):
                    f = ap[i, m]
                    for k in range(6):
                        wp[6 * m + k] -= f * x[i, k]


@njit
def _clear_body(body, i):
    """Body ``i``'s ``g`` and ``h`` set to zero (none for the world)."""
    if i >= 0:
        for k in range(12):
            body[i, B_G + k] = 0.0


@njit
def _minus_jacobian_times(rows, tree_i, c, n, child, body, i, col, x):
    """``x -= J_j,side body[i, col:col + 6]`` (side: the child's if ``child``)."""
    cl, ck = _side_columns(tree_i, c, child)
    for r in range(n):
        row = tree_i[c, T_ROW + r]
        s = 0.0
        for k in range(3):
            s += rows[row, cl + k] * body[i, col + k] + rows[row, ck + k] * body[i, col + 3 + k]
        x[r] -= s


@njit
def _add_jacobian_transpose(rows, tree_i, c, n, child, body, i, lam):
    """``h_i += J_j,side^T lam``."""
    cl, ck = _side_columns(tree_i, c, child)
    for r in range(n):
        row = tree_i[c, T_ROW + r]
        for k in range(3):
            body[i, B_H + k] += rows[row, cl + k] * lam[r]
            body[i, B_H + 3 + k] += rows[row, ck + k] * lam[r]


@njit
def tree_solution(order, n_tree, tree_i, tree_f, cache, body, x):
    """``lambda = K^-1 r`` over the trees (factored by :func:`factor_joint_trees`): ``x[c, :n]`` holds joint
    ``c``'s ``r`` on entry and its ``lambda`` on return (``x``: nk x 2 TREE_ROWS, the rest scratch); each tree
    body's ``h`` (``body[:, B_H:]``) is then the impulse (N s and N m s, world frame) its tree joints give it."""
    for t in range(n_tree):
        c = order[t]
        _clear_body(body, tree_i[c, T_CHILD])
        _clear_body(body, tree_i[c, T_PARENT])
    for t in range(n_tree):
        c = order[t]
        rows, n = cache[c], tree_i[c, T_N]
        child, parent = tree_i[c, T_CHILD], tree_i[c, T_PARENT]
        xc = x[c]
        _minus_jacobian_times(rows, tree_i, c, n, True, body, child, B_G, xc)
        if parent >= 0:
            _minus_jacobian_times(rows, tree_i, c, n, False, body, parent, B_G, xc)
        _ldl_solve(tree_f[c], n, xc)
        if parent >= 0:
            for k in range(6):
                s = 0.0
                for i in range(n):
                    s += tree_f[c, F_A + 6 * i + k] * xc[i]
                body[parent, B_G + k] += s
    for t in range(n_tree - 1, -1, -1):
        c = order[t]
        rows, n = cache[c], tree_i[c, T_N]
        child, parent = tree_i[c, T_CHILD], tree_i[c, T_PARENT]
        xc = x[c]
        if parent >= 0:
            back = x[c, TREE_ROWS:]
            for i in range(n):
                s = 0.0
                for k in range(6):
                    s += tree_f[c, F_A + 6 * i + k] * body[parent, B_H + k]
                back[i] = s
            _ldl_solve(tree_f[c], n, back)
            for i in range(n):
                xc[i] -= back[i]
            _add_jacobian_transpose(rows, tree_i, c, n, False, body, parent, xc)
        _add_jacobian_transpose(rows, tree_i, c, n, True, body, child, xc)


@njit
def _kick_body(sb, u, cv, cw, i, body):
    """``v_i += M_i^-1 h_i`` in columns ``cv``, ``cw`` of ``u``; ``h_i`` cleared (so a body is kicked once)."""
    if i < 0:
        return
    im = sb[i, SB_INV_MASS]
    for k in range(3):
        u[i, cv + k] += im * body[i, B_H + k]
        u[i, cw + k] += (sb[i, SB_INV_I + 3 * k] * body[i, B_H + 3] + sb[i, SB_INV_I + 3 * k + 1] * body[i, B_H + 4]
                         + sb[i, SB_INV_I + 3 * k + 2] * body[i, B_H + 5])
    for k in range(6):
        body[i, B_H + k] = 0.0


@njit
def kick_tree_bodies(sb, u, cv, cw, order, n_tree, tree_i, body):
    """Every tree body's velocities in ``u`` (columns ``cv``, ``cw``: the solver bodies' or the pushes'
    pseudo-velocities) changed by the impulse ``h`` of :func:`tree_solution`."""
    for t in range(n_tree):
        c = order[t]
        _kick_body(sb, u, cv, cw, tree_i[c, T_CHILD], body)
        _kick_body(sb, u, cv, cw, tree_i[c, T_PARENT], body)


@njit
def solve_joint_trees(kf, ki, sb, order, n_tree, tree_i, tree_f, cache, body, x):
    """A velocity pass's share of the trees: every tree joint's equality rows brought to ``J v = 0`` on the
    solver bodies ``sb`` at once, the impulses added to the joints' (``K_ROW_IMPULSE``) and to the step's sums
    of what body a received.  Returns the largest velocity change along a row (m/s or rad/s)."""
    for t in range(n_tree):
        c = order[t]
        a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
        for i in range(tree_i[c, T_N]):
            x[c, i] = -row_rate(sb, SB_V, SB_W, a, b, cache[c], tree_i[c, T_ROW + i])
    tree_solution(order, n_tree, tree_i, tree_f, cache, body, x)
    kick_tree_bodies(sb, sb, SB_V, SB_W, order, n_tree, tree_i, body)
    largest = 0.0
    for t in range(n_tree):
        c = order[t]
        rows = cache[c]
        for i in range(tree_i[c, T_N]):
            r, lam = tree_i[c, T_ROW + i], x[c, i]
            kf[c, K_ROW_IMPULSE + r] += lam
            for k in range(3):
                kf[c, K_SUM_LINEAR + k] += rows[r, R_LA + k] * lam
                kf[c, K_SUM_ANGULAR + k] += rows[r, R_KA + k] * lam
            largest = max(largest, abs(lam) * rows[r, R_K])
    return largest


@njit
def push_joint_trees(ki, sb, pb, h, max_push, order, n_tree, tree_i, tree_f, cache, body, x):
    """A push pass's share of the trees (``joint_rows.push_rigid_joints``): every tree joint's equality rows
    given the pseudo-velocities ``pb`` that close their errors in the sub-step of ``h`` s, ``J v_p = -C / h``
    (no faster than ``max_push``), at once.  Returns the largest pseudo-velocity change (m/s or rad/s)."""
    for t in range(n_tree):
        c = order[t]
        a, b = ki[c, K_BODY_A], ki[c, K_BODY_B]
        rows = cache[c]
        for i in range(tree_i[c, T_N]):
            r = tree_i[c, T_ROW + i]
            x[c, i] = -(row_rate(pb, PB_V, PB_W, a, b, rows, r) + closing_speed(rows, r, h, max_push))
    tree_solution(order, n_tree, tree_i, tree_f, cache, body, x)
    kick_tree_bodies(sb, pb, PB_V, PB_W, order, n_tree, tree_i, body)
    largest = 0.0
    for t in range(n_tree):
        c = order[t]
        for i in range(tree_i[c, T_N]):
            largest = max(largest, abs(x[c, i]) * cache[c, tree_i[c, T_ROW + i], R_K])
    return largest
