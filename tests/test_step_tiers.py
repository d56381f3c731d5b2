"""The lean step: a world of the default settings with no constraint and few contacts steps with a step
compiled without joints, bundles, the other broad phases and integrators, and its results are the full
step's, bit for bit."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

import marbellous as mb
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
