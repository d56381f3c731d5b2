"""Contact dynamics against mechanics: rolling, sliding, sticking, bouncing, collisions, resting forces."""
import math

import numpy as np
import pytest
from mechanics import (DOWNHILL, HEAD_ON, N_INCLINE, ROLLING_ACCELERATION, G, acceleration_downhill, box_on_incline,
                       box_on_slope, head_on_collision, sliding_acceleration, sliding_past_static_angle,
                       sphere_on_incline)

import marbellous as mb

SOLVERS = ["sequential_impulse", "lcp"]   # the penalty scheme has its own tests (test_penalty.py)


@pytest.mark.parametrize("solver", SOLVERS)
def test_sphere_rolls_down_incline_without_slipping(solver):
    # Rolling without slipping: a = 5/7 g sin(theta), omega r = v.
    r = 0.5
    w = mb.World(solver=solver, sleeping=False)
    b = sphere_on_incline(w, r)
    a = acceleration_downhill(w, b)
    assert a == pytest.approx(ROLLING_ACCELERATION, rel=0.02)
    assert np.linalg.norm(b.angular_velocity) * r == pytest.approx(np.linalg.norm(b.velocity), rel=0.02)
    # It stays on the surface (the soft contact yields far less than a millimetre).
    assert b.position @ N_INCLINE == pytest.approx(r, abs=1e-3)


@pytest.mark.parametrize("solver", SOLVERS)
def test_box_slides_with_dynamic_friction(solver):
    mu = 0.2
    w = mb.World(solver=solver, sleeping=False)
    b = box_on_incline(w, mu)
    a = acceleration_downhill(w, b)
    assert a == pytest.approx(sliding_acceleration(mu), rel=0.02)
    # Coulomb: the friction impulse of every contact stays inside its cone.
    for c in w.contacts():
        assert np.linalg.norm(c.tangent_impulse) <= mu * c.normal_impulse * (1.0 + 1e-9)


@pytest.mark.parametrize("solver", SOLVERS)
def test_static_friction_holds_and_dynamic_friction_slides_once_pushed(solver):
    # mu_s = 0.6 > tan(20 deg) = 0.364 > mu_d = 0.2: the box stays put ...
    mu_s, mu_d = 0.6, 0.2
    w = mb.World(solver=solver, sleeping=False)
    b = box_on_incline(w, mu_d, mu_s)
    for _ in range(120):
        w.step(1.0 / 60.0)
    start = b.position
    for _ in range(120):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(b.position - start) < 1e-4
    # ... and, pushed into sliding, it accelerates at g (sin - mu_d cos).
    b.velocity = DOWNHILL * 1.0
    a = acceleration_downhill(w, b, w.time + 0.25, w.time + 1.25)
    assert a == pytest.approx(sliding_acceleration(mu_d), rel=0.02)


@pytest.mark.parametrize("e", [0.5, 0.8, 1.0])
def test_ball_bounces_to_e_squared_h(e):
    drop, dt = 1.0, 1.0 / 240.0
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane(), restitution=e)
    b = w.add_body(mb.Sphere(0.1), position=(0, drop + 0.1, 0), restitution=e)
    peak, bounced, prev = 0.0, False, 0.0
    for _ in range(2000):
        w.step(dt)
        vy = b.velocity[1]
        bounced = bounced or (prev < 0.0 < vy)
        if bounced:
            peak = max(peak, b.position[1] - 0.1)
            if vy < 0.0:
                break
        prev = vy
    # Semi-implicit Euler over sub-steps h loses about v h / 2 of height on the way down and again on the
    # way up (v the impact speed): a relative error of at most 2 v h / drop.
    h = dt / w.substeps
    v = math.sqrt(2 * G * drop)
    assert peak == pytest.approx(e * e * drop, rel=2 * v * h / drop)


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_head_on_collision_conserves_momentum(e):
    a, b = head_on_collision(mb.World(gravity=(0, 0, 0), sleeping=False), e)
    m1, m2, u1, u2 = HEAD_ON
    p1 = m1 * a.velocity + m2 * b.velocity
    np.testing.assert_allclose(p1, [m1 * u1 + m2 * u2, 0, 0], atol=1e-12)
    # Newton's law of restitution: separation speed = e * approach speed.
    v1, v2 = a.velocity[0], b.velocity[0]
    assert v2 - v1 == pytest.approx(e * (u1 - u2), abs=1e-9)
    if e == 1.0:
        ke0 = 0.5 * m1 * u1 ** 2 + 0.5 * m2 * u2 ** 2
        ke1 = 0.5 * m1 * v1 ** 2 + 0.5 * m2 * v2 ** 2
        assert ke1 == pytest.approx(ke0, rel=1e-12)  # position correction adds no energy
    np.testing.assert_allclose(a.angular_velocity, 0.0, atol=1e-12)


