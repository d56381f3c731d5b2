"""Collision filtering by group and mask: two bodies collide only if (a.group & b.mask) and
(b.group & a.mask) are both nonzero; a filtered pair behaves as if the other body were not there."""
import runpy
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb

DT = 1.0 / 60.0
BITS = st.integers(min_value=-(2 ** 63), max_value=2 ** 63 - 1) | st.sampled_from([0, 1, 2, 3, -1, -2, -3])


def _drop(floor_kw=None, ball_kw=None, steps=90):
    """A ball dropped from 2 m onto a floor box; returns the world, the ball and the floor."""
    w = mb.World()
    floor = w.add_static(mb.Box((5.0, 0.5, 5.0)), position=(0.0, -0.5, 0.0), **(floor_kw or {}))
    ball = w.add_body(mb.Sphere(0.25), position=(0.0, 2.0, 0.0), **(ball_kw or {}))
    for _ in range(steps):
        w.step(DT)
    return w, ball, floor


def test_defaults_collide_with_everything():
    w, ball, floor = _drop()
    assert (ball.group, ball.mask, floor.group, floor.mask) == (1, -1, 1, -1)
    assert ball.position[1] == pytest.approx(0.25, abs=5e-3)


@pytest.mark.parametrize("floor_kw, ball_kw", [
    ({"mask": ~2}, {"group": 2}),            # the floor does not take group 2
    ({}, {"mask": 0}),                       # the ball takes no group
    ({"group": 4}, {"mask": 1 | 2}),         # the ball does not take the floor's group
])
def test_a_filtered_pair_moves_as_if_alone(floor_kw, ball_kw):
    """The filtered ball's path is the one it has in a world without the floor, step for step (same
    arithmetic: bit-identical)."""
    _, ball, _ = _drop(floor_kw, ball_kw)
    alone = mb.World()
    free = alone.add_body(mb.Sphere(0.25), position=(0.0, 2.0, 0.0))
    for _ in range(90):
        alone.step(DT)
    assert ball.position[1] < -1.0
    np.testing.assert_array_equal(ball.position, free.position)
    np.testing.assert_array_equal(ball.velocity, free.velocity)


