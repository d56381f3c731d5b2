"""The benchmark runner (bench/__main__.py): a scene's repeats go round the engines in turn, each engine
keeps its fastest run, and an engine that cannot run is not tried again; where a run writes; the runner
starts from any directory; a run that times its own steps (bench/runs.py) is timed by them, time cap included;
native Jolt is "not installed" without a Jolt checkout, and runs a scene (timed by its own clock) with one."""
import os
import subprocess
import sys

import numpy as np
import pytest

import bench.__main__ as runner
from bench.runs import timed_run
from bench.scenes import SCENES


def scripted(times):
    """A stand-in for ``run_one``: engine ``e``'s k-th run takes ``times[e][k]`` ms per step (None: the
    engine is unsupported); the calls are logged in order."""
    calls = []

    def run_one(name, engine, quick, cap, steps=None):
        k = sum(1 for _, e in calls if e == engine)
        calls.append((name, engine))
        ms = times[engine][k]
        if ms is None:
            return {"status": "unsupported: scripted"}
        return {"status": "ok", "steps": 10, "seconds": 1e-2 * ms, "ms_per_step": ms, "steps_per_s": 1e3 / ms,
                "run": k}
    return run_one, calls


def test_repeats_go_round_the_engines_and_the_fastest_run_is_kept(monkeypatch):
    repeats = SCENES["marble_terrain"].repeats
    assert repeats >= 3
    times = {"a": [3.0, 1.0] + [2.0] * (repeats - 2), "b": [float(10 - k) for k in range(repeats)]}
    run_one, calls = scripted(times)
    monkeypatch.setattr(runner, "run_one", run_one)
    results = runner.run_scene("marble_terrain", ["a", "b"], quick=True, cap=None)
    assert [e for _, e in calls] == ["a", "b"] * repeats
    assert results["a"]["ms_per_step"] == 1.0 and results["a"]["run"] == 1
    assert results["b"]["ms_per_step"] == 10.0 - (repeats - 1) and results["b"]["run"] == repeats - 1


def test_an_engine_that_cannot_run_is_tried_once(monkeypatch):
    repeats = SCENES["tower_20"].repeats
    run_one, calls = scripted({"a": [2.0] * repeats, "b": [None] * repeats})
    monkeypatch.setattr(runner, "run_one", run_one)
    results = runner.run_scene("tower_20", ["a", "b"], quick=True, cap=None)
    assert [e for _, e in calls].count("b") == 1
    assert [e for _, e in calls].count("a") == repeats
    assert results["b"]["status"].startswith("unsupported")


def test_a_query_scene_runs_each_engine_once(monkeypatch):
    run_one, calls = scripted({"a": [1.0], "b": [2.0]})
    monkeypatch.setattr(runner, "run_one", run_one)
    results = runner.run_scene("mesh_queries", ["a", "b"], quick=True, cap=None)
    assert [e for _, e in calls] == ["a", "b"]
    assert results["b"]["ms_per_step"] == 2.0


def test_a_run_writes_the_docs_only_when_asked(tmp_path, monkeypatch):
    machine = {"date": "2026-12-02", "hostname": "host"}
    monkeypatch.chdir(tmp_path)                         # the paths do not depend on the working directory
    plain = runner.output_paths(machine)
    assert plain["docs_table"] is None and plain["docs_plot"] is None
    assert plain["results"] == os.path.join(runner.HERE, "results", "2026-12-02-host.json")
    assert plain["plot"] == os.path.join(runner.HERE, "results", "2026-12-02-host.png")
    assert runner.output_paths(machine, quick=True)["results"].endswith("2026-12-02-host-quick.json")
    assert runner.output_paths(machine, out="x.json")["results"] == str(tmp_path / "x.json")
    docs = runner.output_paths(machine, write_docs=True)
    assert docs["docs_table"] == os.path.join(runner.ROOT, "docs", "bench", "latest.md")
    assert docs["docs_plot"] == os.path.join(runner.ROOT, "docs", "bench", "latest.png")
    assert runner.output_paths(machine, plot=False)["plot"] is None


