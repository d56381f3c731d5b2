"""The viewer's stepping (real time, pause, one step, reset, the cap per frame) and its stats line."""
import numpy as np
import pytest

import marbellous as mb
from marbellous.app.sim_runner import SimRunner
from marbellous.app.stats import stats_line


def falling_ball():
    w = mb.World()
    w.add_static(mb.Plane())
    return w, w.add_body(mb.Sphere(0.5), position=(0.0, 3.0, 0.0))


def test_runner_steps_in_real_time_and_pauses():
    w, ball = falling_ball()
    r = SimRunner(w, 1 / 60)
    r.advance(0.05)                            # three steps fit, the rest waits for the next frame
    assert r.steps == 3 and w.time == pytest.approx(0.05)
    assert r.step_seconds is not None and r.step_seconds > 0
    r.paused = True
    r.advance(1.0)
    assert r.steps == 3
    r.step_once()
    assert r.steps == 4 and r.paused and w.time == pytest.approx(4 / 60)


def test_runner_caps_the_steps_of_a_long_frame():
    w, _ = falling_ball()
    r = SimRunner(w, 1 / 60, max_steps=4)
    r.advance(1.0)                             # a stalled frame: 4 steps, the other 56 dropped
    assert r.steps == 4
    r.advance(1 / 60)
    assert r.steps == 5


def test_runner_resets_to_the_start():
    w, ball = falling_ball()
    start = ball.position
    r = SimRunner(w, 1 / 60, paused=True)
    for _ in range(30):
        r.step_once()
    assert ball.position[1] < start[1] - 0.5
    r.reset()
    assert r.steps == 0 and w.time == 0.0 and np.array_equal(ball.position, start)


def test_runner_checks_its_arguments():
    w, _ = falling_ball()
    with pytest.raises(ValueError, match="dt must be > 0"):
        SimRunner(w, 0.0)
    with pytest.raises(TypeError, match="max_steps_per_frame must be an integer"):
        SimRunner(w, 1 / 60, max_steps=2.5)


def test_stats_line():
    w, ball = falling_ball()
    line = stats_line(w, contacts=3, step_seconds=0.00042, paused=True)
    assert line == "bodies 2 (1 static, 0 asleep)  |  contacts 3  |  step 0.42 ms  |  t 0.00 s  |  paused"
    assert "step" not in stats_line(w, contacts=0)
