"""Joint trees solved exactly (``dynamics/joint_tree.py``): the forest the build finds, the linear-time solve
against a dense solve of ``K = J M^-1 J^T``, and the long chains it holds together.

The solve is a block ``L D L^T`` factorization without pivoting of a positive definite ``K`` (with dependent
rows dropped), so its answer meets ``K lambda = r`` to rounding: a residual within a few hundred ulps of
``||K|| ||lambda||`` (the sizes here are at most 40 rows).
"""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.dynamics import joint_tree as jt
from marbellous.dynamics.joint_rows import (ANGULAR, EQUAL, JOINT_ROWS, LINEAR, OFF, R_KA, R_KB, R_KIND, R_LA, R_LB,
                                            ROW_COLS)
from marbellous.state import layout as L

DT = 1.0 / 60.0


def _bodies(rng, nb, still):
    """Solver bodies: random masses and inertia tensors, the ``still`` ones unable to move."""
    sb = np.zeros((nb + 2, L.SB_COLS))
    for i in range(nb):
        if i in still:
            continue
        sb[i, L.SB_INV_MASS] = rng.uniform(0.1, 5.0)
        a = rng.normal(size=(3, 3))
        sb[i, L.SB_INV_I:L.SB_INV_I + 9] = np.linalg.inv(a @ a.T + 0.2 * np.eye(3)).ravel()
        sb[i, L.SB_ISO] = -1.0
    return sb


def _joints(rng, links):
    """A joint per ``(a, b)`` in ``links`` (b = -1: the world) with random equality rows: 2 or 3 point or across
    rows and 0, 2 or 3 orientation rows, as the joint kinds have."""
    nk = len(links)
    ki = np.zeros((nk, L.KI_COLS), dtype=np.int64)
    cache = np.zeros((nk, JOINT_ROWS, ROW_COLS))
    for c, (a, b) in enumerate(links):
        ki[c] = (L.KT_BALL, a, b, L.KF_ALIVE)
        cache[c, :, R_KIND] = OFF
        rows = list(range(LINEAR, LINEAR + rng.choice([2, 3]))) + list(range(ANGULAR, ANGULAR + rng.choice([0, 2, 3])))
        for r in rows:
            cache[c, r, R_KIND] = EQUAL
            cache[c, r, :12] = rng.normal(size=12)
    return ki, cache


def _build(ki, sb, nb):
    nk = ki.shape[0]
    order = np.zeros(nk, dtype=np.int64)
    tree_i = np.zeros((nk, jt.TREE_INT_COLS), dtype=np.int64)
    n, alone = jt.build_joint_trees(ki, nk, sb, nb, order, tree_i, np.zeros(nb + 1, dtype=np.int64),
                                    np.zeros(2 * nk, dtype=np.int64),
                                    np.zeros((nb, jt.TREE_SCRATCH_COLS), dtype=np.int64))
    return order[:n], tree_i, alone


def _still(sb, i):
    return i < 0 or sb[i, L.SB_ISO] == 0.0


def _sets(links, sb, nb):
    """Each body's group (bodies joined through movable bodies), whether the group has a loop (more joints than
    movable bodies minus one plus one hold on the world), by counting: a slow reference for the build."""
    group = list(range(nb))

    def root(i):
        while group[i] != i:
            i = group[i]
        return i
    for a, b in links:
        if not _still(sb, a) and not _still(sb, b):
            group[root(a)] = root(b)
    joints, bodies, holds = {}, {}, {}
    for i in range(nb):
        if not _still(sb, i):
            bodies[root(i)] = bodies.get(root(i), 0) + 1
    for a, b in links:
        if _still(sb, a) and _still(sb, b):
            continue
        r = root(b if _still(sb, a) else a)
        joints[r] = joints.get(r, 0) + 1
        if _still(sb, a) or _still(sb, b):
            holds[r] = holds.get(r, 0) + 1
    looped = {r for r in joints if joints[r] > bodies[r] - 1 + min(holds.get(r, 0), 1) or holds.get(r, 0) > 1}
    return root, looped


