"""The benchmark's peers: the axis mapping to z-up peers (bench/peers/axes.py) is one proper rotation, applied
alike to vectors and orientations; the WebAssembly peers (bench/peers/wasm_world.py: Jolt and Rapier run by
node, skipped where node or their npm packages cannot be had) drop spheres as the integrator says, rest them on
the plane, build every shape they translate, and time their own steps."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

import marbellous as mb
from bench.peers import Unsupported, make_peer, version
from bench.peers.axes import R, from_peer, quat_to_peer, to_peer
from bench.runs import steps_timed
from bench.scenes import DT
from marbellous.math3d import quat_to_matrix_np

WASM_PEERS = ("jolt-wasm", "rapier-wasm")

finite = hst.floats(-10.0, 10.0)


def test_y_up_becomes_z_up():
    assert np.allclose(to_peer([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0])
    assert np.allclose(R @ R.T, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)


@settings(max_examples=200, deadline=None)
@given(hst.tuples(finite, finite, finite))
def test_vectors_round_trip(v):
    assert np.allclose(from_peer(to_peer(v)), v)


@settings(max_examples=200, deadline=None)
@given(hst.tuples(finite, finite, finite, finite).filter(lambda q: np.linalg.norm(q) > 1e-3))
def test_orientations_turn_with_the_axes(q):
    q = np.array(q) / np.linalg.norm(q)
    assert np.allclose(quat_to_matrix_np(quat_to_peer(q)), R @ quat_to_matrix_np(q), atol=1e-12)


@pytest.fixture
def wasm_peers(monkeypatch):
    """Node and the peers' npm packages (installed on first use), or the test skipped saying which is missing.
    Node compiles the engines lazily here: the benchmark's compiling of the whole engine up front takes seconds
    a start and changes no result."""
    from bench.peers import wasm_world
    from bench.peers.npm_cache import node_and_prefix
    try:
        node_and_prefix()
    except ImportError as e:
        pytest.skip(str(e))
    monkeypatch.setattr(wasm_world, "NODE_FLAGS", ("--expose-gc",))


@pytest.mark.parametrize("name", WASM_PEERS)
def test_a_wasm_peer_drops_spheres_as_the_integrator_says_and_rests_them_on_the_plane(name, wasm_peers):
    radius, heights, g = 0.5, np.array([2.0, 3.0, 4.0]), 9.81
    world = mb.World()
    world.add_static(mb.Plane())
    for k, y in enumerate(heights):
        world.add_body(mb.Sphere(radius), position=(2.0 * k, y, 0.0))
    run = make_peer(name, world, DT)
    try:
        assert run.version == version(name)
        n = 20                          # 1/3 s: the lowest sphere is still 0.95 m above the plane
        done, seconds = steps_timed(run, n)
        assert done == n and seconds > 0.0
        t = n * DT
        drop = heights - run.positions()[:, 1]
        # a first-order integrator at step h is off the closed form by at most g t h / 2; float32 positions
        assert np.all(np.abs(drop - g * t * t / 2.0) <= g * t * DT / 2.0 + 1e-4)
        assert np.allclose(run.positions()[:, [0, 2]], [[0.0, 0.0], [2.0, 0.0], [4.0, 0.0]], atol=1e-5)
        steps_timed(run, 100)           # 2 s: the highest sphere landed at 0.85 s
        before = run.positions()
        run.step()
        after = run.positions()
        # resting on the plane, within Jolt's penetration slop of 2 cm
        assert np.all(np.abs(after[:, 1] - radius) < 0.025)
        assert np.all(np.linalg.norm(after - before, axis=1) / DT < 0.05)
        assert run.max_penetration() < 0.025
    finally:
        run.close()


@pytest.mark.parametrize("name", WASM_PEERS)
def test_a_wasm_peer_builds_every_shape_it_translates(name, wasm_peers):
    world = mb.World()
    world.add_static(mb.Plane())
    mesh = mb.TriangleMesh([[4.0, 0.5, -2.0], [8.0, 0.5, -2.0], [8.0, 0.5, 2.0], [4.0, 0.5, 2.0]],
                           [[0, 2, 1], [0, 3, 2]])
    world.add_static(mesh)
    world.add_body(mb.Box((0.5, 0.25, 0.5)), position=(0.0, 0.5, 0.0))
    world.add_body(mb.Capsule(0.25, 0.5), position=(2.0, 1.0, 0.0))
    world.add_body(mb.ConvexHull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float) - 0.25),
                   position=(-2.0, 1.0, 0.0))
    world.add_body(mb.Sphere(0.25), position=(6.0, 1.5, 0.0))
    run = make_peer(name, world, DT)
    try:
        steps_timed(run, 90)
        p = run.positions()
        assert p.shape == (4, 3) and np.all(np.isfinite(p))
        assert np.all(p[:, 1] > 0.0) and np.all(p[:, 1] < 1.0)   # on the plane (the box, capsule, hull)
        assert abs(p[3, 1] - 0.75) < 0.025                        # on the mesh, 0.5 m above the plane
        assert run.max_penetration() < 0.03
    finally:
        run.close()


def test_a_wasm_peer_refuses_what_it_cannot_translate_before_starting_node():
    world = mb.World()
    world.add_static(mb.HeightField(np.zeros((4, 4))))
    with pytest.raises(Unsupported, match="HeightField"):
        make_peer("rapier-wasm", world, DT)


@pytest.mark.parametrize("name", WASM_PEERS)
def test_a_wasm_peer_stops_stepping_past_its_time_budget(name, wasm_peers):
    world = mb.World()
    world.add_body(mb.Sphere(0.5))
    run = make_peer(name, world, DT)
    try:
        seconds = run.timed_steps(1000, budget=0.0)
        assert len(seconds) == 1 and seconds[0] > 0.0
    finally:
        run.close()
