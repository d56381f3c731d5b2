"""Particles and particle networks (``World.add_particles``, ``World.add_network``) against closed forms:
Hooke's period, the catenary, free fall, bounce and slide like bodies, momentum across the coupling with
bodies, and their bookkeeping (pins, removal, snapshots, ray casts, bad input)."""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import marbellous as mb

DT = 1.0 / 60.0
G = 9.81


def run(w, seconds):
    for _ in range(round(seconds / DT)):
        w.step(DT)


# --- springs and rods ---------------------------------------------------------------------------------------
def test_two_particles_on_a_spring_oscillate_with_hookes_period():
    # reduced mass mu = m / 2: T = 2 pi sqrt(mu / k); the sub-steps' backward-Euler-like update only damps the
    # amplitude (at a rate omega^2 h / 2), it does not shift the period beyond (omega h)^2 ~ 2e-4
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    p = w.add_particles([[0.0, 0.0, 0.0], [1.2, 0.0, 0.0]], mass=1.0)
    w.add_network(p, [[0, 1]], kind="spring", stiffness=100.0, rest_length=1.0)
    stretch = []
    for _ in range(600):
        w.step(DT)
        stretch.append(p.positions[1, 0] - p.positions[0, 0] - 1.0)
    d = np.array(stretch)
    k = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
    crossings = (k + d[k] / (d[k] - d[k + 1])) * DT
    period = 2.0 * np.mean(np.diff(crossings))
    assert period == pytest.approx(2.0 * math.pi * math.sqrt(0.5 / 100.0), rel=0.01)
    # momentum: the centre of mass stays put
    assert np.allclose(p.positions.mean(axis=0), (0.6, 0.0, 0.0), atol=1e-9)


def test_a_hanging_particle_stretches_its_spring_by_mg_over_k():
    w = mb.World()
    p = w.add_particles([[0.0, 2.0, 0.0], [0.0, 1.0, 0.0]], mass=2.0)
    p.pin([0])
    net = w.add_network(p, [[0, 1]], kind="spring", stiffness=400.0, damping=20.0)
    run(w, 5.0)
    assert p.positions[1, 1] == pytest.approx(1.0 - 2.0 * G / 400.0, abs=1e-4)
    assert net.forces[0] == pytest.approx(2.0 * G, rel=1e-3)


def catenary_depth(span, length):
    """The catenary's parameter ``c`` (m) for a chain of ``length`` hung between two points ``span`` apart
    at one height: ``length = 2 c sinh(span / 2c)``."""
    return brentq(lambda c: 2.0 * c * math.sinh(0.5 * span / c) - length, 0.05, 1e3)


