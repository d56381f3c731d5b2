"""Ball, hinge, slider and fixed joints (docs/lecture/constraints.md; API.md "Joints") against closed forms.

Tolerances from the maths.  A joint's velocity rows are at most as soft as constraints at half the sub-step
rate (``joint_rows.RIGID_JOINT_RATE``: 120 Hz at 60 Hz with 4 sub-steps, ``omega = pi / h``; the joints of a
tree are solved rigid and exactly, ``joint_tree.py``, the joints of a loop that soft).  At rest under a steady
load a soft row carries the impulse ``lambda = F h`` per sub-step, and the soft step's fixed point leaves it
at ``C = -impulse_scale lambda K / (mass_scale bias_rate) = -F K / omega^2`` (``K``: the row's inverse
effective mass): ``a / omega^2`` for the acceleration ``a = F K`` the load would give along the row.  The
position pass (``push_rigid_joints``) then only takes error out, so that is a bound on what is left.  A
physical pendulum of small amplitude ``theta0`` swings with the period ``T0 (1 + theta0^2 / 16)``; a motor of
torque ``tau`` on inertia ``I`` spins up at ``tau / I``.
"""
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.state import layout as L

G = 9.81
DT = 1.0 / 60.0
#: the joints' soft frequency at the default 4 sub-steps (rad/s): pi / h
OMEGA = math.pi / (DT / 4)
#: the steady sag of a soft joint under its body's weight (m), g / omega^2
SAG = G / OMEGA ** 2
SOLVERS = ("sequential_impulse", "lcp")


def horizontal_bar_sag(d, half_width):
    """The angle (rad) a limit sags by holding a horizontal bar of half length ``d`` by one end: it carries
    the point force's torque ``m g d`` about the centre, against ``I_cm = m (4 d^2 + 4 w^2) / 12``."""
    return G * d / ((4 * d * d + 4 * half_width ** 2) / 12.0) / OMEGA ** 2


def _hanging_bar(solver, theta0, length=1.0, half_width=0.05, mass=2.0):
    """A bar hinged at its top end to the world at the origin about z, turned out by ``theta0``."""
    w = mb.World(solver=solver, sleeping=False)
    bar = w.add_body(mb.Box((half_width, length / 2, half_width)), mass=mass, position=(0.0, -length / 2, 0.0))
    hinge = w.add_hinge(bar, None, anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
    s, c = math.sin(theta0), math.cos(theta0)
    bar.position = (length / 2 * s, -length / 2 * c, 0.0)
    bar.orientation = (math.cos(theta0 / 2), 0.0, 0.0, math.sin(theta0 / 2))
    inertia = mass * (length ** 2 + 4 * half_width ** 2) / 12 + mass * (length / 2) ** 2
    period = 2.0 * math.pi * math.sqrt(inertia / (mass * G * length / 2)) * (1.0 + theta0 ** 2 / 16.0)
    return w, bar, hinge, period


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_hinged_bar_swings_with_the_period_of_a_physical_pendulum_in_its_plane(solver):
    w, bar, hinge, period = _hanging_bar(solver, 0.05)
    assert hinge.angle == pytest.approx(0.05, abs=1e-12)
    dt = 1.0 / 240.0
    crossings, prev, t = [], hinge.angle, 0.0
    while t < 4.0 * period:
        w.step(dt)
        t += dt
        angle = hinge.angle
        if prev > 0.0 >= angle:
            crossings.append(t - dt * angle / (angle - prev))
        prev = angle
        assert abs(bar.position[2]) < 1e-9                    # in the hinge's plane
        assert np.linalg.norm(hinge.anchor) < 2.0 * SAG       # on the hinge
    assert np.diff(crossings) == pytest.approx(period, rel=0.01)


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_hinge_reports_the_force_and_torque_that_hold_the_bar(solver):
    """At the lower limit, a horizontal bar of mass m and half length d is held by the force m g up and the
    torque m g d about the axis."""
    m, d = 2.0, 0.5
    w = mb.World(solver=solver, sleeping=False)
    bar = w.add_body(mb.Box((d, 0.05, 0.05)), mass=m, position=(d, 0.0, 0.0))
    hinge = w.add_hinge(bar, None, anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), limits=(0.0, 0.5))
    for _ in range(120):
        w.step(1.0 / 60.0)
    assert -horizontal_bar_sag(d, 0.05) <= hinge.angle <= 0.0
    assert hinge.force == pytest.approx((0.0, m * G, 0.0), abs=1e-3 * m * G)
    assert hinge.torque == pytest.approx((0.0, 0.0, m * G * d), abs=1e-3 * m * G * d)


