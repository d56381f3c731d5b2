"""The LCP scheme: the bounded LCP solver against enumerated active sets, the assembled matrix against
a dense J M^-1 J^T, and World(solver="lcp") against mechanics."""
import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from mechanics import DT, HEAD_ON, G, head_on_collision

import marbellous as mb
from marbellous.dynamics.lcp import assemble_matrix
from marbellous.dynamics.lcp_solve import solve_bounded_lcp
from marbellous.scenes import box_tower


# --- the bounded LCP solver ---------------------------------------------------------------------------
def to_csr(A):
    """Dense (m, m) -> (ptr, col, val) with every entry stored."""
    m = A.shape[0]
    ptr = np.arange(0, m * m + 1, m, dtype=np.int64)
    col = np.tile(np.arange(m, dtype=np.int64), m)
    return ptr, col, A.ravel().copy()


def random_problem(seed, m):
    """A = J M^-1 J^T of m rows over m + 2 velocity coordinates (positive definite), and b."""
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(m, m + 2))
    inv_mass = rng.uniform(0.5, 2.0, m + 2)
    A = (J * inv_mass) @ J.T
    return A, rng.normal(size=m), rng


def reference_bounded_lcp(A, b, lo, hi):
    """Slow and obvious: try every assignment of each row to its lower bound, upper bound or free, solve the
    free rows' equations and keep the assignment whose solution satisfies all conditions."""
    m = len(b)
    for states in itertools.product((0, 1, 2), repeat=m):   # 0 at lo, 1 at hi, 2 free
        if any((s == 0 and not np.isfinite(lo[i])) or (s == 1 and not np.isfinite(hi[i]))
               for i, s in enumerate(states)):
            continue
        lam = np.where(np.array(states) == 0, lo, hi).astype(float)
        free = [i for i, s in enumerate(states) if s == 2]
        lam[free] = 0.0
        if free:
            fixed = [i for i in range(m) if i not in free]
            rhs = -b[free] - A[np.ix_(free, fixed)] @ lam[fixed]
            lam[free] = np.linalg.solve(A[np.ix_(free, free)], rhs)
        w = A @ lam + b
        ok = all((s == 0 and w[i] >= -1e-9) or (s == 1 and w[i] <= 1e-9)
                 or (s == 2 and lo[i] - 1e-9 <= lam[i] <= hi[i] + 1e-9) for i, s in enumerate(states))
        if ok:
            return lam
    raise AssertionError("no solution found")


def solve(A, b, lo, hi, shift=None, lam0=None):
    m = len(b)
    ptr, col, val = to_csr(A)
    shift = np.zeros(m) if shift is None else shift
    lam = np.zeros(m) if lam0 is None else lam0.copy()
    none = np.full(m, -1, dtype=np.int64)
    sweeps = solve_bounded_lcp(ptr, col, val, shift, b, lo, hi, none, np.zeros(m), none, lam, m, 200000, 1.0,
                               1e-13)
    return lam, sweeps


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), m=st.integers(1, 6))
def test_lcp_solution_is_complementary_and_matches_enumeration(seed, m):
    A, b, _ = random_problem(seed, m)
    assume(np.linalg.cond(A) < 1e3)
    lam, sweeps = solve(A, b, np.zeros(m), np.full(m, np.inf))
    assert sweeps < 200000
    w = A @ lam + b
    scale = np.abs(b).max() + 1e-300
    assert lam.min() >= 0.0
    assert w.min() >= -1e-9 * scale
    assert abs(lam @ w) <= 1e-9 * scale * (np.abs(lam).sum() + 1.0)
    np.testing.assert_allclose(lam, reference_bounded_lcp(A, b, np.zeros(m), np.full(m, np.inf)),
                               atol=1e-8 * scale * np.linalg.cond(A))


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), m=st.integers(1, 5), warm=st.booleans())
def test_mixed_lcp_with_bounds_and_shift_matches_enumeration(seed, m, warm):
    A, b, rng = random_problem(seed, m)
    assume(np.linalg.cond(A) < 1e3)
    lo = -rng.uniform(0.0, 1.0, m)
    hi = rng.uniform(0.0, 1.0, m)
    lo[rng.random(m) < 0.2] = -np.inf      # free below (a rod), or a cable's (-inf, 0]
    hi[rng.random(m) < 0.3] = np.inf
    shift = rng.uniform(0.0, 0.5, m) * np.diag(A)   # soft constraints regularise the diagonal
    lam0 = rng.normal(size=m) if warm else None
    lam, _ = solve(A, b, lo, hi, shift, np.clip(lam0, lo, hi) if warm else None)
    ref = reference_bounded_lcp(A + np.diag(shift), b, lo, hi)
    np.testing.assert_allclose(lam, ref, atol=1e-8 * (np.abs(b).max() + 1.0) * np.linalg.cond(A))


