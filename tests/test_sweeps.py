"""Parameter sweeps (``marbellous/sweeps.py``) on every backend, the autopilot trial they run, the
``marbellous sweep`` command, and Marbellous-v0 in Ray's environment registry for RLlib."""
import csv
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.game.trial import autopilot_trial


def _same_rows(a, b):
    """Rows equal value for value, NaN equal to NaN (a trial that did not reach the goal has time NaN)."""
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        assert list(ra) == list(rb)
        for key in ra:
            same = ra[key] == rb[key] or (isinstance(ra[key], float) and math.isnan(ra[key]) and math.isnan(rb[key]))
            assert same, (key, ra[key], rb[key])


def _square(x, y=0):
    """A run for the tests: importable by the workers."""
    return {"square": x * x + y}


def _not_a_dict(x):
    return [x]


def _clash(x):
    return {"x": x}


def _fails(x):
    raise ArithmeticError(f"run {x} failed")


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray of two CPUs for this module's tests (stopped after them)."""
    import ray

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    ray.shutdown()


def test_a_grid_is_every_combination_with_the_last_axis_fastest():
    assert mb.grid(a=[1, 2], b=("x", "y")) == [{"a": 1, "b": "x"}, {"a": 1, "b": "y"},
                                               {"a": 2, "b": "x"}, {"a": 2, "b": "y"}]
    assert len(mb.grid(seed=range(7), f=[0.1, 0.2, 0.3])) == 21
    assert mb.grid() == [{}]


@pytest.mark.parametrize("axes,error", [({"a": []}, ValueError), ({"a": "abc"}, TypeError), ({"a": 3}, TypeError),
                                        ({"a": {"k": 1}}, TypeError), ({"a": range(10 ** 4), "b": range(10 ** 4)},
                                                                       ValueError)])
def test_a_bad_grid_is_refused_naming_its_axis(axes, error):
    with pytest.raises(error, match=r"^a must|^the grid holds"):
        mb.grid(**axes)


def test_a_sweep_gives_the_parameters_then_the_results_in_the_order_of_the_runs():
    rows = mb.sweep(_square, mb.grid(x=[3, 1, 2], y=[10]))
    assert rows == [{"x": 3, "y": 10, "square": 19}, {"x": 1, "y": 10, "square": 11}, {"x": 2, "y": 10, "square": 14}]
    assert mb.sweep(_square, []) == []


@pytest.mark.parametrize("kwargs,error,word", [
    (dict(run=3, runs=[{"x": 1}]), TypeError, "run"),
    (dict(run=_square, runs={"x": 1}), TypeError, "runs"),
    (dict(run=_square, runs="x=1"), TypeError, "runs"),
    (dict(run=_square, runs=[{"x": 1}, 5]), TypeError, r"runs\[1\]"),
    (dict(run=_square, runs=[{1: 1}]), TypeError, r"runs\[0\]"),
    (dict(run=_square, runs=[{"x": 1}], backend="gpu"), ValueError, "backend"),
    (dict(run=_square, runs=[{"x": 1}], backend=None), TypeError, "backend"),
    (dict(run=_square, runs=[{"x": 1}], workers=0), ValueError, "workers"),
    (dict(run=_square, runs=[{"x": 1}], workers=2.0), TypeError, "workers"),
    (dict(run=_square, runs=[{"x": 1}], address="auto"), ValueError, "address"),
    (dict(run=_square, runs=[{"x": 1}], backend="ray", address=5), ValueError, "address"),
])
def test_bad_sweep_arguments_are_refused_before_any_run(kwargs, error, word):
    with pytest.raises(error, match=word):
        mb.sweep(**kwargs)


@pytest.mark.parametrize("run,error,word", [(_not_a_dict, TypeError, "dict"), (_clash, ValueError, "x"),
                                            (_fails, ArithmeticError, "run 1 failed")])
def test_a_run_that_returns_no_table_row_or_fails_is_reported(run, error, word):
    with pytest.raises(error, match=word):
        mb.sweep(run, [{"x": 1}])


def test_the_autopilot_trial_reports_the_goal_the_time_and_the_progress():
    done = autopilot_trial("course", seconds=40.0)
    assert done["reached"] and done["falls"] == 0
    # the time to the goal is the steps taken to reach it, each of the game's 1/120 s
    assert done["time"] == pytest.approx(done["steps"] / 120.0, abs=1e-9)
    # it stopped where the goal is: near the course's end
    assert done["progress"] > 0.9 * mb_course_length("course")
    short = autopilot_trial("course", seconds=1.0)
    assert not short["reached"] and math.isnan(short["time"]) and short["steps"] == 120
    assert 0.0 < short["progress"] < done["progress"]
    still = autopilot_trial("course", push=0.0, seconds=0.0)
    assert still["steps"] == 0 and still["progress"] == pytest.approx(0.0, abs=0.5)
    assert autopilot_trial("hills", friction=0.3, start_offset=0.2, seconds=2.0) == \
        autopilot_trial("hills", friction=0.3, start_offset=0.2, seconds=2.0)


