"""No energy from nowhere: a body dropped, spinning, onto a static floor never ends a step with more
mechanical energy than it started with, for every solver and integrator (issue "Reliability").

The scene is closed and has no source of energy: gravity is conservative, contacts, friction and the
solvers' position correction may only take energy away.  So with

    E = m |v|^2 / 2 + omega . I_w omega / 2 + m g y        (kinetic, rotational, gravitational potential)

every step must keep ``E <= E0 + 0.01 K0 + m g * 1 mm``: one percent of the starting kinetic energy
(``K0``, rotational included) for the round-off of fast spins, and the work gravity does over a
millimetre for the overlap a resting contact keeps (the soft contact sinks ``g / (2 pi f)^2``, 0.07 mm
at the defaults; the penalty springs ``g / omega^2``, about 1 mm).

Explicit Euler gains energy by its nature: in free fall each sub-step of ``h`` adds exactly
``m g^2 h^2 / 2`` (``y' = y + v h``, ``v' = v - g h``), and its test allows that on top.

The penalty scheme is held to this only where its springs can stop the body within its thickness
(``penalty_holds``); the report's rods (thicker than their springs' overlap) are checked with every solver.

Shapes are drawn from 1 mm to 10 m, boxes also as thin rods and plates, with spins up to 100 rad/s about
random axes and random orientations, as the report's 8 m x 4 cm x 2.4 cm rod spinning at 10 rad/s that
flew to 520 m at 63,000 rad/s.
"""
import math

import numpy as np
import pytest
from hypothesis import assume, given, seed, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.dynamics.mass_properties import MAX_MOMENT_RATIO, conditioned_inertia
from marbellous.dynamics.penalty import STABLE_FRACTION

G = 9.81
DT = 1.0 / 60.0
STEPS = 150                  # 2.5 s at 60 Hz
SOLVERS = ("sequential_impulse", "penalty", "lcp")
INTEGRATORS = ("semi_implicit_euler", "verlet", "rk4")


def energy(body):
    """``(E, K)``: mechanical energy (J) with gravity ``(0, -G, 0)`` and kinetic energy (J) of ``body``."""
    v, w = body.velocity, body.angular_velocity
    kinetic = 0.5 * body.mass * v @ v + 0.5 * w @ body.inertia @ w
    return kinetic + body.mass * G * body.position[1], kinetic


def floor_of(world, kind):
    """A static floor whose top is the plane y = 0: an infinite plane, a large box or a two-triangle mesh."""
    if kind == "plane":
        world.add_static(mb.Plane())
    elif kind == "box":
        world.add_static(mb.Box((60.0, 1.0, 60.0)), position=(0.0, -1.0, 0.0))
    else:
        a = 60.0
        vertices = [(-a, 0.0, -a), (a, 0.0, -a), (a, 0.0, a), (-a, 0.0, a)]
        world.add_static(mb.TriangleMesh(vertices, [(0, 2, 1), (0, 3, 2)]))


def reach(shape):
    """Distance (m) from the centre of ``shape`` to its farthest surface point."""
    if isinstance(shape, mb.Sphere):
        return shape.radius
    if isinstance(shape, mb.Capsule):
        return shape.radius + shape.half_height
    return float(np.linalg.norm(shape.half_extents))


def drop(shape, orientation, spin, gap, solver, integrator, floor="plane", steps=STEPS):
    """Drop ``shape`` from ``gap`` (m) above the floor, turning at ``spin`` (rad/s), for ``steps`` steps of
    60 Hz.  Returns ``(body, E0, K0, energies after each step)``."""
    world = mb.World(solver=solver, integrator=integrator)
    floor_of(world, floor)
    body = world.add_body(shape, position=(0.0, reach(shape) + gap, 0.0), orientation=orientation,
                          angular_velocity=spin)
    e0, k0 = energy(body)
    energies = []
    for _ in range(steps):
        world.step(DT)
        energies.append(energy(body)[0])
    return body, e0, k0, np.array(energies), world


def allowance(body, k0):
    """The most the energy may exceed its start (J): 1% of K0 plus m g over 1 mm."""
    return 0.01 * k0 + body.mass * G * 1e-3


