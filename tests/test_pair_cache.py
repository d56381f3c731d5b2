"""The body-pair cache (``pipeline/pair_cache.py``, ``World.pair_cache``): a pair that has hardly moved keeps last
step's contact points, carried along with its two bodies.

Checked against the pair tests themselves: a rigid motion of both bodies together changes no contact but by
that motion, so the rows rebuilt from the cache must be the rows a fresh test finds at the new poses (to
rounding); a relative move past the thresholds must be tested afresh (the rows are a fresh test's, bit for
bit); a face sliding on a face within them keeps its depth exactly.  In a world: an awake stack stands as it
does without the cache, and the flag is checked like the others.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

import marbellous as mb
from marbellous.pipeline.pair_cache import KEEP_ANGLE, KEEP_DISTANCE
from marbellous.pipeline.collide import narrow_phase_all, pose_tables, update_aabbs
from marbellous.scenes import box_pyramid, box_tower
from marbellous.state import layout as L

DT = 1.0 / 60.0
SPECULATIVE = 0.02


def _two_boxes(tilt, sensor=False):
    """A world of a box resting on a bigger one (b's bottom face on a's top face, sunk 5 mm), b turned about
    the vertical by ``tilt`` rad: four face-face points."""
    w = mb.World()
    w.add_body(mb.Box((0.5, 0.2, 0.5)), position=(0.0, 0.0, 0.0))
    q = (math.cos(tilt / 2), 0.0, math.sin(tilt / 2), 0.0)
    w.add_body(mb.Box((0.25, 0.25, 0.25)), position=(0.05, 0.445, -0.03), orientation=q, sensor=sensor)
    return w


def _narrow(w, previous=None, speculative=SPECULATIVE, matched=None):
    """The narrow phase of the world's one pair at its poses: ``(n, raw_f, raw_i, ci, cf)``, reusing
    ``previous`` (an earlier result) as last step's table when given; its rows ``matched`` (all by default) are
    marked as warm-started from the step before, as a pair test that found the same features twice running
    leaves them (the step's "match" stage)."""
    st = w._state
    nb = st.bodies.end
    aabbs, sweep = np.zeros((nb, 6)), np.zeros(nb)
    pos_t, rot_t, state, q = pose_tables(st.sf.shape[0])
    update_aabbs(st.bf, st.bi, st.sf, st.si, nb, aabbs, sweep, DT, 9.81, speculative, pos_t, rot_t, q)
    pairs = np.array([[0, 1]], dtype=np.int64)
    raw_f, raw_i = np.zeros((64, 7)), np.zeros(64, np.int64)
    ci, cf = np.zeros((64, L.CI_COLS), np.int64), np.zeros((64, L.CF_COLS))
    if previous is None:
        pcf, pci, npc = cf[:0], ci[:0], 0
    else:
        npc, _, _, pci, pcf = previous
        pci = pci.copy()
        pci[:npc if matched is None else matched, L.C_FLAGS] |= L.CP_MATCHED
    n = narrow_phase_all(st.bf, st.bi, st.sf, st.si, st.geom_f, st.geom_i, pairs, 1, sweep, speculative, raw_f,
                         raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)
    return n, raw_f, raw_i, ci, cf


def _reused(w, previous, speculative=SPECULATIVE):
    """Whether the narrow phase takes the pair's rows from ``previous`` rather than testing it: a copy of it
    whose features are marked comes back with the marks only if its rows were used."""
    n, raw_f, raw_i, ci, cf = previous
    marked = ci.copy()
    marked[:n, L.C_FEATURE] = -7
    m, _, out_i, _, _ = _narrow(w, (n, raw_f, raw_i, marked, cf), speculative)
    return bool(np.all(out_i[:m] == -7))


def _quat(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def _mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _rotate(q, v):
    u, s = q[1:], q[0]
    return v + 2.0 * s * np.cross(u, v) + 2.0 * np.cross(u, np.cross(u, v))


def _move_both(w, shift, turn):
    """Both bodies moved together by the rigid motion ``x -> turn x + shift`` (about the origin)."""
    bf = w._state.bf
    for i in range(2):
        bf[i, L.POS:L.POS + 3] = _rotate(turn, bf[i, L.POS:L.POS + 3]) + shift
        bf[i, L.QUAT:L.QUAT + 4] = _mul(turn, bf[i, L.QUAT:L.QUAT + 4])


@settings(max_examples=40, deadline=None)
@given(hs.floats(-0.6, 0.6), hs.lists(hs.floats(-3.0, 3.0), min_size=3, max_size=3),
       hs.lists(hs.floats(-1.0, 1.0), min_size=3, max_size=3).filter(lambda a: np.linalg.norm(a) > 0.1),
       hs.floats(-math.pi, math.pi))
def test_rows_from_the_cache_are_a_fresh_tests_rows_after_a_rigid_motion_of_the_pair(tilt, shift, axis, angle):
    # moving both bodies together moves each contact point with them and changes no depth or feature: the
    # cache's rows at the new poses are the pair test's, to rounding (|x| ~ 3 m: 1e-12 m)
    w = _two_boxes(tilt)
    found = _narrow(w)
    assert found[0] == 4
    _move_both(w, np.asarray(shift), _quat(axis, angle))
    assert _reused(w, found)
    n, raw_f, raw_i, ci, _ = _narrow(w, found)
    fresh_n, fresh_f, fresh_i, fresh_ci, _ = _narrow(w)
    assert n == fresh_n == 4
    # (the same features, in the same order: the pair test's order is by feature)
    assert np.array_equal(raw_i[:n], fresh_i[:n])
    assert np.array_equal(ci[:n], fresh_ci[:n])
    assert np.allclose(raw_f[:n], fresh_f[:n], rtol=0.0, atol=1e-12)


def test_a_pair_moved_past_the_thresholds_is_tested_again_and_a_slide_within_them_keeps_its_depth():
    w = _two_boxes(0.3)
    found = _narrow(w)
    bf = w._state.bf
    # b slides along a's top face by less than KEEP_DISTANCE: kept (the points ride with b, the depth stays)
    bf[1, L.POS] += 0.6 * KEEP_DISTANCE
    assert _reused(w, found)
    n, raw_f, raw_i, _, cf = _narrow(w, found)
    fresh = _narrow(w)
    assert n == 4 and np.array_equal(raw_f[:n, 6], found[1][:n, 6])
    assert np.allclose(raw_f[:n, 6], fresh[1][:n, 6], rtol=0.0, atol=1e-15)
    # the kept rows keep the pose they were found at, so a second slide adds up and passes the threshold
    kept = (n, raw_f, raw_i, found[3], cf)
    bf[1, L.POS] += 0.6 * KEEP_DISTANCE
    assert not _reused(w, kept)
    n, raw_f, raw_i, _, _ = _narrow(w, kept)
    fresh = _narrow(w)
    assert np.array_equal(raw_f[:n], fresh[1][:fresh[0]]) and np.array_equal(raw_i[:n], fresh[2][:fresh[0]])
    # the same pose, but the pair test would now report points farther apart (a faster approach, a bigger
    # speculative distance): tested again (a rock falling at 5 m/s just after its first corner hit the ground
    # kept that one point for the next step, and its next corners went 10 cm into the ground)
    w = _two_boxes(0.3)
    found = _narrow(w)
    assert _reused(w, found, SPECULATIVE) and not _reused(w, found, 2.0 * SPECULATIVE)
    # a turn past KEEP_ANGLE: tested again, bit for bit the pair test
    w = _two_boxes(0.3)
    found = _narrow(w)
    bf = w._state.bf
    bf[1, L.QUAT:L.QUAT + 4] = _mul(_quat((0.0, 1.0, 0.0), 1.2 * KEEP_ANGLE), bf[1, L.QUAT:L.QUAT + 4])
    assert not _reused(w, found)
    n, raw_f, _, _, _ = _narrow(w, found)
    fresh = _narrow(w)
    assert np.array_equal(raw_f[:n], fresh[1][:fresh[0]])
    # and within it, kept: the old points turned with b, not the pair test's
    w = _two_boxes(0.3)
    found = _narrow(w)
    bf = w._state.bf
    bf[1, L.QUAT:L.QUAT + 4] = _mul(_quat((1.0, 0.0, 0.0), 0.5 * KEEP_ANGLE), bf[1, L.QUAT:L.QUAT + 4])
    assert _reused(w, found)
    # (b's points turned with it: the far side of its face 4.4 mm deeper at a turn of 1 degree, as the pair
    # test finds it, to the second order in the angle: 0.25 m (1 - cos 1 deg) = 38 um)
    n, raw_f, raw_i, _, _ = _narrow(w, found)
    fresh = _narrow(w)
    assert n == 4 and np.array_equal(raw_i[:n], found[2][:n])
    assert np.abs(raw_f[:n, 6] - fresh[1][:n, 6]).max() < 0.25 * (1.0 - math.cos(KEEP_ANGLE / 2)) + 1e-12


@pytest.mark.parametrize("build", [lambda: box_pyramid(base=10), lambda: box_tower(height=10)])
def test_an_awake_stack_stands_with_the_cache_as_without_it(build):
    # a stack kept awake for 5 s: with the cache its boxes end where they end without it, within a millimetre
    # (the points are the same to the thresholds: 0.2 mm, half a degree of relative motion between tests)
    ends = []
    for cache in (True, False):
        w, boxes = build()
        w.sleeping = False
        w.pair_cache = cache
        start = np.array([b.position for b in boxes])
        for _ in range(300):
            w.step(DT)
        ends.append(np.array([b.position for b in boxes]))
        assert np.abs(ends[-1] - start).max() < 0.02        # it stands
    assert np.abs(ends[0] - ends[1]).max() < 1e-3


def test_points_found_once_are_tested_again():
    # a pair test's points are kept once they have been found twice running (warm-started): a manifold that
    # changes from one test to the next (a corner touching for one step) is not carried on
    w = _two_boxes(0.3)
    n, raw_f, raw_i, ci, cf = _narrow(w)
    marked = ci.copy()
    marked[:n, L.C_FEATURE] = -7
    # (the first of the four rows warm-started, the others new)
    m, _, out_i, _, _ = _narrow(w, (n, raw_f, raw_i, marked, cf), matched=1)
    assert m == n == 4 and not np.any(out_i[:m] == -7)
    # (all four warm-started: kept)
    m, _, out_i, _, _ = _narrow(w, (n, raw_f, raw_i, marked, cf))
    assert m == n and np.all(out_i[:m] == -7)


def test_a_lone_sphere_and_a_sensor_are_always_tested():
    w = mb.World()
    w.add_body(mb.Box((0.5, 0.2, 0.5)), position=(0.0, 0.0, 0.0))
    w.add_body(mb.Sphere(0.25), position=(0.0, 0.445, 0.0))
    found = _narrow(w)
    assert found[0] == 1 and not _reused(w, found)
    w = _two_boxes(0.3, sensor=True)
    found = _narrow(w)
    assert found[0] > 0 and not _reused(w, found)


def test_the_flag_is_a_checked_bool():
    w = mb.World()
    assert w.pair_cache is True
    w.pair_cache = False
    assert w.pair_cache is False
    with pytest.raises(TypeError, match="pair_cache"):
        w.pair_cache = 1
    assert w.pair_cache is False
