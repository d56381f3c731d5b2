"""Many worlds stepped by one call (``mb.step_worlds``): each world's state after every step is, bit for bit,
what stepping it alone gives, whatever else is in the batch and however many threads share it."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as hs

import marbellous as mb

DT = 1.0 / 60.0


def spheres_on_a_plane(seed):
    """A few spheres dropped on a plane (the lean step)."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.5)
    for k in range(3):
        w.add_body(mb.Sphere(0.2 + 0.1 * rng.random()), position=(k - 1.0, 0.5 + rng.random(), rng.random()),
                   velocity=rng.normal(size=3))
    return w


def box_pile(seed):
    """Forty boxes falling into a pile: the full step, and contact tables that grow past their first rows."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane())
    for k in range(40):
        w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.45 * (k % 4) + 0.05 * rng.random(), 0.25 + 0.45 * (k // 16),
                                                       0.45 * ((k // 4) % 4)))
    return w


def pendulum(seed):
    """A hinged bar and a rod pendulum (constraints: the full step)."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    bar = w.add_body(mb.Box((0.5, 0.05, 0.05)), position=(0.5, 2.0, 0.0))
    w.add_hinge(bar, None, anchor=(0.0, 2.0, 0.0), axis=(0.0, 0.0, 1.0))
    bob = w.add_body(mb.Sphere(0.1), position=(1.0 + rng.random(), 1.0, 0.0))
    w.add_rod(bob, None, anchor_b=(0.0, 1.0, 0.0))
    return w


def bullet(seed):
    """A fast sphere at a thin wall (time-of-impact intervals)."""
    w = mb.World()
    w.add_static(mb.Box((0.01, 1.0, 1.0)), position=(1.0, 0.0, 0.0))
    w.add_body(mb.Sphere(0.05), position=(0.0, 0.0, 0.1 * (seed % 3)), velocity=(300.0, 0.0, 0.0))
    return w


def retroactive(seed):
    """The retroactive time-stepping mode (stepped alone within the batch)."""
    w = mb.World(time_stepping="retroactive")
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.3), position=(0.0, 1.0 + 0.1 * (seed % 5), 0.0), velocity=(0.0, -20.0, 0.0))
    return w


def net(seed):
    """A particle network pinned at one end (the particles' step after the bodies')."""
    w = mb.World()
    w.add_static(mb.Plane())
    parts = w.add_particles([(0.1 * k, 1.0 + 0.01 * (seed % 7), 0.0) for k in range(5)], radius=0.02)
    w.add_network(parts, [(k, k + 1) for k in range(4)], kind="spring", stiffness=200.0)
    parts.pin([0])
    return w


KINDS = (spheres_on_a_plane, box_pile, pendulum, bullet, retroactive, net)


def _hashes(worlds):
    return [w.state_hash() for w in worlds]


@given(kinds=hs.lists(hs.sampled_from(KINDS), min_size=1, max_size=8), seed=hs.integers(0, 1000),
       threads=hs.integers(1, 3))
def test_each_world_of_a_batch_steps_as_it_does_alone(kinds, seed, threads):
    batch = [make(seed + k) for k, make in enumerate(kinds)]
    alone = [make(seed + k) for k, make in enumerate(kinds)]
    for _ in range(20):
        mb.step_worlds(batch, DT, threads=threads)
        for w in alone:
            w.step(DT)
        assert _hashes(batch) == _hashes(alone)


def test_a_large_batch_of_one_layout_on_two_threads():
    batch = [spheres_on_a_plane(k) for k in range(64)]
    alone = [spheres_on_a_plane(k) for k in range(64)]
    for _ in range(30):
        mb.step_worlds(batch, DT, threads=2)
        for w in alone:
            w.step(DT)
    assert _hashes(batch) == _hashes(alone)
    assert all(abs(w.time - 30 * DT) < 1e-12 for w in batch)


def test_an_empty_batch_is_nothing_to_do():
    mb.step_worlds([], DT)


@pytest.mark.parametrize("worlds, dt, threads, error, match", [
    ("not worlds", DT, 1, TypeError, "worlds must be a sequence"),
    (None, DT, 1, TypeError, "worlds must be a sequence"),
    ("one", DT, 1, TypeError, "worlds must be a sequence"),
    ("with a body", DT, 1, TypeError, r"worlds\[1\] must be a World"),
    ("twice", DT, 1, ValueError, "distinct"),
    ("two", 0.0, 1, ValueError, "dt"),
    ("two", float("nan"), 1, ValueError, "dt"),
    ("two", DT, 0, ValueError, "threads"),
    ("two", DT, 1.5, TypeError, "threads"),
])
def test_bad_arguments_are_refused_and_change_nothing(worlds, dt, threads, error, match):
    a, b = spheres_on_a_plane(1), spheres_on_a_plane(2)
    before = _hashes([a, b])
    given_worlds = {"not worlds": 3, None: None, "one": a, "with a body": [a, a.bodies[0]], "twice": [a, b, a],
                    "two": [a, b]}[worlds]
    with pytest.raises(error, match=match):
        mb.step_worlds(given_worlds, dt, threads=threads)
    assert _hashes([a, b]) == before


def test_the_friction_sweep_example_slides_as_coulomb_says():
    """examples/many_worlds.py: a crate launched at v0 stops after v0^2 / (2 mu g); semi-implicit Euler
    at sub-step h places the stop within v0 h of it (it moves by v0 h at most per sub-step)."""
    import runpy
    from pathlib import Path

    example = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "many_worlds.py"))
    coefficients = np.array([0.1, 0.3, 0.8])
    slides = example["sweep"](coefficients, threads=2)
    h = DT / mb.World().substeps
    want = example["V0"] ** 2 / (2 * coefficients * example["G"])
    assert np.all(np.abs(slides - want) <= example["V0"] * h), (slides, want)
