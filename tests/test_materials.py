"""Materials: written at any time, torsional friction against spin about the normal, and damping.

The expected values come from the equations of motion: a sphere resting on a plane is held up by exactly
``m g``, so torsional friction ``tau`` turns its spin down at ``tau m g / I``; damping split off exactly
multiplies a free body's velocities by ``exp(-c h)`` per sub-step.
"""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest

import marbellous as mb
from marbellous.material import FIELDS
from marbellous.state import layout as L

DT = 1.0 / 60.0
SOLVERS = ("sequential_impulse", "lcp", "penalty")
INTEGRATORS = ("explicit_euler", "semi_implicit_euler", "verlet", "rk4")


def test_material_fields_are_the_layouts_columns_in_order():
    assert tuple(col for col, _ in FIELDS.values()) == L.MATERIAL


def _spinning_ball(solver, **ground):
    """A 2 kg ball of radius 0.5 m resting on a plane, spinning at 10 rad/s about the vertical."""
    w = mb.World(solver=solver, sleeping=False)
    w.add_static(mb.Plane((0.0, 1.0, 0.0), 0.0), **ground)
    ball = w.add_body(mb.Sphere(0.5), position=(0.0, 0.5, 0.0), mass=2.0, angular_velocity=(0.0, 10.0, 0.0))
    return w, ball


@pytest.mark.parametrize("solver", SOLVERS)
def test_torsional_friction_stops_a_spin_at_the_rate_of_its_torque(solver):
    """``I domega/dt = -tau m g``, ``I = 2/5 m r^2``: after 2 s the spin is ``10 - 2 tau g / (0.4 r^2)``.
    The ball rests on its contact throughout, so the normal impulse is ``m g h`` to the solver's round-off:
    1e-9 rad/s leaves room for that and for 480 sub-steps of rounding."""
    tau, r = 0.01, 0.5
    w, ball = _spinning_ball(solver, torsional_friction=tau)
    for _ in range(120):
        w.step(DT)
    expected = 10.0 - 9.81 * tau / (0.4 * r * r) * 2.0
    np.testing.assert_allclose(ball.angular_velocity, [0.0, expected, 0.0], atol=1e-9)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_spin_turns_freely_once_its_torsional_friction_is_set_to_zero(solver):
    """Torsional friction slows the spin for 1 s; then the ball's is set to 0 (the plane's is 0): from the
    next step on, no angular impulse about the normal may act, not even the one the contact had
    accumulated (warm-started with nothing left to bound it, it would keep slowing the spin at the old
    rate, 0.98 rad/s^2), so the spin stays as it was to round-off."""
    w, ball = _spinning_ball(solver, torsional_friction=0.0)
    ball.torsional_friction = 0.01
    for _ in range(60):
        w.step(DT)
    ball.torsional_friction = 0.0
    w.step(DT)
    spin = ball.angular_velocity.copy()
    assert spin[1] < 9.1
    for _ in range(60):
        w.step(DT)
    np.testing.assert_allclose(ball.angular_velocity, spin, atol=1e-9)