# --- strategies ------------------------------------------------------------------------------------------
def shapes_from(smallest):
    """Spheres, boxes (also thin rods and plates) and capsules with every dimension from ``10**smallest`` m
    to 10 m, log-uniform."""
    lengths = st.floats(smallest, 1.0).map(lambda e: 10.0 ** e)
    thin = st.floats(smallest, max(smallest, -1.5)).map(lambda e: 10.0 ** e)       # to 3 cm
    long = st.floats(-0.5, 1.0).map(lambda e: 10.0 ** e)                            # 0.3 m to 10 m
    boxes = st.tuples(lengths, lengths, lengths).map(mb.Box)
    rods = st.permutations([0, 1, 2]).flatmap(
        lambda p: st.tuples(long, thin, thin).map(lambda e: mb.Box(tuple(e[p[k]] for k in range(3)))))
    plates = st.permutations([0, 1, 2]).flatmap(
        lambda p: st.tuples(long, long, thin).map(lambda e: mb.Box(tuple(e[p[k]] for k in range(3)))))
    return st.one_of(lengths.map(mb.Sphere), boxes, rods, plates,
                     st.tuples(lengths, lengths).map(lambda rh: mb.Capsule(*rh)))


#: 1 mm to 10 m (until the moments of inertia were conditioned, the impulse solvers held from 5 mm only: a
#: 20 m x 2 mm needle gained energy with every integrator)
shapes = shapes_from(-3.0)
quaternions = st.tuples(*[st.floats(-1.0, 1.0)] * 4).filter(lambda q: sum(x * x for x in q) > 0.01).map(
    lambda q: tuple(np.array(q) / np.linalg.norm(q)))
spins = st.tuples(st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda d: sum(x * x for x in d) > 0.01),
                  st.floats(0.0, 100.0)).map(lambda ds: tuple(np.array(ds[0]) / np.linalg.norm(ds[0]) * ds[1]))
gaps = st.floats(0.0, 2.0)
floors = st.sampled_from(["plane", "plane", "box", "mesh"])


def _check(shape, orientation, spin, gap, floor, solver, integrator, extra=None):
    body, e0, k0, energies, _ = drop(shape, orientation, spin, gap, solver, integrator, floor)
    assert np.all(np.isfinite(energies)), (solver, integrator)
    limit = allowance(body, k0) + (0.0 if extra is None else extra(body, np.arange(1, STEPS + 1)))
    excess = energies - e0 - limit
    worst = int(np.argmax(excess))
    assert excess[worst] <= 0.0, (f"{solver}/{integrator}: step {worst + 1} has {energies[worst] - e0:.6g} J more "
                                  f"than at the start, allowed {np.broadcast_to(limit, excess.shape)[worst]:.6g} J")


@seed(0)
@settings(max_examples=40, database=None)
@given(shape=shapes, orientation=quaternions, spin=spins, gap=gaps, floor=floors)
@pytest.mark.parametrize("solver", ["sequential_impulse", "lcp"])     # (the cases once open: regression tests below)
def test_a_dropped_spinning_body_never_gains_energy(solver, shape, orientation, spin, gap, floor):
    for integrator in INTEGRATORS:
        _check(shape, orientation, spin, gap, floor, solver, integrator)


def thinnest(shape):
    """Half the smallest dimension of ``shape`` (m)."""
    if isinstance(shape, mb.Sphere):
        return shape.radius
    if isinstance(shape, mb.Capsule):
        return shape.radius
    return float(np.min(shape.half_extents))


def penalty_holds(shape, spin, gap):
    """True if the penalty springs can stop ``shape`` within its thickness: a contact spring of angular
    frequency omega (``penalty.STABLE_FRACTION / h`` at 60 Hz and 4 sub-steps, 96.5 rad/s) stopping an
    approach at speed ``v`` overlaps by up to ``v / omega``; the fastest point of the body lands at
    ``v = sqrt(2 g (gap + reach)) + |spin| reach`` at most.  Deeper than half its thinnest side, the body
    is pushed through or out by a depth the step measures anew on the other side, and the scheme makes
    no promise about energy (a 2 m x 2 cm rod falling over at 3.6 m/s sank 7 cm and left at 5 m/s)."""
    omega = 2.0 * math.pi * STABLE_FRACTION / (DT / 4)
    r = reach(shape)
    v = math.sqrt(2.0 * G * (gap + r)) + float(np.linalg.norm(spin)) * r
    return v / omega < thinnest(shape)


#: the penalty scheme holds bodies thicker than its springs' overlap (``penalty_holds``): centimetres at these
#: speeds, so its shapes start at 3 cm and its drops at most 0.5 m (drawn from 1 mm and 2 m, most examples
#: were bodies it makes no promise for, and hypothesis gave up on the filter)
penalty_shapes = shapes_from(-1.5)
penalty_gaps = st.floats(0.0, 0.5)


