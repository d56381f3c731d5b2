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


def _marble_on_a_mesh():
    """A marble rolling over a small bumpy mesh (a new world each call, its mesh built anew)."""
    x, z = np.meshgrid(np.linspace(-4, 4, 9), np.linspace(-4, 4, 9))
    vertices = np.column_stack([x.ravel(), 0.2 * np.sin(x.ravel()) * np.cos(z.ravel()), z.ravel()])
    quads = [(r * 9 + c, r * 9 + c + 9, r * 9 + c + 1, r * 9 + c + 10) for r in range(8) for c in range(8)]
    triangles = [t for a, b, c, d in quads for t in ((a, b, c), (c, b, d))]
    w = mb.World()
    ground = w.add_static(mb.TriangleMesh(vertices, triangles))
    marble = w.add_body(mb.Sphere(0.3), position=(-2.0, 0.6, 0.5), velocity=(2.0, 0.0, 0.3))
    return w, ground, marble


def test_worlds_of_equal_meshes_hold_one_copy_of_their_geometry_and_step_as_alone():
    (a, ground_a, _), (b, _, marble_b), (alone, _, _) = (_marble_on_a_mesh() for _ in range(3))
    assert a._state.geom_f is b._state.geom_f and a._state.geom_i is b._state.geom_i
    a.remove(ground_a)                     # the copy b reads is not touched: a gets a new one
    assert a._state.geom_f is not b._state.geom_f and a._state.geom_f.size == 0
    for _ in range(120):
        mb.step_worlds([a, b], 1 / 60)
        alone.step(1 / 60)
    assert b.state_hash() == alone.state_hash()
    assert marble_b.position[1] > 0.0            # it rolled on the shared mesh, not through it


def test_one_body_row_of_each_world_is_pushed_and_read_as_its_handle_does():
    from marbellous.batch import packed_addresses, step_checked
    from marbellous.pipeline.body_rows import add_forces_at, motions_at

    def world():
        w = mb.World()
        w.add_static(mb.Plane(), friction=0.5)
        for k in range(3):
            w.add_body(mb.Sphere(0.2), position=(k - 1.0, 0.2, 0.0))
        w.add_static(mb.Box((0.1, 0.1, 0.1)), position=(5.0, 0.0, 0.0))
        w.add_kinematic(mb.Sphere(0.1), position=(3.0, 1.0, 0.0), velocity=(0.0, 0.0, 1.0))
        return w
    together, alone = [world() for _ in range(4)], [world() for _ in range(4)]
    for _ in range(60):                          # the spheres at rest fall asleep
        step_checked(together, DT, 1)
        for w in alone:
            w.step(DT)
    assert all(b.is_sleeping for w in together for b in w.bodies[1:4])
    rng = np.random.default_rng(3)
    for _ in range(20):
        picked = rng.integers(0, 6, size=4)      # a sphere (asleep at first: a push wakes it), the plane, the
        forces = rng.normal(scale=5.0, size=(4, 3))   # static box or the kinematic sphere (nothing moves them)
        rows = np.array([w.bodies[k]._index for w, k in zip(together, picked)], dtype=np.int64)
        add_forces_at(packed_addresses(together), rows, forces)
        for w, k, f in zip(alone, picked, forces):
            w.bodies[k].apply_force(f)
        addresses = step_checked(together, DT, 2)
        for w in alone:
            w.step(DT)
        assert _hashes(together) == _hashes(alone)
        motion = np.empty((4, 6))
        motions_at(addresses, rows, motion)
        for m, w, k in zip(motion, alone, picked):
            assert m.tobytes() == np.concatenate([w.bodies[k].position, w.bodies[k].velocity]).tobytes()


def test_plain_worlds_step_again_and_again_as_alone_and_a_split_step_ends_their_plainness():
    from marbellous.batch import packed_addresses, plain_entry, step_checked, step_plain

    assert plain_entry([net(0), spheres_on_a_plane(0)], DT) is None          # particles: not plain
    def bullet_at_a_distance(k):
        w = mb.World()
        w.add_static(mb.Box((0.01, 1.0, 1.0)), position=(5.0 + 0.3 * k, 0.0, 0.0))
        w.add_body(mb.Sphere(0.05), position=(0.0, 0.0, 0.0), velocity=(60.0, 0.0, 0.0))   # 1 m a step
        return w
    together = [bullet_at_a_distance(k) for k in range(3)]                    # time-of-impact intervals ahead
    alone = [bullet_at_a_distance(k) for k in range(3)]
    assert plain_entry(together, DT) is None                                  # (never stepped)
    step_checked(together, DT, 1)
    for w in alone:
        w.step(DT)
    splits = 0
    for _ in range(40):
        entry = plain_entry(together, DT)
        if entry is None:
            step_checked(together, DT, 2)
        else:
            _, plain = step_plain(together, packed_addresses(together), entry, DT, 2)
            splits += not plain
        for w in alone:
            w.step(DT)
        assert _hashes(together) == _hashes(alone)
    assert splits > 0
    assert plain_entry(together, 1.0 / 120.0) is None                         # (parameters for another dt)
