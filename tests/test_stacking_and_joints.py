"""Stacks at 60 Hz with default settings, sleeping and waking, rods, cables and breaking springs."""

import numpy as np
import pytest
from mechanics import DT, rod_pendulum

import marbellous as mb
from marbellous.scenes import box_pyramid, box_tower, sphere_pile


def test_tower_of_twenty_stands_for_ten_seconds():
    w, boxes = box_tower(height=20)
    for _ in range(600):
        w.step(DT)
    assert boxes[-1].is_sleeping
    for i, b in enumerate(boxes):
        # Each resting contact yields ~g / (2 pi f)^2 per box it carries (f = contact stiffness, 60 Hz):
        # a few millimetres in all; the column stays upright within a centimetre.
        assert abs(b.position[1] - (0.5 + i)) < 0.05
        assert np.hypot(b.position[0], b.position[2]) < 0.02


def test_pyramid_stands_falls_asleep_and_wakes_when_hit():
    w, boxes = box_pyramid(base=20)
    start = np.array([b.position for b in boxes])
    for _ in range(300):
        w.step(DT)
    end = np.array([b.position for b in boxes])
    assert np.max(np.abs(end - start)) < 0.05
    assert all(b.is_sleeping for b in boxes)
    # A ball thrown at the top wakes its island.
    top = boxes[-1]
    w.add_body(mb.Sphere(0.3), position=top.position + np.array([-3.0, 0.0, 0.0]), velocity=(20.0, 0, 0),
               mass=3000.0)  # the boxes weigh a tonne each
    for _ in range(30):
        w.step(DT)
    assert not top.is_sleeping
    assert np.linalg.norm(top.position - end[-1]) > 0.1


def test_a_world_at_rest_runs_no_sub_step_until_something_moves():
    # every box asleep: no contact to solve and no body to move, so the step skips its sub-steps (no velocity
    # iteration, no time in their stages); a kinematic pusher set moving runs them again and wakes what it meets
    w, boxes = box_pyramid(base=4)
    pusher = w.add_kinematic(mb.Box((0.2, 0.5, 2.0)), position=(-4.0, 0.5, 0.0))
    for _ in range(120):
        w.step(DT)
    assert all(b.is_sleeping for b in boxes)
    w.profiling = True
    for _ in range(10):
        w.step(DT)
    p = w.profile
    assert p.iterations == 0 and p.seconds["integrate_velocities"] == 0.0 and p.seconds["solve"] == 0.0
    start = boxes[0].position.copy()
    pusher.velocity = (2.0, 0.0, 0.0)
    w.reset_profile()
    for _ in range(60):
        w.step(DT)
    assert w.profile.iterations > 0 and w.profile.seconds["integrate_positions"] > 0.0
    assert np.linalg.norm(boxes[0].position - start) > 0.1


def test_a_pile_of_a_thousand_spheres_with_rolling_and_torsional_friction_falls_asleep_once_settled():
    # Spheres without rolling or torsional friction keep rolling and spinning on each other, so a pile never
    # comes quite to rest; with a centimetre of each it is asleep within 10 s of settling (here: of its
    # fastest sphere going slower than 0.5 m/s for good, the benchmark's "settled"), as in Jolt and Box2D.
    w, spheres = sphere_pile(count=1000, rolling_friction=0.01, torsional_friction=0.01)
    fell = settled = 0.0
    while w.time < 30.0 and not all(b.is_sleeping for b in spheres):
        w.step(DT)
        if max(np.linalg.norm(b.velocity) for b in spheres) >= 0.5:
            fell, settled = True, w.time
    assert fell and all(b.is_sleeping for b in spheres)
    assert w.time - settled < 10.0
    # asleep, it holds still: no sphere sinks into another or the floor by more than a centimetre
    assert min(b.position[1] for b in spheres) > 0.5 - 0.01


def test_force_wakes_a_sleeping_body():
    w = mb.World()
    w.add_static(mb.Plane())
    b = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0, 0.5, 0))
    for _ in range(120):
        w.step(DT)
    assert b.is_sleeping
    b.apply_force((0, 2e4, 0))
    assert not b.is_sleeping
    w.step(DT)
    assert b.position[1] > 0.5


def test_wake_wakes_the_island_only():
    w = mb.World()
    w.add_static(mb.Plane())
    stack = [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0, 0.5 + k, 0)) for k in range(3)]
    lone = w.add_body(mb.Sphere(0.5), position=(5, 0.5, 0))
    for _ in range(300):
        w.step(DT)
    assert all(b.is_sleeping for b in stack) and lone.is_sleeping
    before = [b.position for b in stack]
    stack[-1].wake()
    assert not any(b.is_sleeping for b in stack) and lone.is_sleeping
    w.step(DT)
    assert not any(b.is_sleeping for b in stack)     # the rest timer restarted
    # woken, the stack still rests where it slept (a wake adds no motion)
    assert max(np.max(np.abs(b.position - p)) for b, p in zip(stack, before)) < 1e-3