@seed(0)
@settings(max_examples=40, database=None)
@given(shape=penalty_shapes, orientation=quaternions, spin=spins, gap=penalty_gaps, floor=floors)
def test_penalty_springs_never_gain_energy_where_they_can_hold(shape, orientation, spin, gap, floor):
    assume(penalty_holds(shape, spin, gap))
    for integrator in INTEGRATORS:
        _check(shape, orientation, spin, gap, floor, "penalty", integrator)


# Examples the hypothesis test above once found gaining energy: the LCP ones fixed by the split impulses
# (overlap pushed out on pseudo-velocities, never kept as velocity: dynamics/contact_solver.py), kept as
# regression tests; the open ones strict, so that a fix shows up as an unexpected pass.
def test_a_spinning_rod_with_sequential_impulse():
    # a 3.6 m x 2 cm rod spinning at 96 rad/s onto a plane gained 4% of K0 (sequential impulses)
    _check(mb.Box((0.01, 1.7782794100389228, 0.01)), tuple(np.array([1.0, -1.0, -1.0, -0.75]) / 1.887458608817687),
           (39.19183588453085, 78.3836717690617, -39.19183588453085), 0.0, "plane", "sequential_impulse",
           "semi_implicit_euler")


def test_a_thin_blade_with_lcp():
    # the LCP let a 20 m x 2 mm x 2 cm blade through the floor; with RK4 it then exploded
    _check(mb.Box((10.0, 0.001, 0.01)), (0.0, 0.0, 1.0, 0.0), (0.0, 0.4472135954999579, 0.8944271909999159), 0.0,
           "plane", "lcp", "rk4")


def _needle(shape, spin, solver, integrator):
    q = np.array([0.5, 0.0, 1.0, 0.0])
    _check(shape, tuple(q / np.linalg.norm(q)), spin, 0.0, "plane", solver, integrator)


def test_a_millimetre_needle_with_lcp():
    # a 2 m x 2 mm needle exploded with the LCP
    _needle(mb.Box((0.001, 0.001, 1.0)), (0.0, 0.0, 0.0), "lcp", "semi_implicit_euler")


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("solver", ["sequential_impulse", "lcp"])
def test_a_millimetre_needle_twenty_metres_long(solver, integrator):
    # Its principal moments are 5e7 apart: the impulses at its end's corners, 2 mm apart, spun it about its
    # long axis at hundreds of rad/s, it went through the floor and gained 250 J (semi-implicit Euler),
    # 1e31 J (RK4).  Simulated with its moments conditioned to 1e4 (mass_properties.conditioned_inertia).
    _needle(mb.Box((10.0, 0.001, 0.001)), (0.0, 0.7071067811865475, 0.7071067811865475), solver, integrator)


#: needles 4 to 20 m long and 1 to 6 mm thick (their moments 4e5 to 4e8 apart), about any axis
needles = st.tuples(st.floats(0.3, 1.0), st.floats(-3.3, -2.5), st.floats(-3.3, -2.5), st.permutations([0, 1, 2])).map(
    lambda e: mb.Box(tuple(10.0 ** (e[0], e[1], e[2])[e[3][k]] for k in range(3))))


@seed(1)
@settings(max_examples=25, database=None, deadline=None)
@given(shape=needles, orientation=quaternions, spin=spins, gap=st.floats(0.0, 1.0))
@pytest.mark.parametrize("solver", ["sequential_impulse", "lcp"])
def test_a_dropped_needle_never_gains_energy(solver, shape, orientation, spin, gap):
    # (unconditioned, 30 of 120 such drops gained energy, some without bound)
    for integrator in INTEGRATORS:
        _check(shape, orientation, spin, gap, "plane", solver, integrator)


