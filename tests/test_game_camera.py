"""The follow camera against closed forms: dead zone, critically damped smoothing, look-ahead, no clipping."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from marbellous.game.camera import FollowCamera, critically_damped_step, dead_zone_anchor

finite = st.floats(-50, 50, allow_nan=False)
vec3 = st.tuples(finite, finite, finite).map(np.array)


def closed_form(e0, v0, omega, t):
    """Critically damped response x'' = -w^2 x - 2 w x' from x(0) = e0, x'(0) = v0."""
    decay = math.exp(-omega * t)
    return (e0 + (v0 + omega * e0) * t) * decay, (v0 - omega * (v0 + omega * e0) * t) * decay


@settings(max_examples=300)
@given(e0=finite, v0=finite, omega=st.floats(0.1, 20), steps=st.lists(st.floats(1e-4, 0.2), min_size=1, max_size=30))
def test_smoothing_matches_closed_form_for_any_frame_times(e0, v0, omega, steps):
    x, v = e0, v0
    for h in steps:
        x, v = critically_damped_step(x, v, 0.0, omega, h)
    xe, ve = closed_form(e0, v0, omega, sum(steps))
    scale = abs(e0) + abs(v0) / omega + 1e-12
    assert float(x) == pytest.approx(xe, abs=1e-9 * scale)
    assert float(v) == pytest.approx(ve, abs=1e-9 * scale * omega)


@settings(max_examples=200)
@given(e0=st.floats(-20, 20).filter(lambda e: abs(e) > 1e-6), omega=st.floats(0.1, 20))
def test_smoothing_from_rest_never_overshoots_and_settles(e0, omega):
    x, v, target = e0 + 3.0, 0.0, 3.0
    for _ in range(400):
        x, v = critically_damped_step(x, v, target, omega, 0.05)
        assert (x - target) * e0 >= -1e-12
    # after t = 20 / omega the error is (1 + w t) e^{-w t} e0 < 5e-8 e0
    t = 400 * 0.05
    assert abs(x - target) <= abs(e0) * (1 + omega * t) * math.exp(-omega * t) + 1e-12


def test_smoothing_satisfies_the_differential_equation():
    omega, h = 3.0, 1e-5
    x0, v0 = critically_damped_step(1.0, -0.5, 0.2, omega, 0.3)
    x1, v1 = critically_damped_step(x0, v0, 0.2, omega, h)
    acc = (v1 - v0) / h
    assert acc == pytest.approx(-omega ** 2 * (x0 - 0.2) - 2 * omega * v0, rel=1e-4)
    assert (x1 - x0) / h == pytest.approx(v0, rel=1e-4)


@settings(max_examples=300)
@given(anchor=vec3, point=vec3, radius=st.floats(0.01, 5))
def test_dead_zone_moves_anchor_the_least_distance(anchor, point, radius):
    new = dead_zone_anchor(anchor, point, radius)
    d = np.linalg.norm(point - anchor)
    if d <= radius:
        assert np.array_equal(new, anchor)
    else:
        assert np.linalg.norm(point - new) == pytest.approx(radius, rel=1e-9, abs=1e-9)
        assert np.linalg.norm(new - anchor) == pytest.approx(d - radius, rel=1e-9, abs=1e-9)
        # moved straight towards the point
        assert np.linalg.norm(np.cross(new - anchor, point - anchor)) <= 1e-9 * (d * d + 1)


def test_camera_ignores_small_movements_inside_dead_zone():
    cam = FollowCamera(dead_zone=0.6)
    start = np.array([1.0, 2.0, 3.0])
    cam.reset(start, 0.3)
    eye0 = cam.eye.copy()
    rng = np.random.default_rng(1)
    for _ in range(300):
        jitter = rng.normal(size=3)
        jitter *= 0.59 * rng.uniform() / np.linalg.norm(jitter)
        view = cam.update(1 / 60, start + jitter, (0.0, 0.0, 0.0))
    assert np.array_equal(view.target, start)
    assert np.array_equal(view.eye, eye0)


def test_camera_follows_a_jump_with_the_critically_damped_response():
    r, omega = 0.5, 4.0
    cam = FollowCamera(dead_zone=r, omega=omega)
    cam.reset((0.0, 0.0, 0.0), 0.0)
    marble = np.array([3.0, 0.0, 4.0])           # 5 m away, at rest
    target = marble * (1 - r / 5.0)              # the dead zone's edge
    t = 0.0
    for h in [1 / 60] * 30 + [1 / 144] * 50 + [0.1] * 5:
        view = cam.update(h, marble, (0.0, 0.0, 0.0))
        t += h
        e, _ = closed_form(-1.0, 0.0, omega, t)  # unit error from rest
        assert np.allclose(view.target, target + e * target, atol=1e-12)


def test_look_ahead_steady_state_lag_of_a_ramp():
    # constant velocity: the anchor trails by r, the target leads it by v L, and a critically
    # damped follower of a ramp lags its target by 2 v / omega.
    r, omega, L, v = 0.4, 5.0, 0.3, 2.0
    cam = FollowCamera(dead_zone=r, omega=omega, lookahead=L, max_lookahead=10.0, turn_speed=100.0)
    cam.reset((0.0, 0.0, 0.0), 0.0)
    h = 1 / 120
    for k in range(1, 2401):
        p = np.array([v * k * h, 0.0, 0.0])
        view = cam.update(h, p, (v, 0.0, 0.0))
    lag = p[0] - view.target[0]
    # The target is held constant over each step (sampled at the step's end).  In the sampled steady
    # state the focus lags by delta and has velocity u at the sample instants; with e0 = -v h - delta
    # and E = exp(-w h) the exact step gives  -delta = (e0 + (u + w e0) h) E  and
    # u = (u - w (u + w e0) h) E: two linear equations for (delta, u).
    E = math.exp(-omega * h)
    a = np.array([[E * (1 + omega * h) - 1, -E * h], [-omega ** 2 * h * E, 1 - E + omega * h * E]])
    b = np.array([-E * v * h * (1 + omega * h), omega ** 2 * h * h * E * v])
    delta, _u = np.linalg.solve(a, b)
    # ... which tends to the continuous ramp lag 2 v / w as h -> 0
    assert delta == pytest.approx(2 * v / omega, abs=v * h)
    assert lag == pytest.approx(r - v * L + delta, abs=1e-9)
    assert abs(view.target[2]) < 1e-12


def test_look_ahead_is_capped():
    cam = FollowCamera(dead_zone=0.0, omega=50.0, lookahead=1.0, max_lookahead=1.5, turn_speed=100.0)
    cam.reset((0.0, 0.0, 0.0), 0.0)
    for _ in range(600):
        view = cam.update(1 / 60, (0.0, 0.0, 0.0), (0.0, 0.0, 9.0))
    assert np.allclose(view.target, [0.0, 0.0, 1.5], atol=1e-9)


def test_heading_turns_to_the_direction_of_travel_the_short_way():
    cam = FollowCamera(heading_omega=2.0)
    cam.reset((0.0, 0.0, 0.0), math.radians(170))
    headings = []
    for _ in range(600):
        cam.update(1 / 60, (0.0, 0.0, 0.0), (-1.0, 0.0, -0.2))   # direction ~ -169 degrees
        headings.append(cam.heading)
    goal = math.atan2(-0.2, -1.0) + 2 * math.pi
    assert cam.heading == pytest.approx(goal, abs=1e-6)
    assert max(headings) <= goal + 1e-9                     # went through 180, no overshoot
    assert all(b >= a - 1e-12 for a, b in zip(headings, headings[1:]))


def test_heading_holds_while_slow():
    cam = FollowCamera(turn_speed=1.0)
    cam.reset((0.0, 0.0, 0.0), 0.7)
    cam.update(1 / 60, (0.0, 0.0, 0.0), (0.0, 0.0, 0.9))
    assert cam.heading == 0.7


def test_eye_is_pulled_in_front_of_geometry():
    cam = FollowCamera(distance=6.0, height=3.0, margin=0.25)
    cam.reset((0.0, 0.0, 0.0), 0.0)
    wall_x = -2.0                    # a wall x = -2 between the marble and the eye behind it (-x)

    def raycast(origin, direction, max_distance):
        if direction[0] >= 0:
            return None
        t = (wall_x - origin[0]) / direction[0]
        return t if 0 <= t <= max_distance else None

    view = cam.update(1 / 60, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), raycast)
    d = view.eye - view.target
    assert view.eye[0] > wall_x
    assert np.linalg.norm(d) == pytest.approx(2.0 / (6.0 / math.hypot(6.0, 3.0)) - 0.25)
    # the eye stays on the line from the focus to where it wanted to be
    want = cam.desired_eye() - view.target      # (the marble is at the focus here)
    assert np.linalg.norm(np.cross(d, want)) < 1e-9
    free = cam.update(1 / 60, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), lambda o, d, m: None)
    assert np.allclose(free.eye, cam.desired_eye())
