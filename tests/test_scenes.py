"""The terrain and free-body scenes: their geometry against slow references, and their physics
against closed forms (small sizes; the benchmark runs the full ones)."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as hst

import marbellous as mb
from marbellous.scenes.free_bodies import free_bodies, free_bodies_start, free_fall_positions
from marbellous.scenes.terrain import marble_on_terrain, terrain_arrays, terrain_height

CELLS = 16
SPACING = 0.5


def _reference_height(x, z, vertices, triangles):
    """Height of the triangle whose x-z projection holds (x, z), by testing every triangle."""
    for tri in triangles:
        a, b, c = vertices[tri]
        d = (b[2] - c[2]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[2] - c[2])
        u = ((b[2] - c[2]) * (x - c[0]) + (c[0] - b[0]) * (z - c[2])) / d
        v = ((c[2] - a[2]) * (x - c[0]) + (a[0] - c[0]) * (z - c[2])) / d
        w = 1.0 - u - v
        if min(u, v, w) >= -1e-12:
            return u * a[1] + v * b[1] + w * c[1]
    raise AssertionError("point outside the terrain")


def test_terrain_triangles_face_up_and_count():
    v, t = terrain_arrays(CELLS, SPACING)
    assert t.shape == (2 * CELLS * CELLS, 3)
    assert v.shape == ((CELLS + 1) ** 2, 3)
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    assert np.all(n[:, 1] > 0.0)
    # every triangle's x-z area is half a cell: the grid is covered once
    assert np.allclose(n[:, 1], SPACING * SPACING)


def test_default_terrain_has_131072_triangles():
    _, t = terrain_arrays()
    assert t.shape[0] == 131072


@settings(max_examples=200, deadline=None)
@given(hst.floats(-3.99, 3.99), hst.floats(-3.99, 3.99))
def test_terrain_height_matches_the_triangles(x, z):
    v, t = terrain_arrays(CELLS, SPACING)
    assert math.isclose(terrain_height(x, z, CELLS, SPACING), _reference_height(x, z, v, t), abs_tol=1e-9)


def test_marble_rolls_on_the_terrain():
    """The marble stays on the surface (never sinks, hops less than a few cm) and rolls downhill."""
    w, (terrain, marble) = marble_on_terrain(cells=32, spacing=SPACING)
    r = marble.shapes[0][0].radius
    start = marble.position
    for _ in range(240):
        w.step(1.0 / 60.0)
        p = marble.position
        gap = p[1] - terrain_height(p[0], p[2], 32, SPACING) - r
        assert -0.01 * r < gap < 0.05
        assert abs(p[0]) < 8.0 and abs(p[2]) < 8.0
    assert np.linalg.norm(marble.position - start) > 2.0
    # rolling, not sliding: the contact point is at rest, v = omega x (r n) with n the surface normal
    v, omega = marble.velocity, marble.angular_velocity
    assert np.linalg.norm(v + np.cross(omega, np.array([0.0, -r, 0.0]))) < 0.1 * np.linalg.norm(v) + 0.05


def test_free_bodies_fall_as_semi_implicit_euler_says():
    """x_n = x0 + v0 t + g t^2/2 + g h t/2 exactly for semi-implicit Euler with sub-step h (no contacts)."""
    count = 27
    w, spheres = free_bodies(count=count)
    p0, v0 = free_bodies_start(count)
    dt, steps = 1.0 / 60.0, 90
    for _ in range(steps):
        w.step(dt)
    t = steps * dt
    h = dt / w.substeps
    g = w.gravity
    expected = free_fall_positions(p0, v0, g, t) + 0.5 * g * h * t
    got = np.array([s.position for s in spheres])
    assert np.allclose(got, expected, rtol=0.0, atol=1e-6)
    assert w.contacts() == []


def test_free_bodies_start_apart():
    p, v = free_bodies_start(1000, spacing=2.0)
    d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)
    np.fill_diagonal(d, np.inf)
    assert d.min() == 2.0
    assert np.all(np.abs(v) <= 0.5)


def test_scenes_take_a_world():
    w = mb.World(substeps=2)
    w2, _ = free_bodies(w, count=8)
    assert w2 is w and len(w.bodies) == 8
