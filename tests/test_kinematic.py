"""Kinematic bodies: moved by their velocities only, they carry and push dynamic bodies and are never
pushed; ``move_to`` sets the velocities that reach a pose in one step; assigning a pose teleports."""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest

import marbellous as mb

DT = 1.0 / 60.0
SOLVERS = ("sequential_impulse", "lcp", "penalty")


def _platform_world(solver="sequential_impulse"):
    w = mb.World(solver=solver)
    w.add_static(mb.Plane())
    platform = w.add_kinematic(mb.Box((1.0, 0.1, 1.0)), position=(0.0, 1.0, 0.0), friction=0.8)
    crate = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.3, 1.3, 0.0), friction=0.8)
    return w, platform, crate


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_platform_that_accelerates_gently_carries_a_crate_without_sliding(solver):
    """The platform follows x(t) = t^2 (2 m/s^2, below mu g = 7.8 m/s^2) for 1 s, then 2 m/s, by move_to
    each step.  Static friction holds the crate: it keeps its place on the platform within the solver's
    sticking creep (1 mm over the run; the penalty scheme's friction is a spring, which stretches by
    m a / k_t, under 1 mm here too)."""
    w, platform, crate = _platform_world(solver)
    for _ in range(60):
        w.step(DT)
    assert crate.is_sleeping
    start = crate.position - platform.position
    for k in range(1, 121):
        t = k * DT
        x = t * t if t <= 1.0 else 2.0 * t - 1.0
        platform.move_to((x, 1.0, 0.0), (1.0, 0.0, 0.0, 0.0), DT)
        w.step(DT)
    assert platform.position[0] == pytest.approx(3.0, abs=1e-9)
    np.testing.assert_allclose(crate.position - platform.position, start, atol=1e-3)
    np.testing.assert_allclose(crate.velocity, [2.0, 0.0, 0.0], atol=1e-3)


def test_a_kinematic_body_is_never_pushed():
    """A 1000 kg box thrown at a kinematic wall, and a rod pulling on it: the wall keeps its velocity and
    path exactly (x = x0 + v t, to round-off)."""
    w = mb.World()
    wall = w.add_kinematic(mb.Box((0.1, 1.0, 1.0)), position=(0.0, 2.0, 0.0), velocity=(0.5, 0.0, 0.0))
    w.add_body(mb.Box((0.3, 0.3, 0.3)), mass=1000.0, position=(1.0, 2.0, 0.0), velocity=(-5.0, 0.0, 0.0))
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 0.5, 0.0))
    w.add_rod(wall, ball)
    wall.apply_force((1e6, 0.0, 0.0))
    wall.apply_impulse((0.0, 1e6, 0.0))
    for _ in range(120):
        w.step(DT)
    np.testing.assert_allclose(wall.velocity, [0.5, 0.0, 0.0], atol=0.0)
    np.testing.assert_allclose(wall.position, [0.5 * 120 * DT, 2.0, 0.0], atol=1e-12)
    assert (wall.mass, wall.is_kinematic, wall.is_static, wall.is_sleeping) == (math.inf, True, False, False)


@pytest.mark.parametrize("phase", [0.0, 0.25, 0.5, 0.75])
def test_a_paddle_pushes_a_ball_at_its_own_speed(phase):
    """A paddle at 1 m/s meets a ball on frictionless ice (``phase``: where in a step they meet): an
    inelastic push (e = 0) through one contact point leaves the ball moving exactly as fast as the paddle,
    face to face with it."""
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.0)
    paddle = w.add_kinematic(mb.Box((0.1, 0.3, 0.5)), position=(-1.0 - phase * DT, 0.3, 0.0),
                             velocity=(1.0, 0.0, 0.0), friction=0.0)
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 0.2, 0.0), friction=0.0)
    for _ in range(90):
        w.step(DT)
    np.testing.assert_allclose(ball.velocity, [1.0, 0.0, 0.0], atol=1e-12)
    assert ball.position[0] - paddle.position[0] == pytest.approx(0.3, abs=1e-12)


@pytest.mark.xfail(strict=True, reason="known: a face of four contact points that closes exactly at a step's "
                                       "end is left up to 3.3% too fast (one relax pass under-solves it, the "
                                       "warm start then over-solves); a 1e6 kg dynamic paddle does the same")
def test_a_paddle_pushes_a_box_at_its_own_speed():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    paddle = w.add_kinematic(mb.Box((0.1, 0.3, 0.5)), position=(-0.4, 0.3, 0.0), velocity=(1.0, 0.0, 0.0))
    box = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.0, 0.2, 0.0))
    for _ in range(30):
        w.step(DT)
    assert box.velocity[0] == pytest.approx(paddle.velocity[0], abs=1e-3)


