"""Time stepping and continuous collision (docs/lecture/time.md; API.md "Time stepping and continuous
collision"): bounces taken in time-of-impact order against their closed forms, no ghost collisions, no
tunnelling, retroactive halving, an exact clock, and snapshots and determinism in every mode.

Tolerances come from the maths: a face met head on is reached by one conservative advance whose bound is
exact (``collision/toi/closing_time.py``), so the bounce positions carry rounding only, a few ulps of the
distances (~1e-16 m per metre) per bounce; 1e-9 m leaves room for thousands of bounces.
"""
import math
import zlib

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import marbellous as mb
from marbellous.pipeline.step import MAX_TURN, turning_substeps
from marbellous.scenes import box_tower
from marbellous.state.params import MAX_TURN_SUBSTEPS

MODES = ("fixed", "retroactive", "conservative")
DT = 1.0 / 60.0
#: the walls' inner faces at x = +-WALL; a ball of radius R between them moves in [-(WALL - R), WALL - R]
WALL, R = 1.0, 0.1
#: rounding of positions after many bounces (module docstring)
ROUNDING = 1e-9


def reflected(u, half):
    """Closed form of a point moving freely on a line, reflected elastically at -half and +half: where the
    unfolded coordinate ``u`` (start 0) folds to (a triangle wave of period 4 half)."""
    p = (u + half) % (4.0 * half)
    return p - half if p <= 2.0 * half else 3.0 * half - p


