"""The wide contact solver (dynamics/contact_bundles.py): no colour has two contacts on one movable body,
every solved contact is in exactly one lane or the overflow, and a pass over the bundles gives bit for
bit what the scalar pass (contact_solver.solve_contacts) gives visiting the same contacts in bundle
order, and a push pass of the split impulses (push_bundles) what contact_solver.push_contacts gives: for
spheres (isotropic inertia), for flat boxes (the inertia turns with the body) and for a mix of spheres,
cubes and flat boxes, with and without rolling and torsional friction.  Balls rolling or spinning on a
plane, enough of them for the step to bundle their contacts, slow down as the closed forms say."""
import numpy as np
import pytest
from numba import njit

import marbellous as mb
from marbellous._numba.wide import LANES
from marbellous.dynamics.contact_bundles import (MAX_COLOURS, MIN_BUNDLED_CONTACTS, accumulate_bundles,
                                                 bundle_capacity, bundle_contacts, load_bundle_bodies, push_bundles,
                                                 solve_bundles, store_bundles, warm_start_bundles)
from marbellous.dynamics.contact_solver import accumulate_applied, push_contacts, solve_contacts, warm_start_listed
from marbellous.dynamics.solver_bodies import prepare_solver_bodies
from marbellous.scenes import sphere_pile
from marbellous.state import layout as L
from marbellous.state.layout import (BUNDLE_FIELDS, BUNDLE_ROWS, PB_COLS, SB_COLS, SB_ISO, WB_LAMBDA_P, WI_CONTACT,
                                     WI_READ_A, WI_READ_B, WI_ROLLING, WI_TURNING, WI_WRITE_A, WI_WRITE_B)

DT = 1 / 60
H = DT / 4
SOFT = (30.0, 0.9, 0.1, 3.0)    # (bias rate, mass scale, impulse scale, max push) of a soft contact
RATE = 30.0             # bias rate of the push (1/s)
MAX_PUSH = 0.05         # (low enough that some contacts push at the cap)
DEPTH = 1e-3            # overlap left to the velocity passes (m)
G = 9.81


@njit
def _solver_bodies(bf, bi, nb):
    sb = np.zeros((nb + 2, SB_COLS))   # the pad and sink rows last
    prepare_solver_bodies(bf, bi, nb, sb)
    return sb


@njit
def _accumulate(cf, ci, nc):
    accumulate_applied(cf, ci, nc)


def _rolling_materials(cf):
    """Rolling friction on contacts 0, 2, 4, ..., torsional friction on contacts 1, 2, 5, 6, ... (so some
    have both, some neither), and an angular impulse to warm-start of up to 1.5 times 1 % of the normal
    impulse on each contact with either (some start beyond their bounds) and on every eighth without (as
    a contact keeps its impulse when its bodies' rolling friction is set to zero: warm-started, never
    solved)."""
    rng = np.random.default_rng(11)
    for c in range(len(cf)):
        cf[c, L.C_ROLL] = 0.01 if c % 2 == 0 else 0.0
        cf[c, L.C_TORSION] = 0.01 if c % 4 in (1, 2) else 0.0
        if cf[c, L.C_ROLL] > 0.0 or cf[c, L.C_TORSION] > 0.0 or c % 8 == 7:
            cf[c, L.C_LAMBDA_R:L.C_LAMBDA_R + 3] = 0.015 * cf[c, L.C_LAMBDA_N] * rng.uniform(-1.0, 1.0, 3)


