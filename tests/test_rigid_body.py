"""Mass properties, torque, and torque-free rotation conserving angular momentum."""
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.math3d import quat_to_matrix_np


def voxel_inertia(inside, half, n=160):
    """Slow reference: mass and inertia of a unit-density solid by midpoint voxel integration."""
    g = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y, z = np.meshgrid(g * half[0], g * half[1], g * half[2], indexing="ij")
    mask = inside(x, y, z)
    dv = 8.0 * half[0] * half[1] * half[2] / n ** 3
    m = mask.sum() * dv
    pts = np.stack([x[mask], y[mask], z[mask]], axis=1)
    r2 = (pts ** 2).sum(axis=1)
    inertia = (np.eye(3) * r2.sum() - pts.T @ pts) * dv
    return m, inertia


def test_box_inertia_closed_form():
    m, inertia = mb.Box((0.5, 1.0, 1.5)).mass_properties(2.0)
    assert m == pytest.approx(2.0 * 1.0 * 2.0 * 3.0)
    a, b, c = 1.0, 2.0, 3.0
    np.testing.assert_allclose(np.diag(inertia), [m / 12 * (b * b + c * c), m / 12 * (a * a + c * c),
                                                  m / 12 * (a * a + b * b)])


def test_capsule_inertia_against_voxel_integration():
    r, hh = 0.4, 0.7
    cap = mb.Capsule(r, hh)

    def inside(x, y, z):
        yc = np.clip(y, -hh, hh)
        return x * x + (y - yc) ** 2 + z * z <= r * r

    m_ref, i_ref = voxel_inertia(inside, (r, hh + r, r))
    m, inertia = cap.mass_properties(1.0)
    # Midpoint voxels of size ~0.01 m resolve a 0.4 m radius to ~0.5 %.
    assert m == pytest.approx(m_ref, rel=5e-3)
    np.testing.assert_allclose(inertia, i_ref, rtol=1e-2, atol=1e-4 * np.abs(i_ref).max())


def test_sphere_inertia_matches_lecture():
    m, inertia = mb.Sphere(0.5).mass_properties(1000.0)
    np.testing.assert_allclose(inertia, np.eye(3) * 0.4 * m * 0.25)


def test_compound_parallel_axis():
    w = mb.World(gravity=(0, 0, 0))
    s = mb.Sphere(0.2)
    d = 1.0
    b = w.add_body([(s, (-d, 0, 0)), (s, (d, 0, 0))], position=(0, 0, 0))
    m1, i1 = s.mass_properties(1000.0)
    assert b.mass == pytest.approx(2 * m1)
    np.testing.assert_allclose(b.inertia, np.diag([2 * i1[0, 0], 2 * (i1[1, 1] + m1 * d * d),
                                                   2 * (i1[2, 2] + m1 * d * d)]))


def test_compound_centre_of_mass_is_the_body_origin():
    w = mb.World(gravity=(0, 0, 0))
    b = w.add_body([(mb.Sphere(0.5), (1.0, 0, 0)), (mb.Sphere(0.5), (3.0, 0, 0))], position=(0, 0, 0))
    local = [p for _, p, _ in b.shapes]
    np.testing.assert_allclose(local[0], [-1.0, 0, 0])
    np.testing.assert_allclose(local[1], [1.0, 0, 0])


def test_mass_argument_scales_inertia():
    w = mb.World()
    b = w.add_body(mb.Box((1, 2, 3)), mass=6.0)
    assert b.mass == 6.0
    np.testing.assert_allclose(np.diag(b.inertia), [6 / 3 * (4 + 9), 6 / 3 * (1 + 9), 6 / 3 * (1 + 4)])