def test_resting_normal_impulses_carry_the_weight():
    dt = 1.0 / 60.0
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane())
    box = w.add_body(mb.Box((0.5, 0.25, 0.5)), mass=10.0, position=(0, 0.25, 0))
    for _ in range(120):
        w.step(dt)
    contacts = w.contacts()
    assert len(contacts) == 4
    total = sum(c.normal_impulse for c in contacts)
    assert total == pytest.approx(10.0 * G * dt, rel=1e-3)
    for c in contacts:
        # The plane is body_a (added first): normals point from it up into the box.
        np.testing.assert_allclose(c.normal, [0, 1, 0], atol=1e-12)
        assert c.body_b is box


def test_marble_comes_to_rest_by_rolling_friction():
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane(), friction=0.5, rolling_friction=0.01)
    r = 0.1
    b = w.add_body(mb.Sphere(r), position=(0, r, 0), velocity=(2.0, 0, 0), angular_velocity=(0, 0, -20.0),
                   friction=0.5, rolling_friction=0.01)
    # Rolling resistance torque rho N decelerates a rolling ball at a = rho g / (r (1 + 2/5)) (solid sphere).
    decel = 0.01 * G / (r * 1.4)
    t_stop = 2.0 / decel
    for _ in range(int((t_stop + 0.5) * 60)):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(b.velocity) < 1e-3
    assert np.linalg.norm(b.angular_velocity) < 1e-2
    assert b.position[0] == pytest.approx(2.0 ** 2 / (2 * decel), rel=0.05)


def test_sensor_reports_overlap_and_exerts_no_force():
    w = mb.World()
    goal = w.add_static(mb.Box((1, 1, 1)), position=(0, 1, 0), sensor=True)
    ball = w.add_body(mb.Sphere(0.25), position=(0, 3, 0))
    seen = False
    for _ in range(90):
        w.step(1.0 / 60.0)
        seen = seen or any(c.body_a is goal or c.body_b is goal for c in w.contacts())
    assert seen
    assert ball.position[1] < -1.0  # fell straight through


def test_contacts_are_reported_at_the_start_of_the_step():
    w = mb.World(sleeping=False)
    plane = w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.5), position=(0, 0.5, 0))
    w.step(1.0 / 60.0)
    (c,) = w.contacts()
    assert c.body_a is plane and c.body_b is ball
    np.testing.assert_allclose(c.point, [0, 0, 0], atol=1e-12)
    assert c.depth == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_box_lets_go_within_a_fifth_of_a_degree_of_the_static_friction_angle(solver):
    """mu_s = 0.6 > mu_d = 0.4: at atan(0.6) - 0.2 deg the box stays put (it moves less than 0.1 mm in
    2 s, the contact's settling); at atan(0.6) + 0.2 deg it breaks loose, and sliding it accelerates at
    g (sin - mu_d cos), dynamic friction's, within 1% (the soft contact's sub-millimetre settling)."""
    angle = math.degrees(math.atan(0.6))
    w, box, _ = box_on_slope(solver, angle - 0.2)
    for _ in range(10):
        w.step(1.0 / 60.0)
    start = box.position
    for _ in range(120):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(box.position - start) < 1e-4
    measured, expected = sliding_past_static_angle(solver)
    assert measured == pytest.approx(expected, rel=0.01)