class Bundled:
    """The last step's contacts of a world laid out in bundles, with the solver bodies they were made from
    (``rolling``: with :func:`_rolling_materials`)."""

    def __init__(self, world, rolling=False, deeper=0.0):
        self.nc = world._state.n_cached
        self.cf = world._state.cache_f[:self.nc].copy()
        self.ci = world._state.cache_i[:self.nc].copy()
        self.cf[:, L.C_ADJ_SEP] -= deeper           # overlap, some of it deeper than DEPTH, for the pushes
        if rolling:
            _rolling_materials(self.cf)
        self.sb = _solver_bodies(world._state.bf, world._state.bi, world._state.bodies.end)
        capacity = bundle_capacity(self.nc, 1)
        self.wide_f = np.zeros(capacity * BUNDLE_FIELDS * LANES)
        self.wide_i = np.zeros(capacity * BUNDLE_ROWS * LANES, dtype=np.int64)
        self.overflow = np.zeros(self.nc, dtype=np.int64)
        used = np.zeros(self.sb.shape[0], dtype=np.int64)
        self.colour = np.zeros(self.nc, dtype=np.int64)
        self.bundles, self.n_over = bundle_contacts(self.cf, self.ci, np.arange(self.nc), 0, self.nc, self.sb,
                                                    used, self.colour, np.zeros(MAX_COLOURS + 1, dtype=np.int64),
                                                    self.wide_f, self.wide_i, 0, self.overflow, 0)
        load_bundle_bodies(self.wide_f, self.wide_i, self.bundles, self.sb, True)

    def block(self, bundle, kind):
        start = (bundle * BUNDLE_ROWS + kind) * LANES
        return self.wide_i[start:start + LANES]

    def lane_order(self):
        """The contacts in the order the bundles visit them."""
        lanes = np.concatenate([self.block(k, WI_CONTACT) for k in range(self.bundles)])
        return lanes[lanes >= 0]


def _settle(world, steps):
    for _ in range(steps):
        world.step(DT)
    return world


@pytest.fixture(scope="module")
def pile():
    return _settle(sphere_pile(count=400, seed=3)[0], 240)


@pytest.fixture(scope="module")
def slabs():
    """Two layers of flat boxes (not cubes: their world inertia turns with them) on the ground."""
    w = mb.World()
    w.add_static(mb.Plane())
    for layer in range(2):
        for i in range(4):
            for j in range(4):
                x, z = i * 1.0 + 0.3 * layer, j * 0.8 + 0.2 * layer
                w.add_body(mb.Box((0.45, 0.2, 0.35)), position=(x, 0.2 + 0.41 * layer, z), friction=0.6)
    return _settle(w, 30)


@pytest.fixture(scope="module")
def mixed():
    """Spheres, cubes (isotropic inertia) and flat boxes (not) side by side and on one another on the ground."""
    w = mb.World()
    w.add_static(mb.Plane())
    shapes = (mb.Sphere(0.3), mb.Box((0.3, 0.3, 0.3)), mb.Box((0.45, 0.2, 0.35)))
    for layer in range(2):
        for i in range(4):
            for j in range(4):
                x, z = i * 1.0 + 0.2 * layer, j * 1.0 + 0.1 * layer
                w.add_body(shapes[(i + j + layer) % 3], position=(x, 0.35 + 0.65 * layer, z), friction=0.6)
    return _settle(w, 40)


def test_a_colour_shares_no_movable_body_and_every_contact_has_one_place(pile):
    b = Bundled(pile, rolling=True)
    assert b.nc >= MIN_BUNDLED_CONTACTS
    assert b.bundles * LANES < 1.2 * b.nc                       # bundles are mostly full
    pad, sink = b.sb.shape[0] - 2, b.sb.shape[0] - 1
    seen = list(b.overflow[:b.n_over])
    assert seen == []                                           # rolling resistance too in the bundles
    for k in range(b.bundles):
        contacts = b.block(k, WI_CONTACT)
        real = contacts[contacts >= 0]
        angular = (b.cf[real, L.C_ROLL] > 0.0) | (b.cf[real, L.C_TORSION] > 0.0)
        angular |= np.any(b.cf[real, L.C_LAMBDA_R:L.C_LAMBDA_R + 3] != 0.0, axis=1)
        assert np.all(b.block(k, WI_ROLLING) == int(np.any(angular)))     # the whole bundle, or none of it
        for lane, c in enumerate(contacts):
            rows = [b.block(k, kind)[lane] for kind in (WI_READ_A, WI_READ_B, WI_WRITE_A, WI_WRITE_B)]
            if c < 0:
                assert rows == [pad, pad, sink, sink]
                continue
            seen.append(c)
            for read, write, side in ((rows[0], rows[2], L.C_BODY_A), (rows[1], rows[3], L.C_BODY_B)):
                assert read == b.ci[c, side]
                movable = b.sb[read, SB_ISO] != 0.0
                assert write == (read if movable else sink)
        real = contacts[contacts >= 0]
        assert len(set(b.colour[real])) == 1                    # a bundle holds one colour
    assert sorted(seen) == list(range(b.nc))
    lanes = b.lane_order()
    assert np.all(np.diff(b.colour[lanes]) >= 0)                # colour by colour
    for colour in set(b.colour[lanes]):
        movable = [body for c in lanes[b.colour[lanes] == colour] for body in b.ci[c, :2]
                   if b.sb[body, SB_ISO] != 0.0]
        assert len(movable) == len(set(movable))                # no movable body twice in a colour