@pytest.mark.parametrize("solver", SOLVERS)
def test_limits_hold_a_loaded_hinge(solver):
    """A horizontal bar falls about its hinge to the lower limit -0.3 rad and stays there (to the sag of the
    soft limit; the limit's rigid speculative row lets it reach the limit but not pass it at speed)."""
    w = mb.World(solver=solver, sleeping=False)
    bar = w.add_body(mb.Box((0.5, 0.05, 0.05)), mass=5.0, position=(0.5, 0.0, 0.0))
    hinge = w.add_hinge(bar, None, anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), limits=(-0.3, 0.3))
    lowest = 0.0
    for _ in range(180):
        w.step(1.0 / 60.0)
        lowest = min(lowest, hinge.angle)
    sag = horizontal_bar_sag(0.5, 0.05) * math.cos(0.3)     # the load's torque is m g d cos(0.3) there
    assert lowest >= -0.3 - 2.0 * sag
    assert -0.3 - sag <= hinge.angle <= -0.3


def test_a_motor_spins_a_wheel_up_at_its_torque_and_no_faster_than_its_speed():
    """A wheel (a sphere of inertia 2/5 m r^2) on a hinge through its centre: the motor's torque tau
    accelerates it at tau / I until it turns at the motor's speed, then holds that speed."""
    m, r, tau, speed = 3.0, 0.4, 2.0, 10.0
    inertia = 0.4 * m * r * r
    w = mb.World(gravity=(0.0, 0.0, 0.0), sleeping=False)
    wheel = w.add_body(mb.Sphere(r), mass=m)
    hinge = w.add_hinge(wheel, None, anchor=(0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0), motor_speed=speed,
                        max_motor_torque=tau)
    dt = 1.0 / 60.0
    t_reach = speed * inertia / tau
    for k in range(1, 120):
        w.step(dt)
        expected = min(tau / inertia * k * dt, speed)
        assert hinge.angular_speed == pytest.approx(expected, abs=1e-9 * speed)
        assert wheel.angular_velocity == pytest.approx((hinge.angular_speed, 0.0, 0.0), abs=1e-9)
    assert 119 * dt > t_reach


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_slider_keeps_its_line_and_slides_down_it_at_g_along_the_axis(solver):
    n = np.array([1.0, -1.0, 0.5]) / 1.5
    w = mb.World(solver=solver, sleeping=False)
    box = w.add_body(mb.Box((0.2, 0.1, 0.1)), mass=1.0, position=(0.0, 1.0, 0.0), orientation=(0.9, 0.1, 0.3, 0.0))
    slider = w.add_slider(box, None, anchor=(0.0, 1.0, 0.0), axis=tuple(n))
    q0 = box.orientation.copy()
    dt = 1.0 / 60.0
    h = dt / w.substeps
    for k in range(1, 61):
        w.step(dt)
        t = k * dt
        along = slider.position
        # semi-implicit Euler over N = k substeps sub-steps of h: x_N = a h^2 N (N + 1) / 2
        steps = k * w.substeps
        assert along == pytest.approx(G * (-n[1]) * h * h * steps * (steps + 1) / 2, rel=1e-6)
        off = (box.position - np.array([0.0, 1.0, 0.0])) - along * n
        assert np.linalg.norm(off) < 1e-9
        assert np.abs(box.orientation - q0).max() < 1e-9
        assert slider.speed == pytest.approx(G * -n[1] * t, rel=1e-6)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_chain_of_twenty_ball_joints_keeps_every_joint_within_a_millimetre(solver):
    """Twenty 0.2 kg links of 10 cm hanging from the world, let go at 0.5 rad from the vertical: the chain
    swings and every joint's anchors stay within 1 mm (the top joints carry the whole chain, ~40 N, on
    links of 0.2 kg: their soft rows alone would give ``F K / omega^2`` ~ 0.7 mm)."""
    w = mb.World(solver=solver, sleeping=False)
    tilt = 0.5
    s, c = math.sin(tilt), math.cos(tilt)
    links, joints, prev = [], [], None
    for k in range(20):
        link = w.add_body(mb.Capsule(0.02, 0.05), mass=0.2, position=(s * (0.1 * k + 0.05), -c * (0.1 * k + 0.05), 0.0),
                          orientation=(math.cos(tilt / 2), 0.0, 0.0, math.sin(tilt / 2)))
        joints.append(w.add_ball_joint(link, prev, anchor=(s * 0.1 * k, -c * 0.1 * k, 0.0)))
        links.append(link)
        prev = link
    worst = 0.0
    for _ in range(240):
        w.step(DT)
        for j in joints:
            b = j.body_b
            kb = j.anchor_b if b is None else b.position + _rotation(b.orientation) @ j.anchor_b
            gap = float(np.linalg.norm(j.anchor - kb))
            assert j.separation == pytest.approx(gap, abs=1e-12)
            worst = max(worst, gap)
    assert worst < 1e-3
    assert links[-1].position[0] < 0.0                  # it did swing through


