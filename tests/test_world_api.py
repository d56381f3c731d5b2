"""World and Body API: time stepping, accumulator, springs, removal, snapshots, bad input."""
import math
import pickle

import numpy as np
import pytest

import marbellous as mb


def simple_world(**kw):
    w = mb.World(**kw)
    a = w.add_body(mb.Sphere(0.3), position=(0, 5, 0), velocity=(1, 2, 3), angular_velocity=(0.5, 0, 1))
    b = w.add_body(mb.Box((0.2, 0.4, 0.6)), position=(2, 5, 0), angular_velocity=(1, 2, 0.1))
    w.add_spring(a, b, rest_length=1.5, stiffness=80.0, damping=0.5, anchor_b=(0.1, 0.2, 0.0))
    return w, a, b


def test_step_advances_time_exactly():
    w, *_ = simple_world()
    for _ in range(3):
        w.step(0.25)
    assert w.time == 0.75


def test_substeps_split_the_step():
    # Semi-implicit free fall in 4 substeps equals 4 steps of a quarter of dt.
    w1 = mb.World(substeps=4)
    b1 = w1.add_body(mb.Sphere(1.0), position=(0, 10, 0))
    w2 = mb.World(substeps=1)
    b2 = w2.add_body(mb.Sphere(1.0), position=(0, 10, 0))
    w1.step(0.1)
    for _ in range(4):
        w2.step(0.025)
    np.testing.assert_allclose(b1.position, b2.position, atol=1e-14)


def test_advance_returns_alpha_and_loses_no_step():
    w = mb.World()
    b = w.add_body(mb.Sphere(0.5))
    alpha = w.advance(1.0 / 60.0 * 0.5, dt=1.0 / 60.0)
    assert alpha == pytest.approx(0.5)
    assert w.time == 0.0
    alpha = w.advance(1.0 / 60.0 * 0.75, dt=1.0 / 60.0)
    assert alpha == pytest.approx(0.25)
    assert w.time == pytest.approx(1.0 / 60.0)
    # 600 frames of 1/60 s at dt = 1/120: exactly 1200 steps, none lost to round-off in the sum.
    w2 = mb.World()
    w2.add_body(mb.Sphere(0.5))
    steps = 0
    for _ in range(600):
        before = w2.time
        a = w2.advance(1.0 / 60.0, dt=1.0 / 120.0)
        steps += round((w2.time - before) * 120)
        assert 0.0 <= a < 1.0
    assert steps == 1200
    assert b.position[1] < 0.0


def test_advance_max_steps_drops_the_excess():
    w = mb.World()
    w.add_body(mb.Sphere(0.5))
    alpha = w.advance(1.0, dt=0.01, max_steps=5)
    assert w.time == pytest.approx(0.05)
    assert alpha == 0.0


def test_spring_force_is_hooke():
    # One sub-step: the recorded mean force is the force at the step's start.
    w = mb.World(gravity=(0, 0, 0), substeps=1)
    a = w.add_body(mb.Sphere(0.1), position=(0, 0, 0))
    b = w.add_body(mb.Sphere(0.1), position=(3, 0, 0))
    s = w.add_spring(a, b, rest_length=1.0, stiffness=10.0)
    w.step(1e-3)
    # Stretched by 2 m: 20 N pulling a towards b.
    np.testing.assert_allclose(s.force, [20.0, 0, 0])
    assert not s.broken


def test_spring_damping_resists_stretching_rate():
    w = mb.World(gravity=(0, 0, 0), substeps=1)
    a = w.add_body(mb.Sphere(0.1), position=(0, 0, 0))
    b = w.add_body(mb.Sphere(0.1), position=(1, 0, 0), velocity=(2.0, 0, 0))
    s = w.add_spring(a, b, rest_length=1.0, stiffness=10.0, damping=3.0)
    w.step(1e-3)
    np.testing.assert_allclose(s.force, [6.0, 0, 0])


def test_spring_breaks_past_its_breaking_force():
    w = mb.World()
    ball = w.add_body(mb.Sphere(0.1), mass=1.0, position=(0, -1, 0))
    s = w.add_spring(ball, None, rest_length=1.0, stiffness=50.0, breaking_force=30.0)
    for _ in range(60):
        w.step(1.0 / 60.0)
    # Hanging at rest it would need 9.81 N; the bounce from release peaks near 2 m g = 19.6 N: no break.
    assert not s.broken
    ball.apply_impulse((0, -10.0, 0))
    for _ in range(60):
        w.step(1.0 / 60.0)
    assert s.broken
    w.step(1.0 / 60.0)
    v = ball.velocity[1]
    w.step(1.0 / 60.0)
    assert ball.velocity[1] - v == pytest.approx(-9.81 / 60.0, rel=1e-12)  # free fall once broken