@njit
def _bundled_in_step(t):
    """How many bundles and overflow contacts the last step's passes had (test-only reader of the context)."""
    return t.part_bundles[1], t.part_overflow[1]


def test_the_serial_step_solves_a_pile_in_bundles(pile):
    bundles, n_over = _bundled_in_step(pile._state.context)
    n = pile._state.n_cached
    assert n_over == 0 and n <= bundles * LANES < n + LANES * MAX_COLOURS


def _compare_passes(world, rolling=False):
    """Warm start, three soft and one rigid velocity pass and three push passes, wide and scalar in the same
    contact order (``rolling``: with :func:`_rolling_materials`)."""
    b = Bundled(world, rolling=rolling, deeper=3e-3)
    order = b.lane_order()
    assert b.n_over == 0 and len(order) == b.nc and b.bundles >= 4
    cf, sb = b.cf.copy(), b.sb[:-2].copy()
    warm_start_listed(cf, b.ci, order, len(order), sb)
    warm_start_bundles(b.wide_f, b.wide_i, b.bundles, b.sb)
    assert np.array_equal(b.sb[:-2], sb)
    largest = np.zeros(LANES)
    for soft in (SOFT, SOFT, SOFT, (0.0, 1.0, 0.0, 0.0)):
        wide = solve_bundles(b.wide_f, b.wide_i, 0, b.bundles, b.sb, H, soft, largest)
        scalar = solve_contacts(cf, b.ci, order, 0, len(order), sb, H, soft)
        assert wide == scalar
        assert np.array_equal(b.sb[:-2], sb)
    pb_wide, pb_scalar = np.zeros((len(b.sb), PB_COLS)), np.zeros((len(b.sb), PB_COLS))
    lam_p = np.zeros(b.nc)
    for first_pass in (True, False, False):
        wide = push_bundles(b.wide_f, b.wide_i, 0, b.bundles, b.sb, pb_wide, H, RATE, MAX_PUSH, DEPTH, first_pass,
                            largest)
        scalar = push_contacts(cf, b.ci, order, 0, len(order), sb, pb_scalar, lam_p, H, RATE, MAX_PUSH, DEPTH,
                               first_pass)
        assert wide == scalar > 0.0
        assert np.array_equal(pb_wide[:-2], pb_scalar[:-2])
    for bundle in range(b.bundles):
        for lane, c in enumerate(b.block(bundle, WI_CONTACT)):
            if c >= 0:
                assert b.wide_f[(bundle * BUNDLE_FIELDS + WB_LAMBDA_P) * LANES + lane] == lam_p[c]
    assert np.count_nonzero(lam_p) > b.nc // 4
    _accumulate(cf, b.ci, b.nc)
    accumulate_bundles(b.wide_f, b.bundles)
    stored = b.cf.copy()
    store_bundles(b.wide_f, b.wide_i, b.bundles, stored)
    assert np.array_equal(stored, cf)
    flagged = [b.block(k, WI_ROLLING)[0] for k in range(b.bundles)]
    if not rolling:
        assert not any(flagged)                                  # no rolling friction: no rolling block
        return b
    assert any(flagged)
    # lambda_r was solved: across the normal some contacts hold their bound rho lambda_n, along it some
    # hold tau lambda_n, and those without rolling or torsional friction kept what they had
    lambda_r, n = cf[:, L.C_LAMBDA_R:L.C_LAMBDA_R + 3], cf[:, L.C_NORMAL:L.C_NORMAL + 3]
    spin = np.sum(lambda_r * n, axis=1)
    across = np.linalg.norm(lambda_r - spin[:, None] * n, axis=1)
    rolling_bound, torsion_bound = cf[:, L.C_ROLL] * cf[:, L.C_LAMBDA_N], cf[:, L.C_TORSION] * cf[:, L.C_LAMBDA_N]
    inert = (b.cf[:, L.C_ROLL] == 0.0) & (b.cf[:, L.C_TORSION] == 0.0)
    rounding = 1e-12 * np.linalg.norm(lambda_r, axis=1)
    assert np.all((across <= rolling_bound + rounding) | inert)
    assert np.all((np.abs(spin) <= torsion_bound + rounding) | inert)
    assert np.count_nonzero((rolling_bound > 0.0) & (across >= rolling_bound * (1 - 1e-12))) > 0
    assert np.count_nonzero((torsion_bound > 0.0) & (np.abs(spin) >= torsion_bound * (1 - 1e-12))) > 0
    assert np.array_equal(lambda_r[inert], b.cf[inert, L.C_LAMBDA_R:L.C_LAMBDA_R + 3])
    assert np.any(lambda_r[inert] != 0.0)
    return b


