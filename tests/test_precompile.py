"""A cold lean step compiled in helper processes (``pipeline/precompile.py``): what they compile is what the step
then calls, this process loads it from the kernel cache instead of compiling it, the results do not change, and
helpers that end (for their memory, or fail) neither stop nor stall the step."""
import io
import os
import pickle
import shutil
import subprocess
import sys

import numba
import numpy as np
import pytest

import marbellous as mb
from marbellous._numba import cache, progress
from marbellous.game.goal import GoalArea
from marbellous.pipeline import precompile
from marbellous.pipeline.step import LEAN


def test_the_particle_kernels_are_typed_ahead_as_the_step_calls_them():
    # what a cold step shares out with the helpers must be what the particles' step then calls, or the helpers
    # compiled in vain
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.2), position=(2.0, 1.0, 0.0))
    vertices, triangles = mb.cloth_grid(1.0, 1.0, 3, 3)
    w.add_cloth(vertices, triangles, mass=0.1, position=(0.0, 1.0, 0.0))
    work = w._state.particles.kernel_work(w._state)
    assert len(work) == 3
    w.step(1 / 60)
    for kernel, arguments in work:
        assert tuple(numba.typeof(a) for a in arguments) in kernel.signatures


def test_the_ray_cast_compiled_ahead_is_the_one_a_ray_then_calls():
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.2), position=(0.0, 1.0, 0.0))
    kernel, arguments = w._ray_kernel(np.zeros(3), np.array([0.0, -1.0, 0.0]), 1.0, -1)
    assert w.raycast((0.0, 3.0, 0.0), (0.0, -1.0, 0.0), 10.0) is not None
    assert tuple(numba.typeof(a) for a in arguments) in kernel.signatures


def run_a_ball_in_a_cold_cache(tmp_path, forget, before, report):
    """Run, in a new process with a kernel cache in ``tmp_path`` that holds this session's kernels but none of
    the package files ``forget`` (paths without ``.py``: what a fresh install compiles, as far as the sharing out
    is concerned, at a fraction of the cost), a ball of 0.25 m dropped from 2 m onto a plane (``w``, ``b``), code
    ``before`` its 120 steps of 1/60 s, and code ``report`` after them; returns what ``report`` printed, split
    into words.  ``compiled_here(kernels)`` counts the compiles of ``kernels`` in that process, ``stages(tier)`` are
    the stage kernels of the sequential-impulse step for spheres of ``tier``."""
    shutil.copytree(cache.CACHE_DIR, tmp_path, ignore=shutil.ignore_patterns("*.tmp.*"), dirs_exist_ok=True)
    for module in forget:
        for f in (tmp_path / os.path.dirname(module)).glob(os.path.basename(module) + ".*"):
            f.unlink()
    code = ("import numpy as np\n"
            "import marbellous as mb\n"
            "from marbellous.pipeline import precompile, step\n"
            "def compiled_here(kernels):\n"
            "    return sum(sum(k._cache_misses.values()) for k in kernels)\n"
            "def stages(tier):\n"
            "    return tuple(stage for stage, _ in precompile.step_stages(0, 0, tier))\n"
            "w = mb.World(); w.add_static(mb.Plane(), friction=0.6)\n"
            "b = w.add_body(mb.Sphere(0.25), position=(0, 2, 0), restitution=0.5)\n"
            + before + "for _ in range(120): w.step(1 / 60)\n" + report)
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path), MARBELLOUS_PROGRESS="0")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


#: the step's stages and entry, and the packing of its context
STEP, CONTEXT = os.path.join("pipeline", "step"), os.path.join("pipeline", "context")

#: the lean step's stages for spheres (what a ball on a plane compiles)
LEAN_STAGES = tuple(stage for stage, _ in precompile.step_stages(0, 0, LEAN))


