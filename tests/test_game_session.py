"""The game with physics: each level holds a resting marble, controls push it, falls respawn, goals count."""
import numpy as np
import pytest

from marbellous.game.goal import BestTimes, GoalArea
from marbellous.game.level import LevelError, load_level
from marbellous.game.session import Game


def game(name, **kw):
    return Game(load_level(name), best_times=BestTimes(persistent=False), **kw)


@pytest.mark.parametrize("name", ["course", "hills", "blocks"])
def test_marble_at_start_comes_to_rest_on_the_level(name):
    g = game(name)
    for _ in range(int(4.0 / g.dt)):
        g.step()
    b = g.marble
    assert g.respawns == 0
    assert np.linalg.norm(b.velocity) < 0.05
    assert np.linalg.norm(b.angular_velocity) * g.spec.radius < 0.05
    # it rests where it was put (the starts are on flat ground), on the surface, not in it
    assert np.linalg.norm(b.position[[0, 2]] - g.level.start_position[[0, 2]]) < 0.3
    assert g.on_ground()
    below = g.raycast_level(b.position, np.array([0.0, -1.0, 0.0]), 5.0)
    assert below == pytest.approx(g.spec.radius, abs=0.02)


def test_push_rolls_the_marble_along_the_camera_heading():
    g = game("blocks")
    for _ in range(60):
        g.step()
    x0 = g.marble.position.copy()
    for _ in range(120):            # 1 s forward
        g.step((1.0, 0.0))
    p, v = g.marble.position, g.marble.velocity
    # heading 0 looks along +x; rolling without slipping: a = 5/7 F/m on level ground
    assert v[0] > 0.5 * 5 / 7 * g.spec.push * 1.0
    assert abs(p[2] - x0[2]) < 0.05
    w = g.marble.angular_velocity
    assert w[2] == pytest.approx(-v[0] / g.spec.radius, rel=0.1)   # rolling: omega x r = v


def test_jump_only_from_the_ground():
    g = game("blocks")
    for _ in range(60):
        g.step()
    g.step(jump=True)
    assert g.marble.velocity[1] > 0.8 * g.spec.jump_speed
    for _ in range(10):
        g.step()
    vy = g.marble.velocity[1]
    g.step(jump=True)               # in the air: no second jump
    assert g.marble.velocity[1] < vy


def test_fall_respawns_and_restart_resets_timer():
    g = game("course")
    g.marble.position = (0.0, g.level.fall_height + 0.1, -30.0)
    g.marble.velocity = (0.0, -3.0, 0.0)
    for _ in range(10):
        g.step()
    assert g.respawns == 1
    assert np.allclose(g.marble.position, g.level.start_position, atol=0.1)
    assert g.elapsed > 0
    g.restart()
    assert g.elapsed == 0 and g.respawns == 0


def test_goal_box_sphere_test_against_closest_point():
    goal = GoalArea((1.0, 2.0, 3.0), (0.5, 1.0, 1.5))
    rng = np.random.default_rng(2)
    for _ in range(300):
        p = rng.uniform(-3, 6, 3)
        r = rng.uniform(0.05, 1.0)
        closest = np.clip(p, goal.center - goal.half_extents, goal.center + goal.half_extents)
        d = np.linalg.norm(p - closest)
        if abs(d - r) > 1e-6:
            assert goal.reached(p, r) == (d < r)


def test_reaching_goal_stops_timer_and_records_best():
    g = game("blocks")
    g.marble.position = g.level.goal_center
    g.step()
    assert g.finished and g.new_best and g.finish_time == pytest.approx(g.dt)
    t = g.elapsed
    g.step()
    assert g.elapsed == t
    assert g.best_times.get("blocks") == pytest.approx(g.dt)
    assert any("GOAL" in line for line in g.hud_lines())


def test_camera_never_ends_inside_geometry():
    g = game("blocks")
    # the marble beside the ramp, the camera low and looking along -x: the eye wants to be at
    # x = 15, inside the goal platform (x 11..17, y 0..1.5)
    g.marble.position = (9.0, 0.3, 2.0)
    g.camera.height = 0.5
    g.camera.reset(g.marble.position, np.pi)
    view = g.update_camera(1 / 60)
    d = view.eye - view.target
    hit = g.raycast_level(view.target, d / np.linalg.norm(d), np.linalg.norm(d))
    assert hit is None
    assert np.linalg.norm(d) < g.camera.distance


def test_a_marble_bounces_off_the_soft_bumper_and_restart_rests_it():
    game = Game(load_level("blocks"), flag=False)
    bumper, = game.soft_blocks
    rest = bumper.positions
    game.marble.position = (-3.5, 0.32, -0.5)
    game.marble.velocity = (0.0, 0.0, 4.0)
    dented = 0.0
    for _ in range(240):
        game.step()
        dented = max(dented, np.abs(bumper.positions - rest).max())
    assert game.marble.velocity[2] < -0.5          # thrown back
    assert 0.005 < dented < 0.25 and np.all(np.isfinite(bumper.positions))      # dented, not torn through
    game.restart()
    assert np.array_equal(bumper.positions, rest) and not bumper.velocities.any()


def test_the_brook_carries_the_marble_downstream_and_restart_calms_it():
    game = Game(load_level("blocks"), flag=False)
    brook, = game.streams
    stream = game.level.streams[0]
    game.marble.position = (3.0, 0.32, 0.0)
    game.marble.velocity = (0.0, 0.0, 0.0)
    for _ in range(240):                          # 2 s in the brook, no control
        game.step()
    assert game.marble.velocity[2] > 0.1 and game.marble.position[2] > 0.1      # rolled along +z
    # the pump holds the stream's mean velocity within the share that the marble in it takes away over PUMP_TIME
    mean = brook.velocity.mean(axis=(0, 1, 2))
    assert mean == pytest.approx(stream.velocity, abs=0.1 * np.linalg.norm(stream.velocity))
    brook.dye = np.ones(brook.resolution)
    game.restart()
    assert not brook.dye.any() and np.allclose(brook.velocity, stream.velocity)


def test_a_level_whose_marble_starts_in_the_goal_is_refused():
    level = load_level("course")
    level.start_position = level.goal_center + (0.0, level.goal_half_extents[1] + 0.1, 0.0)   # on the goal's top
    with pytest.raises(LevelError, match="starts in the goal"):
        Game(level, best_times=BestTimes(persistent=False), flag=False)