def test_inertia_is_conditioned_to_a_ratio_of_moments_about_the_same_axes():
    rng = np.random.default_rng(3)
    axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    inertia = axes @ np.diag([1e-9, 0.5, 2.0]) @ axes.T
    conditioned = conditioned_inertia(inertia)
    moments, turned = np.linalg.eigh(conditioned)
    assert moments == pytest.approx([2.0 / MAX_MOMENT_RATIO, 0.5, 2.0], rel=1e-12)
    # the same principal axes (each up to sign)
    assert np.abs(np.abs(np.sum(turned * axes, axis=0)) - 1.0).max() < 1e-12
    # within the ratio: the very same tensor
    within = np.diag([0.001, 1.0, 5.0])
    assert conditioned_inertia(within) is within
    # what a body is simulated with, and reports
    needle = mb.World().add_body(mb.Box((10.0, 0.001, 0.001)), mass=1.0)
    assert np.linalg.eigvalsh(needle.inertia) == pytest.approx([100.0 / 3.0 / MAX_MOMENT_RATIO, 100.0 / 3.0,
                                                               100.0 / 3.0], rel=1e-6)


def _free_fall_gain(body, steps):
    """What explicit Euler adds in free fall over ``steps`` steps of 4 sub-steps: m g^2 h^2 / 2 each."""
    h = DT / 4
    return 0.5 * body.mass * G * G * h * h * 4 * steps


@seed(0)
@settings(max_examples=20, database=None)
@given(shape=shapes, orientation=quaternions, spin=spins, gap=gaps)
@pytest.mark.parametrize("solver", SOLVERS)
def test_explicit_euler_gains_no_more_than_its_own_free_fall_error(solver, shape, orientation, spin, gap):
    if solver == "penalty":
        assume(penalty_holds(shape, spin, gap))
    _check(shape, orientation, spin, gap, "plane", solver, "explicit_euler", extra=_free_fall_gain)


def test_explicit_euler_free_fall_gain_is_the_closed_form():
    # y' = y + v h, v' = v - g h: each sub-step adds m g^2 h^2 / 2 exactly (the allowance above).
    w = mb.World(integrator="explicit_euler")
    b = w.add_body(mb.Sphere(0.1), position=(0.0, 100.0, 0.0))
    e0, _ = energy(b)
    for _ in range(30):
        w.step(DT)
    assert energy(b)[0] - e0 == pytest.approx(_free_fall_gain(b, 30), rel=1e-6)


REPORTED = [mb.Box((4.0, 0.02, 0.012)), mb.Box((4.0, 0.05, 0.05)), mb.Box((2.0, 0.02, 0.02))]


@pytest.mark.parametrize("integrator", INTEGRATORS + ("explicit_euler",))
@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("shape", REPORTED, ids=["rod_8m_4cm", "beam_8m_10cm", "rod_4m_4cm"])
def test_the_reported_spinning_rods_stay_bounded(shape, solver, integrator):
    # The report: dropped from 5 m turned half a turn about z, spinning at 10 rad/s about z, 180 steps.
    world = mb.World(solver=solver, integrator=integrator)
    world.add_static(mb.Plane())
    body = world.add_body(shape, position=(0.0, 5.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0),
                          angular_velocity=(0.0, 0.0, 10.0))
    e0, k0 = energy(body)
    limit = allowance(body, k0)
    worst = -math.inf
    for n in range(1, 181):
        world.step(DT)
        e = energy(body)[0]
        assert math.isfinite(e)
        worst = max(worst, e - e0 - limit - (_free_fall_gain(body, n) if integrator == "explicit_euler" else 0.0))
    assert worst <= 0.0
    assert body.position[1] < 5.0 + reach(shape)    # it never rose above where it started


def test_free_rotation_of_a_thin_rod_keeps_energy_and_momentum_for_any_step():
    # Torque-free: L is constant and the kinetic energy L . I_w^-1 L / 2 with it, whatever |omega| h.  The
    # midpoint rule keeps L to round-off and the energy to 1e-10 of itself, even at 5 rad per sub-step
    # about the rod's long axis (moment 1e-4 of the others).
    for integrator in INTEGRATORS + ("explicit_euler",):
        w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
        b = w.add_body(mb.Box((4.0, 0.02, 0.012)), angular_velocity=(1200.0, 10.0, 3.0),
                       orientation=(0.9, 0.1, 0.3, 0.2))
        l0 = b.inertia @ b.angular_velocity
        k0 = 0.5 * b.angular_velocity @ l0
        for _ in range(60):
            w.step(DT)
            lw = b.inertia @ b.angular_velocity
            assert np.linalg.norm(lw - l0) <= 1e-9 * np.linalg.norm(l0), integrator
            assert 0.5 * b.angular_velocity @ lw == pytest.approx(k0, rel=1e-8), integrator