def mb_course_length(level):
    from marbellous.game.course import CoursePath
    from marbellous.game.level import load_level

    lvl = load_level(level)
    return CoursePath(lvl.path).length


@pytest.mark.parametrize("name,value,error", [
    ("level", 3, TypeError), ("level", "nosuch-level", ValueError), ("friction", -0.1, ValueError),
    ("friction", math.nan, ValueError), ("push", "9", TypeError), ("push", 1e4, ValueError),
    ("start_offset", math.inf, ValueError), ("seconds", -1.0, ValueError), ("seconds", 1e9, ValueError),
    ("flag", 1, TypeError)])
def test_bad_trial_parameters_are_refused_naming_them(name, value, error):
    with pytest.raises(error, match=name if name != "level" else "level|nosuch"):
        autopilot_trial(**{"seconds": 0.5, name: value})


def test_a_sweep_in_local_processes_equals_the_serial_one():
    runs = mb.grid(friction=[0.3, 0.7], start_offset=[-0.2, 0.2], seconds=[0.5])
    _same_rows(mb.sweep(autopilot_trial, runs, backend="processes", workers=2), mb.sweep(autopilot_trial, runs))


def test_a_sweep_of_100_runs_on_a_local_ray_equals_the_serial_one(local_ray):
    runs = mb.grid(friction=np.linspace(0.1, 1.0, 10).tolist(), start_offset=np.linspace(-0.4, 0.4, 10).tolist(),
                   seconds=[0.5])
    assert len(runs) == 100
    on_ray = mb.sweep(autopilot_trial, runs, backend="ray")
    assert local_ray.is_initialized()             # (a Ray the caller started is left running)
    serial = mb.sweep(autopilot_trial, runs)
    _same_rows(on_ray, serial)
    assert len({r["progress"] for r in serial}) > 10     # the runs differ: the parameters reached them


def test_marbellous_v0_is_in_rays_registry_for_rllib_and_its_workers_make_it(local_ray):
    import gymnasium as gym

    from marbellous.app.envs.rllib import make_env, register_rllib

    register_rllib()

    @local_ray.remote
    def first_steps(config):
        """On a Ray worker: the environment RLlib would make from the registry, reset and stepped."""
        from ray.tune.registry import ENV_CREATOR, _global_registry

        env = _global_registry.get(ENV_CREATOR, "Marbellous-v0")(config)
        obs, _ = env.reset(seed=5)
        return [obs] + [env.step(np.array([0.5, -0.25], np.float32))[0] for _ in range(3)]

    config = {"level": "hills", "frame_skip": 2}
    remote = local_ray.get(first_steps.remote(config))
    env = gym.make("Marbellous-v0", **config)
    here = [env.reset(seed=5)[0]] + [env.step(np.array([0.5, -0.25], np.float32))[0] for _ in range(3)]
    for a, b in zip(remote, here):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(TypeError, match="env_config"):
        make_env("hills")
    with pytest.raises(TypeError, match="name"):
        register_rllib("")


def test_the_sweep_command_writes_the_table_of_the_runs(tmp_path, capsys):
    from marbellous.cli import main

    out = tmp_path / "sweep.csv"
    assert main(["sweep", "--backend", "serial", "--friction", "0.3", "0.6", "--seconds", "0.5",
                 "--out", str(out)]) == 0
    assert "2 runs, 0 reached the goal" in capsys.readouterr().out
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    want = [autopilot_trial("course", friction=f, seconds=0.5) for f in (0.3, 0.6)]
    assert [float(r["progress"]) for r in rows] == [w["progress"] for w in want]
    assert [int(r["steps"]) for r in rows] == [60, 60] and [r["level"] for r in rows] == ["course", "course"]


@pytest.mark.parametrize("argv,word", [(["--level", "nosuch-level"], "nosuch-level"),
                                       (["--friction", "-1"], "friction"), (["--out", "table.txt"], "--out"),
                                       (["--friction", "0.5", "11"], "friction"),
                                       (["--push", "9", "9", "-2"], "push"),
                                       (["--start-offset", "0", "1e9"], "start_offset"),
                                       (["--workers", "0"], "workers"), (["--seconds", "nan"], "seconds")])
def test_the_sweep_command_refuses_bad_arguments_in_one_line(argv, word, capsys, tmp_path, monkeypatch):
    """Every run's numbers are checked before any run starts (a bad value in the last run too)."""
    from marbellous.cli import main
    from marbellous.game import trial

    played = []
    monkeypatch.setattr(trial, "autopilot_trial", lambda **run: played.append(run))
    assert main(["sweep", "--backend", "serial", "--seconds", "0.5", "--out", str(tmp_path / "t.csv")] + argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("marbellous sweep: error:") and word in err and err.count("\n") == 1
    assert not (tmp_path / "t.csv").exists() and played == []