def test_the_runner_starts_from_any_directory(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    r = subprocess.run([sys.executable, os.path.join(runner.HERE), "--help"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "--write-docs" in r.stdout
    r = subprocess.run([sys.executable, os.path.join(runner.HERE), "--quick", "--write-docs"], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "not a --quick check" in r.stderr


def test_a_quick_run_does_not_judge_a_pile_that_had_no_time_to_settle():
    assert not SCENES["pile_1k"].judged_when_quick and not SCENES["pile_8k"].judged_when_quick
    assert SCENES["tower_20"].judged_when_quick
    assert runner._verdict({"ok": None}) == "n/a (quick)"
    assert runner._verdict({"ok": True}) == "yes" and runner._verdict({"ok": False}) == "NO"
    row = {"status": "ok", "steps": 10, "seconds": 0.01, "ms_per_step": 1.0, "steps_per_s": 1e3,
           "sanity": {"ok": None, "spread": 1.0}}
    text = runner.table({"pile_1k": {"marbellous": row}}, ["marbellous"])
    assert "n/a (quick)" in text and " NO" not in text


class SelfTimed:
    """A stand-in for an engine that times its own steps: each takes 0.5 s by its account."""

    def __init__(self):
        self.done = 0

    def timed_steps(self, n, budget=None):
        seconds = []
        while len(seconds) < n and (budget is None or sum(seconds) <= budget):
            seconds.append(0.5)
            self.done += 1
        return seconds

    def positions(self):
        return np.full((1, 3), float(self.done))

    def max_penetration(self):
        return 0.0


def test_a_run_that_times_its_own_steps_is_timed_by_them():
    res = timed_run(SelfTimed(), 20)
    assert res["steps"] == 20 and res["seconds"] == 10.0
    assert [step for step, _ in res["positions"]] == [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 19, 20]
    assert all(p[0, 0] == step for step, p in res["positions"])
    # chunks of 2 steps: the fourth chunk stops after its first step, past the 3 s cap, then the final step
    capped = timed_run(SelfTimed(), 20, time_cap=3.0)
    assert capped["steps"] == 8 and capped["seconds"] == 4.0


def test_native_jolt_is_reported_not_installed_without_a_jolt_source(monkeypatch):
    from bench.peers import jolt_build
    monkeypatch.delenv(jolt_build.ENV, raising=False)
    assert runner.run_one("one_body", "jolt-native", quick=True, cap=None) == {"status": "not installed"}
    assert runner.run_one("one_body", "jolt-native-2t", quick=True, cap=None) == {"status": "not installed"}


def test_the_jolt_source_must_be_a_jolt_checkout(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        runner.main(["--jolt-source", str(tmp_path), "--quick"])
    assert stop.value.code == 2 and "is not a Jolt Physics checkout" in capsys.readouterr().err


@pytest.mark.parametrize("engine", ["jolt-native", "jolt-native-2t"])
def test_native_jolt_runs_a_scene_timed_by_its_own_clock(engine, monkeypatch):
    """Skipped unless $MARBELLOUS_JOLT_SOURCE names a Jolt checkout native Jolt can be built from (not in CI)."""
    from bench.peers import jolt_build, make_peer
    try:
        jolt_build.driver_and_version()
    except ImportError as e:
        pytest.skip(str(e))
    world, _ = SCENES["one_body"].build(True)
    run = make_peer(engine, world, 1 / 60)
    try:
        seconds = run.timed_steps(5)
        assert len(seconds) == 5 and all(0.0 < s < 0.01 for s in seconds)      # one body: microseconds a step
    finally:
        run.close()
    r = runner.run_one("one_body", engine, quick=True, cap=None)
    assert r["status"] == "ok" and r["sanity"]["ok"] and r["steps"] == SCENES["one_body"].n_steps(True)