def between_walls(mode, speed):
    """A ball (restitution 1, no friction, no gravity) at the centre between two static walls, moving at
    ``speed`` (m/s) along x."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), time_stepping=mode)
    for side in (-1.0, 1.0):
        w.add_static(mb.Box((0.05, 1.0, 1.0)), position=(side * (WALL + 0.05), 0.0, 0.0), restitution=1.0,
                     friction=0.0)
    ball = w.add_body(mb.Sphere(R), velocity=(speed, 0.0, 0.0), restitution=1.0, friction=0.0)
    return w, ball


# --- time-of-impact ordering -------------------------------------------------------------------------------
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("speed", [100.0, 500.0, 2000.0])
def test_a_ball_between_two_walls_is_where_the_closed_form_puts_it(mode, speed):
    """Several bounces in one step (500 m/s: 8.3 m a step between faces 1.8 m apart), each at its time of
    impact: after every step the ball is at the folded free flight, at its speed."""
    w, ball = between_walls(mode, speed)
    for k in range(1, 21):
        w.step(DT)
        assert ball.position[0] == pytest.approx(reflected(speed * k * DT, WALL - R), abs=ROUNDING)
        assert abs(ball.velocity[0]) == pytest.approx(speed, rel=1e-12)
        assert ball.velocity[1] == ball.velocity[2] == 0.0
    bounces = speed * DT / (2.0 * (WALL - R))
    assert w.last_step.toi_events >= math.floor(bounces)
    assert w.last_step.steps == w.last_step.toi_events + 1


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("integrator", ["rk4", "verlet"])
def test_a_ball_dropped_with_restitution_one_returns_to_its_height(mode, integrator):
    """RK4 and Verlet are exact in free flight under gravity (Verlet's positions: ``x' = x + v h + g h^2 / 2``
    whatever the sub-steps' lengths), and the impact is taken at its time, with the velocity the ball meets
    the plane with (Verlet stores the mean over its last sub-step, handed over before the impact): every step
    ends where the periodic bounce of period ``2 sqrt(2 h / g)`` puts the ball."""
    g, h = 9.81, 1.0
    w = mb.World(integrator=integrator, time_stepping=mode)
    w.add_static(mb.Plane(), restitution=1.0, friction=0.0)
    ball = w.add_body(mb.Sphere(R), position=(0.0, R + h, 0.0), restitution=1.0, friction=0.0, ccd=True)
    fall = math.sqrt(2.0 * h / g)
    for k in range(1, 241):                     # four seconds: four bounces
        w.step(DT)
        t = (k * DT + fall) % (2.0 * fall) - fall   # time from the last impact's mirror apex
        assert ball.position[1] == pytest.approx(R + h - 0.5 * g * t * t, abs=1e-9)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("integrator, sign", [("semi_implicit_euler", -1.0), ("explicit_euler", 1.0)])
def test_first_order_integrators_change_the_bounce_height_by_their_known_error(mode, integrator, sign):
    """Under a constant acceleration ``-g`` a sub-step ``tau`` of semi-implicit Euler changes the specific
    energy ``e = g y + v^2 / 2`` by exactly ``-g^2 tau^2 / 2`` and explicit Euler by ``+g^2 tau^2 / 2``
    (expand ``v' = v - g tau`` in ``e' - e``).  So a step with no impact changes it by ``n`` times that
    (``n`` sub-steps); a step with an elastic impact taken at its time, whose sub-steps are cut there
    (the squares of the pieces sum to less than ``tau^2``), by less than that and with the same sign; and
    the ball loses (gains) height bounce after bounce by the sum, never by the impact itself."""
    g, h = 9.81, 1.0
    w = mb.World(integrator=integrator, time_stepping=mode)
    w.add_static(mb.Plane(), restitution=1.0, friction=0.0)
    ball = w.add_body(mb.Sphere(R), position=(0.0, R + h, 0.0), restitution=1.0, friction=0.0, ccd=True)

    def energy():
        return g * (ball.position[1] - R) + 0.5 * float(ball.velocity @ ball.velocity)

    per_substep = 0.5 * (g * DT / w.substeps) ** 2
    full = sign * w.substeps * per_substep
    e0, impacts = energy(), 0
    for _ in range(200):                        # 3.3 s: four bounces
        before = energy()
        w.step(DT)
        change = energy() - before
        if w.last_step.toi_events == 0:
            assert change == pytest.approx(full, abs=1e-12)
        else:
            impacts += 1
            assert 0.0 < sign * change < sign * full
    assert impacts == 4
    # over four bounces the ball's top height moved by the sum: 196 whole steps and 4 cut ones
    assert 196 * abs(full) < sign * (energy() - e0) < 200 * abs(full)


# --- ghost collisions ----------------------------------------------------------------------------------------
def _passing(mode, where, speed, clearance):
    """A ball of radius R passing a static unit box (or a mesh floor) with ``clearance`` (m), along a path
    whose closest approach is at the middle of its flight; returns (world, ball, velocity)."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), time_stepping=mode)
    d = R + clearance
    if where == "seam":
        # a floor of two triangles per square metre, its seams along x, z and the diagonals
        xs = np.arange(-4.0, 5.0)
        vertices = np.array([(x, 0.0, z) for x in xs for z in xs])
        n = len(xs)
        tris = []
        for i in range(n - 1):
            for j in range(n - 1):
                a, b, c, e = i * n + j, i * n + j + 1, (i + 1) * n + j, (i + 1) * n + j + 1
                tris += [(a, b, e), (a, e, c)]
        w.add_static(mb.TriangleMesh(vertices, np.array(tris)))
        closest = np.array([0.0, d, 0.0])
        u = np.array([1.0, 0.0, 0.3]) / math.sqrt(1.09)
    else:
        w.add_static(mb.Box((0.5, 0.5, 0.5)))
        out = {"face": np.array([0.0, 1.0, 0.0]), "edge": np.array([0.0, 1.0, 1.0]) / math.sqrt(2.0),
               "corner": np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)}[where]
        feature = {"face": np.array([0.0, 0.5, 0.0]), "edge": np.array([0.0, 0.5, 0.5]),
                   "corner": np.array([0.5, 0.5, 0.5])}[where]
        closest = feature + d * out
        u = {"face": np.array([1.0, 0.0, 0.0]), "edge": np.array([1.0, 0.0, 0.0]),
             "corner": np.array([1.0, -1.0, 0.0]) / math.sqrt(2.0)}[where]
    steps = 2 + math.ceil(6.0 / (speed * DT))
    start = closest - u * speed * DT * (steps // 2 + 0.37)
    ball = w.add_body(mb.Sphere(R), position=tuple(start), velocity=tuple(u * speed), friction=0.5)
    return w, ball, u * speed, steps


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("where", ["face", "edge", "corner", "seam"])
@given(speed=st.floats(1.0, 2000.0), clearance=st.floats(1e-3, 0.05))
def test_a_ball_passing_with_clearance_keeps_its_velocity(mode, where, speed, clearance):
    """No ghost collisions: a path that misses by 1 mm or more is not touched, at any speed up to 2000 m/s
    (speculative contacts whose pair the time-of-impact search finds missing are dropped)."""
    w, ball, velocity, steps = _passing(mode, where, speed, clearance)
    for _ in range(steps):
        w.step(DT)
        assert np.allclose(ball.velocity, velocity, rtol=1e-12, atol=0.0)
        assert np.array_equal(ball.angular_velocity, np.zeros(3))


# --- tunnelling ------------------------------------------------------------------------------------------------
def _shots(count, seed):
    """``count`` random shots: (is_box, speed m/s, unit direction into +x within 60 degrees, angular
    velocity rad/s)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        speed = 10.0 ** rng.uniform(1.0, math.log10(2000.0))
        cos = rng.uniform(0.5, 1.0)
        phi = rng.uniform(0.0, 2.0 * math.pi)
        sin = math.sqrt(1.0 - cos * cos)
        out.append((bool(rng.integers(2)), speed, np.array([cos, sin * math.cos(phi), sin * math.sin(phi)]),
                    rng.normal(0.0, 20.0, 3)))
    return out


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("target", ["box_wall", "mesh_floor"])
def test_no_shot_tunnels_through_a_thin_wall_or_a_mesh_floor(mode, target):
    """1,000 shots of spheres and boxes at 10 to 2,000 m/s: none ends behind a 1 cm box wall or below a
    triangle-mesh floor (``ccd=True``, the default)."""
    through = []
    for k, (is_box, speed, u, omega) in enumerate(_shots(1000, seed=zlib.crc32(f"{mode} {target}".encode()))):
        w = mb.World(time_stepping=mode)
        if target == "box_wall":
            w.add_static(mb.Box((0.005, 50.0, 50.0)), position=(1.0, 0.0, 0.0))
            direction, start = u, np.zeros(3)
        else:
            v = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]]) * 200.0 - (100, 0, 100)
            w.add_static(mb.TriangleMesh(v, np.array([[0, 1, 3], [0, 3, 2]])))
            direction, start = np.array([u[1], -u[0], u[2]]), np.array([0.0, 1.0, 0.0])
        shape = mb.Box((0.05, 0.1, 0.075)) if is_box else mb.Sphere(0.05)
        body = w.add_body(shape, position=tuple(start), velocity=tuple(direction * speed),
                          angular_velocity=tuple(omega))
        for _ in range(int(2.0 / (speed * DT)) + 3):
            w.step(DT)
        side = body.position[0] - 1.0 if target == "box_wall" else -body.position[1]
        if side > 0.0:
            through.append((k, is_box, speed))
    assert through == []


@pytest.mark.parametrize("mode", MODES)
def test_a_ball_pressed_from_rest_by_its_user_force_does_not_go_through_a_mesh(mode):
    """A 2 cm ball of 10 g at rest 5 cm above a mesh one triangle thick, pressed down at 100 times its weight:
    in its first step it would go ``(1 + 1/n) / 2 a dt^2`` = 14 cm; its force widens its box and sweep as
    gravity does (reached by its velocity and gravity alone, it went through the mesh and fell)."""
    w = mb.World(time_stepping=mode)
    v = np.array([[-1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0]])
    w.add_static(mb.TriangleMesh(v, np.array([[0, 1, 3], [0, 3, 2]])))
    ball = w.add_body(mb.Sphere(0.02), position=(0.0, 0.05, 0.0), mass=0.01)
    for _ in range(30):
        ball.apply_force((0.0, -100.0 * 9.81 * 0.01, 0.0))
        w.step(DT)
        assert 0.0 < ball.position[1] < 0.05
    assert abs(ball.velocity[1]) < 1e-6


@pytest.mark.parametrize("mode", MODES)
def test_a_plank_spun_from_rest_by_its_user_torque_does_not_turn_through_a_mesh(mode):
    """A 1 m plank of 1 kg at rest 4 cm above a mesh one triangle thick, spun by 250 N m about its short axis
    (3,000 rad/s^2): in its first step its end would turn ~20 cm down through the mesh; its torque widens its
    box and sweep.  Its end stays above the mesh within what a contact's linear motion misses of the end's arc
    over a sub-step turning at most ``MAX_TURN``, ``r (1 - cos MAX_TURN)``, r = 0.5 m."""
    w = mb.World(time_stepping=mode)
    v = np.array([[-2.0, 0.0, -2.0], [-2.0, 0.0, 2.0], [2.0, 0.0, -2.0], [2.0, 0.0, 2.0]])
    w.add_static(mb.TriangleMesh(v, np.array([[0, 1, 3], [0, 3, 2]])))
    half = np.array([0.5, 0.01, 0.05])
    plank = w.add_body(mb.Box(tuple(half)), position=(0.0, 0.05, 0.0), mass=1.0)
    plank.apply_torque((0.0, 0.0, -250.0))
    w.step(DT)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    w_, x_, y_, z_ = plank.orientation
    lowest = (corners @ Rotation.from_quat([x_, y_, z_, w_]).as_matrix().T + plank.position)[:, 1].min()
    assert lowest > -0.5 * (1.0 - math.cos(MAX_TURN))


@pytest.mark.parametrize("seed, shot", [(122, 5), (275, 109), (335, 113)])
def test_a_box_that_spins_up_on_the_wall_does_not_go_through_it(seed, shot):
    """Three of 70,000 shots that went through the wall: a box hitting it at 62 to 100 m/s off its centre
    leaves the impact spinning at 400 to 660 rad/s, still moving into the wall.  It turned 1.7 rad per
    sub-step, more than contact velocities linear over a sub-step describe, and up to 11 rad in the rest of
    the step, past the contact points found at its start.  Automatic sub-steps now turn no body by more
    than 0.25 rad, and an interval no body with contacts by more than 0.5 rad."""
    is_box, speed, u, omega = _shots(200, seed)[shot]
    assert is_box
    w = mb.World()
    w.add_static(mb.Box((0.005, 50.0, 50.0)), position=(1.0, 0.0, 0.0))
    body = w.add_body(mb.Box((0.05, 0.1, 0.075)), velocity=tuple(u * speed), angular_velocity=tuple(omega))
    for _ in range(int(2.0 / (speed * DT)) + 3):
        w.step(DT)
        assert body.position[0] < 1.0
        assert np.all(np.isfinite(body.velocity))


def test_automatic_sub_steps_turn_no_body_by_more_than_a_quarter_radian():
    w = mb.World()
    box = w.add_body(mb.Box((0.1, 0.1, 0.1)), angular_velocity=(0.0, 400.0, 0.0))
    ball = w.add_body(mb.Sphere(0.1), position=(3.0, 0.0, 0.0), angular_velocity=(0.0, 4000.0, 0.0))
    st = w._state
    args = (st.bf, st.bi, st.sf, st.si, st.bodies.end, DT)
    # 400 rad/s over 1/60 s is 6.7 rad: 27 sub-steps of at most 0.25 rad; the sphere turning about its centre
    # moves no surface and does not count
    assert turning_substeps(*args, 4, MAX_TURN_SUBSTEPS) == math.ceil(400.0 * DT / MAX_TURN) == 27
    assert turning_substeps(*args, 4, 0) == 4                   # a number the user set is taken exactly
    box.angular_velocity = (0.0, 4e4, 0.0)
    assert turning_substeps(*args, 4, MAX_TURN_SUBSTEPS) == MAX_TURN_SUBSTEPS
    box.angular_velocity = (0.0, 50.0, 0.0)                     # 0.21 rad per sub-step of four
    assert turning_substeps(*args, 4, MAX_TURN_SUBSTEPS) == 4
    assert ball.angular_velocity[1] == 4000.0


# --- retroactive detection --------------------------------------------------------------------------------------
def _deepest(w):
    return max([c.depth for c in w.contacts()], default=0.0)


def test_retroactive_steps_end_no_deeper_than_max_penetration():
    """Without continuous collision a 30 m/s ball sinks 0.5 m into a box in a fixed step; retroactive steps
    halve until the overlap at the end is at most ``max_penetration``, and report it."""
    w = mb.World(time_stepping="retroactive", ccd=False, gravity=(0.0, 0.0, 0.0))
    w.add_static(mb.Box((1.0, 1.0, 1.0)), position=(0.0, -1.0, 0.0))
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 0.5, 0.0), velocity=(0.0, -30.0, 0.0))
    assert w.last_step == mb.StepReport(0, 0, 0, 0.0)
    halvings = 0
    for _ in range(10):
        t0 = w.time
        w.step(DT)
        assert w.time == t0 + DT
        assert _deepest(w) <= w.max_penetration
        r = w.last_step
        halvings += r.halvings
        assert r.steps == r.halvings + 1
        assert r.smallest_dt in [DT / 2 ** k for k in range(w.max_halvings + 1)]
    assert halvings > 0
    assert ball.position[1] > 0.2 - w.max_penetration


@pytest.mark.parametrize("mode", ["retroactive", "conservative"])
def test_resting_bodies_take_whole_steps(mode):
    """A resting stack never asks for a halving (its contacts stay far shallower than the threshold) nor
    for an advance (touching contacts do not limit conservative advancement)."""
    w = mb.World(time_stepping=mode)
    box_tower(w, height=5)
    for _ in range(120):
        w.step(DT)
        assert w.last_step == mb.StepReport(1, 0, 0, DT)
        assert _deepest(w) < 0.5 * w.max_penetration


# --- the clock, the report, snapshots, determinism -------------------------------------------------------------
def _busy(mode):
    """A scene that splits steps: a fast ball between walls, boxes dropped on a plane."""
    w, _ = between_walls(mode, 300.0)
    w.gravity = (0.0, -9.81, 0.0)
    w.add_static(mb.Plane(offset=-1.0))
    for k in range(4):
        w.add_body(mb.Box((0.1, 0.1, 0.1)), position=(-0.5 + 0.3 * k, -0.5, 0.3), velocity=(0.0, -5.0, 0.0))
    return w


@pytest.mark.parametrize("mode", MODES)
@given(dt=st.floats(1e-3, 0.05))
def test_the_clock_advances_by_exactly_dt(mode, dt):
    w = _busy(mode)
    for _ in range(3):
        t0 = w.time
        w.step(dt)
        assert w.time == t0 + dt


@pytest.mark.parametrize("mode", MODES)
def test_snapshots_and_determinism_hold_in_every_mode(mode):
    a, b = _busy(mode), _busy(mode)
    for _ in range(20):
        a.step(DT)
        b.step(DT)
    assert a.state_hash() == b.state_hash()
    snap = a.snapshot()
    for _ in range(20):
        a.step(DT)
    end = a.state_hash()
    a.restore(snap)
    for _ in range(20):
        a.step(DT)
    assert a.state_hash() == end


def test_the_contact_report_carries_the_impulse_of_the_whole_step():
    """A 1 kg ball bouncing elastically off a wall within a step: the wall's contact reports the momentum
    change ``2 m v`` though the step went on after the impact."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    w.add_static(mb.Box((0.05, 1.0, 1.0)), position=(1.05, 0.0, 0.0), restitution=1.0, friction=0.0)
    w.add_body(mb.Sphere(R), mass=1.0, position=(0.5, 0.0, 0.0), velocity=(60.0, 0.0, 0.0), restitution=1.0,
               friction=0.0)
    w.step(DT)
    assert w.last_step.toi_events == 1
    assert sum(c.normal_impulse for c in w.contacts()) == pytest.approx(120.0, rel=1e-12)


# --- per-body choice --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("ccd", [None, False])
def test_add_body_ccd_false_is_never_swept_and_true_always(ccd):
    """A 300 m/s ball (5 m a step) against a 2 cm wall: stopped unless added with ``ccd=False``; a slow one
    bouncing off a wall is taken in time order only when added with ``ccd=True``."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    w.add_static(mb.Box((0.01, 1.0, 1.0)), position=(5.0, 0.0, 0.0))
    ball = w.add_body(mb.Sphere(0.05), position=(0.3, 0.0, 0.0), velocity=(300.0, 0.0, 0.0), ccd=ccd)
    for _ in range(5):
        w.step(DT)
    assert (ball.position[0] > 5.0) == (ccd is False)
    # a slow ball (2 cm a step, radius 10 cm) is left to speculative contacts unless asked
    for ccd, events in ((None, 0), (True, 1)):
        w, ball = between_walls("fixed", 1.2)
        w.remove(ball)
        w.add_body(mb.Sphere(R), position=(0.89, 0.0, 0.0), velocity=(1.2, 0.0, 0.0), restitution=1.0,
                   friction=0.0, ccd=ccd)
        w.step(DT)
        assert w.last_step.toi_events == events


# --- closed forms of the miss test ------------------------------------------------------------------------------
_coord = st.floats(-2.0, 2.0)


@given(d0=st.tuples(_coord, _coord, _coord), u=st.tuples(_coord, _coord, _coord), radius=st.floats(0.01, 1.0))
def test_spheres_come_within_matches_a_dense_sampling(d0, u, radius):
    """The closed form against the gap sampled at 20,001 times of [0, 1] s: they agree unless the smallest
    gap is within the sampling's own error, ``|u| dt / 2`` with dt = 5e-5 s, of the tolerance."""
    from marbellous.collision.toi.closed_forms import spheres_come_within

    t = np.linspace(0.0, 1.0, 20001)
    gaps = np.linalg.norm(np.array(d0)[None, :] + t[:, None] * np.array(u)[None, :], axis=1) - radius
    slack = 0.5 * np.linalg.norm(u) * 5e-5 + 1e-12
    if abs(gaps.min() - 1e-3) > slack:
        assert spheres_come_within(d0, u, radius, 1.0, 1e-3) == (gaps.min() <= 1e-3)


@given(gap=st.floats(0.0, 1.0), speed=st.floats(-5.0, 5.0), acceleration=st.floats(-20.0, 20.0))
def test_gap_comes_within_matches_a_dense_sampling(gap, speed, acceleration):
    from marbellous.collision.toi.closed_forms import gap_comes_within

    t = np.linspace(0.0, 0.5, 20001)
    smallest = (gap - speed * t - 0.5 * acceleration * t * t).min()
    slack = (abs(speed) + 10.0 * abs(acceleration)) * 2.5e-5 + 1e-12
    if abs(smallest - 1e-3) > slack:
        assert gap_comes_within(gap, speed, acceleration, 0.5, 1e-3) == (smallest <= 1e-3)


@pytest.mark.parametrize("setting, value", [("gravity", (0.0, -1.0, 0.0)), ("max_penetration", 0.02),
                                            ("time_stepping", "conservative"), ("iterations", 8)])
def test_the_step_report_outlives_a_change_of_setting(setting, value):
    """Changing a setting between steps leaves :attr:`last_step` telling how the last step was taken."""
    w = mb.World()
    w.add_body(mb.Sphere(R))
    w.step(DT)
    setattr(w, setting, value)
    assert w.last_step == mb.StepReport(1, 0, 0, DT)
    w.step(DT / 2)
    assert w.last_step == mb.StepReport(1, 0, 0, DT / 2)
