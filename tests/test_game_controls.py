"""Controls, course path and best-time records (no physics needed)."""
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from marbellous.game.controls import (clip_to_disc, control_force, control_forces, heading_axes, move_for_direction,
                                      move_from_keys)
from marbellous.game.course import CoursePath
from marbellous.game.goal import BestTimes, format_time

unit = st.floats(-1, 1, allow_nan=False)
angle = st.floats(-10, 10, allow_nan=False)


@settings(max_examples=300)
@given(f=unit, r=unit, heading=angle)
def test_force_lies_in_ground_plane_relative_to_camera(f, r, heading):
    force = control_force((f, r), heading, mass=2.0, push=5.0)
    fwd, right = heading_axes(heading)
    m = clip_to_disc((f, r))
    assert force[1] == 0.0
    assert np.linalg.norm(force) == pytest.approx(10.0 * np.hypot(*m), abs=1e-12)
    assert force @ fwd == pytest.approx(10.0 * m[0], abs=1e-12)
    assert force @ right == pytest.approx(10.0 * m[1], abs=1e-12)
    assert np.hypot(*m) <= 1.0 + 1e-12


@settings(max_examples=300)
@given(f=unit, r=unit, heading=angle)
def test_move_for_direction_inverts_control_force(f, r, heading):
    m = clip_to_disc((f, r))
    force = control_force(m, heading, mass=1.0, push=1.0)
    assert np.allclose(move_for_direction(force, heading), m, atol=1e-12)


@settings(max_examples=200)
@given(actions=st.lists(st.tuples(st.floats(-5, 5, allow_nan=False, width=32),
                                  st.floats(-5, 5, allow_nan=False, width=32)), min_size=1, max_size=20),
       headings=st.lists(angle, min_size=20, max_size=20))
def test_forces_of_many_actions_are_each_ones_force_bit_for_bit(actions, headings):
    a = np.array(actions, np.float32)
    forces = control_forces(a, headings[:len(a)], 0.7, 12.0)
    for row, action, heading in zip(forces, a, headings):
        want = control_force(move_for_direction((action[0], 0.0, action[1]), heading), heading, 0.7, 12.0)
        assert row.tobytes() == want.tobytes()


def test_heading_axes_right_handed_y_up():
    fwd, right = heading_axes(0.0)
    assert np.allclose(fwd, [1, 0, 0]) and np.allclose(right, [0, 0, 1])
    assert np.allclose(np.cross(right, fwd), [0, 1, 0])
    fwd, _ = heading_axes(math.pi / 2)
    assert np.allclose(fwd, [0, 0, 1])


def test_keys_map_to_moves():
    assert np.allclose(move_from_keys({"W"}), [1, 0])
    assert np.allclose(move_from_keys({"DOWN"}), [-1, 0])
    assert np.allclose(move_from_keys({"D"}), [0, 1])
    assert np.allclose(move_from_keys({"LEFT", "UP"}), [math.sqrt(0.5), -math.sqrt(0.5)])
    assert np.allclose(move_from_keys({"W", "S"}), [0, 0])
    assert np.allclose(move_from_keys(set()), [0, 0])


def test_bad_move_is_rejected():
    with pytest.raises(ValueError, match="move"):
        control_force((float("nan"), 0.0), 0.0, 1.0, 1.0)


def test_course_path_projection_and_points():
    path = CoursePath([[0, 0, 0], [4, 0, 0], [4, 0, 3]], speeds=[1, 2, 3])
    assert path.length == pytest.approx(7.0)
    assert path.project((2.0, 0.5, 0.3)) == pytest.approx(2.0)
    assert path.project((5.0, 0.0, 2.0)) == pytest.approx(6.0)
    assert np.allclose(path.point_at(5.5), [4, 0, 1.5])
    assert np.allclose(path.point_at(-3), [0, 0, 0]) and np.allclose(path.point_at(99), [4, 0, 3])
    assert path.speed_at(2.0) == pytest.approx(1.5)
    # with a hint, only the nearby part of the course counts
    loop = CoursePath([[0, 0, 0], [10, 0, 0], [10, 0, 1], [0, 0, 1]])
    assert loop.project((5.0, 0.0, 0.4)) == pytest.approx(5.0)
    assert loop.project((5.0, 0.0, 0.4), near=15.0, window=3.0) == pytest.approx(16.0)


@settings(max_examples=200)
@given(s=st.floats(0, 7))
def test_point_at_projects_back(s):
    path = CoursePath([[0, 0, 0], [4, 0, 0], [4, 0, 3]])
    assert path.project(path.point_at(s)) == pytest.approx(s, abs=1e-9)