def test_off_centre_force_gives_torque():
    # torque = p x f; for one semi-implicit step from rest: domega = I^-1 (r x F) h, dv = F/m h.
    w = mb.World(gravity=(0, 0, 0), substeps=1)
    b = w.add_body(mb.Box((0.5, 0.5, 0.5)), mass=3.0)
    f = np.array([0.0, 0.0, 6.0])
    p = np.array([0.5, 0.0, 0.0])
    b.apply_force(f, point=p)
    h = 0.01
    w.step(h)
    inertia = 3.0 / 3.0 * 0.5
    np.testing.assert_allclose(b.velocity, f / 3.0 * h, atol=1e-15)
    np.testing.assert_allclose(b.angular_velocity, np.cross(p, f) / inertia * h, atol=1e-12)
    # The force lasts one step only.
    w.step(h)
    np.testing.assert_allclose(b.velocity, f / 3.0 * h, atol=1e-15)


def test_force_through_centre_gives_no_torque():
    w = mb.World(gravity=(0, 0, 0))
    b = w.add_body(mb.Box((0.5, 0.2, 0.3)))
    b.apply_force((1.0, 2.0, 0.0), point=b.position + np.array([0.5, 1.0, 0.0]))
    w.step(0.01)
    np.testing.assert_allclose(b.angular_velocity, 0.0, atol=1e-15)


def test_apply_impulse_changes_momentum_at_once():
    w = mb.World(gravity=(0, 0, 0))
    b = w.add_body(mb.Sphere(0.5), mass=2.0)
    b.apply_impulse((4.0, 0.0, 0.0), point=(0.0, 0.5, 0.0))
    np.testing.assert_allclose(b.velocity, [2.0, 0, 0])
    inertia = 0.4 * 2.0 * 0.25
    np.testing.assert_allclose(b.angular_velocity, np.cross([0, 0.5, 0], [4.0, 0, 0]) / inertia)


def angular_momentum(b):
    return b.inertia @ b.angular_velocity


def kinetic_rot(b):
    return 0.5 * b.angular_velocity @ b.inertia @ b.angular_velocity


@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "verlet", "rk4"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_torque_free_rotation_conserves_angular_momentum(integrator, axis):
    # Box with three different moments; spin about each principal axis with a small perturbation
    # (axis 1, the intermediate one, is unstable and flips: the Dzhanibekov effect). 10 s at 120 Hz.
    w = mb.World(gravity=(0, 0, 0), integrator=integrator)
    omega = np.full(3, 0.05)
    omega[axis] = 6.0
    b = w.add_body(mb.Box((0.6, 0.35, 0.1)), angular_velocity=omega)
    l0 = angular_momentum(b)
    e0 = kinetic_rot(b)
    worst = 0.0
    for _ in range(1200):
        w.step(1.0 / 120.0)
        worst = max(worst, np.linalg.norm(angular_momentum(b) - l0) / np.linalg.norm(l0))
    assert worst < 1e-2
    if integrator != "rk4":
        # Momentum-conserving rotation keeps L to round-off.
        assert worst < 1e-9
    assert kinetic_rot(b) == pytest.approx(e0, rel=2e-2)
    np.testing.assert_allclose(np.linalg.norm(b.orientation), 1.0, atol=1e-12)


def test_intermediate_axis_flips():
    # The Dzhanibekov effect: spinning about the intermediate axis is unstable, the body turns over.
    w = mb.World(gravity=(0, 0, 0))
    b = w.add_body(mb.Box((0.6, 0.35, 0.1)), angular_velocity=(0.01, 6.0, 0.0))
    ys = []
    for _ in range(1200):
        w.step(1.0 / 120.0)
        ys.append(quat_to_matrix_np(b.orientation)[:, 1] @ np.array([0.0, 1.0, 0.0]))
    assert min(ys) < -0.9  # the body's y axis points down at some time


def test_orientation_stays_unit_under_fast_spin():
    w = mb.World(gravity=(0, 0, 0), integrator="explicit_euler")
    b = w.add_body(mb.Box((0.3, 0.2, 0.1)), angular_velocity=(30.0, 20.0, 10.0))
    for _ in range(500):
        w.step(1.0 / 60.0)
    assert np.linalg.norm(b.orientation) == pytest.approx(1.0, abs=1e-12)
    assert math.isfinite(b.angular_velocity.sum())