def test_friction_rows_stay_in_the_disc_of_their_normal_row():
    # One contact: a normal row and two tangents (an isotropic tangent block, as for a sphere on a plane),
    # the tangents driven hard: |lambda_t| = mu lambda_n.
    A = np.array([[1.0, 0.2, 0.1], [0.2, 1.5, 0.0], [0.1, 0.0, 1.5]])
    b = np.array([-1.0, 5.0, -4.0])
    m, mu = 3, 0.4
    ptr, col, val = to_csr(A)
    link = np.array([-1, 0, 0], dtype=np.int64)
    partner = np.array([-1, 2, 1], dtype=np.int64)
    lam = np.zeros(m)
    solve_bounded_lcp(ptr, col, val, np.zeros(m), b, np.array([0.0, -np.inf, -np.inf]), np.full(m, np.inf),
                      link, np.array([0.0, mu, mu]), partner, lam, m, 10000, 1.0, 1e-14)
    assert lam[0] > 0.0
    assert math.hypot(lam[1], lam[2]) == pytest.approx(mu * lam[0], rel=1e-9)
    w = A @ lam + b
    assert w[0] == pytest.approx(0.0, abs=1e-9)
    # Sliding: the friction impulse opposes the tangential velocity (maximal dissipation).
    cos = -(lam[1:] @ w[1:]) / (np.linalg.norm(lam[1:]) * np.linalg.norm(w[1:]))
    assert cos == pytest.approx(1.0, abs=1e-6)


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), nb=st.integers(1, 5), m=st.integers(1, 12))
def test_assembled_matrix_equals_dense_j_minv_jt(seed, nb, m):
    rng = np.random.default_rng(seed)
    sb = np.zeros((nb, 10))
    for k in range(nb):
        if rng.random() < 0.8:                                 # the others are static (zero inverse mass)
            sb[k, 0] = rng.uniform(0.1, 2.0)
            R = rng.normal(size=(3, 3))
            sb[k, 1:] = (R @ R.T + 0.1 * np.eye(3)).ravel()
    rows = np.empty((m, 2), dtype=np.int64)
    for i in range(m):
        a, b = rng.choice(np.arange(-1, nb), 2, replace=False)
        rows[i] = (a, b) if a >= 0 else (b, a)                 # body a is never the world
    J = rng.normal(size=(m, 12))
    # Dense reference over all bodies' 6 velocity coordinates.
    Jd = np.zeros((m, 6 * nb))
    Minv = np.zeros((6 * nb, 6 * nb))
    for k in range(nb):
        Minv[6 * k:6 * k + 3, 6 * k:6 * k + 3] = sb[k, 0] * np.eye(3)
        Minv[6 * k + 3:6 * k + 6, 6 * k + 3:6 * k + 6] = sb[k, 1:].reshape(3, 3)
    MJ = np.zeros((m, 12))
    for i in range(m):
        for side in range(2):
            k = rows[i, side]
            if k >= 0:
                Jd[i, 6 * k:6 * k + 6] += J[i, 6 * side:6 * side + 6]
                MJ[i, 6 * side:6 * side + 6] = Minv[6 * k:6 * k + 6, 6 * k:6 * k + 6] @ J[i, 6 * side:6 * side + 6]
    ptr, col, val = assemble_matrix(rows, J, MJ, m, sb, nb)
    A = np.zeros((m, m))
    for i in range(m):
        for p in range(ptr[i], ptr[i + 1]):
            A[i, col[p]] += val[p]
        assert len(set(col[ptr[i]:ptr[i + 1]])) == ptr[i + 1] - ptr[i]   # each column stored once
    np.testing.assert_allclose(A, Jd @ Minv @ Jd.T, atol=1e-12 * (1.0 + np.abs(Jd).max() ** 2 * 10))