def test_a_chain_of_rods_pinned_at_both_ends_hangs_in_a_catenary():
    n, span, length, mass = 40, 2.0, 3.0, 0.1
    a, seg = 0.5 * span, length / n
    s = np.linspace(0.0, length, n + 1)
    sag = math.sqrt((0.5 * length) ** 2 - a * a)
    x = np.interp(s, [0.0, 0.5 * length, length], [-a, 0.0, a])
    y = -np.interp(s, [0.0, 0.5 * length, length], [0.0, sag, 0.0])
    w = mb.World()
    p = w.add_particles(np.column_stack([x, y, np.zeros_like(x)]), mass=mass, damping=2.0)
    net = w.add_network(p, np.column_stack([np.arange(n), np.arange(1, n + 1)]), kind="rod", rest_length=seg)
    p.pin([0, n])
    run(w, 10.0)
    c = catenary_depth(span, length)
    X = p.positions
    expected = c * np.cosh(X[:, 0] / c) - c * math.cosh(a / c)
    # the bar: within 1 cm (measured 4 mm at 16 sub-steps, the links stretched by 0.3 %)
    assert np.max(np.abs(X[:, 1] - expected)) < 0.01
    assert np.max(np.abs(np.linalg.norm(np.diff(X, axis=0), axis=1) / seg - 1.0)) < 0.005
    # the tension at the lowest link is the horizontal tension w c (w the weight per length)
    assert net.forces[n // 2] == pytest.approx(mass / seg * G * c, rel=0.03)


def test_a_cable_is_slack_until_taut_and_a_rod_pushes():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    p = w.add_particles([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]], velocity=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    p.pin([0])
    cable = w.add_network(p, [[0, 1]], kind="cable", rest_length=1.0)
    run(w, 0.25)                                    # 0.25 m of 0.5 m slack: free flight
    assert p.velocities[1, 0] == pytest.approx(1.0, abs=1e-12)
    assert cable.forces[0] == 0.0
    run(w, 0.5)                                     # taut: it swings no further than the cable's length
    assert np.linalg.norm(p.positions[1]) == pytest.approx(1.0, abs=1e-9)
    q = w.add_particles([[0.0, 2.0, 0.0], [0.5, 2.0, 0.0]], velocity=[[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    rod = w.add_network(q, [[0, 1]], kind="rod")
    run(w, 0.1)
    assert np.linalg.norm(q.positions[1] - q.positions[0]) == pytest.approx(0.5, abs=1e-9)
    assert np.allclose(q.velocities, [[-0.5, 0.0, 0.0]] * 2, atol=1e-9)     # momentum shared
    assert rod.forces[0] == pytest.approx(0.0, abs=1e-6)


def test_an_edge_breaks_at_its_breaking_force():
    w = mb.World()
    p = w.add_particles([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]], mass=1.0)
    p.pin([0])
    net = w.add_network(p, [[0, 1]], kind="rod", breaking_force=15.0)
    run(w, 0.5)
    assert not net.broken[0]                        # 9.81 N < 15 N
    p.apply_force((0.0, -10.0, 0.0), [1])           # 19.81 N > 15 N
    w.step(DT)
    assert net.broken[0] and net.forces[0] == 0.0
    run(w, 0.5)
    assert p.positions[1, 1] < 0.0                  # falling freely


# --- contacts: as bodies ------------------------------------------------------------------------------------
def test_a_particle_falls_freely_and_comes_to_rest_on_the_ground():
    w = mb.World()
    w.add_static(mb.Plane())
    p = w.add_particles([[0.0, 3.0, 0.0]], radius=0.05)
    w.step(DT)
    # semi-implicit Euler over 16 sub-steps: y = y0 - g t (t + h) / 2
    h = DT / w.particle_substeps
    assert p.positions[0, 1] == pytest.approx(3.0 - 0.5 * G * DT * (DT + h), abs=1e-12)
    run(w, 2.0)
    assert p.positions[0, 1] == pytest.approx(0.05, abs=1e-9)
    assert np.linalg.norm(p.velocities[0]) < 1e-9


@pytest.mark.parametrize("e", [0.5, 0.8, 1.0])
def test_a_particle_bounces_to_e_squared_of_its_height(e):
    drop = 1.0
    w = mb.World()
    w.add_static(mb.Plane(), restitution=0.0)       # restitution combines by maximum, as for bodies
    p = w.add_particles([[0.0, 0.05 + drop, 0.0]], radius=0.05, restitution=e)
    top = 0.0
    for k in range(round(1.5 / DT)):
        w.step(DT)
        if k > 30:
            top = max(top, p.positions[0, 1] - 0.05)
    # the impact is taken at the sub-step's end: the height is off by at most the impact speed times a
    # sub-step, before and after (v h (1 + e)), and the top is sampled once a step (g dt^2 / 8)
    v = math.sqrt(2.0 * G * drop)
    h = DT / w.particle_substeps
    assert top == pytest.approx(e * e * drop, abs=v * h * (1 + e) + G * DT * DT / 8)


@pytest.mark.parametrize("degrees, mu", [(30.0, 0.3), (35.0, 0.5), (45.0, 0.9)])
def test_a_particle_slides_down_a_slope_with_coulombs_law(degrees, mu):
    th = math.radians(degrees)
    w = mb.World()
    w.add_static(mb.Plane(normal=(-math.sin(th), math.cos(th), 0.0)), friction=mu)
    p = w.add_particles([[0.0, 0.05 / math.cos(th), 0.0]], radius=0.05, friction=mu)
    run(w, 1.0)
    a = G * (math.sin(th) - mu * math.cos(th))
    speed = np.linalg.norm(p.velocities[0])
    if a <= 0.0:
        assert speed < 1e-9
    else:
        assert speed == pytest.approx(a * 1.0, rel=1e-6)


def test_a_particle_holds_below_the_static_angle_and_slides_above_it():
    mu_s, mu_d = 0.6, 0.4
    for degrees, held in ((math.degrees(math.atan(mu_s)) - 0.2, True), (math.degrees(math.atan(mu_s)) + 0.2, False)):
        th = math.radians(degrees)
        w = mb.World()
        w.add_static(mb.Plane(normal=(-math.sin(th), math.cos(th), 0.0)), friction=mu_d, static_friction=mu_s)
        p = w.add_particles([[0.0, 0.05 / math.cos(th), 0.0]], radius=0.05, friction=mu_d, static_friction=mu_s)
        run(w, 1.0)
        speed = np.linalg.norm(p.velocities[0])
        if held:
            assert speed < 1e-9
        else:
            assert speed == pytest.approx(G * (math.sin(th) - mu_d * math.cos(th)), rel=1e-6)


def test_particles_rest_on_a_mesh_and_a_height_field_without_falling_through():
    w = mb.World()
    verts = np.array([[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]], dtype=float)
    w.add_static(mb.TriangleMesh(verts, np.array([[0, 2, 1], [0, 3, 2]])))
    heights = np.zeros((9, 9))
    w.add_static(mb.HeightField(heights, spacing=(0.5, 0.5), origin=(4.0, 0.0, -2.0)))
    rng = np.random.default_rng(1)
    on_mesh = rng.uniform(-1.5, 1.5, (50, 3)) * (1, 0, 1) + (0, 1, 0)
    on_field = on_mesh + (6.0, 0.0, 0.0)
    p = w.add_particles(np.vstack([on_mesh, on_field]), radius=0.02, velocity=(0.0, -20.0, 0.0))
    run(w, 1.0)
    assert np.allclose(p.positions[:, 1], 0.02, atol=1e-6)


def test_particles_pressed_from_rest_by_their_user_force_land_on_a_mesh_and_a_height_field():
    # pressed down at 100 times their weight from rest 5 cm above a mesh one triangle thick and a height field, in
    # one step a particle would go (1 + 1/n) / 2 a dt^2 = 14 cm (n sub-steps of semi-implicit Euler): its force
    # widens the reach in which it looks for shapes (boxed by its velocity and gravity alone, it went through)
    w = mb.World()
    verts = np.array([[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]], dtype=float)
    w.add_static(mb.TriangleMesh(verts, np.array([[0, 2, 1], [0, 3, 2]])))
    w.add_static(mb.HeightField(np.zeros((9, 9)), spacing=(0.5, 0.5), origin=(4.0, 0.0, -2.0)))
    rng = np.random.default_rng(2)
    on_mesh = rng.uniform(-1.5, 1.5, (20, 3)) * (1, 0, 1) + (0, 0.05, 0)
    p = w.add_particles(np.vstack([on_mesh, on_mesh + (6.0, 0.0, 0.0)]), mass=0.01, radius=0.02)
    for _ in range(10):
        p.apply_force((0.0, -100.0 * G * 0.01, 0.0))
        w.step(DT)
        assert np.allclose(p.positions[:, 1], 0.02, atol=1e-6)


# --- two ways with bodies -------------------------------------------------------------------------------------
@pytest.mark.parametrize("ball_mass, ball_radius, radius", [(1.0, 0.1, 0.01), (0.1, 0.05, 0.005)])
def test_a_ball_dropped_on_a_layer_of_grains_on_the_ground_rests_on_it(ball_mass, ball_radius, radius):
    # a square layer of touching 1 g grains on the plane, a grain under the ball's middle, and a ball dropped onto
    # it from 20 cm: it rests on that grain, its bottom two grain radii up, the grains on the plane.  The bodies'
    # step stops the ball on the plane itself, through the grains; split by the inverse masses, the grains took
    # almost all of each push out and were pushed into the plane and out: the 1 kg ball went through to the plane
    # and the grains flew up; the ground now holds the grains, so the ball takes the push whole
    # (particle_contacts._shape_contacts)
    w = mb.World()
    w.add_static(mb.Plane((0.0, 1.0, 0.0), 0.0))
    g = np.arange(-0.5, 0.5 + 1e-9, 2.0 * radius)
    x, z = np.meshgrid(g, g)
    grains = w.add_particles(np.column_stack([x.ravel(), np.full(x.size, radius), z.ravel()]), mass=0.001,
                             radius=radius, collide_particles=True)
    ball = w.add_body(mb.Sphere(ball_radius), position=(0.0, 2.0 * radius + ball_radius + 0.2, 0.0), mass=ball_mass)
    run(w, 3.0)
    assert ball.position[1] - ball_radius == pytest.approx(2.0 * radius, abs=0.05 * radius)
    assert abs(ball.velocity[1]) < 0.01
    assert grains.positions[:, 1] == pytest.approx(radius, abs=0.05 * radius)


def test_momentum_is_conserved_when_a_particle_hits_a_free_box():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    box = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(2.0, 0.3, 0.1), density=10.0)
    p = w.add_particles([[0.0, 0.0, 0.0]], mass=3.0, radius=0.1, velocity=(10.0, 0.0, 0.0), restitution=0.5)
    before = 3.0 * p.velocities[0] + box.mass * box.velocity
    run(w, 0.5)
    after = 3.0 * p.velocities[0] + box.mass * box.velocity
    assert box.velocity[0] > 0.0 and p.velocities[0, 0] < 10.0
    assert np.allclose(after, before, rtol=1e-12, atol=1e-9)
    assert np.linalg.norm(box.angular_velocity) > 0.0          # hit off its centre: it turns


@pytest.mark.parametrize("e, offset", [(0.0, 0.0), (1.0, 0.0), (0.0, 0.03)])
def test_a_ball_striking_a_particle_pinned_to_a_box_strikes_the_box(e, offset):
    # no gravity: a 1 kg ball at 1 m/s strikes a 1 g particle pinned to the face of a free 1 kg box; the particle is
    # a point of the box, so it is the box the ball strikes.  Momentum is kept; head on, the two leave with
    # restitution's closed forms (e = 0: together at 0.5 m/s; e = 1: the ball stops, the box takes its 1 m/s);
    # off the line of centres the box turns too, and the angular momentum about the origin is kept within 0.5 % (the
    # pushes are positional, each at the poses of its sub-step; pushed at the particle's centre rather than at the
    # contact, the friction's torque was lost and 5.7 % of it went).  (The box stayed at rest and the ball bounced
    # off the particle as off a wall at 0.95 m/s: the particle took the push by its own mass and was put back on
    # the box.)
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    box = w.add_body(mb.Box((0.05, 0.05, 0.05)), mass=1.0)
    p = w.add_particles([(0.1, 0.0, 0.0)], mass=0.001, radius=0.02)
    p.pin([0], body=box)
    ball = w.add_body(mb.Sphere(0.05), position=(0.4, offset, 0.0), mass=1.0, velocity=(-1.0, 0.0, 0.0),
                      restitution=e)
    def angular_momentum():
        return sum(b.mass * np.cross(b.position, b.velocity) + b.inertia @ b.angular_velocity for b in (box, ball))
    brought = angular_momentum()
    run(w, 1.0)
    assert box.velocity + ball.velocity == pytest.approx((-1.0, 0.0, 0.0), abs=1e-9)
    assert angular_momentum() == pytest.approx(brought, abs=0.005 * np.linalg.norm(brought))
    if offset == 0.0:
        assert box.velocity == pytest.approx((-(1.0 + e) / 2.0, 0.0, 0.0), abs=1e-6)
        assert ball.velocity == pytest.approx((-(1.0 - e) / 2.0, 0.0, 0.0), abs=1e-6)
    else:
        assert abs(box.angular_velocity[2]) > 0.1


@pytest.mark.parametrize("box_mass", [5.0, 50.0])
def test_a_box_hangs_from_a_rope_of_particles(box_mass):
    # a rope of 10 rods (beads of 50 g) pinned to the world at the top and to a box at the bottom: the box
    # hangs at the rope's length and the top rod carries the box and the free beads.  One Gauss-Seidel pass per
    # sub-step hands a heavy load up a chain of light beads slowly (mass ratio 100): the rope gives about 8 mm
    # at 16 sub-steps, and the box bobs on that give; past 2 % the tethers hold it (a 50 kg box: 2 cm instead
    # of 6), and the rods then report only the part of the load they carry.
    n, seg, bead = 10, 0.1, 0.05
    w = mb.World()
    top = np.array([0.0, 3.0, 0.0])
    rope = w.add_particles([top - (0.0, seg * k, 0.0) for k in range(n + 1)], mass=bead, damping=5.0)
    net = w.add_network(rope, np.column_stack([np.arange(n), np.arange(1, n + 1)]), kind="rod")
    box = w.add_body(mb.Box((0.1, 0.1, 0.1)), position=top - (0.0, seg * n + 0.1, 0.0), density=box_mass / 0.008)
    rope.pin([0])
    rope.pin([n], body=box)
    run(w, 2.0)
    pull = []
    for _ in range(60):
        w.step(DT)
        pull.append(net.forces[0])
    assert box.position[1] == pytest.approx(top[1] - seg * n - 0.1, abs=0.02 * seg * n + 1e-9)
    if box_mass < 10.0:
        # (the pinned ends are the world's and the box's points: the free beads are 9)
        assert np.mean(pull) == pytest.approx((box_mass + (n - 1) * bead) * G, rel=0.02)


def test_a_particle_pinned_to_a_box_carries_it_on_one_rod_exactly():
    # a pinned particle is a point of its body: the rod from a world pin holds the box at once, with its weight
    w = mb.World()
    p = w.add_particles([[0.0, 2.0, 0.0], [0.0, 1.5, 0.0]])
    p.pin([0])
    box = w.add_body(mb.Box((0.1, 0.1, 0.1)), position=(0.0, 1.4, 0.0), density=5.0 / 0.008)
    p.pin([1], body=box)
    net = w.add_network(p, [[0, 1]], kind="rod")
    run(w, 1.0)
    assert box.position[1] == pytest.approx(1.4, abs=1e-9)
    assert net.forces[0] == pytest.approx(5.0 * G, rel=1e-9)


def test_a_heavy_ball_pulls_a_spring_down_by_its_weight_over_the_stiffness():
    # a 2 kg ball hangs from a particle pinned to it, on a spring of 2000 N/m from a world pin: it settles
    # (M g) / k = 9.8 mm below the spring's rest length
    k, m_ball = 2000.0, 2.0
    w = mb.World()
    ball = w.add_body(mb.Sphere(0.1), position=(0.0, 0.8, 0.0), density=m_ball / (4.0 / 3.0 * math.pi * 0.001))
    p = w.add_particles([[0.0, 1.4, 0.0], [0.0, 0.9, 0.0]])
    p.pin([0])
    p.pin([1], body=ball)
    w.add_network(p, [[0, 1]], kind="spring", stiffness=k, damping=40.0)
    w.sleeping = False
    run(w, 4.0)
    # the ball, in free fall in the bodies' step, falls again in the particles' sub-steps as they do, so that at
    # rest it hangs still where its weight and the spring balance, and reports no velocity
    assert ball.position[1] == pytest.approx(0.8 - m_ball * G / k, abs=1e-9)
    assert np.linalg.norm(ball.velocity) < 1e-9


def test_a_ball_dropped_on_a_pinned_net_comes_to_rest_on_it():
    n, size = 9, 1.0
    g = np.linspace(-0.5 * size, 0.5 * size, n)
    xz = np.array([(x, z) for x in g for z in g])
    w = mb.World()
    net = w.add_particles(np.column_stack([xz[:, 0], np.ones(len(xz)), xz[:, 1]]), mass=0.02, radius=0.03,
                          damping=2.0)
    index = np.arange(n * n).reshape(n, n)
    edges = np.vstack([np.column_stack([index[:, :-1].ravel(), index[:, 1:].ravel()]),
                       np.column_stack([index[:-1, :].ravel(), index[1:, :].ravel()])])
    w.add_network(net, edges, kind="spring", stiffness=3000.0, damping=30.0)
    border = np.concatenate([index[0], index[-1], index[:, 0], index[:, -1]])
    net.pin(border)
    ball = w.add_body(mb.Sphere(0.15), position=(0.0, 1.6, 0.0), density=300.0)
    run(w, 8.0)
    # at rest, above the net's lowest point, the net sagging under it
    assert np.linalg.norm(ball.velocity) < 1e-2
    lowest = net.positions[:, 1].min()
    assert 0.5 < lowest < 1.0 - 0.01
    assert ball.position[1] - 0.15 > lowest - 0.03


# --- particles against particles -------------------------------------------------------------------------------
def test_equal_particles_swap_velocities_in_an_elastic_head_on_collision():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    p = w.add_particles([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], radius=0.1, restitution=1.0, friction=0.0,
                        velocity=[[2.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], collide_particles=True)
    run(w, 1.0)
    assert np.allclose(p.velocities, [[-1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], atol=1e-9)


def test_a_heap_of_colliding_particles_does_not_interpenetrate():
    w = mb.World()
    w.add_static(mb.Plane())
    for x in (-0.55, 0.55):
        w.add_static(mb.Box((0.05, 1.0, 0.6)), position=(x, 1.0, 0.0))
    for z in (-0.55, 0.55):
        w.add_static(mb.Box((0.6, 1.0, 0.05)), position=(0.0, 1.0, z))
    rng = np.random.default_rng(3)
    grid = np.stack(np.meshgrid(np.arange(8), np.arange(8), np.arange(8)), -1).reshape(-1, 3)
    x = grid * 0.12 + (-0.42, 0.1, -0.42) + rng.uniform(-0.01, 0.01, (512, 3))
    p = w.add_particles(x, radius=0.05, collide_particles=True, friction=0.3)
    run(w, 3.0)
    X = p.positions
    d = np.linalg.norm(X[:, None] - X[None], axis=-1) + np.eye(len(X)) * 9.0
    # one pass per sub-step leaves each layer's overlap to the next sub-step: the weight of k layers above
    # gives about k^2 g h^2 (0.7 mm under 8 layers at h = 1/960 s)
    give = 8 ** 2 * G * (DT / w.particle_substeps) ** 2
    assert d.min() > 0.1 - 3.0 * give
    assert X[:, 1].min() > 0.05 - 3.0 * give
    assert np.abs(X[:, [0, 2]]).max() < 0.5 - 0.05 + 3.0 * give


# --- pins, ray casts, removal, snapshots, bad input ----------------------------------------------------------
def test_pins_hold_in_the_world_and_on_a_moving_body():
    w = mb.World()
    platform = w.add_kinematic(mb.Box((0.5, 0.1, 0.5)), position=(0.0, 1.0, 0.0), velocity=(1.0, 0.0, 0.0))
    p = w.add_particles([[0.0, 1.2, 0.0], [3.0, 2.0, 0.0]])
    p.pin([0], body=platform)
    p.pin([1])
    run(w, 1.0)
    assert np.allclose(p.positions[0], platform.position + (0.0, 0.2, 0.0), atol=1e-9)
    assert np.allclose(p.positions[1], (3.0, 2.0, 0.0))
    p.unpin([1])
    run(w, 0.5)
    assert p.positions[1, 1] < 2.0 - 0.5 * G * 0.2


def test_a_ray_hits_the_nearest_particle():
    w = mb.World()
    w.add_static(mb.Box((1.0, 1.0, 1.0)), position=(10.0, 0.0, 0.0))
    p = w.add_particles([[5.0, 0.0, 0.0], [3.0, 0.2, 0.0]], radius=0.5)
    hit = w.raycast((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert hit.object is p and hit.index == 1 and hit.body is None
    assert hit.distance == pytest.approx(3.0 - math.sqrt(0.25 - 0.04), abs=1e-12)
    assert np.allclose(hit.normal, (hit.point - (3.0, 0.2, 0.0)) / 0.5)
    w.remove(p)
    assert w.raycast((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)).object.is_static


def test_snapshots_repeat_a_run_and_removal_drops_the_networks():
    w = mb.World()
    w.add_static(mb.Plane())
    box = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.0, 0.5, 0.0))
    p = w.add_particles(np.random.default_rng(0).uniform(-0.5, 0.5, (30, 3)) + (0, 1.5, 0), radius=0.05,
                        collide_particles=True)
    net = w.add_network(p, [[k, k + 1] for k in range(29)], kind="spring", stiffness=50.0)
    run(w, 0.5)
    s = w.snapshot()
    run(w, 0.5)
    end = w.state_hash()
    w.restore(s)
    run(w, 0.5)
    assert w.state_hash() == end
    assert w.constraints == [net] and w.particles == [p]
    w.remove(p)
    assert w.particles == [] and w.constraints == []
    with pytest.raises(ValueError, match="removed"):
        net.forces
    with pytest.raises(ValueError, match="removed since"):
        w.restore(s)
    run(w, 0.5)
    assert box.position[1] == pytest.approx(0.2, abs=1e-3)


@pytest.mark.parametrize("kwargs, match", [
    (dict(positions=[[0, 0, 0]], mass=0.0), "mass"),
    (dict(positions=[[0, 0, 0]], radius=-1.0), "radius"),
    (dict(positions=[[0, float("nan"), 0]]), "positions"),
    (dict(positions=[[0, 0]]), "positions"),
    (dict(positions=[[0, 0, 0]], velocity=[1, 2]), "velocity"),
    (dict(positions=[[0, 0, 0]], friction=-1.0), "friction"),
    (dict(positions=[[0, 0, 0]], restitution=2.0), "restitution"),
    (dict(positions=[[0, 0, 0]], damping=-1.0), "damping"),
    (dict(positions=[[0, 0, 0]], collide_particles=1), "collide_particles"),
    (dict(positions=np.zeros((0, 3))), "positions"),
])
def test_bad_particles_are_refused_by_name_and_change_nothing(kwargs, match):
    w = mb.World()
    h = w.state_hash()
    with pytest.raises((TypeError, ValueError), match=match):
        w.add_particles(**kwargs)
    assert w.particles == [] and w.state_hash() == h


@pytest.mark.parametrize("edges, kwargs, match", [
    ([[0, 2]], dict(kind="rod"), "edges"),
    ([[0, 0]], dict(kind="rod"), "edges"),
    ([[0.0, 1.0]], dict(kind="rod"), "edges"),
    ([[0, 1]], dict(kind="spring"), "stiffness"),
    ([[0, 1]], dict(kind="glue"), "kind"),
    ([[0, 1]], dict(kind="rod", rest_length=-1.0), "rest_length"),
    ([[0, 1]], dict(kind="rod", breaking_force=0.0), "breaking_force"),
    ([[0, 1]], dict(kind="spring", stiffness=1.0, damping=float("inf")), "damping"),
])
def test_bad_networks_are_refused_by_name_and_change_nothing(edges, kwargs, match):
    w = mb.World()
    p = w.add_particles([[0, 0, 0], [1, 0, 0]])
    h = w.state_hash()
    with pytest.raises((TypeError, ValueError), match=match):
        w.add_network(p, edges, **kwargs)
    assert w.constraints == [] and w.state_hash() == h


def test_the_particles_example_ends_at_rest_in_one_piece():
    """examples/particles.py after 6 s: the dropped bodies rest on the net, the crate hangs on the rope's
    last bead, the grain settles in the bowl without overlapping."""
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "particles.py"))["run"]
    r = run()
    assert r["fastest_drop"] < 0.1 and r["drops_above_net"] > 0.0 and 1.0 < r["net_lowest"] < 1.5
    assert r["crate_hangs"] < 1e-6 and r["rope_stretch"] < 0.05
    assert r["grain_overlap"] < 1e-3 and r["grain_spilled"] == 0 and r["fastest_grain"] < 0.5


def test_a_particle_wakes_the_sleeping_box_it_hits_and_removing_a_body_frees_its_pins():
    w = mb.World()
    w.add_static(mb.Plane())
    box = w.add_body(mb.Box((0.3, 0.3, 0.3)), position=(0.0, 0.3, 0.0))
    run(w, 2.0)
    assert box.is_sleeping
    p = w.add_particles([[-2.0, 0.3, 0.0]], mass=5.0, radius=0.05, velocity=(8.0, 0.0, 0.0))
    run(w, 0.5)
    # 40 kg m/s into a 216 kg box: 0.19 m/s at most, which ground friction (mu 0.5) stops within
    # v^2 / (2 mu g) = 3.5 mm
    assert not box.is_sleeping and 0.001 < box.position[0] < 0.01
    q = w.add_particles([[3.0, 1.0, 0.0]])
    q.pin([0], body=box)
    assert q.pinned[0]
    w.remove(box)
    assert not q.pinned[0]
    run(w, 0.5)
    assert q.positions[0, 1] < 1.0                 # falls freely now
    assert p.positions[0, 1] >= 0.05 - 1e-9


def test_a_grain_in_the_groove_of_two_holds_them_by_static_friction():
    # two grains touching on the floor and one resting in their groove: each floor grain is pushed sideways by
    # W / (2 tan 60) and pressed down by 1.5 W (W one grain's weight), so a friction of 0.19 holds them; 0.5 must
    m = 0.1
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.5)
    p = w.add_particles([[-0.05, 0.05, 0.0], [0.05, 0.05, 0.0], [0.0, 0.05 + 0.1 * math.sin(math.pi / 3), 0.0]],
                        radius=0.05, mass=m, friction=0.5, collide_particles=True)
    run(w, 10.0)
    assert p.positions[1, 0] - p.positions[0, 0] == pytest.approx(0.1, abs=1e-5)
    # (each sub-step the floor reopens a little of the grains' overlap: a jitter below gravity's g h)
    assert np.abs(p.velocities).max() < G * DT / w.particle_substeps


def test_particles_that_cannot_meet_step_the_same_with_the_kernels_that_leave_meeting_out(monkeypatch):
    # a cloth that does not collide with itself, hanging by a corner onto a plane and a box, and a net of plain
    # particles: their step takes kernels compiled without the paths of particles meeting each other
    # (particle_step._kernels), bit for bit what the full kernels give
    from marbellous.cloth import cloth_grid
    from marbellous.deformables.particle_state import ParticleState

    def scene():
        w = mb.World()
        w.add_static(mb.Plane())
        w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.1, 0.2, 0.0))
        v, t = cloth_grid(0.6, 0.6, 8, 8)
        c = w.add_cloth(v + (0.0, 0.8, 0.0), t, mass=0.1, self_collision=False)
        c.pin([0])
        parts = w.add_particles([(0.5 + 0.1 * k, 1.0, 0.3) for k in range(4)], radius=0.02)
        w.add_network(parts, [(k, k + 1) for k in range(3)], kind="rod")
        return w
    apart = scene()
    assert not apart._state.particles.meeting()
    for _ in range(60):
        apart.step(DT)
    monkeypatch.setattr(ParticleState, "meeting", lambda self: True)
    together = scene()
    for _ in range(60):
        together.step(DT)
    assert apart.state_hash() == together.state_hash()