@pytest.mark.parametrize("rolling", (False, True))
def test_bundles_solve_spheres_as_the_scalar_pass(pile, rolling):
    b = _compare_passes(pile, rolling)
    assert not any(b.block(k, WI_TURNING)[0] for k in range(b.bundles))


@pytest.mark.parametrize("rolling", (False, True))
def test_bundles_solve_turning_boxes_as_the_scalar_pass(slabs, rolling):
    b = _compare_passes(slabs, rolling)
    assert all(b.block(k, WI_TURNING)[0] for k in range(b.bundles))


@pytest.mark.parametrize("rolling", (False, True))
def test_bundles_solve_spheres_cubes_and_boxes_as_the_scalar_pass(mixed, rolling):
    b = _compare_passes(mixed, rolling)
    # bundles that turn hold lanes whose bodies are all isotropic (spheres, cubes, the ground) beside others
    isotropic = 0
    for k in range(b.bundles):
        contacts = b.block(k, WI_CONTACT)
        lanes = contacts[contacts >= 0]
        assert b.block(k, WI_TURNING)[0] == np.any(b.sb[b.ci[lanes, :2], SB_ISO] < 0.0)
        if b.block(k, WI_TURNING)[0]:
            isotropic += np.count_nonzero(np.all(b.sb[b.ci[lanes, :2], SB_ISO] >= 0.0, axis=1))
    assert isotropic > 0


