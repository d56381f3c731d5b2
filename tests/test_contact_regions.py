"""Contact passes on several threads (dynamics/contact_regions.py): regions that share no movable body,
bundles of a region that write only its bodies, the same result on every run, and the same physics as
the serial solver."""
import numpy as np
import pytest
from numba import njit

import marbellous as mb
from marbellous._numba.wide import LANES
from marbellous.state.layout import BUNDLE_ROWS, WI_CONTACT, WI_WRITE_A, WI_WRITE_B
from marbellous.dynamics.contact_regions import MIN_PARALLEL_CONTACTS
from marbellous.scenes import sphere_pile
from marbellous.state import layout as L

DT = 1 / 60


@njit
def _regions(t):
    """The step's contact order and region starts (test-only reader of the record)."""
    return t.contact_order.copy(), t.region_starts.copy(), t.slab.copy()


@njit
def _parts(t):
    """Each region's bundles and overflow, and the bundles' body rows (test-only reader of the record)."""
    return t.part_bundles.copy(), t.part_overflow.copy(), t.wide_i.copy(), t.overflow.copy()


def _settled_pile(threads, steps=240):
    w, spheres = sphere_pile(count=400, seed=3)
    w.threads = threads
    for _ in range(steps):
        w.step(DT)
    return w, spheres


@pytest.fixture(scope="module")
def piles():
    return _settled_pile(1), _settled_pile(2)


def test_regions_share_no_movable_body(piles):
    w, _ = piles[1]
    assert w._state.n_cached >= MIN_PARALLEL_CONTACTS
    order, starts, slab = _regions(w._state.context)
    n = w._state.n_cached
    assert sorted(order[:n]) == list(range(n))          # every contact once
    assert starts[0] == 0 and starts[3] == n
    moving = [bool(w._state.bi[i, L.FLAGS] & L.F_ALIVE) and not w._state.bi[i, L.FLAGS] & (L.F_STATIC | L.F_SLEEPING)
              for i in range(w._state.bodies.end)]
    ci = w._state.cache_i        # the cache now holds the contacts the step's passes ran over
    for r in range(2):
        rows = order[starts[r]:starts[r + 1]]
        assert len(rows) > n // 4                          # both regions have work
        for c in rows:
            for body in (ci[c, L.C_BODY_A], ci[c, L.C_BODY_B]):
                assert not moving[body] or slab[body] == r
    for c in order[starts[2]:starts[3]]:                   # the boundary joins the two slabs
        assert {slab[ci[c, L.C_BODY_A]], slab[ci[c, L.C_BODY_B]]} == {0, 1}


def test_each_region_has_bundles_that_write_only_its_own_bodies(piles):
    w, _ = piles[1]
    _, _, slab = _regions(w._state.context)
    part_bundles, part_overflow, wide_i, overflow = _parts(w._state.context)
    sink = w._state.bf.shape[0] + 1                      # the solver bodies' last row
    solved = []
    for part in range(3):                          # two regions, then the boundary
        first, last = part_bundles[part], part_bundles[part + 1]
        assert last > first
        for bundle in range(first, last):
            rows = bundle * BUNDLE_ROWS * LANES
            contacts = wide_i[rows + WI_CONTACT * LANES:rows + (WI_CONTACT + 1) * LANES]
            solved += [c for c in contacts if c >= 0]
            for kind in (WI_WRITE_A, WI_WRITE_B):
                written = [r for r in wide_i[rows + kind * LANES:rows + (kind + 1) * LANES] if r != sink]
                assert len(written) == len(set(written))
                if part < 2:
                    assert all(slab[r] == part for r in written)
        solved += list(overflow[part_overflow[part]:part_overflow[part + 1]])
    assert sorted(solved) == list(range(w._state.n_cached))   # every contact in one lane or one overflow list


def test_threads_give_the_same_result_on_every_run(piles):
    again, _ = _settled_pile(2)
    assert again.state_hash() == piles[1][0].state_hash()


def test_threads_visit_contacts_in_another_order_with_the_same_physics(piles):
    """Momentum: over one step the floor and walls give the pile the vertical impulse  M g dt + dP_y  (the
    contacts between spheres cancel in pairs), to round-off, whichever order the contacts were solved in."""
    for w, spheres in piles:
        mass = sum(s.mass for s in spheres)
        before = [s.mass * s.velocity[1] for s in spheres]
        w.step(DT)
        after = [s.mass * s.velocity[1] for s in spheres]
        lifts = []
        for c in w.contacts():
            j = c.normal_impulse * c.normal + c.tangent_impulse      # on b, from a
            if c.body_a.is_static and not c.body_b.is_static:
                lifts.append(j[1])
            elif c.body_b.is_static and not c.body_a.is_static:
                lifts.append(-j[1])
        weight = mass * 9.81 * DT
        # the sums' round-off: at most (number of terms) * eps * (sum of their magnitudes)
        terms = np.abs(np.concatenate([lifts, before, after, [weight]]))
        bound = len(terms) * np.finfo(float).eps * terms.sum()
        assert abs((sum(lifts) - weight) - (sum(after) - sum(before))) <= bound
        assert max(c.depth for c in w.contacts()) < 2e-3     # no sinking
    serial, parallel = piles[0][0], piles[1][0]
    assert serial.state_hash() != parallel.state_hash()     # the parallel path did run
    heights = [np.mean([s.position[1] for s in spheres]) for _, spheres in piles]
    assert heights[0] == pytest.approx(heights[1], abs=0.01)


def test_threads_is_validated():
    w = mb.World()
    for bad, err in ((0, ValueError), (65, ValueError), (1.5, TypeError), (True, TypeError)):
        with pytest.raises(err, match="threads"):
            w.threads = bad
    assert w.threads == 1
    with pytest.raises(ValueError, match="threads"):
        mb.World(threads=0)