# --- World(solver="lcp") against mechanics (rolling, sliding and sticking: test_contact_dynamics.py; the rod
# pendulum: test_stacking_and_joints.py) ------------------------------------------------------------------
def test_stack_of_five_stays_at_rest():
    w, boxes = box_tower(mb.World(solver="lcp", sleeping=False), height=5)
    for _ in range(60):
        w.step(DT)
    settled = np.array([b.position for b in boxes])
    for _ in range(300):
        w.step(DT)
    # Soft contacts (60 Hz) yield ~ g / (2 pi 60)^2 per box carried: about 2 mm at the top.
    assert np.abs(settled[:, 1] - (0.5 + np.arange(5))).max() < 5e-3
    assert np.abs(np.array([b.position for b in boxes]) - settled).max() < 1e-4
    assert max(np.linalg.norm(b.velocity) for b in boxes) < 1e-3


def test_resting_normal_impulses_carry_the_weight():
    w = mb.World(solver="lcp", sleeping=False)
    w.add_static(mb.Plane())
    w.add_body(mb.Box((0.5, 0.25, 0.5)), mass=10.0, position=(0, 0.25, 0))
    for _ in range(120):
        w.step(DT)
    contacts = w.contacts()
    assert len(contacts) == 4
    assert sum(c.normal_impulse for c in contacts) == pytest.approx(10.0 * G * DT, rel=1e-3)


@pytest.mark.parametrize("e", [0.0, 1.0])
def test_head_on_collision_conserves_momentum(e):
    a, b = head_on_collision(mb.World(gravity=(0, 0, 0), solver="lcp", sleeping=False), e)
    m1, m2, u1, u2 = HEAD_ON
    np.testing.assert_allclose(m1 * a.velocity + m2 * b.velocity, [m1 * u1 + m2 * u2, 0, 0], atol=1e-12)
    assert b.velocity[0] - a.velocity[0] == pytest.approx(e * (u1 - u2), abs=1e-9)


def test_cable_hangs_a_weight_and_a_ball_rests_on_a_box_in_one_problem():
    # A weight on a cable with a ball resting on it: the cable carries both weights, the contact one.
    w = mb.World(solver="lcp", sleeping=False)
    weight = w.add_body(mb.Box((0.2, 0.1, 0.2)), mass=2.0, position=(0, -1.0, 0))
    cable = w.add_cable(weight, None, max_length=1.0, anchor_b=(0, 0, 0))
    w.add_body(mb.Sphere(0.1), mass=1.0, position=(0, -0.8, 0))
    for _ in range(180):
        w.step(DT)
    assert weight.position[1] == pytest.approx(-1.0, abs=2e-3)
    np.testing.assert_allclose(cable.force, [0, 3.0 * G, 0], rtol=0.01, atol=0.05)
    (c,) = [c for c in w.contacts()]
    assert c.normal_impulse == pytest.approx(1.0 * G * DT, rel=0.01)


def test_lcp_tunables_are_validated():
    w = mb.World(solver="lcp")
    for name, bad in (("lcp_sweeps", 0.0), ("lcp_relaxation", 2.5), ("lcp_relaxation", float("nan"))):
        with pytest.raises(ValueError, match=name):
            setattr(w, name, bad)