def test_bundles_refresh_the_masses_of_turned_bodies_as_the_scalar_pass(slabs):
    # After the flat boxes turned (0.3 rad about a tilted axis), the effective masses of their contacts
    # change and their impulses are scaled down with them: lane by lane as the contact table's.
    from marbellous.dynamics.contact_bundles import refresh_bundle_masses
    from marbellous.dynamics.contact_solver import refresh_turning_masses
    from marbellous.math3d import quat_step
    from marbellous.state.layout import WB_MASS_N, WB_MASS_T1, WB_MASS_T2

    b = Bundled(slabs)
    cf = b.cf.copy()
    st = slabs._state
    bf = st.bf.copy()
    axis = np.array([0.3, 0.8, -0.5]) / np.linalg.norm([0.3, 0.8, -0.5])
    for i in range(st.bodies.end):
        if not st.bi[i, L.FLAGS] & L.F_STATIC:
            bf[i, L.QUAT:L.QUAT + 4] = quat_step(tuple(bf[i, L.QUAT:L.QUAT + 4]), tuple(0.3 * axis), 1.0)
    sb = _solver_bodies(bf, st.bi, st.bodies.end)
    refresh_turning_masses(cf, b.ci, None, b.nc, sb)
    refresh_bundle_masses(b.wide_f, b.wide_i, b.bundles, sb)
    changed = 0
    for bundle in range(b.bundles):
        for lane, c in enumerate(b.block(bundle, WI_CONTACT)):
            if c < 0:
                continue
            for field, column in ((WB_MASS_N, L.C_MASS_N), (WB_MASS_T1, L.C_MASS_T1), (WB_MASS_T2, L.C_MASS_T2)):
                value = b.wide_f[(bundle * BUNDLE_FIELDS + field) * LANES + lane]
                assert value == cf[c, column]
                changed += value != b.cf[c, column]
    stored = b.cf.copy()
    store_bundles(b.wide_f, b.wide_i, b.bundles, stored)
    for column in (L.C_LAMBDA_N, L.C_LAMBDA_T1, L.C_LAMBDA_T2):
        assert np.array_equal(stored[:, column], cf[:, column])
        assert np.all(np.abs(cf[:, column]) <= np.abs(b.cf[:, column]))     # scaled down, never up
    assert changed > 0


def _balls_on_a_plane(radius, angular_velocity, velocity=(0.0, 0.0, 0.0), **material):
    """81 balls of ``radius`` (m) and 2 kg on a plane, 9 by 9, 4 m apart along x and 1.5 m along z (one contact
    each: enough contacts for the step to solve them in bundles), the plane and the balls of ``material``."""
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane(), **material)
    balls = [w.add_body(mb.Sphere(radius), mass=2.0, position=(4.0 * i, radius, 1.5 * j), velocity=velocity,
                        angular_velocity=angular_velocity, **material) for i in range(9) for j in range(9)]
    return w, balls


def _bundled(world):
    bundles, n_over = _bundled_in_step(world._state.context)
    return bundles > 0 and n_over == 0


def test_balls_rolling_in_bundles_stop_as_rolling_friction_says():
    """A ball rolling on a plane feels the rolling resistance torque rho N (and the friction force that
    keeps it rolling): it slows at a = rho g / (r (1 + 2/5)) (a solid sphere) and stops after v^2 / (2 a),
    as test_contact_dynamics' marble does through the scalar pass."""
    r, v0, rho = 0.1, 2.0, 0.01
    w, balls = _balls_on_a_plane(r, (0.0, 0.0, -v0 / r), (v0, 0.0, 0.0), friction=0.5, rolling_friction=rho)
    decel = rho * G / (r * 1.4)
    start = [b.position[0] for b in balls]
    for step in range(int((v0 / decel + 0.5) * 60)):
        w.step(DT)
        if step == 30:
            assert _bundled(w)
            for b in balls:
                assert b.velocity[0] == pytest.approx(v0 - decel * 31 * DT, rel=0.02)
    assert _bundled(w)
    for b, x0 in zip(balls, start):
        assert np.linalg.norm(b.velocity) < 1e-3
        assert np.linalg.norm(b.angular_velocity) < 1e-2
        assert b.position[0] - x0 == pytest.approx(v0 ** 2 / (2 * decel), rel=0.05)


def test_balls_spinning_in_bundles_stop_at_the_rate_of_torsional_friction():
    """A ball resting on a plane spinning about the normal: I domega/dt = -tau m g, I = 2/5 m r^2, so after
    2 s the spin is 10 - 2 tau g / (0.4 r^2) (test_materials' ball, solved here in bundles)."""
    tau, r = 0.01, 0.5
    w, balls = _balls_on_a_plane(r, (0.0, 10.0, 0.0), torsional_friction=tau)
    for _ in range(120):
        w.step(DT)
    assert _bundled(w)
    expected = 10.0 - G * tau / (0.4 * r * r) * 2.0
    for b in balls:
        np.testing.assert_allclose(b.angular_velocity, [0.0, expected, 0.0], atol=1e-9)