def _rotation(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@pytest.mark.parametrize("solver", SOLVERS)
def test_two_welded_boxes_fall_and_tumble_as_one_body(solver):
    w = mb.World(solver=solver)
    w.add_static(mb.Plane())
    a = w.add_body(mb.Box((0.3, 0.1, 0.1)), mass=1.0, position=(0.0, 2.0, 0.0), angular_velocity=(1.0, 2.0, 3.0))
    b = w.add_body(mb.Box((0.1, 0.3, 0.1)), mass=3.0, position=(0.35, 2.25, 0.0), angular_velocity=(1.0, 2.0, 3.0))
    # b moves with a's rotation: its velocity is omega x (x_b - x_a)
    b.velocity = tuple(np.cross((1.0, 2.0, 3.0), b.position - a.position))
    w.add_fixed_joint(a, b)
    rel_pos = _rotation(a.orientation).T @ (b.position - a.position)
    rel_rot = _rotation(a.orientation).T @ _rotation(b.orientation)
    for _ in range(180):
        w.step(1.0 / 60.0)
        ra = _rotation(a.orientation)
        assert np.linalg.norm(ra.T @ (b.position - a.position) - rel_pos) < 1e-3
        assert np.abs(ra.T @ _rotation(b.orientation) - rel_rot).max() < 1e-3
    assert a.position[1] < 1.0                           # it fell, and landed


@pytest.mark.parametrize("factor, breaks", [(1.2, False), (0.8, True)])
def test_a_joint_breaks_at_its_breaking_force(factor, breaks):
    """A 2 kg ball hangs on a ball joint: the joint carries m g and breaks only if that exceeds its
    breaking force."""
    w = mb.World(sleeping=False)
    ball = w.add_body(mb.Sphere(0.1), mass=2.0)
    joint = w.add_ball_joint(ball, None, anchor=(0.0, 0.1, 0.0), breaking_force=factor * 2.0 * G)
    for _ in range(60):
        w.step(1.0 / 60.0)
    assert joint.broken == breaks
    if breaks:
        assert ball.position[1] < -1.0
        assert "broken" in repr(joint)
    else:
        assert joint.force == pytest.approx((0.0, 2.0 * G, 0.0), rel=1e-3)
        assert ball.position[1] == pytest.approx(0.0, abs=2.0 * SAG)


def test_jointed_bodies_do_not_collide_until_the_joint_is_removed():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    a = w.add_body(mb.Box((0.5, 0.5, 0.5)))
    b = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.6, 0.0, 0.0))
    joint = w.add_ball_joint(a, b, anchor=(0.3, 0.0, 0.0))
    for _ in range(10):
        w.step(1.0 / 60.0)
        assert w.contacts() == []
    assert np.linalg.norm(b.position - a.position) == pytest.approx(0.6, abs=1e-9)
    w.remove(joint)
    w.step(1.0 / 60.0)
    assert len(w.contacts()) > 0