def test_move_to_reaches_the_pose_in_one_step():
    w = mb.World()
    door = w.add_kinematic(mb.Box((0.5, 1.0, 0.05)), position=(1.0, 1.0, 0.0))
    axis = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    target = (math.cos(math.pi / 4), *(axis * math.sin(math.pi / 4)))       # 90 deg about axis
    door.move_to((2.0, 1.5, -1.0), target, 0.05)
    np.testing.assert_allclose(door.angular_velocity, axis * (math.pi / 2) / 0.05, rtol=1e-12)
    w.step(0.05)
    np.testing.assert_allclose(door.position, [2.0, 1.5, -1.0], atol=1e-12)
    np.testing.assert_allclose(door.orientation, target, atol=1e-12)


def test_teleporting_a_platform_drops_what_slept_on_it():
    w, platform, crate = _platform_world()
    for _ in range(60):
        w.step(DT)
    assert crate.is_sleeping
    platform.position = (10.0, 1.0, 0.0)
    np.testing.assert_array_equal(platform.velocity, [0.0, 0.0, 0.0])
    assert not crate.is_sleeping
    for _ in range(60):
        w.step(DT)
    assert crate.position[1] == pytest.approx(0.2, abs=1e-3)           # fell to the ground


def test_a_platform_set_moving_wakes_its_sleeping_riders():
    w, platform, crate = _platform_world()
    for _ in range(60):
        w.step(DT)
    assert crate.is_sleeping
    platform.move_to((0.0, 1.01, 0.0), (1.0, 0.0, 0.0, 0.0), DT)      # rises 1 cm per step
    w.step(DT)
    # the wake step reports the pair once: its four corners, met afresh (not also kept from the cache)
    assert sum(platform in (c.body_a, c.body_b) for c in w.contacts()) == 4
    for _ in range(29):
        w.step(DT)
    assert not crate.is_sleeping
    assert crate.position[1] - platform.position[1] == pytest.approx(0.3, abs=1e-3)


@pytest.mark.parametrize("call, name", [
    (lambda w, k, d: d.move_to((0, 0, 0), (1, 0, 0, 0), DT), "move_to"),
    (lambda w, k, d: k.move_to((0, 0, 0), (1, 0, 0, 0), 0.0), "dt"),
    (lambda w, k, d: k.move_to((0, float("nan"), 0), (1, 0, 0, 0), DT), "position"),
    (lambda w, k, d: k.move_to((1e12, 0, 0), (1, 0, 0, 0), 1e-6), "position"),
    (lambda w, k, d: w.add_kinematic(mb.Plane()), "static only"),
    (lambda w, k, d: w.add_kinematic(mb.Sphere(1.0), velocity=(0, float("inf"), 0)), "velocity"),
    (lambda w, k, d: w.add_rod(k, None, length=1.0), "dynamic body"),
])
def test_bad_kinematic_calls_are_refused_and_change_nothing(call, name):
    w = mb.World()
    kinematic = w.add_kinematic(mb.Sphere(0.5), position=(0.0, 2.0, 0.0))
    dynamic = w.add_body(mb.Sphere(0.5))
    before = w.state_hash()
    with pytest.raises((ValueError, TypeError), match=name):
        call(w, kinematic, dynamic)
    assert w.state_hash() == before


def _ride():
    return runpy.run_path(str(Path(__file__).parents[1] / "examples" / "platforms.py"))["run"]()


def test_the_example_elevator_carries_its_crate_and_the_turntable_turns_it():
    """examples/platforms.py: after 6 s the elevator's crate rests on it (0.3 m above: half heights 0.1 +
    0.2, within the contact's 0.1 mm sink); the turntable turned by the sum of its angular velocities
    and its crate went round with it (the same angle within 1e-3 rad, 0.6 mm along its path: it does not
    slip along the path; it creeps outwards, below)."""
    above, crate_angle, table_angle, _ = _ride()
    assert above == pytest.approx(0.3, abs=2e-4)
    turned = sum(min(0.5 * (k + 1) / 60.0, 1.0) for k in range(360)) / 60.0
    assert table_angle % (2 * math.pi) == pytest.approx(turned % (2 * math.pi), abs=1e-9)
    assert abs(math.remainder(crate_angle - table_angle, 2 * math.pi)) < 1e-3    # 0.6 mm along its path


@pytest.mark.xfail(strict=True, reason="known: a crate on a turntable creeps outwards by (omega r dt)^2 / (2 r) "
                                       "per step (2.4 cm in 6 s here): friction acts at the contact points "
                                       "found when the step began")
def test_the_turntable_crate_keeps_its_radius():
    assert _ride()[3] == pytest.approx(0.6, abs=1e-3)