def test_remove_keeps_other_bodies_valid():
    w = mb.World()
    bodies = [w.add_body(mb.Sphere(0.5), position=(i, 10, 0)) for i in range(4)]
    w.remove(bodies[1])
    assert w.bodies == [bodies[0], bodies[2], bodies[3]]
    w.step(0.1)
    np.testing.assert_allclose(bodies[3].position[0], 3.0)
    with pytest.raises(ValueError, match="removed"):
        bodies[1].position
    with pytest.raises(ValueError):
        w.remove(bodies[1])


def test_remove_body_removes_its_springs():
    w, a, b = simple_world()
    (s,) = w.constraints
    w.remove(a)
    assert w.constraints == []
    with pytest.raises(ValueError):
        s.force
    w.step(0.01)


def test_snapshot_restore_repeats_bit_for_bit():
    for integrator in ("semi_implicit_euler", "verlet", "rk4", "explicit_euler"):
        w, a, b = simple_world(integrator=integrator)
        for _ in range(10):
            w.step(1.0 / 60.0)
        snap = w.snapshot()
        for _ in range(50):
            w.step(1.0 / 60.0)
        h1, p1 = w.state_hash(), b.position
        w.restore(pickle.loads(pickle.dumps(snap)))
        for _ in range(50):
            w.step(1.0 / 60.0)
        assert w.state_hash() == h1
        assert np.array_equal(b.position, p1)


def test_restore_into_a_world_built_the_same_way():
    w1, _, b1 = simple_world()
    w2, _, b2 = simple_world()
    for _ in range(20):
        w1.step(1.0 / 60.0)
    w2.restore(w1.snapshot())
    for _ in range(20):
        w1.step(1.0 / 60.0)
        w2.step(1.0 / 60.0)
    assert w1.state_hash() == w2.state_hash()


def test_restore_drops_bodies_added_later():
    w, a, b = simple_world()
    snap = w.snapshot()
    c = w.add_body(mb.Sphere(1.0))
    w.restore(snap)
    assert w.bodies == [a, b]
    with pytest.raises(ValueError):
        c.position


def test_runs_are_deterministic():
    hashes = set()
    for _ in range(2):
        w, *_ = simple_world(integrator="rk4")
        for _ in range(100):
            w.step(1.0 / 60.0)
        hashes.add(w.state_hash())
    assert len(hashes) == 1


def test_body_handles_are_the_same_objects():
    w, a, b = simple_world()
    assert w.bodies[0] is a and w.bodies[1] is b
    c = w.constraints[0]
    assert c.body_a is a and c.body_b is b


def test_returned_vectors_are_copies():
    w, a, _ = simple_world()
    p = a.position
    p[0] = 99.0
    assert a.position[0] == 0.0
    assert p.dtype == np.float64 and p.shape == (3,)


def test_setting_state_by_hand():
    w = mb.World(integrator="verlet", substeps=1)
    b = w.add_body(mb.Sphere(0.5))
    w.step(0.01)
    b.position = (1, 2, 3)
    b.velocity = (1, 0, 0)
    w.step(0.01)
    # Verlet restarts from the state set by hand: x1 = x0 + v0 h + g h^2 / 2.
    np.testing.assert_allclose(b.position, [1.01, 2 - 0.5 * 9.81 * 1e-4, 3], atol=1e-14)


def test_static_body_never_moves():
    w = mb.World()
    s = w.add_static(mb.Plane())
    g = w.add_static(mb.Box((1, 1, 1)), position=(0, 3, 0))
    g.apply_force((100, 0, 0))
    w.step(0.1)
    np.testing.assert_allclose(g.position, [0, 3, 0])
    assert s.is_static and math.isinf(s.mass)
    with pytest.raises(ValueError, match="static"):
        g.velocity = (1, 0, 0)