@pytest.mark.parametrize("integrator, solver", [("semi_implicit_euler", "sequential_impulse"),
                                               ("verlet", "sequential_impulse"), ("rk4", "sequential_impulse"),
                                               ("semi_implicit_euler", "lcp")])
def test_rod_pendulum_keeps_length_and_period(integrator, solver):
    worst, period, exact = rod_pendulum(mb.World(integrator=integrator, solver=solver))
    assert worst < 2e-3
    assert period == pytest.approx(exact, rel=1e-3)


@pytest.mark.parametrize("integrator", ["explicit_euler", "semi_implicit_euler", "verlet", "rk4"])
def test_a_rod_pulls_three_times_the_weight_at_the_bottom_of_a_swing(integrator):
    """A 1 kg bob on a 1 m rod released level: at the bottom the rod pulls ``m g + m v^2 / L = 3 m g``
    (``v^2 = 2 g L``), with every integrator (Verlet's read 39 N once).  Read once a step, the largest
    force is at most ``3 m g theta^2 / 2`` low for the step's nearest angle to the bottom, ``theta`` at
    most half a step's turn ``sqrt(2 g / L) dt / 2`` (0.02 N), plus the methods' energy error over the
    quarter swing: 0.06 N in all."""
    w = mb.World(integrator=integrator, sleeping=False)
    bob = w.add_body(mb.Sphere(0.05), mass=1.0, position=(1.0, 0.0, 0.0))
    rod = w.add_rod(bob, None, length=1.0)
    largest = 0.0
    for _ in range(40):
        w.step(1.0 / 60.0)
        largest = max(largest, float(np.linalg.norm(rod.force)))
    assert largest == pytest.approx(3.0 * 9.81, abs=0.06)


def test_rod_between_two_bodies_and_its_force():
    w = mb.World(gravity=(0, 0, 0))
    a = w.add_body(mb.Sphere(0.1), mass=1.0, position=(0, 0, 0), velocity=(0, 1.0, 0))
    b = w.add_body(mb.Sphere(0.1), mass=1.0, position=(1, 0, 0), velocity=(0, -1.0, 0))
    rod = w.add_rod(a, b)
    assert rod.length == pytest.approx(1.0)
    for _ in range(120):
        w.step(DT)
    assert np.linalg.norm(b.position - a.position) == pytest.approx(1.0, abs=2e-3)
    # Spinning about the centre at omega = 2 v / L: the rod pulls each with m v^2 / r = 1 * 1 / 0.5 = 2 N.
    assert np.linalg.norm(rod.force) == pytest.approx(2.0, rel=0.02)
    np.testing.assert_allclose(a.velocity + b.velocity, 0.0, atol=1e-9)


def test_cable_is_slack_below_its_length_and_taut_at_it():
    w = mb.World()
    weight = w.add_body(mb.Sphere(0.1), mass=2.0, position=(0, -0.5, 0))
    cable = w.add_cable(weight, None, max_length=1.0, anchor_b=(0, 0, 0))
    w.step(DT)
    assert np.linalg.norm(cable.force) == 0.0  # slack: free fall
    for _ in range(180):
        w.step(DT)
    assert weight.position[1] == pytest.approx(-1.0, abs=2e-3)
    # Hanging still: the cable carries the weight.
    np.testing.assert_allclose(cable.force, [0, 2.0 * 9.81, 0], rtol=0.02, atol=0.05)
    weight.velocity = (0, 3.0, 0)  # thrown up: the cable goes slack again
    w.step(DT)
    assert np.linalg.norm(cable.force) == 0.0


def test_chain_of_springs_breaks_at_its_weakest_link():
    # Three balls hang from springs; a strong pull breaks the link that carries the most load first.
    w = mb.World()
    balls = [w.add_body(mb.Sphere(0.1), mass=1.0, position=(0, -(i + 1), 0)) for i in range(3)]
    springs = [w.add_spring(balls[0], None, rest_length=1.0, stiffness=2000.0, damping=20.0, breaking_force=200.0)]
    for i in range(2):
        springs.append(w.add_spring(balls[i], balls[i + 1], rest_length=1.0, stiffness=2000.0, damping=20.0,
                                    breaking_force=200.0))
    for _ in range(60):
        w.step(DT)
    assert not any(s.broken for s in springs)
    balls[2].apply_force((0, -12000.0, 0))
    for _ in range(5):
        w.step(DT)
        balls[2].apply_force((0, -12000.0, 0)) if not any(s.broken for s in springs) else None
    assert springs[0].broken or springs[2].broken


@pytest.mark.parametrize("kwargs,name", [({"length": 0.0}, "length"), ({"length": float("nan")}, "length"),
                                         ({"anchor_a": (1, 2)}, "anchor_a")])
def test_bad_rod_input(kwargs, name):
    w = mb.World()
    b = w.add_body(mb.Sphere(0.1))
    before = w.state_hash()
    with pytest.raises((ValueError, TypeError), match=name):
        w.add_rod(b, None, **kwargs)
    assert w.state_hash() == before
    with pytest.raises(ValueError, match="max_length"):
        w.add_cable(b, None, max_length=-1.0)
