"""Reliability (issue "Reliability"): what used to explode or sink, checked against the physics.

- Bodies spawned into one another are pushed apart by split impulses: pseudo-velocities that move the poses
  and are never kept as velocity, each body's capped at ``max_push_speed``, for overlap deeper than the
  soft solve passes open through the velocities (``soft.SOFT_DEPTH``, 1 cm).  After every step no body is
  faster than gravity made it (``g t``) plus ``max_push_speed``, nor moved further than that speed over
  the step.  (When the velocities opened overlap up to ``max_push / rate``, 17 cm at the default 60 Hz
  and 4 sub-steps, the biases of a heap's contacts added up along its chains: 215 m/s.)
- Springs too stiff for an explicit force (``(k h^2 + c h) / m_eff > 1``) are solved implicitly (backward
  Euler), so a spring-mass system never gains energy at any stiffness; rods correct their length no faster
  than ``max_push_speed``.
- Resting bodies stay on the floor at steps of half a second and a second: no sub-step is longer than
  1/120 s (``state/params.MAX_SUBSTEP``), so the velocity passes converge as at 60 Hz (at dt = 1 s in 4
  sub-steps a three-cube stack sank 20 cm per step and toppled) and the penalty springs stay stable.
"""
import math

import numpy as np
import pytest
from numba import njit

import marbellous as mb
from marbellous.dynamics.soft import SOFT_DEPTH

G = 9.81
DT = 1.0 / 60.0


# --- bodies spawned at one point ---------------------------------------------------------------------------
def test_a_thousand_spheres_spawned_at_one_point_separate_no_faster_than_max_push():
    rng = np.random.default_rng(0)
    w = mb.World()
    w.add_static(mb.Plane())
    radii = rng.uniform(0.1, 0.5, 1000)
    balls = [w.add_body(mb.Sphere(float(r)), position=(0.0, 2.0, 0.0)) for r in radii]
    before = np.array([b.position for b in balls])
    # the soft solve passes open overlap of up to SOFT_DEPTH through the velocities, at rate * overlap
    # (soft.py, the sub-step's bias rate), and the relax pass takes that velocity out again after the
    # positions moved: within a step a body may move that much faster than its velocity at the end
    h = DT / w.substeps
    omega = 2.0 * math.pi * w.contact_hertz
    soft_speed = omega / (2.0 * w.contact_damping_ratio + h * omega) * SOFT_DEPTH
    for n in range(1, 46):                  # 0.75 s: the heap lands at about 0.4 s
        w.step(DT)
        x = np.array([b.position for b in balls])
        v = np.array([b.velocity for b in balls])
        bound = w.max_push_speed + G * n * DT
        # velocities: gravity's and the contacts' (which only stop bodies), never the pushes
        assert np.linalg.norm(v, axis=1).max() <= bound * (1.0 + 1e-12)
        # poses: each sub-step moves a body by (v + v_push) h with |v| <= g t + soft_speed and
        # |v_push| <= max_push
        assert (np.linalg.norm(x - before, axis=1) / DT).max() <= (bound + soft_speed) * (1.0 + 1e-12)
        before = x
        if n > 40:
            # landed: the pushes never press a body into the floor; what overlap the heap's weight leaves is
            # within the soft zone, which the velocity passes open gradually (2.5 to 6 mm here, with 4
            # iterations under a heap 3.8 m high)
            assert (x[:, 1] - radii).min() > -SOFT_DEPTH


# --- heavy on light in every execution variant ---------------------------------------------------------------
@njit
def _bundled(t):
    return t.bundled