def test_a_cold_lean_step_is_compiled_by_helpers_which_end_for_their_memory(tmp_path):
    # the step and its packing missing from the cache: the packing's compile starts helpers, each ending after
    # one kernel (a memory of one byte), so that fresh helpers take the rest of the list; this process compiles
    # none of the step's kernels, loads its entry from the cache, and the ball lands where it always does
    lean, height, here, loaded, helpers = run_a_ball_in_a_cold_cache(
        tmp_path, (STEP, CONTEXT),
        "precompile.HELPER_MEMORY = 1\n"
        "started = []\n"
        "start = precompile._start_helper\n"
        "precompile._start_helper = lambda claims: started.append(claims) or start(claims)\n",
        "entry = step.STEPS[0][0][step.LEAN]\n"
        "print(w._state.tier == step.LEAN, round(float(b.position[1]), 4),\n"
        "      compiled_here(stages(step.LEAN) + (entry,)), sum(entry._cache_hits.values()),\n"
        "      len(started))\n")
    assert lean == "True" and float(height) == pytest.approx(0.25, abs=0.01)
    assert int(here) == 0 and int(loaded) == 1
    # (one helper for each of the list's 18 kernels, give or take those a helper found claimed meanwhile)
    assert int(helpers) >= len(LEAN_STAGES)


def test_a_cold_full_step_is_compiled_by_helpers_with_the_flags_its_scheme_passes(tmp_path):
    # a rod makes the step full: the helpers compile its stages for the constant flags the scheme passes some of
    # them (or the entry would compile those here again) and its entry; this process compiles none of them and
    # loads the entry from the cache, and the ball lands where it always does
    full, height, here, loaded = run_a_ball_in_a_cold_cache(
        tmp_path, (STEP, CONTEXT),
        "bob = w.add_body(mb.Sphere(0.1), position=(5, 1, 0))\n"
        "w.add_rod(bob, None, anchor_b=(5, 2, 0))\n",
        "entry = step.STEPS[0][0][step.FULL]\n"
        "print(w._state.tier == step.FULL, round(float(b.position[1]), 4),\n"
        "      compiled_here(stages(step.FULL) + (entry,)), sum(entry._cache_hits.values()))\n")
    assert full == "True" and float(height) == pytest.approx(0.25, abs=0.01)
    assert int(here) == 0 and int(loaded) == 1


def test_an_entry_that_compiles_here_takes_the_stages_from_helpers_that_never_wait_for_it(tmp_path):
    # only the step missing from the cache: its entry begins to compile in this process, holding the entry's
    # lock (_numba/shared_compile.py), and that starts the helpers; this process waits for the stages, not for
    # the entry (a helper that took it would wait for this process's lock: with no time limit, for ever), then
    # compiles the entry against the stages the helpers saved
    here, entry_here, height = run_a_ball_in_a_cold_cache(
        tmp_path, (STEP,), "precompile.HELPER_TIMEOUT = 1e9\n",
        "print(compiled_here(stages(step.LEAN)), compiled_here((step.STEPS[0][0][step.LEAN],)),\n"
        "      round(float(b.position[1]), 4))\n")
    assert int(here) == 0 and int(entry_here) == 1
    assert float(height) == pytest.approx(0.25, abs=0.01)


def test_a_step_compiled_ahead_with_a_ray_cast_lands_the_same(tmp_path):
    # the step and the ray cast missing from the cache: the helpers compile the ray cast, then the step's
    # stages, before the first step; the ray waits for the ray cast and loads it, and the ball lands as always
    started, finished, distance, height, here = run_a_ball_in_a_cold_cache(
        tmp_path, (STEP, os.path.join("pipeline", "raycast")),
        "w._compile_ahead(1 / 60)\n"
        "started = w._state.sharing is not None\n"
        "hit = w.raycast((3, 5, 0), (0, -1, 0), 10.0)\n"
        "ray = w._ray_kernel(np.zeros(3), np.ones(3), 1.0, -1)[0]\n",
        "print(started, w._state.sharing is None, round(hit.distance, 6), round(float(b.position[1]), 4),\n"
        "      compiled_here(stages(step.LEAN) + (ray,)))\n")
    assert started == "True" and finished == "True"
    assert float(distance) == 5.0
    assert float(height) == pytest.approx(0.25, abs=0.01)
    assert int(here) == 0