# --- bad input: a clear error naming the argument, and the world unchanged --------------------------
BAD_CALLS = [
    ("dt", lambda w, b: w.step(float("nan"))),
    ("dt", lambda w, b: w.step(-0.1)),
    ("dt", lambda w, b: w.step(0.0)),
    ("position", lambda w, b: w.add_body(mb.Sphere(1), position=(0, float("nan"), 0))),
    ("position", lambda w, b: w.add_body(mb.Sphere(1), position=(0, 1))),
    ("velocity", lambda w, b: w.add_body(mb.Sphere(1), velocity=(0, float("inf"), 0))),
    ("orientation", lambda w, b: w.add_body(mb.Sphere(1), orientation=(0, 0, 0, 0))),
    ("mass", lambda w, b: w.add_body(mb.Sphere(1), mass=0.0)),
    ("mass", lambda w, b: w.add_body(mb.Sphere(1), mass=-1.0)),
    ("density", lambda w, b: w.add_body(mb.Sphere(1), density=float("nan"))),
    ("mass or density", lambda w, b: w.add_body(mb.Sphere(1), mass=1.0, density=1.0)),
    ("friction", lambda w, b: w.add_body(mb.Sphere(1), friction=-0.1)),
    ("static_friction", lambda w, b: w.add_body(mb.Sphere(1), static_friction=float("nan"))),
    ("restitution", lambda w, b: w.add_body(mb.Sphere(1), restitution=1.5)),
    ("rolling_friction", lambda w, b: w.add_body(mb.Sphere(1), rolling_friction=-1.0)),
    ("static only", lambda w, b: w.add_body(mb.Plane())),
    ("shape", lambda w, b: w.add_body("sphere")),
    ("shape", lambda w, b: w.add_body([])),
    ("sensor", lambda w, b: w.add_body(mb.Sphere(1), sensor="yes")),
    ("stiffness", lambda w, b: w.add_spring(b, None, rest_length=1, stiffness=-5)),
    ("rest_length", lambda w, b: w.add_spring(b, None, rest_length=float("nan"), stiffness=5)),
    ("breaking_force", lambda w, b: w.add_spring(b, None, rest_length=1, stiffness=5, breaking_force=0)),
    ("anchor_a", lambda w, b: w.add_spring(b, None, rest_length=1, stiffness=5, anchor_a=(1, 2))),
    ("a", lambda w, b: w.add_spring("x", None, rest_length=1, stiffness=5)),
    ("force", lambda w, b: b.apply_force((float("nan"), 0, 0))),
    ("point", lambda w, b: b.apply_force((1, 0, 0), point=(0, float("inf"), 0))),
    ("torque", lambda w, b: b.apply_torque((1, 0))),
    ("impulse", lambda w, b: b.apply_impulse("up")),
    ("position", lambda w, b: setattr(b, "position", (float("nan"), 0, 0))),
    ("orientation", lambda w, b: setattr(b, "orientation", (0, 0, 0, 0))),
    ("angular_velocity", lambda w, b: setattr(b, "angular_velocity", (1, 2, 3, 4))),
    ("frame_time", lambda w, b: w.advance(float("nan"))),
    ("dt", lambda w, b: w.advance(0.1, dt=-1)),
    ("body_or_constraint", lambda w, b: w.remove(3)),
    ("snapshot", lambda w, b: w.restore({})),
]


@pytest.mark.parametrize("name,call", BAD_CALLS, ids=[f"{i}-{n}" for i, (n, _) in enumerate(BAD_CALLS)])
def test_bad_input_is_refused_and_changes_nothing(name, call):
    w, b, _ = simple_world()
    w.step(0.01)
    before = w.state_hash()
    n_bodies, n_cons = len(w.bodies), len(w.constraints)
    with pytest.raises((ValueError, TypeError), match=name):
        call(w, b)
    assert w.state_hash() == before
    assert len(w.bodies) == n_bodies and len(w.constraints) == n_cons


@pytest.mark.parametrize("kwargs,name", [
    ({"solver": "magic"}, "solver"), ({"integrator": "euler"}, "integrator"),
    ({"broadphase": "quad"}, "broadphase"), ({"iterations": 0}, "iterations"),
    ({"substeps": 2.5}, "substeps"), ({"gravity": (0, float("nan"), 0)}, "gravity"),
    ({"ccd": 1}, "ccd"), ({"sleeping": None}, "sleeping"),
])
def test_bad_world_options(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        mb.World(**kwargs)


@pytest.mark.parametrize("make,name", [
    (lambda: mb.Sphere(0), "radius"), (lambda: mb.Sphere(float("nan")), "radius"),
    (lambda: mb.Box((1, 0, 1)), "half_extents"), (lambda: mb.Box((1, 1)), "half_extents"),
    (lambda: mb.Capsule(1, -1), "half_height"), (lambda: mb.Plane((0, 0, 0)), "normal"),
    (lambda: mb.Plane(offset=float("inf")), "offset"), (lambda: mb.Sphere("1"), "radius"),
])
def test_bad_shapes(make, name):
    with pytest.raises((ValueError, TypeError), match=name):
        make()


def test_a_sleeping_body_still_reports_the_contacts_that_hold_it():
    """A 3 kg ball resting on the ground falls asleep; its contacts stay in ``contacts()``, carrying its
    weight: the normal impulses over a step sum to m g dt (29.43 N over 1/60 s)."""
    w = mb.World()
    ground = w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.2), mass=3.0, position=(0.0, 0.2, 0.0))
    dt = 1.0 / 60.0
    for _ in range(240):
        w.step(dt)
    assert ball.is_sleeping
    for _ in range(3):                                    # it stays reported, step after step
        w.step(dt)
        contacts = w.contacts()
        assert contacts and all({c.body_a, c.body_b} == {ground, ball} for c in contacts)
        assert sum(c.normal_impulse for c in contacts) / dt == pytest.approx(3.0 * 9.81, rel=1e-3)
    ball.apply_impulse((1.0, 0.0, 0.0))                  # woken, solved again: no duplicate rows
    w.step(dt)
    assert not ball.is_sleeping
    assert len(w.contacts()) == len(contacts)
