"""Adaptive iteration counts (``World.adaptive_iterations``): deep stacks get more velocity passes, easy scenes
stop early.

The support depth (``dynamics/support_depth.py``) is checked on contact graphs with known answers; the
world's behaviour on a tall stack, against the same stack with a fixed pass count."""
import numpy as np
import pytest

import marbellous as mb
from marbellous.dynamics.support_depth import DEPTH_PASSES, MAX_ADAPTIVE, iteration_cap, support_depth
from marbellous.state.layout import BI_COLS, C_BODY_A, C_BODY_B, CI_COLS, F_ALIVE, F_KINEMATIC, F_SLEEPING, F_STATIC

DT = 1.0 / 60.0


def depth_of(flags, pairs):
    nb = len(flags)
    bi = np.zeros((nb, BI_COLS), np.int64)
    bi[:, 0] = flags
    ci = np.zeros((max(len(pairs), 1), CI_COLS), np.int64)
    for c, (a, b) in enumerate(pairs):
        ci[c, C_BODY_A], ci[c, C_BODY_B] = a, b
    scratch = [np.zeros(nb, np.int64), np.zeros(nb + 1, np.int64), np.zeros(2 * len(pairs) + 1, np.int64),
               np.zeros(nb, np.int64)]
    return support_depth(bi, ci, len(pairs), nb, *scratch)


GROUND = F_ALIVE | F_STATIC
BODY = F_ALIVE


def test_a_chain_on_the_ground_is_as_deep_as_it_is_long():
    # ground 0; bodies 1..5 stacked, each contact listed twice (two points per pair), in shuffled order
    pairs = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5)] * 2
    order = np.random.default_rng(0).permutation(len(pairs))
    assert depth_of([GROUND] + [BODY] * 5, [pairs[k] for k in order]) == 5


def test_the_shortest_way_down_counts():
    # a ring 1-2-3-4-1 standing on the ground at 1 and 3: 2 and 4 are one contact further up
    assert depth_of([GROUND] + [BODY] * 4, [(0, 1), (0, 3), (1, 2), (2, 3), (3, 4), (4, 1)]) == 2


def test_kinematic_and_sleeping_bodies_hold_like_the_ground():
    assert depth_of([F_ALIVE | F_KINEMATIC, BODY, BODY], [(0, 1), (1, 2)]) == 2
    assert depth_of([F_ALIVE | F_SLEEPING, BODY, BODY], [(1, 0), (2, 1)]) == 2


def test_a_pile_in_the_air_has_no_depth():
    assert depth_of([BODY] * 3, [(0, 1), (1, 2)]) == 0
    assert depth_of([GROUND, BODY], []) == 0


def test_the_cap_grows_with_the_depth_within_its_bounds():
    assert iteration_cap(4, False, 30) == 4
    assert iteration_cap(4, True, 1) == 4
    assert iteration_cap(4, True, 20) == DEPTH_PASSES * 20
    assert iteration_cap(4, True, 10_000) == MAX_ADAPTIVE
    assert iteration_cap(200, True, 10) == 200


def tower(adaptive, n=20, seconds=5.0):
    """``n`` cubes of 0.5 m stacked on the ground, stepped for ``seconds`` with ``adaptive_iterations`` on or
    off: the top cube's sideways drift (m) and the mean passes per step."""
    w = mb.World(sleeping=False)
    w.adaptive_iterations = adaptive
    w.profiling = True
    w.add_static(mb.Plane())
    boxes = [w.add_body(mb.Box((0.25, 0.25, 0.25)), position=(0.0, 0.25 + 0.5 * k, 0.0), density=500)
             for k in range(n)]
    for _ in range(round(seconds / DT)):
        w.step(DT)
    top = boxes[-1].position
    return float(np.hypot(top[0], top[2])), w.profile.iterations


def test_a_tall_tower_stands_longer_with_the_adaptive_count():
    drift, passes = tower(True)
    fixed, fixed_passes = tower(False)
    # 20 cubes over 5 s: with 4 passes per sub-step the top walks off by decimetres; with up to the depth's
    # 40 it stays within a centimetre or two (it still leans over within 20 s: bench/bench_stacks.py), and
    # the extra passes stop once no velocity changes by 1 mm/s
    assert drift < 0.02
    assert fixed > 5.0 * drift
    assert passes < 4 * DEPTH_PASSES * 20
    assert fixed_passes <= 4 * 4


def test_the_settings_read_back():
    w = mb.World()
    assert w.iterations == 4 and w.adaptive_iterations is False
    w.iterations = 12
    w.adaptive_iterations = True
    assert w.iterations == 12 and w.adaptive_iterations is True
    w.iterations = None
    assert w.iterations == 4
    with pytest.raises(ValueError, match="iterations"):
        w.iterations = 0
    with pytest.raises(TypeError, match="adaptive_iterations"):
        w.adaptive_iterations = 1