def test_compiling_ahead_with_the_step_in_the_cache_starts_nothing_and_changes_nothing():
    # (this process's cache holds the step by now) no helper, and the world steps as one never compiled ahead,
    # its first step's report included
    def run(ahead):
        w = mb.World()
        w.add_static(mb.Plane())
        w.add_body(mb.Sphere(0.25), position=(0.0, 1.0, 0.0))
        w.step(1 / 60)
        w2 = mb.World()
        w2.add_static(mb.Plane())
        b = w2.add_body(mb.Sphere(0.25), position=(0.0, 1.0, 0.0), restitution=0.3)
        if ahead:
            w2._compile_ahead(1 / 60)
            assert w2._state.sharing is None
        w2.substeps = 2
        for _ in range(30):
            w2.step(1 / 60)
        return w2.state_hash(), w2.last_step, tuple(b.position)
    assert run(True) == run(False)


def test_typing_the_particle_kernels_ahead_changes_nothing():
    # the cold first step types the particles' kernels before the particles' step has run (above); a pinned
    # cloth's tethers, found from the cloth tables, once came out wrong that way and the run changed
    def run(ahead):
        w = mb.World()
        vertices, triangles = mb.cloth_grid(1.0, 1.0, 6, 6)
        cloth = w.add_cloth(vertices, triangles, mass=0.1, position=(0.0, 1.0, 0.0))
        cloth.pin([0, 5, 30, 35])
        w.add_body(mb.Box((0.1, 0.05, 0.1)), position=(0.0, 1.3, 0.0))
        if ahead:
            w._state.particles.kernel_work(w._state)
        for _ in range(60):
            w.step(1 / 60)
        return w.state_hash()
    assert run(True) == run(False)


def test_without_a_helper_the_step_compiles_alone(monkeypatch):
    # a temporary directory that cannot be written (or no interpreter to start) leaves the sharing out: no
    # error, no helper, nothing waited for; the step then compiles every kernel itself
    monkeypatch.setattr(precompile.cache, "CACHE_DIR", "/nonexistent")

    def unwritable(*args, **kwargs):
        raise PermissionError("read-only")
    with monkeypatch.context() as m:
        m.setattr(precompile.tempfile, "mkdtemp", unwritable)
        sharing = precompile.Sharing((0, 0, LEAN))
        sharing.start([])
        assert sharing.claims is None and sharing.helpers == []
        sharing.finish()

    def no_interpreter(*args, **kwargs):
        raise FileNotFoundError("python")
    monkeypatch.setattr(precompile.subprocess, "Popen", no_interpreter)
    sharing = precompile.Sharing((0, 0, LEAN))
    sharing.start([])
    assert sharing.claims is None and sharing.helpers == []
    sharing.wait(LEAN_STAGES[0])
    sharing.finish()


def _claims(tmp_path, work):
    """A claims directory in ``tmp_path`` holding ``work``."""
    claims = str(tmp_path)
    with open(os.path.join(claims, "work"), "wb") as f:
        pickle.dump(work, f)
    return claims


def test_a_kernel_is_done_once_compiled_or_once_its_claimer_has_ended(tmp_path):
    # a kernel claimed by a running process is not done until its marker says so; one whose claimer died (a
    # crash, a kill) counts as done, so that a process waiting for it goes on and compiles it with its caller
    claims = str(tmp_path)
    assert not precompile._done(claims, "a")                    # (not claimed)
    with open(os.path.join(claims, "a"), "w") as f:
        f.write(str(os.getpid()))
    assert not precompile._done(claims, "a")
    open(os.path.join(claims, "a.done"), "w").close()
    assert precompile._done(claims, "a")
    ended = subprocess.Popen([sys.executable, "-c", "pass"])
    ended.wait()
    with open(os.path.join(claims, "b"), "w") as f:
        f.write(str(ended.pid))
    assert precompile._done(claims, "b")


