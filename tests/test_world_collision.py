"""Collision inside the world: marbles on meshes and height fields, identical results for every
mesh acceleration and broad phase, ray casts."""
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.state import layout as L

DT = 1.0 / 60.0


def grid_mesh(n=40, half=10.0, height=None):
    """A square (2 half)^2 floor of 2 n^2 triangles; ``height(x, z)`` bends it (None: flat)."""
    xs = np.linspace(-half, half, n + 1)
    verts = np.array([[x, 0.0 if height is None else height(x, z), z] for x in xs for z in xs])
    tris = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            b, c = a + 1, a + n + 1
            tris += [[a, b, c + 1], [a, c + 1, c]]
    return verts, np.array(tris)


@pytest.mark.parametrize("accel", ["brute", "grid2d", "bvh"])
def test_marble_rolls_diagonally_across_a_flat_mesh_without_ghost_bumps(accel):
    verts, tris = grid_mesh()
    w = mb.World(sleeping=False)
    w.add_static(mb.TriangleMesh(verts, tris, accel=accel))
    r = 0.3
    ball = w.add_body(mb.Sphere(r), position=(-8, r, -8), velocity=(3, 0, 3), angular_velocity=(3 / r, 0, -3 / r))
    heights, sideways = [], []
    for _ in range(240):
        w.step(DT)
        heights.append(ball.position[1])
        sideways.append(ball.velocity[0] - ball.velocity[2])
    # It crosses ~16 triangle edges and vertices: it stays at its radius (within 1 %) and on its line.
    assert np.all(np.abs(np.array(heights) - r) < 0.01 * r)
    assert np.max(np.abs(sideways)) < 1e-9
    assert ball.position[0] == pytest.approx(ball.position[2], abs=1e-9)
    assert ball.position[0] > 3.0


def bumpy(x, z):
    return 0.3 * math.sin(0.7 * x) * math.cos(0.5 * z)


def run_bumpy(accel, broadphase="sap", steps=180):
    verts, tris = grid_mesh(30, 8.0, bumpy)
    w = mb.World(sleeping=False, broadphase=broadphase)
    w.add_static(mb.TriangleMesh(verts, tris, accel=accel), friction=0.7)
    balls = [w.add_body(mb.Sphere(0.25), position=(-5 + i, 1.5, -4 + 0.7 * i), velocity=(2, 0, 1.5),
                        friction=0.7) for i in range(5)]
    w.add_body(mb.Box((0.3, 0.2, 0.4)), position=(2, 1.5, 2), angular_velocity=(1, 2, 3))
    w.add_body(mb.Capsule(0.2, 0.4), position=(-2, 1.5, 3), orientation=(0.9, 0.3, 0.1, 0.2))
    for _ in range(steps):
        w.step(DT)
    return w, balls


def test_bumpy_mesh_trajectories_are_bit_identical_for_every_accel():
    states = []
    for accel in ("brute", "grid2d", "bvh"):
        w, balls = run_bumpy(accel)
        states.append(w._state.bf[:w._state.bodies.end].copy())
        # Everything is still on (or above) the terrain.
        for b in balls:
            assert b.position[1] > bumpy(b.position[0], b.position[2]) - 0.05
    assert np.array_equal(states[0], states[1])
    assert np.array_equal(states[0], states[2])


@pytest.mark.parametrize("broadphase", ["brute", "grid", "bvh", "octree", "kdtree", "bsp"])
def test_simulation_is_bit_identical_for_every_broad_phase(broadphase):
    ref, _ = run_bumpy("grid2d", "sap", steps=90)
    w, _ = run_bumpy("grid2d", broadphase, steps=90)
    assert np.array_equal(ref._state.bf[:ref._state.bodies.end], w._state.bf[:w._state.bodies.end])


def test_marble_comes_to_rest_on_a_height_field_and_agrees_with_height_at():
    n = 33
    xs = np.linspace(0.0, 16.0, n)
    heights = np.array([[0.5 * math.sin(0.4 * x) + 0.3 * math.cos(0.3 * z) for z in xs] for x in xs])
    hf = mb.HeightField(heights, spacing=(0.5, 0.5), origin=(-8.0, 0.0, -8.0))
    w = mb.World()
    w.add_static(hf, friction=0.8, rolling_friction=0.02)
    r = 0.25
    ball = w.add_body(mb.Sphere(r), position=(0.3, 2.0, -0.7), friction=0.8, rolling_friction=0.02)
    for _ in range(900):
        w.step(DT)
    x, y, z = ball.position
    assert np.linalg.norm(ball.velocity) < 0.05
    # Resting on the surface: the centre is r above it along the surface normal there (to a few mm).
    foot = ball.position - r * hf.normal_at(x, z)
    assert foot[1] == pytest.approx(hf.height_at(foot[0], foot[2]), abs=5e-3)


def test_raycast_finds_the_nearest_body_of_each_shape():
    verts, tris = grid_mesh(4, 2.0)
    w = mb.World()
    plane = w.add_static(mb.Plane(offset=-5.0))
    mesh = w.add_static(mb.TriangleMesh(verts, tris), position=(10, 0, 0))
    box = w.add_body(mb.Box((1, 1, 1)), position=(0, 3, 0))
    ball = w.add_body(mb.Sphere(0.5), position=(5, 1, 0))
    cap = w.add_body(mb.Capsule(0.5, 1.0), position=(-5, 0, 0))
    for origin, target, distance, normal in [((0, 10, 0), box, 6.0, (0, 1, 0)),
                                             ((5, 10, 0), ball, 8.5, (0, 1, 0)),
                                             ((-5, 10, 0), cap, 8.5, (0, 1, 0)),
                                             ((10.5, 10, 0.5), mesh, 10.0, (0, 1, 0)),
                                             ((20, 10, 0), plane, 15.0, (0, 1, 0))]:
        hit = w.raycast(origin, (0, -3, 0))
        assert hit.body is target
        assert hit.distance == pytest.approx(distance, abs=1e-12)
        np.testing.assert_allclose(hit.normal, normal, atol=1e-12)
        np.testing.assert_allclose(hit.point, np.array(origin) + (0, -distance, 0), atol=1e-12)
    assert w.raycast((20, 10, 0), (0, 1, 0)) is None
    assert w.raycast((20, 10, 0), (0, -1, 0), max_distance=14.0) is None
    with pytest.raises(ValueError, match="direction"):
        w.raycast((0, 0, 0), (0, 0, 0))


def test_contacts_keep_features_across_steps():
    # A box resting inside one triangle of a mesh keeps the same contact features, so impulses are
    # warm-started.  (Over shared edges a corner can change triangle, and with it its feature id.)
    verts, tris = grid_mesh(8, 4.0)
    w = mb.World(sleeping=False)
    w.add_static(mb.TriangleMesh(verts, tris))
    w.add_body(mb.Box((0.1, 0.05, 0.1)), position=(0.7, 0.05, 0.25))
    for _ in range(60):
        w.step(DT)
    n = w._state.n_cached
    assert n == 4
    assert np.all(w._state.cache_i[:n, L.C_FLAGS] & L.CP_MATCHED)