def _random_links(rng, nb, extra):
    """A random forest over ``nb`` bodies, some trees held by the world, plus ``extra`` random joints."""
    links = []
    for i in range(1, nb):
        if rng.random() < 0.8:
            links.append((i, int(rng.integers(0, i))))
    for i in range(nb):
        if rng.random() < 0.15:
            links.append((i, -1))
    for _ in range(extra):
        a, b = int(rng.integers(0, nb)), int(rng.integers(-1, nb))
        if a != b:
            links.append((a, b))
    rng.shuffle(links)
    return links


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), nb=st.integers(1, 12), extra=st.integers(0, 2))
def test_the_trees_are_the_joint_groups_without_loops_children_first(seed, nb, extra):
    """Every joint of a group without a loop is in the trees and none of a group with one (a counting reference);
    each tree joint joins its child to its parent or the world, every body is some joint's child at most once,
    a group holds the world once at most, and a joint comes after every joint below its child."""
    rng = np.random.default_rng(seed)
    sb = _bodies(rng, nb, set(rng.choice(nb, size=int(rng.integers(0, 3)), replace=True).tolist()))
    links = _random_links(rng, nb, extra)
    if not links:
        return
    ki, _ = _joints(rng, links)
    order, tree_i, _ = _build(ki, sb, nb)
    root, looped = _sets(links, sb, nb)
    for c, (a, b) in enumerate(links):
        movable = [e for e in (a, b) if not _still(sb, e)]
        expected = bool(movable) and root(movable[0]) not in looped
        assert (tree_i[c, jt.T_MEMBER] != 0) == expected
    assert sorted(order.tolist()) == [c for c in range(len(links)) if tree_i[c, jt.T_MEMBER] != 0]
    children = [tree_i[c, jt.T_CHILD] for c in order]
    assert len(set(children)) == len(children)
    place = {c: t for t, c in enumerate(order)}
    for c in order:
        child, parent = tree_i[c, jt.T_CHILD], tree_i[c, jt.T_PARENT]
        a, b = links[c]
        assert {child, parent} == {a if not _still(sb, a) else -1, b if not _still(sb, b) else -1}
        assert (a == child) == (tree_i[c, jt.T_CHILD_IS_A] != 0)
        for d in order:
            if tree_i[d, jt.T_PARENT] == child:
                assert place[d] < place[c]
    holds = [root(tree_i[c, jt.T_CHILD]) for c in order if tree_i[c, jt.T_PARENT] < 0]
    assert len(holds) == len(set(holds))


def _dense(sb, nb, ki, cache, order, tree_i):
    """``J`` (tree rows x 6 nb, rows as the trees list them) and ``M^-1``."""
    m_inv = np.zeros((6 * nb, 6 * nb))
    for i in range(nb):
        m_inv[6 * i:6 * i + 3, 6 * i:6 * i + 3] = sb[i, L.SB_INV_MASS] * np.eye(3)
        m_inv[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = sb[i, L.SB_INV_I:L.SB_INV_I + 9].reshape(3, 3)
    jac, where = [], []
    for c in order:
        for q in range(tree_i[c, jt.T_N]):
            r = tree_i[c, jt.T_ROW + q]
            row = np.zeros(6 * nb)
            for e, cl, ck in ((ki[c, L.K_BODY_A], R_LA, R_KA), (ki[c, L.K_BODY_B], R_LB, R_KB)):
                if not _still(sb, e):
                    row[6 * e:6 * e + 3] = cache[c, r, cl:cl + 3]
                    row[6 * e + 3:6 * e + 6] = cache[c, r, ck:ck + 3]
            jac.append(row)
            where.append((c, q))
    return np.array(jac).reshape(-1, 6 * nb), m_inv, where


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), nb=st.integers(1, 12))
def test_the_tree_solve_meets_every_row_as_a_dense_solve_does(seed, nb):
    """On random forests (random masses, inertia tensors, Jacobians of 2 to 6 rows, holds on the world, bodies
    that cannot move): ``K lambda = r`` to rounding, and each body's ``h`` is ``J^T lambda``."""
    rng = np.random.default_rng(seed)
    sb = _bodies(rng, nb, set(rng.choice(nb, size=int(rng.integers(0, 2)), replace=True).tolist()))
    links = _random_links(rng, nb, 0)
    if not links:
        return
    ki, cache = _joints(rng, links)
    order, tree_i, _ = _build(ki, sb, nb)
    n = len(order)
    if n == 0:
        return
    tree_f = np.zeros((len(links), jt.TREE_FLOAT_COLS))
    body = np.zeros((nb, jt.TREE_BODY_COLS))
    jt.factor_joint_trees(sb, order, n, tree_i, tree_f, cache, body, np.zeros((4, 6, 6)))
    # a random joint whose rows are all but dependent (a pivot under SINGULAR of its diagonal) has that row
    # dropped, by design: K lambda = r then does not hold in its direction (the dependent-row test's case)
    assume(all(tree_f[c, jt.F_DINV + q] != 0.0 for c in order[:n] for q in range(tree_i[c, jt.T_N])))
    jac, m_inv, where = _dense(sb, nb, ki, cache, order, tree_i)
    k = jac @ m_inv @ jac.T
    r = rng.normal(size=len(where))
    x = np.zeros((len(links), 2 * jt.TREE_ROWS))
    for (c, q), value in zip(where, r):
        x[c, q] = value
    jt.tree_solution(order, n, tree_i, tree_f, cache, body, x)
    lam = np.array([x[c, q] for c, q in where])
    eps = np.finfo(float).eps
    assert np.linalg.norm(k @ lam - r) <= 500 * eps * len(r) * (np.linalg.norm(k, 2) * np.linalg.norm(lam)
                                                                 + np.linalg.norm(r))
    h = (jac.T @ lam).reshape(nb, 6)
    for c in order:
        for e in (tree_i[c, jt.T_CHILD], tree_i[c, jt.T_PARENT]):
            if e >= 0:
                np.testing.assert_allclose(body[e, jt.B_H:jt.B_H + 6], h[e], rtol=1e-9,
                                           atol=1e-9 * np.abs(h).max())