@pytest.mark.parametrize("ratio", [1e3, 1e4, 1e6])
@pytest.mark.parametrize("variant", ["bundled", "lcp"])
def test_a_heavy_box_stands_on_a_light_one_when_bundled_and_with_the_lcp(variant, ratio):
    # As tests/test_energy.py's scalar case: the heavy box's contacts are solved once more per pass with the
    # light one held (shock propagation), on the velocities and on the pushes; here beside a pile of 80
    # spheres (80 floor contacts and more: the step is solved in bundles), and with the LCP scheme.  No
    # sleeping: the stack is solved in every one of the 300 steps.  (Vertically it holds to two millimetres
    # throughout its last second, and moves up or down by less than one in it: it holds to microns.  Its
    # reported velocity is not its motion: under a load 1,000 to 1,000,000 times the light box's weight the
    # soft contacts leave the heavy box a vertical velocity of a few mm/s at the step's end while its height
    # stays within 10 um (not yet explained).  It was checked at the last step alone, 1e-5 m/s there when it
    # peaked at 0.1 m/s in that second at 1:1000; with the body-pair cache it stays at 2 to 5 mm/s.  Sideways
    # the heavy box still jitters by up to a few cm/s with the light one, and drifts by up to 6 cm in 5 s:
    # friction between such masses is open.)
    w = mb.World(solver="lcp" if variant == "lcp" else "sequential_impulse", sleeping=False)
    w.add_static(mb.Plane())
    light = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0), mass=1.0)
    heavy = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 1.5, 0.0), mass=ratio)
    if variant == "bundled":
        for i in range(80):
            w.add_body(mb.Sphere(0.2), position=(3.0 + 0.5 * (i % 10), 0.2, 0.5 * (i // 10)))
    lowest = math.inf
    last_second = []
    for step in range(300):
        w.step(DT)
        lowest = min(lowest, light.position[1])
        if step >= 240:
            last_second.append(heavy.position[1])
        if variant == "bundled":
            assert _bundled(w._state.context)
    assert lowest > 0.5 - 1e-3                                  # never below the floor, nor into it
    assert light.position[1] == pytest.approx(0.5, abs=1e-3)
    assert heavy.position[1] == pytest.approx(1.5, abs=2e-3)
    height = np.array(last_second)
    assert np.abs(height - 1.5).max() < 2e-3 and abs(height[-1] - height[0]) < 1e-3
    assert np.linalg.norm(heavy.velocity) < 0.1


# --- springs of any stiffness ----------------------------------------------------------------------------------
def spring_energy(a, b, k, rest):
    """Kinetic energy of the two bodies plus the spring's k (l - rest)^2 / 2 (J)."""
    stretch = np.linalg.norm(b.position - a.position) - rest
    return 0.5 * a.mass * a.velocity @ a.velocity + 0.5 * b.mass * b.velocity @ b.velocity + 0.5 * k * stretch ** 2


@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "verlet", "rk4", "explicit_euler"])
@pytest.mark.parametrize("k", [1.0, 10.0, 1e2, 1e5, 1e10, 1e15])
def test_a_spring_between_one_gram_bodies_never_gains_energy_at_any_stiffness(k, integrator):
    # Two 1 g spheres, no gravity, a spring stretched by 0.3 m.  m_eff = 0.5 g, h = 1/240 s: the spring is an
    # explicit force while k h^2 / m_eff <= 1 (k <= 28.8 N/m; omega h <= 1), where semi-implicit Euler and
    # Verlet keep a modified energy within a factor 1 + omega h of E0 and RK4 loses energy; beyond, the
    # solver takes it implicitly (backward Euler), which never adds energy.  k = 1e15 N/m used to raise
    # ZeroDivisionError within a few steps.  (Explicit Euler gains (omega h)^2 per step by its nature:
    # tests/test_integrators.py; it is held here only where the spring is implicit.)
    m, rest, h = 1e-3, 1.0, DT / 4
    w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
    a = w.add_body(mb.Sphere(0.01), mass=m, position=(0.0, 0.0, 0.0))
    b = w.add_body(mb.Sphere(0.01), mass=m, position=(rest + 0.3, 0.0, 0.0))
    w.add_spring(a, b, rest_length=rest, stiffness=k)
    e0 = spring_energy(a, b, k, rest)
    omega_h = math.sqrt(k / (m / 2)) * h
    explicit = omega_h <= 1.0
    if integrator == "explicit_euler" and explicit:
        pytest.skip("explicit Euler gains energy by its nature (tests/test_integrators.py)")
    limit = e0 * ((1.0 + omega_h) if explicit else (1.0 + 1e-9))
    for _ in range(120):
        w.step(DT)
        e = spring_energy(a, b, k, rest)
        assert np.all(np.isfinite(a.position)) and np.all(np.isfinite(b.position))
        assert e <= limit
    if not explicit:
        # backward Euler damps the oscillation: the bodies come to rest at the spring's length
        assert np.linalg.norm(b.position - a.position) == pytest.approx(rest, abs=1e-3)


def mechanical_energy(body):
    """Kinetic plus gravitational potential energy of ``body`` (J), the floor at y = 0."""
    v, w = body.velocity, body.angular_velocity
    return 0.5 * body.mass * v @ v + 0.5 * w @ body.inertia @ w + body.mass * G * body.position[1]


# --- rods far from their length --------------------------------------------------------------------------------
def test_a_rod_far_from_its_length_pulls_no_faster_than_max_push():
    # A 2 m rod made between spheres 30 m apart (the soak run's --violent-joints): its length error is
    # corrected at no more than max_push_speed (3 m/s) of the ends' relative speed, and the relax pass takes
    # that speed out again, so the ends close the 28 m in about 28 / 3 = 9.3 s, never faster.
    w = mb.World()
    w.add_static(mb.Plane())
    a = w.add_body(mb.Sphere(0.3), position=(0.0, 0.3, 0.0))
    b = w.add_body(mb.Sphere(0.3), position=(30.0, 0.3, 0.0))
    w.add_rod(a, b, length=2.0)
    gap = 28.0
    for _ in range(900):
        w.step(DT)
        now = np.linalg.norm(b.position - a.position) - 2.0
        assert np.all(np.isfinite(a.position)) and np.all(np.isfinite(b.position))
        assert gap - now <= w.max_push_speed * DT * (1.0 + 1e-9)
        assert max(np.linalg.norm(a.velocity), np.linalg.norm(b.velocity)) <= w.max_push_speed
        gap = now
    assert gap == pytest.approx(0.0, abs=1e-3)


def test_violent_rods_between_random_bodies_settle_without_nan():
    # bench/soak.py --violent-joints in small: 2 m rods between random pairs of bodies tens of metres apart,
    # some sharing bodies (loops that cannot all be at length): the bodies are pulled together at a bounded
    # speed and nothing becomes NaN.
    rng = np.random.default_rng(0)
    w = mb.World()
    w.add_static(mb.Plane())
    bodies = [w.add_body(mb.Sphere(0.3) if k % 2 else mb.Box((0.3, 0.2, 0.4)),
                         position=tuple(rng.uniform((-20.0, 0.5, -20.0), (20.0, 10.0, 20.0))))
              for k in range(30)]
    for _ in range(40):
        i, j = rng.choice(len(bodies), 2, replace=False)
        w.add_rod(bodies[i], bodies[j], length=2.0)
    # The rods correct their length through the velocities (a soft constraint and one relax pass, not
    # split impulses), and in loops that cannot all be at length the relax pass does not take all of the
    # pull out again: what stays is bounded by the cap, no more than every body moving at max_push_speed,
    # sum(m) max_push^2 / 2 (20.6 kJ here; the most seen is 6.1 kJ, in the first steps).  (Uncapped, the
    # soak run's rods reached 6e17 m/s and NaN.)
    e0 = sum(mechanical_energy(body) for body in bodies)
    allowed = 0.5 * sum(body.mass for body in bodies) * w.max_push_speed ** 2
    for _ in range(1200):
        w.step(DT)
        for body in bodies:
            assert np.all(np.isfinite(body.position)) and np.all(np.isfinite(body.velocity))
        assert sum(mechanical_energy(body) for body in bodies) <= e0 + allowed


# --- large steps -----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("dt", [0.5, 1.0])
@pytest.mark.parametrize("solver", ["sequential_impulse", "lcp"])
def test_resting_bodies_stay_on_the_floor_at_large_steps(solver, dt):
    # A cube, a sphere and a stack of three cubes at rest on the floor, stepped at 2 Hz and 1 Hz (in sub-steps
    # of at most 1/120 s): nothing gains energy, and nothing sinks more than a millimetre beyond what the
    # contacts' softness allows.  Sequential impulses open shallow overlap softly, at contact_hertz capped at
    # a quarter of the sub-step rate (30 Hz here): a load W on a contact level of effective mass m_n
    # compresses it by W / (m_n omega^2), as the penalty springs below (their figures); the LCP's rows are
    # rigid and its pushes open every overlap.
    w = mb.World(solver=solver)
    w.add_static(mb.Plane())
    bodies = [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0)),
              w.add_body(mb.Sphere(0.5), position=(3.0, 0.5, 0.0))]
    bodies += [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(6.0, 0.5 + 1.0 * k, 0.0)) for k in range(3)]
    rest = np.array([b.position[1] for b in bodies])
    omega = 2.0 * math.pi * min(w.contact_hertz, 0.25 * 120.0)
    soft = np.array([1.0, 1.0, 3.0, 3.0 + 4.0, 3.0 + 4.0 + 2.0]) * G / omega ** 2 if solver != "lcp" else 0.0
    e0 = sum(b.mass * G * b.position[1] for b in bodies)
    for _ in range(int(round(20.0 / dt))):
        w.step(dt)
        heights = np.array([b.position[1] for b in bodies])
        assert np.all(heights > rest - soft - 1e-3)
        e = sum(b.mass * (G * b.position[1] + 0.5 * b.velocity @ b.velocity) for b in bodies)
        assert e <= e0 + sum(b.mass for b in bodies) * G * 1e-3


