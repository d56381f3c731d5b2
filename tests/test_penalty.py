"""The penalty scheme: the contact spring's restitution against a fine integration of its equation, and
World(solver="penalty") against mechanics: weight carried, sinking g / omega^2, stacks at rest, rolling,
sliding, restitution, momentum."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mechanics import (DT, HEAD_ON, ROLLING_ACCELERATION, G, acceleration_downhill, box_on_incline, box_on_slope,
                       head_on_collision, sliding_acceleration, sliding_past_static_angle, sphere_on_incline)

import marbellous as mb
from marbellous.dynamics.penalty import STABLE_FRACTION, damping_ratio, spring_restitution
from marbellous.scenes import box_tower


def contact_omega(w, dt=DT):
    """The contact springs' angular frequency (rad/s) for steps of dt: the capped penalty_hertz."""
    h = dt / w.substeps
    return 2.0 * math.pi * min(w.penalty_hertz, STABLE_FRACTION / h)


def reference_restitution(zeta, steps=200000):
    """Integrate d'' = -(d + 2 zeta d') (w0 = 1, d(0) = 0, d'(0) = 1) by RK4 while the force d + 2 zeta d'
    pushes; the restitution is the speed at release."""
    h = 10.0 / steps
    d, v = 0.0, 1.0

    def acc(d, v):
        return -(d + 2.0 * zeta * v)

    for _ in range(steps):
        k1d, k1v = v, acc(d, v)
        k2d, k2v = v + 0.5 * h * k1v, acc(d + 0.5 * h * k1d, v + 0.5 * h * k1v)
        k3d, k3v = v + 0.5 * h * k2v, acc(d + 0.5 * h * k2d, v + 0.5 * h * k2v)
        k4d, k4v = v + h * k3v, acc(d + h * k3d, v + h * k3v)
        nd = d + h / 6.0 * (k1d + 2 * k2d + 2 * k3d + k4d)
        nv = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if nd + 2.0 * zeta * nv <= 0.0:
            # Release between the two samples: interpolate the force's zero crossing.
            f0, f1 = d + 2.0 * zeta * v, nd + 2.0 * zeta * nv
            return -(v + (nv - v) * f0 / (f0 - f1))
        d, v = nd, nv
    raise AssertionError("never released")


@settings(max_examples=12, deadline=None)
@given(zeta=st.floats(0.0, 1.0))
def test_spring_restitution_matches_integration(zeta):
    assert spring_restitution(zeta) == pytest.approx(reference_restitution(zeta), abs=1e-6)


@settings(max_examples=300, deadline=None)
@given(e=st.floats(math.exp(-2.0) + 1e-6, 1.0))
def test_damping_ratio_inverts_restitution(e):
    assert spring_restitution(damping_ratio(e)) == pytest.approx(e, abs=1e-9)


def test_low_restitution_gets_critical_damping():
    assert damping_ratio(0.0) == 1.0
    assert spring_restitution(1.0) == pytest.approx(math.exp(-2.0))


def test_resting_ball_carries_its_weight_and_sinks_g_over_omega_squared():
    w = mb.World(solver="penalty", sleeping=False)
    w.add_static(mb.Plane())
    r, m = 0.2, 3.0
    ball = w.add_body(mb.Sphere(r), mass=m, position=(0, r, 0))
    for _ in range(120):
        w.step(DT)
    total = 0.0
    for _ in range(60):
        w.step(DT)
        (c,) = w.contacts()
        total += c.normal_impulse
    assert total / (60 * DT) == pytest.approx(m * G, rel=1e-6)
    # The contact is a spring of stiffness m omega^2 (a sphere's effective mass is m): it yields g / omega^2.
    assert r - ball.position[1] == pytest.approx(G / contact_omega(w) ** 2, rel=1e-6)


def test_user_forces_are_kept_beside_the_contact_springs():
    # A box pulled up by half its weight rests on the springs with the other half; the pull is not lost.
    w = mb.World(solver="penalty", sleeping=False)
    w.add_static(mb.Plane())
    box = w.add_body(mb.Box((0.5, 0.25, 0.5)), mass=10.0, position=(0, 0.25, 0))
    for _ in range(180):
        box.apply_force((0, 0.5 * 10.0 * G, 0))
        w.step(DT)
    assert sum(c.normal_impulse for c in w.contacts()) == pytest.approx(0.5 * 10.0 * G * DT, rel=1e-6)