def test_joints_survive_a_snapshot_and_restore():
    w, bar, hinge, _ = _hanging_bar("sequential_impulse", 0.3)
    w.step(1.0 / 60.0)
    snap = w.snapshot()
    trace = []
    for _ in range(30):
        w.step(1.0 / 60.0)
        trace.append(hinge.angle)
    w.restore(snap)
    for expected in trace:
        w.step(1.0 / 60.0)
        assert hinge.angle == expected


def test_motor_and_limits_can_change_while_running():
    """A wheel spun to 3 rad/s by its motor, then let go with limits (-1, 1) set: it turns on at 3 rad/s
    until the angle reaches 1 rad and stops there."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), sleeping=False)
    wheel = w.add_body(mb.Sphere(0.3), mass=1.0)
    hinge = w.add_hinge(wheel, None, anchor=(0.0, 0.0, 0.0), axis=(0.0, 1.0, 0.0))
    assert hinge.motor_speed is None and hinge.limits is None
    hinge.max_motor_torque = 100.0
    hinge.motor_speed = 3.0
    for _ in range(5):
        w.step(1.0 / 60.0)
    assert hinge.angular_speed == pytest.approx(3.0, rel=1e-9)
    assert hinge.angle < 1.0
    hinge.motor_speed = None
    hinge.limits = (-1.0, 1.0)
    assert hinge.limits == (-1.0, 1.0) and hinge.motor_speed is None
    for _ in range(60):
        w.step(1.0 / 60.0)
        assert hinge.angle <= 1.0 + 1e-9
    assert hinge.angle == pytest.approx(1.0, abs=1e-6)
    assert hinge.angular_speed == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("call, message", [
    (lambda w, a: w.add_hinge(a, None, anchor=(0, 0, 0), axis=(0, 0, 0)), "axis"),
    (lambda w, a: w.add_hinge(a, None, anchor=(0, 0, 0), axis=(0, 0, 1), limits=(0.5, -0.5)), "limits"),
    (lambda w, a: w.add_hinge(a, None, anchor=(0, 0, 0), axis=(0, 0, 1), limits=(-4.0, 0.0)), "limits"),
    (lambda w, a: w.add_hinge(a, None, anchor=(0, 0, 0), axis=(0, 0, 1), motor_speed=math.nan), "motor_speed"),
    (lambda w, a: w.add_hinge(a, None, anchor=(0, 0, 0), axis=(0, 0, 1), max_motor_torque=-1.0),
     "max_motor_torque"),
    (lambda w, a: w.add_slider(a, None, anchor=(0, 0, 0), axis=(1, 0, 0), max_motor_force=math.inf),
     "max_motor_force"),
    (lambda w, a: w.add_ball_joint(a, a, anchor=(0, 0, 0)), "different"),
    (lambda w, a: w.add_ball_joint(a, None, anchor=(0, math.nan, 0)), "anchor"),
    (lambda w, a: w.add_fixed_joint(a, None, breaking_force=0.0), "breaking_force"),
])
def test_bad_joint_arguments_are_refused_by_name_and_change_nothing(call, message):
    w = mb.World()
    a = w.add_body(mb.Sphere(0.1))
    with pytest.raises((TypeError, ValueError), match=message):
        call(w, a)
    assert w.constraints == []
    assert not (w._state.bi[0, L.FLAGS] & L.F_JOINTED)


def test_a_sleeping_joint_still_reports_the_force_that_holds_its_body():
    w = mb.World()
    lamp = w.add_body(mb.Sphere(0.2), mass=5.0)
    cord = w.add_ball_joint(lamp, None, anchor=(0.0, 0.2, 0.0))
    for _ in range(240):
        w.step(DT)
    assert lamp.is_sleeping
    assert cord.force == pytest.approx((0.0, 5.0 * G, 0.0), rel=1e-3)


def _energy(w):
    """Kinetic (linear and rotational) plus gravitational energy of the moving bodies (J)."""
    return _energy_of([b for b in w.bodies if not b.is_static])


def _widest_gap(joints):
    return max(j.separation for j in joints)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_ragdoll_falls_down_the_stairs_without_exploding(solver):
    """Nothing in the fall can add energy (no motor, no restitution): the total never rises above its start
    (beyond the soft contacts' and joints' stored energy, a few joules), no joint opens by a centimetre,
    and it ends below the landing it started on."""
    from marbellous.scenes import ragdoll, stairs
    w, top = stairs(mb.World(solver=solver))
    parts, joints = ragdoll(w, position=(0.0, top, -0.3), velocity=(0.0, 0.0, 1.5))
    e0 = _energy(w)
    for _ in range(300):
        w.step(DT)
        assert _energy(w) < e0 + 5.0
        assert _widest_gap(joints) < 0.01
    assert parts["torso"].position[2] > 0.0


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_bridge_of_thirty_hinged_planks_holds_a_marble(solver):
    """A 5 kg marble dropped on the middle of a sagging bridge of thirty 1 kg planks stays on it, in its dip,
    as the bridge swings; the energy never rises above its start and no hinge opens by a centimetre."""
    from marbellous.scenes import plank_bridge
    w, planks, hinges = plank_bridge(mb.World(solver=solver))
    marble = w.add_body(mb.Sphere(0.25), mass=5.0, position=planks[15].position + (0.1, 0.8, 0.0))
    e0 = _energy(w)
    for _ in range(300):
        w.step(DT)
        assert _energy(w) < e0 + 1.0
        assert _widest_gap(hinges) < 0.01
        assert abs(marble.position[0]) < 0.6 and 0.0 < marble.position[2] < planks[-1].position[2]
    lowest_plank = min(p.position[1] for p in planks)
    assert lowest_plank + 0.2 < marble.position[1] < lowest_plank + 0.5       # on the bridge, in its dip


def test_a_hinged_chain_gains_no_energy_when_steps_are_cut_into_intervals():
    """A box spinning on the ground cuts every step at a time of impact, down to intervals of microseconds;
    the joints keep the frequency of the whole step's sub-steps there (at the interval's own, their bias in
    a 40 us interval was metres per second and the chain gained kilojoules)."""
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane())
    w.add_body(mb.Box((0.3, 0.05, 0.3)), position=(-3.0, 0.05, 0.0), angular_velocity=(0.0, 60.0, 0.0))
    links, previous = [], None
    for k in range(10):
        link = w.add_body(mb.Box((0.1, 0.03, 0.09)), mass=1.0, position=(0.0, 2.0, 0.1 + 0.2 * k))
        w.add_hinge(link, previous, anchor=(0.0, 2.0, 0.2 * k), axis=(1.0, 0.0, 0.0))
        links.append(link)
        previous = link
    w.add_hinge(previous, None, anchor=(0.0, 2.0, 2.0), axis=(1.0, 0.0, 0.0))
    e0 = _energy_of(links)
    cut = 0
    for _ in range(120):
        w.step(DT)
        cut += w.last_step.steps > 1
        assert _energy_of(links) < e0 + 1e-3
    assert cut > 40                                     # (most steps were cut)


def _energy_of(bodies):
    return sum(0.5 * b.mass * float(b.velocity @ b.velocity) + G * b.mass * float(b.position[1])
               + 0.5 * float(b.angular_velocity @ b.inertia @ b.angular_velocity) for b in bodies)


def test_the_ragdolls_example_keeps_every_joint_within_a_centimetre():
    import runpy
    from pathlib import Path
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "ragdolls.py"))["run"]
    torsos, marble, worst = run(steps=240)
    assert worst < 0.01
    assert all(t[2] > 0.0 for t in torsos[:2])          # over the landing's edge, down the stairs
    assert 2.4 < marble[1] < 3.0                          # on the bridge