@settings(max_examples=100)
@given(points=st.lists(st.tuples(*[st.floats(-20, 20)] * 3), min_size=2, max_size=12),
       positions=st.lists(st.tuples(*[st.floats(-30, 30)] * 3), min_size=1, max_size=8),
       near=st.one_of(st.none(), st.floats(-5, 60)), window=st.floats(0.0, 20.0))
def test_projecting_many_positions_gives_each_ones_projection_bit_for_bit(points, positions, near, window):
    path = CoursePath(points)
    p = np.array(positions)
    hints = None if near is None else near + np.arange(len(p), dtype=np.float64)
    many = path.project_many(p, hints, window)
    for k, q in enumerate(p):
        assert many[k] == path.project(q, None if hints is None else hints[k], window)
        assert many[k] == _projection_over_every_segment(path, q, None if hints is None else hints[k], window)
    # and it is the nearest point of the path (searched where the hint allows): slow reference
    for k, q in enumerate(p):
        best, where = np.inf, None
        for s in np.linspace(0.0, path.length, 2001):
            if hints is None or abs(s - hints[k]) <= window:
                d = np.linalg.norm(path.point_at(s) - q)
                best, where = (d, s) if d < best else (best, where)
        if where is not None:
            if hints is not None:
                assert abs(many[k] - hints[k]) <= window + 1e-9
            assert np.linalg.norm(path.point_at(many[k]) - q) <= best + 1e-9


def _projection_over_every_segment(path, q, near, window):
    """The slow reference of ``project``: every segment's nearest point (within the window's part of it),
    segments outside the window left out, the first of the nearest taken (none in the window: the first
    segment's)."""
    best, best_d2 = None, np.inf
    for i in range(len(path.seg_len)):
        a, d, s0, length = path.points[i], path._d[i], path.s[i], path.seg_len[i]
        pa = q - a
        t = min(max((pa[0] * d[0] + pa[1] * d[1] + pa[2] * d[2]) / path._len2[i], 0.0), 1.0)
        if near is not None:
            if not (s0 + length >= near - window and s0 <= near + window):
                continue
            scale = max(length, 1e-300)
            t = min(max(t, min(max((near - window - s0) / scale, 0.0), 1.0)),
                    min(max((near + window - s0) / scale, 0.0), 1.0))
        e = a + t * d - q
        d2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
        if d2 < best_d2:
            best, best_d2 = s0 + t * length, d2
    if best is None:                                # (no segment in the window)
        a, d = path.points[0], path._d[0]
        pa = q - a
        t = min(max((pa[0] * d[0] + pa[1] * d[1] + pa[2] * d[2]) / path._len2[0], 0.0), 1.0)
        scale = max(path.seg_len[0], 1e-300)
        t = min(max(t, min(max((near - window) / scale, 0.0), 1.0)), min(max((near + window) / scale, 0.0), 1.0))
        best = path.s[0] + t * path.seg_len[0]
    return best


def test_best_times_are_stored_per_level(tmp_path):
    bt = BestTimes(tmp_path / "sub" / "best.json")
    assert bt.get("course") is None
    assert bt.record("course", 30.0) is True
    assert bt.record("course", 31.0) is False
    assert bt.record("course", 25.5) is True
    assert bt.record("hills", 40.0) is True
    again = BestTimes(tmp_path / "sub" / "best.json")
    assert again.get("course") == 25.5 and again.get("hills") == 40.0
    assert json.loads((tmp_path / "sub" / "best.json").read_text()) == {"course": 25.5, "hills": 40.0}


def test_best_times_survive_a_corrupt_file_and_default_to_user_dir(tmp_path, monkeypatch):
    p = tmp_path / "best.json"
    p.write_text("{not json")
    bt = BestTimes(p)
    assert bt.get("course") is None
    assert bt.record("course", 12.0)
    assert BestTimes(p).get("course") == 12.0
    monkeypatch.setenv("MARBELLOUS_DATA_DIR", str(tmp_path / "data"))
    assert BestTimes().path == tmp_path / "data" / "best_times.json"
    mem = BestTimes(persistent=False)
    assert mem.record("x", 3.0) and mem.get("x") == 3.0 and not mem.path.exists()


def test_format_time():
    assert format_time(0) == "0:00.0"
    assert format_time(83.25) == "1:23.2" or format_time(83.25) == "1:23.3"
    assert format_time(9.96) == "0:10.0"
    assert format_time(59.96) == "1:00.0"
