"""The wide contact solver (dynamics/contact_bundles.py): no colour has two contacts on one movable body,
every solved contact is in exactly one lane or the overflow, and a pass over the bundles gives bit for
bit what the scalar pass (contact_solver.solve_contacts) gives visiting the same contacts in bundle
order, and a push pass of the split impulses (push_bundles) what contact_solver.push_contacts gives: for
spheres (isotropic inertia) and for flat boxes (the inertia turns with the body)."""
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
                                     WI_READ_A, WI_READ_B, WI_TURNING, WI_WRITE_A, WI_WRITE_B)

DT = 1 / 60
H = DT / 4
SOFT = (30.0, 0.9, 0.1, 3.0)    # (bias rate, mass scale, impulse scale, max push) of a soft contact
RATE = 30.0             # bias rate of the push (1/s)
MAX_PUSH = 0.05         # (low enough that some contacts push at the cap)
DEPTH = 1e-3            # overlap left to the velocity passes (m)


@njit
def _solver_bodies(bf, bi, nb):
    sb = np.zeros((nb + 2, SB_COLS))   # the pad and sink rows last
    prepare_solver_bodies(bf, bi, nb, sb)
    return sb


@njit
def _accumulate(cf, ci, nc):
    accumulate_applied(cf, ci, nc)


class Bundled:
    """The last step's contacts of a world laid out in bundles, with the solver bodies they were made from."""

    def __init__(self, world, rolling=(), deeper=0.0):
        self.nc = world._state.n_cached
        self.cf = world._state.cache_f[:self.nc].copy()
        self.ci = world._state.cache_i[:self.nc].copy()
        self.cf[:, L.C_ADJ_SEP] -= deeper           # overlap, some of it deeper than DEPTH, for the pushes
        for c in rolling:
            self.cf[c, L.C_ROLL] = 0.01
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


def test_a_colour_shares_no_movable_body_and_every_contact_has_one_place(pile):
    b = Bundled(pile, rolling=(5, 17))
    assert b.nc >= MIN_BUNDLED_CONTACTS
    assert b.bundles * LANES < 1.2 * b.nc                       # bundles are mostly full
    pad, sink = b.sb.shape[0] - 2, b.sb.shape[0] - 1
    seen = list(b.overflow[:b.n_over])
    assert sorted(seen) == [5, 17]                              # rolling resistance: the scalar pass
    for k in range(b.bundles):
        contacts = b.block(k, WI_CONTACT)
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


def _compare_passes(world):
    """Warm start, three soft and one rigid velocity pass and three push passes, wide and scalar in the same
    contact order."""
    b = Bundled(world, deeper=3e-3)
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
    return b


def test_bundles_solve_spheres_as_the_scalar_pass(pile):
    b = _compare_passes(pile)
    assert not any(b.block(k, WI_TURNING)[0] for k in range(b.bundles))


def test_bundles_solve_turning_boxes_as_the_scalar_pass(slabs):
    b = _compare_passes(slabs)
    assert all(b.block(k, WI_TURNING)[0] for k in range(b.bundles))


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