@settings(max_examples=60, deadline=None)
@given(ga=BITS, ma=BITS, gb=BITS, mb_=BITS, broadphase=st.sampled_from(["brute", "sap", "grid", "bvh"]))
def test_the_rule_both_ways(ga, ma, gb, mb_, broadphase):
    """Two overlapping balls push apart exactly when the rule lets them collide, in any broad phase."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), broadphase=broadphase)
    a = w.add_body(mb.Sphere(0.5), position=(0.0, 0.0, 0.0), group=ga, mask=ma)
    b = w.add_body(mb.Sphere(0.5), position=(0.8, 0.0, 0.0), group=gb, mask=mb_)
    w.step(DT)
    collide = (ga & mb_) != 0 and (gb & ma) != 0
    assert bool(w.contacts()) == collide
    assert (b.position[0] > 0.8) == collide
    assert (a.position[0] < 0.0) == collide


def test_changing_the_mask_wakes_a_sleeping_body_which_then_falls_through():
    w, ball, floor = _drop(steps=240)
    assert ball.is_sleeping
    ball.mask = 0
    assert not ball.is_sleeping
    for _ in range(60):
        w.step(DT)
    assert ball.position[1] < -1.0


def test_changing_the_floor_wakes_what_rests_on_it():
    w, ball, floor = _drop(steps=240)
    assert ball.is_sleeping
    floor.mask = ~ball.group
    assert not ball.is_sleeping
    for _ in range(60):
        w.step(DT)
    assert ball.position[1] < -1.0
    floor.mask = -1       # the floor collides again, but the ball is now below it: it keeps falling
    ball.group = 8
    assert (floor.mask, ball.group) == (-1, 8)


def test_raycast_mask_picks_the_groups_it_hits():
    w = mb.World()
    w.add_static(mb.Plane(), group=1)
    box = w.add_static(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 2.0, 0.0), group=2)
    down = ((0.0, 10.0, 0.0), (0.0, -1.0, 0.0))
    assert w.raycast(*down).body is box
    assert w.raycast(*down, mask=2).body is box
    floor_hit = w.raycast(*down, mask=1)
    assert floor_hit.distance == pytest.approx(10.0)
    assert w.raycast(*down, mask=4) is None
    assert w.raycast(*down, mask=0) is None


def test_snapshot_keeps_the_filter():
    w, ball, floor = _drop(ball_kw={"group": 6, "mask": 5}, steps=1)
    snap = w.snapshot()
    ball.group, ball.mask = 1, -1
    w.restore(snap)
    assert (ball.group, ball.mask) == (6, 5)


@pytest.mark.parametrize("value, error", [(1.5, TypeError), (True, TypeError), ("1", TypeError), (None, TypeError),
                                          (2 ** 63, ValueError), (-(2 ** 63) - 1, ValueError)])
def test_bad_bits_are_refused_naming_the_argument_and_change_nothing(value, error):
    w, ball, floor = _drop(steps=1)
    before = w.snapshot()
    for call, name in ((lambda: setattr(ball, "group", value), "group"),
                       (lambda: setattr(floor, "mask", value), "mask"),
                       (lambda: w.add_body(mb.Sphere(1.0), mask=value), "mask"),
                       (lambda: w.add_static(mb.Plane(), group=value), "group"),
                       (lambda: w.raycast((0, 5, 0), (0, -1, 0), mask=value), "mask")):
        with pytest.raises(error, match=name):
            call()
    assert w.snapshot().state_hash() == before.state_hash()
    assert len(w.bodies) == 2


def test_the_example_marble_rolls_through_the_debris():
    """examples/filtering.py: the marble, launched sliding at 2 m/s, ends rolling at 5/7 of that (friction's
    closed form for a solid ball) as if the debris were not there; the debris rests on the ground
    (centres 0.1 m up, within the soft contact's ~0.1 mm sink); the ground ray ignores the debris."""
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "filtering.py"))["run"]
    x, speed, lowest, ground = run()
    assert speed == pytest.approx(2.0 * 5.0 / 7.0, rel=1e-3)
    assert lowest == pytest.approx(0.1, abs=1e-3)
    assert ground == pytest.approx(0.3, abs=1e-3)
    assert x > 2.0


@settings(max_examples=200, deadline=None)
@given(st.integers(min_value=2, max_value=12), st.data())
def test_jointed_pairs_are_dropped_as_a_slow_scan_of_every_joint_finds_them(nb, data):
    """The broad phase drops a pair exactly when a live, unbroken ball, hinge, slider or fixed joint joins its
    two bodies (springs, rods, cables, dead and broken joints and joints to the world do not count), as a
    scan of every joint for every pair decides; the kept pairs keep their order."""
    from marbellous.dynamics.joint_rows import drop_joined_pairs
    from marbellous.state import layout as L

    joint = st.tuples(st.integers(0, nb - 1), st.integers(-1, nb - 1), st.integers(L.KT_SPRING, L.KT_FIXED),
                      st.sampled_from([L.KF_ALIVE, L.KF_ALIVE | L.KF_BROKEN, 0]))
    joints = data.draw(st.lists(joint, max_size=3 * nb))
    pairs = data.draw(st.lists(st.tuples(st.integers(0, nb - 1), st.integers(0, nb - 1)), max_size=nb * nb))
    ki = np.zeros((len(joints) + 1, L.KI_COLS), dtype=np.int64)
    bi = np.zeros((nb, L.BI_COLS), dtype=np.int64)
    for c, (a, b, kind, flags) in enumerate(joints):
        ki[c] = (kind, a, b, flags)
        if kind >= L.KT_BALL:
            bi[a, L.FLAGS] |= L.F_JOINTED
            if b >= 0:
                bi[b, L.FLAGS] |= L.F_JOINTED

    def joined(i, j):
        return any(kind >= L.KT_BALL and flags == L.KF_ALIVE and {a, b} == {i, j} for a, b, kind, flags in joints)

    table = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    start, other = np.full(nb + 1, -7, dtype=np.int64), np.full(2 * ki.shape[0], -7, dtype=np.int64)
    kept = drop_joined_pairs(table, len(pairs), bi, ki, len(joints), nb, start, other)
    assert table[:kept].tolist() == [list(p) for p in pairs if not joined(*p)]