def test_a_helper_waits_for_what_a_kernel_calls_and_skips_what_others_claimed(tmp_path, monkeypatch):
    # the list: x (claimed by another process, still running), y (calls x), z; the helper compiles z while x is
    # under way, then y once x is done; it never compiles x
    compiled = []
    kernels = {name: type("K", (), {"compile": lambda self, sig, name=name: compiled.append(name)})()
               for name in "xyz"}
    monkeypatch.setattr(precompile, "_kernel", lambda module, name, path: kernels[name])
    work = [("m", "x", (), (), ()), ("m", "y", (), (), ("m.x",)), ("m", "z", (), (), ())]
    claims = _claims(tmp_path, work)
    with open(os.path.join(claims, "m.x"), "w") as f:
        f.write(str(os.getpid()))

    def finish_x(seconds):
        open(os.path.join(claims, "m.x.done"), "w").close()
    monkeypatch.setattr(precompile.time, "sleep", finish_x)
    precompile.compile_claimed(claims)
    assert compiled == ["z", "y"]
    assert all(os.path.exists(os.path.join(claims, f"m.{n}.done")) for n in "xyz")


def test_a_helper_past_its_memory_ends_after_the_kernel_it_is_compiling(tmp_path, monkeypatch):
    compiled = []
    kernels = {name: type("K", (), {"compile": lambda self, sig, name=name: compiled.append(name)})()
               for name in "xy"}
    monkeypatch.setattr(precompile, "_kernel", lambda module, name, path: kernels[name])
    claims = _claims(tmp_path, [("m", "x", (), (), ()), ("m", "y", (), (), ())])
    precompile.compile_claimed(claims, memory=1)
    assert compiled == ["x"] and precompile._unclaimed(claims)
    precompile.compile_claimed(claims, memory=1)
    assert compiled == ["x", "y"] and not precompile._unclaimed(claims)


def test_the_helpers_kernels_count_on_this_process_progress_line(tmp_path, monkeypatch):
    # the helpers log each kernel they compile; this process counts the whole lines on its progress line
    counted = []
    monkeypatch.setattr(precompile.PROGRESS, "compiled_elsewhere", counted.append)
    compiled = precompile._Compiled(str(tmp_path))
    with open(os.path.join(str(tmp_path), "compiled-1"), "w") as log:
        log.write("math3d.dot3\npipeline.step.stage_aab")
    compiled.report()
    assert counted == ["math3d.dot3"]
    with open(os.path.join(str(tmp_path), "compiled-1"), "a") as log:
        log.write("bs\n")
    compiled.report()
    assert counted == ["math3d.dot3", "pipeline.step.stage_aabbs"]


def test_a_kernel_compiled_elsewhere_counts_and_reports_like_one_compiled_here():
    class Clock:
        now = 0.0

        def __call__(self):
            return self.now
    out, clock = io.StringIO(), Clock()
    listener = progress.CompileProgress(out, clock)
    for k in range(5):
        clock.now += 20.0
        listener.compiled_elsewhere(f"pipeline.step.stage_{k}")
    listener.finish()
    lines = out.getvalue().splitlines()
    # (the first comes before the line is due, :data:`QUIET_SECONDS`; the second is shown, counted)
    assert lines[0].startswith("marbellous: compiling kernels (first run only) 2/~")
    assert "pipeline.step.stage_1" in lines[0]
    assert lines[-1].startswith("marbellous: compiled 5 kernels in 1 min 20 s")


def test_the_goal_test_compiled_ahead_is_the_one_the_goal_then_calls():
    goal = GoalArea((0.0, 0.0, 0.0), (1.0, 0.5, 1.0))
    kernel, arguments = goal.test_call((0.0, 0.6, 0.0), 0.2)
    assert goal.reached(np.array([0.0, 0.6, 0.0]), 0.2)
    assert tuple(numba.typeof(a) for a in arguments) in kernel.signatures
