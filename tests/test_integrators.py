"""Integrators against closed forms: free fall, projectile, Hooke's oscillator, orders of accuracy, energy."""
import math

import numpy as np
import pytest

import marbellous as mb

G = 9.81
INTEGRATORS = ["explicit_euler", "semi_implicit_euler", "verlet", "rk4"]


def falling_ball(integrator, v0=(0.0, 0.0, 0.0)):
    w = mb.World(integrator=integrator, substeps=1)
    b = w.add_body(mb.Sphere(0.5), position=(0.0, 100.0, 0.0), velocity=v0)
    return w, b


@pytest.mark.parametrize("integrator", ["verlet", "rk4"])
def test_free_fall_is_exact_for_second_order_methods(integrator):
    # Constant acceleration: y(t) = y0 - g t^2 / 2 is reproduced exactly by Verlet and RK4.
    w, b = falling_ball(integrator)
    h = 1.0 / 60.0
    for _ in range(120):
        w.step(h)
    t = w.time
    assert b.position[1] == pytest.approx(100.0 - 0.5 * G * t * t, abs=1e-9)


def test_free_fall_semi_implicit_matches_its_discrete_solution():
    # v_n = -g h n, y_n = y0 - g h^2 n (n + 1) / 2: first order, error g h t / 2 below the exact curve.
    w, b = falling_ball("semi_implicit_euler")
    h, n = 1.0 / 60.0, 120
    for _ in range(n):
        w.step(h)
    assert b.position[1] == pytest.approx(100.0 - G * h * h * n * (n + 1) / 2.0, abs=1e-9)
    assert b.velocity[1] == pytest.approx(-G * h * n, abs=1e-9)


def test_free_fall_explicit_euler_matches_its_discrete_solution():
    # x uses the old velocity: y_n = y0 - g h^2 n (n - 1) / 2.
    w, b = falling_ball("explicit_euler")
    h, n = 1.0 / 60.0, 120
    for _ in range(n):
        w.step(h)
    assert b.position[1] == pytest.approx(100.0 - G * h * h * n * (n - 1) / 2.0, abs=1e-9)


@pytest.mark.parametrize("integrator", ["verlet", "rk4"])
def test_projectile_follows_the_parabola(integrator):
    v0 = np.array([3.0, 7.0, -2.0])
    w, b = falling_ball(integrator, v0)
    for _ in range(90):
        w.step(1.0 / 90.0)
    t = w.time
    expected = np.array([0.0, 100.0, 0.0]) + v0 * t + 0.5 * np.array([0.0, -G, 0.0]) * t * t
    np.testing.assert_allclose(b.position, expected, atol=1e-9)


def oscillator(integrator, h, t_end, k=100.0, m=2.0, x0=0.3, rest=1.0):
    """Mass on a spring to a world anchor, no gravity: x(t) = x0 cos(omega t), omega = sqrt(k/m).

    The spring stays linear while the amplitude is below its ``rest`` length.
    """
    w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator, substeps=1)
    b = w.add_body(mb.Sphere(0.1), mass=m, position=(rest + x0, 0.0, 0.0))
    w.add_spring(b, None, rest_length=rest, stiffness=k)
    xs, vs = [], []
    n = int(round(t_end / h))
    for _ in range(n):
        w.step(h)
        xs.append(b.position[0] - rest)
        vs.append(b.velocity[0])
    return np.array(xs), np.array(vs), w.time


def test_hooke_period_rk4():
    # Period 2 pi sqrt(m/k), measured from upward zero crossings of the displacement.
    k, m, h = 100.0, 2.0, 1.0 / 240.0
    xs, _, _ = oscillator("rk4", h, 3.0, k=k, m=m)
    t = (np.arange(len(xs)) + 1) * h
    idx = np.where((xs[:-1] < 0) & (xs[1:] >= 0))[0]
    crossings = t[idx] - h * xs[idx] / (xs[idx + 1] - xs[idx]) + h
    period = np.diff(crossings).mean()
    # Linear interpolation of zero crossings is accurate to O(omega^2 h^2) of the step: ~1e-4 relative here.
    assert period == pytest.approx(2 * math.pi * math.sqrt(m / k), rel=2e-4)


def test_hooke_period_semi_implicit_matches_the_discrete_frequency():
    # Symplectic Euler rotates phase space by theta per step with cos(theta) = 1 - (omega h)^2 / 2.
    k, m, h = 100.0, 2.0, 1.0 / 60.0
    omega = math.sqrt(k / m)
    theta = math.acos(1.0 - (omega * h) ** 2 / 2.0)
    xs, _, _ = oscillator("semi_implicit_euler", h, 6.0, k=k, m=m)
    t = (np.arange(len(xs)) + 1) * h
    idx = np.where((xs[:-1] < 0) & (xs[1:] >= 0))[0]
    crossings = t[idx] - h * xs[idx] / (xs[idx + 1] - xs[idx])
    assert np.diff(crossings).mean() == pytest.approx(2 * math.pi * h / theta, rel=2e-3)


@pytest.mark.parametrize("integrator,order", [("explicit_euler", 1), ("semi_implicit_euler", 1),
                                              ("verlet", 2), ("rk4", 4)])
def test_order_of_accuracy(integrator, order):
    # Halving h divides the global error at a fixed time by about 2^order.
    k, m, x0, t_end = 100.0, 2.0, 0.3, 1.0
    omega = math.sqrt(k / m)
    errors = []
    for h in (1.0 / 200.0, 1.0 / 400.0, 1.0 / 800.0):
        xs, _, t = oscillator(integrator, h, t_end, k=k, m=m, x0=x0)
        errors.append(abs(xs[-1] - x0 * math.cos(omega * t)))
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    for r in ratios:
        assert 2 ** order * 0.8 < r < 2 ** order * 1.25, (errors, ratios)


def energy(xs, vs, k=100.0, m=2.0):
    return 0.5 * m * vs ** 2 + 0.5 * k * xs ** 2


def test_explicit_euler_gains_energy_and_symplectic_methods_do_not():
    k, m, x0, h = 100.0, 2.0, 0.3, 1.0 / 60.0
    omega_h = math.sqrt(k / m) * h
    e0 = 0.5 * k * x0 ** 2
    xs, vs, _ = oscillator("explicit_euler", h, 15.0, rest=1e3)
    e = energy(xs, vs)
    # Each explicit step multiplies the energy by exactly 1 + (omega h)^2.
    assert e[-1] / e0 == pytest.approx((1 + omega_h ** 2) ** len(e), rel=1e-5)
    assert e[-1] > 10 * e0
    for name in ("semi_implicit_euler", "verlet"):
        xs, vs, _ = oscillator(name, h, 20.0)
        e = energy(xs, vs)
        # Bounded: the modified energy of the symplectic map differs from E by O(omega h).
        assert np.max(np.abs(e / e0 - 1.0)) < omega_h, name


def test_rk4_reevaluates_springs_at_its_stages():
    # A stiff spring over a coarse step: a method that froze the spring force over the step would be
    # only first order; RK4's one-step error must be O(h^5).
    k, m, x0 = 100.0, 2.0, 0.3
    omega = math.sqrt(k / m)
    errs = []
    for h in (0.02, 0.01):
        xs, _, _ = oscillator("rk4", h, h, k=k, m=m, x0=x0)
        errs.append(abs(xs[0] - x0 * math.cos(omega * h)))
    assert errs[0] / errs[1] > 25.0