# --- heavy on light ------------------------------------------------------------------------------------
def heavy_on_light(solver, ratio, steps=300):
    """A 1 kg cube of 1 m on the ground and a cube of ``ratio`` kg on it; 5 s.  Returns both bodies and
    the lowest the light cube's centre went."""
    w = mb.World(solver=solver)
    w.add_static(mb.Plane())
    light = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0), mass=1.0)
    heavy = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 1.5, 0.0), mass=ratio)
    lowest = math.inf
    for _ in range(steps):
        w.step(DT)
        lowest = min(lowest, light.position[1])
    return light, heavy, lowest


@pytest.mark.parametrize("ratio", [1e3, 1e4, 1e6])
def test_a_heavy_box_stands_on_a_light_one(ratio):
    # The contact of the heavy box with the light one is solved once more per pass with the light one held
    # (shock propagation): the stack stands as an equal-mass one does, each contact level sinking
    # g / (2 pi f)^2 = 0.07 mm (contact_hertz 60 Hz) and the speculative and soft slop of a millimetre.
    light, heavy, lowest = heavy_on_light("sequential_impulse", ratio)
    assert lowest > 0.5 - 1e-3                                  # never below the floor, nor into it
    assert light.position[1] == pytest.approx(0.5, abs=1e-3)
    assert heavy.position[1] == pytest.approx(1.5, abs=2e-3)
    assert np.linalg.norm(heavy.velocity) < 1e-2


def test_penalty_heavy_on_light_sinks_by_the_spring_law():
    # Penalty springs have k = m_n omega^2 from the contact's effective mass: four corners of a light cube
    # on the ground (m_n = m / 4 each) hold (M + m) g with k = m omega^2, and four between the cubes
    # (m_n = 1 / (4/m + 4/M)) hold M g with k = omega^2 m M / (m + M): the heavy cube sinks by
    # 2 (M + m) g / (m omega^2) in all, so the stack stands while that is well below the light cube's
    # half height: M / m < (0.5 m) omega^2 / (2 g), about 230 at 60 Hz (omega = 96.5 rad/s).
    m, big = 1.0, 100.0
    omega = 2.0 * math.pi * STABLE_FRACTION / (DT / 4)
    light, heavy, _ = heavy_on_light("penalty", big, steps=600)
    assert 0.5 - light.position[1] == pytest.approx((big + m) * G / (m * omega ** 2), rel=0.02)
    assert 1.5 - heavy.position[1] == pytest.approx(2.0 * (big + m) * G / (m * omega ** 2), rel=0.02)


def test_bodies_spawned_into_one_another_keep_a_bounded_number_of_contacts():
    # 300 spheres at one point are 44,850 overlapping pairs; once the broad phase finds more than
    # MAX_PAIRS_PER_BODY pairs per body, each movable body keeps at most that many (the first in the canonical
    # order), so the contacts stay below MAX_PAIRS_PER_BODY per body (one point per sphere pair).
    from marbellous.pipeline.collide import MAX_PAIRS_PER_BODY

    w = mb.World()
    w.add_static(mb.Plane())
    balls = [w.add_body(mb.Sphere(0.1), position=(0.0, 1.0, 0.0)) for _ in range(300)]
    w.step(DT)
    assert 0 < len(w.contacts()) <= MAX_PAIRS_PER_BODY * len(balls)
    assert all(np.all(np.isfinite(b.position)) for b in balls)


@pytest.mark.parametrize("dt", [0.5, 1.0])
@pytest.mark.parametrize("solver", SOLVERS)
def test_huge_steps_gain_no_energy(solver, dt):
    # Steps of half a second and a second (2 and 1 Hz): contacts are softened to a quarter of the sub-step
    # rate (contact_hertz, penalty frequency), so bodies sink in (not tested: at 1 Hz a resting cube sinks
    # g / (2 pi)^2 = 25 cm per contact level), but nothing may gain energy or become NaN.
    from marbellous.scenes.stacks import box_tower

    w, boxes = box_tower(mb.World(solver=solver), height=10)
    bodies = boxes + [w.add_body(mb.Sphere(0.3), position=(2.0 + 0.7 * i, 0.3 + 0.1 * i, 0.0)) for i in range(12)]
    e0 = sum(energy(b)[0] for b in bodies)
    tolerance = sum(b.mass for b in bodies) * G * 1e-3
    for _ in range(int(round(10.0 / dt))):
        w.step(dt)
        e = sum(energy(b)[0] for b in bodies)
        assert math.isfinite(e)
        assert e <= e0 + tolerance
