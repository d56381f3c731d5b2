"""The benchmark runner (bench/__main__.py): a scene's repeats go round the engines in turn, each engine
keeps its fastest run, and an engine that cannot run is not tried again."""
import bench.__main__ as runner
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