def test_a_dependent_row_gets_no_impulse_and_the_rest_are_met():
    """A joint with a repeated row (dependent rows, as a hinge turned a quarter turn off its axis has): the
    repeat's pivot is dropped, the other rows are met exactly."""
    rng = np.random.default_rng(7)
    sb = _bodies(rng, 2, set())
    ki, cache = _joints(rng, [(0, -1), (1, 0)])
    cache[1, LINEAR + 2] = cache[1, LINEAR + 1]
    order, tree_i, _ = _build(ki, sb, 2)
    tree_f = np.zeros((2, jt.TREE_FLOAT_COLS))
    body = np.zeros((2, jt.TREE_BODY_COLS))
    jt.factor_joint_trees(sb, order, 2, tree_i, tree_f, cache, body, np.zeros((4, 6, 6)))
    jac, m_inv, where = _dense(sb, 2, ki, cache, order, tree_i)
    k = jac @ m_inv @ jac.T
    r = rng.normal(size=len(where))
    r[where.index((1, 2))] = r[where.index((1, 1))]        # (a consistent right-hand side)
    x = np.zeros((2, 2 * jt.TREE_ROWS))
    for (c, q), value in zip(where, r):
        x[c, q] = value
    jt.tree_solution(order, 2, tree_i, tree_f, cache, body, x)
    assert x[1, 2] == 0.0
    lam = np.array([x[c, q] for c, q in where])
    np.testing.assert_allclose(k @ lam, r, rtol=1e-9, atol=1e-9)


def _chain(substeps, iterations, links=20):
    """One chain of ``links`` ball-jointed 0.2 kg boxes hung from the world, tilted by 0.5 rad and let go."""
    w = mb.World(sleeping=False, substeps=substeps, iterations=iterations)
    s, c = math.sin(0.5), math.cos(0.5)
    down = np.array([s, -c, 0.0])
    top = np.array([0.0, 3.0, 0.0])
    q = (math.cos(0.25), 0.0, 0.0, math.sin(0.25))
    joints, bodies, prev = [], [], None
    for k in range(links):
        b = w.add_body(mb.Box((0.02, 0.04, 0.02)), mass=0.2, position=top + down * 0.1 * (k + 0.5), orientation=q)
        joints.append(w.add_ball_joint(b, prev, anchor=top + down * 0.1 * k))
        bodies.append(b)
        prev = b
    return w, bodies, joints


def _energy(bodies):
    """Kinetic (linear and rotational) plus gravitational energy (J)."""
    return sum(0.5 * b.mass * float(b.velocity @ b.velocity) + 9.81 * b.mass * float(b.position[1])
               + 0.5 * float(b.angular_velocity @ b.inertia @ b.angular_velocity) for b in bodies)


@pytest.mark.parametrize("substeps, iterations", [(1, 10), (1, 1), (2, 1), (4, 4)])
def test_a_long_chain_holds_together_at_any_budget_and_gains_no_energy(substeps, iterations):
    """Twenty links swinging down from a tilt: every step's pushes close the tree's joints to first order, so
    what is left is the second-order error of turning a link by ``theta = omega h`` about an anchor ``r`` away,
    ``r theta^2 / 2``: under 1 mm for ``r`` = 5 cm and ``omega h`` under 0.2 rad (links under 12 rad/s at one
    sub-step).  Gauss-Seidel passes left these chains metres apart at one sub-step.  No step adds energy
    (pushes move no velocity; the velocity passes project)."""
    w, bodies, joints = _chain(substeps, iterations)
    e0 = _energy(bodies)
    for _ in range(600):
        w.step(DT)
        assert max(j.separation for j in joints) < 1e-3
        assert _energy(bodies) < e0 + 1e-6