@pytest.mark.parametrize("dt", [0.5, 1.0])
def test_the_penalty_springs_hold_at_large_steps_as_their_stiffness_allows(dt):
    # The same scene with the penalty scheme: its springs, at most omega = 0.4 / h = 48 rad/s in sub-steps of
    # 1/120 s (dynamics/penalty.py), carry a load W on a contact level of effective mass m_n by a compression
    # W / (m_n omega^2): g / omega^2 = 4.3 mm for a body on the floor (m_n = m), 3 g / omega^2 for the stack's
    # bottom cube, 2 m g / ((m / 2) omega^2) more for the middle one (a box-box contact's m_n is m / 2) and
    # 2 g / omega^2 more for the top one.  It rests there (at most 10 % lower while it settles: the dashpots
    # of several contacts act on one body), never explodes (it reached 1e138 m/s at dt = 0.5 in 4 sub-steps)
    # and never gains energy.
    w = mb.World(solver="penalty")
    w.add_static(mb.Plane())
    bodies = [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0)),
              w.add_body(mb.Sphere(0.5), position=(3.0, 0.5, 0.0))]
    bodies += [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(6.0, 0.5 + 1.0 * k, 0.0)) for k in range(3)]
    rest = np.array([b.position[1] for b in bodies])
    omega = 0.4 * 120.0
    sink = np.array([1.0, 1.0, 3.0, 3.0 + 4.0, 3.0 + 4.0 + 2.0]) * G / omega ** 2
    e0 = sum(b.mass * G * b.position[1] for b in bodies)
    for _ in range(int(round(20.0 / dt))):
        w.step(dt)
        heights = np.array([b.position[1] for b in bodies])
        assert np.all(heights > rest - 1.1 * sink)
        e = sum(b.mass * (G * b.position[1] + 0.5 * b.velocity @ b.velocity) for b in bodies)
        assert e <= e0 + sum(b.mass for b in bodies) * G * 1e-3
    assert heights == pytest.approx(rest - sink, abs=2e-3)
