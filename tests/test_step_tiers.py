"""The lean step: a world of the default settings with no constraint and few contacts steps with a step
compiled without joints, bundles, the other broad phases and integrators, and its results are the full
step's, bit for bit."""
import os
import subprocess
import sys

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

import marbellous as mb
from marbellous.pipeline import precompile
from marbellous.pipeline.step import FULL, LEAN
from marbellous.state import world_state


def _scene(seed, kinds):
    """A handful of bodies of ``kinds`` dropped, spinning, onto a plane, a box and a bumpy mesh."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.6)
    w.add_static(mb.Box((0.6, 0.2, 0.6)), position=(1.5, 0.2, 0.0))
    x, z = np.meshgrid(np.linspace(-2.0, 2.0, 5), np.linspace(-2.0, 2.0, 5))
    y = 0.1 * rng.standard_normal(x.shape)
    vertices = np.column_stack([x.ravel() - 3.0, y.ravel() + 0.05, z.ravel()])
    faces = [(r * 5 + c, (r + 1) * 5 + c, r * 5 + c + 1) for r in range(4) for c in range(4)]
    faces += [(r * 5 + c + 1, (r + 1) * 5 + c, (r + 1) * 5 + c + 1) for r in range(4) for c in range(4)]
    w.add_static(mb.TriangleMesh(vertices, faces))
    shapes = {"sphere": lambda: mb.Sphere(rng.uniform(0.1, 0.3)),
              "box": lambda: mb.Box(rng.uniform(0.1, 0.3, 3)),
              "capsule": lambda: mb.Capsule(rng.uniform(0.08, 0.2), rng.uniform(0.1, 0.4))}
    for k in range(6):
        w.add_body(shapes[kinds[k % len(kinds)]](), position=(rng.uniform(-4.0, 2.0), 0.6 + 0.5 * k,
                                                              rng.uniform(-1.0, 1.0)),
                   velocity=rng.normal(0.0, 2.0, 3), angular_velocity=rng.normal(0.0, 3.0, 3),
                   restitution=rng.uniform(0.0, 0.6), rolling_friction=rng.uniform(0.0, 0.01))
    return w


def _run(w, steps):
    tiers = set()
    for _ in range(steps):
        w.step(1 / 60)
        tiers.add(w._state.tier)
    return w.state_hash(), tiers


@settings(max_examples=6, deadline=None)
@given(seed=hs.integers(0, 2 ** 31), kinds=hs.sampled_from([("sphere",), ("sphere", "box", "capsule")]))
def test_the_lean_step_gives_the_full_steps_results_bit_for_bit(seed, kinds):
    lean, lean_tiers = _run(_scene(seed, kinds), 90)
    assert lean_tiers == {LEAN}
    with pytest.MonkeyPatch.context() as m:
        m.setattr(world_state, "scene_tier", lambda *args: FULL)
        full, full_tiers = _run(_scene(seed, kinds), 90)
    assert full_tiers == {FULL}
    assert lean == full


def test_a_world_leaves_the_lean_step_for_what_it_does_not_compile():
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.25), position=(0.0, 1.0, 0.0))
    w.step(1 / 60)
    assert w._state.tier == LEAN
    for change, undo in [(lambda: setattr(w, "integrator", "rk4"), lambda: setattr(w, "integrator",
                                                                                  "semi_implicit_euler")),
                         (lambda: setattr(w, "broadphase", "sap"), lambda: setattr(w, "broadphase", "grid")),
                         (lambda: setattr(w, "solver", "lcp"), lambda: setattr(w, "solver", "sequential_impulse"))]:
        change()
        w.step(1 / 60)
        assert w._state.tier == FULL
        undo()
        w.step(1 / 60)
        assert w._state.tier == LEAN
    w.add_spring(ball, None, anchor_b=(0.0, 2.0, 0.0), rest_length=0.5, stiffness=10.0)
    w.step(1 / 60)
    assert w._state.tier == FULL


def test_a_pile_outgrowing_the_first_contact_rows_goes_on_with_the_full_step_unchanged(monkeypatch):
    # 40 boxes start with the full step (more moving bodies than a lean world has) ...
    def pile():
        w = mb.World()
        w.add_static(mb.Plane())
        for k in range(40):
            w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.5 * (k % 4), 0.3 + 0.45 * (k // 4), 0.5 * (k % 3)))
        return w
    w = pile()
    w.step(1 / 60)
    assert w._state.tier == FULL
    # ... and allowed to start lean, past 64 contact points the contact table grows, the context gets its
    # bundle tables and the world steps with the full tier; the run is the full tier's all along
    monkeypatch.setattr(world_state, "LEAN_MAX_BODIES", 40)
    hashed, tiers = _run(pile(), 120)
    assert tiers == {LEAN, FULL}
    with monkeypatch.context() as m:
        m.setattr(world_state, "scene_tier", lambda *args: FULL)
        assert _run(pile(), 120)[0] == hashed


@pytest.mark.parametrize("solver", ["penalty", "lcp"])
def test_the_other_schemes_step_with_their_full_step(solver):
    w = mb.World(solver=solver)
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.25), position=(0.0, 1.0, 0.0))
    w.step(1 / 60)
    assert w._state.tier == FULL


def test_the_particle_kernels_are_typed_ahead_as_the_step_calls_them():
    # what a cold step shares out with the helper must be what the particles' step then calls, or the helper
    # compiled in vain
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.2), position=(2.0, 1.0, 0.0))
    vertices, triangles = mb.cloth_grid(1.0, 1.0, 3, 3)
    w.add_cloth(vertices, triangles, mass=0.1, position=(0.0, 1.0, 0.0))
    work = w._state.particles.kernel_work(w._state)
    assert len(work) == 2
    w.step(1 / 60)
    for kernel, arguments in work:
        assert tuple(numba.typeof(a) for a in arguments) in kernel.signatures


def run_a_ball_in_a_cold_cache(tmp_path, before, report):
    """Run, in a new process with a fresh kernel cache in ``tmp_path``, a ball of 0.25 m dropped from 2 m onto a
    plane (``w``, ``b``), code ``before`` its 120 steps of 1/60 s, and code ``report`` after them; returns what
    ``report`` printed, split into words."""
    code = ("import marbellous as mb\n"
            "from marbellous.pipeline import precompile, step\n"
            "w = mb.World(); w.add_static(mb.Plane(), friction=0.6)\n"
            "b = w.add_body(mb.Sphere(0.25), position=(0, 2, 0), restitution=0.5)\n"
            + before + "for _ in range(120): w.step(1 / 60)\n" + report)
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path), MARBELLOUS_PROGRESS="0")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=900)
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


@pytest.mark.skipif(precompile._cores() < 2, reason="the helper runs only with a second core")
def test_a_cold_lean_step_is_compiled_with_a_helper_process(tmp_path):
    # a fresh kernel cache: the first world's step compiles, and some of its stages come from the helper
    # (loaded from the cache, a cache hit in this process); the ball lands where it always does
    lean, height, from_helper = run_a_ball_in_a_cold_cache(
        tmp_path, "", "print(w._state.tier == step.LEAN, round(float(b.position[1]), 4),\n"
                      "      sum(sum(s._cache_hits.values()) > 0 for s in precompile.lean_stages(0)))\n")
    assert lean == "True" and float(height) == pytest.approx(0.25, abs=0.01)
    assert int(from_helper) >= 1


@pytest.mark.skipif(precompile._cores() < 2, reason="the helper runs only with a second core")
def test_a_step_compiled_ahead_overlaps_a_ray_cast_and_lands_the_same(tmp_path):
    # a fresh kernel cache: the step's stages start compiling in the helper before the first step, while this
    # process compiles a ray cast; the first step then finds stages in the cache, and the ball lands as always
    started, finished, distance, height, from_helper = run_a_ball_in_a_cold_cache(
        tmp_path, "w._compile_ahead(1 / 60)\n"
                  "started = w._state.sharing is not None\n"
                  "hit = w.raycast((3, 5, 0), (0, -1, 0), 10.0)\n",
        "print(started, w._state.sharing is None, round(hit.distance, 6), round(float(b.position[1]), 4),\n"
        "      sum(sum(s._cache_hits.values()) > 0 for s in precompile.lean_stages(0)))\n")
    assert started == "True" and finished == "True"
    assert float(distance) == 5.0
    assert float(height) == pytest.approx(0.25, abs=0.01)
    assert int(from_helper) >= 1


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
    # error, nothing claimed, the step then compiles every kernel itself
    claimed = []
    monkeypatch.setattr(precompile, "_cores", lambda: 2)
    monkeypatch.setattr(precompile.cache, "CACHE_DIR", "/nonexistent")
    monkeypatch.setattr(precompile, "compile_claimed", lambda work, claims: claimed.append(work))

    def unwritable(*args, **kwargs):
        raise PermissionError("read-only")
    monkeypatch.setattr(precompile.tempfile, "mkdtemp", unwritable)
    sharing = precompile.Sharing(0)
    sharing.start([])
    sharing.finish()
    monkeypatch.undo()
    monkeypatch.setattr(precompile, "_cores", lambda: 2)
    monkeypatch.setattr(precompile.cache, "CACHE_DIR", "/nonexistent")
    monkeypatch.setattr(precompile, "compile_claimed", lambda work, claims: claimed.append(work))

    def no_interpreter(*args, **kwargs):
        raise FileNotFoundError("python")
    monkeypatch.setattr(precompile.subprocess, "Popen", no_interpreter)
    sharing = precompile.Sharing(0)
    sharing.start([])
    sharing.finish()
    assert claimed == []