@pytest.mark.parametrize("height", [3, 5])
def test_stack_stays_at_rest(height):
    w, boxes = box_tower(mb.World(solver="penalty", sleeping=False), height=height)
    for _ in range(120):
        w.step(DT)
    settled = np.array([b.position for b in boxes])
    for _ in range(300):
        w.step(DT)
    # Five seconds later nothing has moved by more than 10 micrometres (the last of the damped settling).
    assert np.abs(np.array([b.position for b in boxes]) - settled).max() < 1e-5
    assert max(np.linalg.norm(b.velocity) for b in boxes) < 1e-5
    # Four corner springs of effective mass m/4 on the ground (stiffness m omega^2), m/8 between two boxes
    # (m omega^2 / 2): layer k carries (height - k) boxes, so box i sinks by sum over the layers below it.
    g_w2 = G / contact_omega(w) ** 2
    for i in range(height):
        expected = height * g_w2 + sum(2.0 * (height - k) * g_w2 for k in range(1, i + 1))
        assert 0.5 + i - settled[i, 1] == pytest.approx(expected, rel=0.02)


def test_sphere_rolls_down_incline_without_slipping():
    r = 0.5
    w = mb.World(solver="penalty", sleeping=False)
    b = sphere_on_incline(w, r)
    assert acceleration_downhill(w, b) == pytest.approx(ROLLING_ACCELERATION, rel=0.02)
    assert np.linalg.norm(b.angular_velocity) * r == pytest.approx(np.linalg.norm(b.velocity), rel=0.02)


def test_box_slides_with_dynamic_friction():
    mu = 0.2
    w = mb.World(solver="penalty", sleeping=False)
    b = box_on_incline(w, mu)
    assert acceleration_downhill(w, b) == pytest.approx(sliding_acceleration(mu), rel=0.02)


@pytest.mark.parametrize("e", [0.3, 0.5, 0.8, 1.0])
def test_resolved_collision_has_the_restitution_and_conserves_momentum(e):
    # A soft spring resolved by many sub-steps (omega h = 0.03): the explicit force lags the motion by a
    # sub-step, an error of order omega h in the separation speed.
    w = mb.World(gravity=(0, 0, 0), solver="penalty", sleeping=False, substeps=64)
    w.penalty_hertz = 20.0
    a, b = head_on_collision(w, e)
    m1, m2, u1, u2 = HEAD_ON
    np.testing.assert_allclose(m1 * a.velocity + m2 * b.velocity, [m1 * u1 + m2 * u2, 0, 0], atol=1e-12)
    omega_h = contact_omega(w) * DT / w.substeps
    assert (b.velocity[0] - a.velocity[0]) / (u1 - u2) == pytest.approx(e, abs=omega_h / 2)


def test_stiffness_above_the_stable_limit_is_capped():
    w, boxes = box_tower(mb.World(solver="penalty", sleeping=False), height=3)
    w.penalty_hertz = 1e6
    for _ in range(240):
        w.step(DT)
    assert all(np.all(np.isfinite(b.position)) for b in boxes)
    assert max(np.linalg.norm(b.velocity) for b in boxes) < 1e-6


def test_penalty_hertz_is_validated():
    w = mb.World(solver="penalty")
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="penalty_hertz"):
            w.penalty_hertz = bad



def test_a_box_between_the_two_friction_angles_stays_put():
    """mu_s = 0.6, mu_d = 0.4 and a slope of 25 deg (atan 0.4 = 21.8 < 25 < atan 0.6 = 31.0): released at
    rest, the box is held by static friction (it slid 1.4 m in 2 s when its landing slip counted as
    sliding).  It settles onto its springs (the penalty scheme's sink and stretch, below 2 mm) and stays."""
    w, box, _ = box_on_slope("penalty", 25.0)
    for _ in range(30):
        w.step(1.0 / 60.0)
    start = box.position
    for _ in range(120):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(box.position - start) < 1e-4


def test_a_box_holds_up_to_the_static_friction_angle_and_slides_past_it():
    """mu_s = 0.6, mu_d = 0.4.  Released at rest 0.2 deg below atan(mu_s), the box slips while its springs
    take its weight (up to 6 cm/s: they start from zero force) and static friction, at its cone, holds that
    slip back (g (mu_s cos - sin) = 0.04 m/s^2): it is at rest within 2.5 s.  (It used to break loose about
    3 deg early: the slip of that landing counted as sliding.)  0.2 deg above, it breaks loose and slides
    with dynamic friction's acceleration g (sin - mu_d cos), to the sub-millimetre settling of its springs."""
    angle = math.degrees(math.atan(0.6))
    w, box, _ = box_on_slope("penalty", angle - 0.2)
    for _ in range(150):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(box.velocity) < 1e-3
    measured, expected = sliding_past_static_angle("penalty")
    assert measured == pytest.approx(expected, rel=0.01)