@pytest.mark.parametrize("solver", SOLVERS)
def test_rolling_friction_leaves_a_spin_about_the_normal_alone(solver):
    """Rolling resistance acts across the normal only: a ball spinning about the vertical on its one
    contact point feels no torque about it (the friction force's lever arm is parallel to the normal)."""
    w, ball = _spinning_ball(solver, rolling_friction=0.05)
    for _ in range(60):
        w.step(DT)
    np.testing.assert_allclose(ball.angular_velocity, [0.0, 10.0, 0.0], atol=1e-9)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_damping_decays_a_free_bodys_velocities_exactly(integrator):
    """No force: ``v(t) = v0 exp(-c t)`` and ``omega(t) = omega0 exp(-c_w t)`` for every integrator, to
    round-off.  The box spins about its principal axis z, so the angular velocity keeps its direction.
    Its position follows the split's sum ``x = v0 h f (1 - f^n) / (1 - f)``, ``f = exp(-c h)``: damping
    acts first, so even explicit Euler moves each sub-step with the damped velocity."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator, substeps=4, sleeping=False)
    box = w.add_body(mb.Box((0.1, 0.2, 0.3)), velocity=(3.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 2.0),
                     linear_damping=0.7, angular_damping=1.3)
    for _ in range(60):
        w.step(DT)
    np.testing.assert_allclose(box.velocity, [3.0 * math.exp(-0.7), 0.0, 0.0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(box.angular_velocity, [0.0, 0.0, 2.0 * math.exp(-1.3)], rtol=1e-12, atol=1e-15)
    h, n = DT / 4, 240
    f = math.exp(-0.7 * h)
    x = 3.0 * h * f * (1.0 - f ** n) / (1.0 - f)
    assert box.position[0] == pytest.approx(x, rel=1e-12)


def test_damping_against_gravity_reaches_the_splits_terminal_speed():
    """Under gravity the split ``v := v exp(-c h) + g h`` settles at ``g h / (1 - exp(-c h))``, within
    ``c h / 2`` of the exact ``g / c``.  After 20 time constants the gap to it is ``exp(-20)`` of g / c."""
    c = 2.0
    w = mb.World(substeps=4, sleeping=False)
    ball = w.add_body(mb.Sphere(0.1), linear_damping=c)
    for _ in range(600):
        w.step(DT)
    h = DT / 4
    terminal = 9.81 * h / (1.0 - math.exp(-c * h))
    assert ball.velocity[1] == pytest.approx(-terminal, rel=1e-8)
    assert terminal == pytest.approx(9.81 / c, rel=c * h / 2 * 1.01)


def _box_on_slope(friction):
    """A box resting on a plane tilted 30 degrees about z (friction ``friction`` on both)."""
    angle = math.radians(30.0)
    w = mb.World()
    slope = w.add_static(mb.Plane((-math.sin(angle), math.cos(angle), 0.0), 0.0), friction=friction)
    box = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.0, 0.2, 0.0),
                     orientation=(math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)), friction=friction)
    return w, slope, box


def test_writing_a_static_bodys_friction_wakes_what_rests_on_it():
    """A box at rest on a 30 degree slope (mu = 1 > tan 30 deg) falls asleep; with the slope's friction set
    and static friction to 0 (combined sqrt(0 x 1) = 0) it wakes and slides down at g sin 30 deg."""
    w, slope, box = _box_on_slope(1.0)
    for _ in range(120):
        w.step(DT)
    assert box.is_sleeping
    slope.friction = 0.0
    slope.static_friction = 0.0
    assert (slope.friction, slope.static_friction, box.is_sleeping) == (0.0, 0.0, False)
    for _ in range(30):
        w.step(DT)
    v = box.velocity
    speed = float(np.linalg.norm(v))
    # 0.5 s of frictionless sliding from rest: g sin(30 deg) t (the contact is held within the solver's
    # velocity tolerance, 1e-5 m/s per sub-step).
    assert speed == pytest.approx(9.81 * 0.5 * 0.5, rel=1e-3)
    assert v[1] < 0.0 and v[0] < 0.0


def test_writing_a_bodys_restitution_changes_its_next_bounce():
    """A ball dropped onto a plane from rest bounces back to ``e^2`` of its drop height: set ``e`` to 0.5
    in flight and the apex after the bounce is a quarter of the drop (speculative contacts take the
    impact at its time; the tolerance is the integrator's ``g h^2 / 2`` per sub-step)."""
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.1), position=(0.0, 1.1, 0.0))
    w.step(DT)
    ball.restitution = 0.5
    assert ball.restitution == 0.5
    apex = 0.0
    for _ in range(90):
        w.step(DT)
        if ball.velocity[1] <= 0.0 < ball.position[1] - 0.1 and w.time > 0.5:
            apex = max(apex, ball.position[1] - 0.1)
    assert apex == pytest.approx(0.25, abs=0.01)


@pytest.mark.parametrize("name, value", [
    ("friction", -0.1), ("static_friction", float("nan")), ("restitution", 1.5), ("rolling_friction", -1.0),
    ("torsional_friction", float("inf")), ("linear_damping", -1.0), ("angular_damping", "fast"),
])
def test_a_bad_material_value_is_refused_and_changes_nothing(name, value):
    w = mb.World()
    ball = w.add_body(mb.Sphere(0.1))
    before = w.state_hash()
    with pytest.raises((ValueError, TypeError), match=name):
        setattr(ball, name, value)
    assert w.state_hash() == before
    with pytest.raises((ValueError, TypeError), match=name):
        w.add_body(mb.Sphere(0.1), **{name: value})
    assert w.state_hash() == before


def test_material_values_read_back_and_a_removed_body_refuses():
    w = mb.World()
    ball = w.add_body(mb.Sphere(0.1), friction=0.3, torsional_friction=0.002, linear_damping=0.1)
    assert (ball.friction, ball.static_friction, ball.torsional_friction, ball.linear_damping,
            ball.angular_damping) == (0.3, 0.3, 0.002, 0.1, 0.0)
    for name in FIELDS:
        setattr(ball, name, 0.25)
        assert getattr(ball, name) == 0.25
    w.remove(ball)
    with pytest.raises(ValueError, match="removed"):
        ball.friction = 0.5


def test_the_example_changes_materials_as_the_equations_say():
    """examples/materials.py: after 2.5 s the top spins at ``10 - tau g t / (0.4 r^2)``; 1 s after the
    slope turned to ice the crate slides at ``g (sin 30 - sqrt(0.05) cos 30) t`` (combined friction by
    geometric mean); 1 s after its damping came on the probe drifts at ``2 exp(-0.5)``."""
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "materials.py"))["run"]
    spin, crate, probe = run()
    assert spin == pytest.approx(10.0 - 0.01 * 9.81 * 2.5 / 0.1, abs=1e-9)
    mu = math.sqrt(0.05)
    assert crate == pytest.approx(9.81 * (0.5 - mu * math.cos(math.radians(30.0))), rel=1e-3)
    assert probe == pytest.approx(2.0 * math.exp(-0.5), rel=1e-12)
