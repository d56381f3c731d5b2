"""The benchmark's peers: the axis mapping to z-up peers (bench/peers/axes.py) is one proper rotation, applied
alike to vectors and orientations; the peers in a process of their own (bench/peers/pipe.py) -- the WebAssembly
peers (bench/peers/wasm_world.py: Jolt and Rapier run by node, skipped where node or their npm packages cannot be
had) and native Jolt (bench/peers/jolt_native_world.py, skipped unless $MARBELLOUS_JOLT_SOURCE names a Jolt
checkout it can be built from, so in CI) -- drop spheres as the integrator says, rest them on the plane, build
every shape they translate, and time their own steps; native Jolt's build is keyed on what it is built from,
its JSON reader reads what Python writes, and its two-thread peer runs two threads."""
import json
import os
import subprocess

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

import marbellous as mb
from bench.peers import JOLT_NATIVE, Unsupported, jolt_build, make_peer, version
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
def native_jolt():
    """Native Jolt's driver (built on first use from the checkout $MARBELLOUS_JOLT_SOURCE names), or the test
    skipped saying why not: no checkout named (CI), CMake or a compiler missing, or the build failed."""
    try:
        return jolt_build.driver_and_version()[0]
    except ImportError as e:
        pytest.skip(str(e))


@pytest.fixture(params=WASM_PEERS + JOLT_NATIVE)
def piped(request, monkeypatch):
    """The name of a peer in a process of its own, once it can be had, or the test skipped saying what is missing.
    Node compiles the WebAssembly engines lazily here: the benchmark's compiling of the whole engine up front
    takes seconds a start and changes no result."""
    name = request.param
    if name in JOLT_NATIVE:
        request.getfixturevalue("native_jolt")
        return name
    from bench.peers import wasm_world
    from bench.peers.npm_cache import node_and_prefix
    try:
        node_and_prefix()
    except ImportError as e:
        pytest.skip(str(e))
    monkeypatch.setattr(wasm_world, "NODE_FLAGS", ("--expose-gc",))
    return name


def test_a_piped_peer_drops_spheres_as_the_integrator_says_and_rests_them_on_the_plane(piped):
    name = piped
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


def test_a_piped_peer_builds_every_shape_it_translates(piped):
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
    run = make_peer(piped, world, DT)
    try:
        steps_timed(run, 90)
        p = run.positions()
        assert p.shape == (4, 3) and np.all(np.isfinite(p))
        assert np.all(p[:, 1] > 0.0) and np.all(p[:, 1] < 1.0)   # on the plane (the box, capsule, hull)
        assert abs(p[3, 1] - 0.75) < 0.025                        # on the mesh, 0.5 m above the plane
        assert run.max_penetration() < 0.03
    finally:
        run.close()


@pytest.mark.parametrize("name", ("rapier-wasm", "jolt-native"))
def test_a_piped_peer_refuses_what_it_cannot_translate_before_starting_its_engine(name, monkeypatch, tmp_path):
    monkeypatch.setenv(jolt_build.ENV, str(tmp_path))     # no Jolt there: nothing could be built or started
    world = mb.World()
    world.add_static(mb.HeightField(np.zeros((4, 4))))
    with pytest.raises(Unsupported, match="HeightField"):
        make_peer(name, world, DT)


def test_a_piped_peer_stops_stepping_past_its_time_budget(piped):
    world = mb.World()
    world.add_body(mb.Sphere(0.5))
    run = make_peer(piped, world, DT)
    try:
        seconds = run.timed_steps(1000, budget=0.0)
        assert len(seconds) == 1 and seconds[0] > 0.0
    finally:
        run.close()


def test_native_jolt_is_not_installed_without_a_checkout(monkeypatch, tmp_path):
    monkeypatch.delenv(jolt_build.ENV, raising=False)
    with pytest.raises(ImportError, match="no Jolt source"):
        jolt_build.driver_and_version()
    assert version("jolt-native") is None
    monkeypatch.setenv(jolt_build.ENV, str(tmp_path))
    with pytest.raises(ImportError, match="not a Jolt Physics checkout"):
        jolt_build.driver_and_version()
    assert version("jolt-native-2t") is None


def test_native_jolt_is_built_for_the_instruction_sets_the_cpu_has():
    zen4 = {"sse4_1", "sse4_2", "popcnt", "avx", "avx2", "bmi1", "abm", "f16c", "fma", "avx512f", "avx512vl",
            "avx512dq"}
    assert set(jolt_build.instruction_sets(zen4).values()) == {"ON"}
    no_512 = jolt_build.instruction_sets(zen4 - {"avx512vl"})
    assert no_512["USE_AVX512"] == "OFF" and no_512["USE_AVX2"] == "ON"
    old = jolt_build.instruction_sets({"sse4_1", "sse4_2", "popcnt"})
    assert [k for k, v in old.items() if v == "ON"] == ["USE_SSE4_1", "USE_SSE4_2"]
    assert jolt_build.instruction_sets(None) == {}            # unknown CPU: Jolt's defaults


def test_native_jolt_builds_anew_when_its_source_its_options_or_its_compiler_change(tmp_path):
    for d in ("Jolt", "Build"):
        (tmp_path / d).mkdir()
    (tmp_path / "Jolt" / "Jolt.h").write_text("// 1\n")
    (tmp_path / "Build" / "CMakeLists.txt").write_text("project(JoltPhysics VERSION 5.5.1 LANGUAGES CXX)\n")
    assert jolt_build.checkout_problem(str(tmp_path)) is None
    assert jolt_build.jolt_version(str(tmp_path)) == "5.5.1"         # not a git checkout: no commit
    options, compiler = {"USE_AVX2": "ON"}, ("c++", "g++ 12.2.0")
    key = jolt_build.build_key(str(tmp_path), options, compiler)
    assert key == jolt_build.build_key(str(tmp_path), dict(options), compiler)
    assert key != jolt_build.build_key(str(tmp_path), {"USE_AVX2": "OFF"}, compiler)
    assert key != jolt_build.build_key(str(tmp_path), options, ("c++", "g++ 13.1.0"))
    (tmp_path / "Jolt" / "Jolt.h").write_text("// 2, longer\n")
    assert key != jolt_build.build_key(str(tmp_path), options, compiler)


def test_native_jolt_reads_the_json_python_writes_and_answers_a_bad_request_with_an_error(native_jolt):
    value = {"a": [1, -2.5e-3, 1e300, -0.0, "x\"y\\é中\n\t/"], "b": [], "c": [{"d": None}, 3, True, False],
             "nested": [[1, 2], [3]], "": {}}
    lines = [json.dumps({"op": "echo", "value": value}), json.dumps({"op": "echo", "value": float("nan")}),
             '  {"op" :"echo","value":[ 1 ,2 ] }  ', json.dumps({"op": "bogus"}),
             json.dumps({"op": "echo", "value": 1})]
    r = subprocess.run([native_jolt], input="\n".join(lines) + "\n", capture_output=True, text=True, timeout=60)
    answers = [json.loads(line) for line in r.stdout.splitlines()]
    assert answers[:3] == [{"value": value}, {"value": None}, {"value": [1, 2]}]
    assert answers[3:] == [{"error": "unknown op bogus"}] and r.returncode == 1      # it stops at an error
    for bad, message in (('{"op": "echo", "value": [1, 2}', "bad JSON at character 29: expected ']'"),
                         ('{"op": "echo"}', 'missing "value"'),
                         ('{"op": "echo", "value": tru}', "bad JSON at character 24: expected a value"),
                         ('{"op": "build", "dt": 0.1, "gravity": [0, 1], "shapes": [], "bodies": []}',
                          "expected 3 numbers")):
        r = subprocess.run([native_jolt], input=bad + "\n", capture_output=True, text=True, timeout=60)
        assert json.loads(r.stdout) == {"error": message} and r.returncode == 1


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="counts threads in /proc")
@pytest.mark.parametrize("name, threads", [("jolt-native", 1), ("jolt-native-2t", 2)])
def test_native_jolt_steps_with_as_many_threads_as_its_name_says(name, threads, native_jolt):
    world = mb.World()
    world.add_static(mb.Plane())
    for k in range(20):
        world.add_body(mb.Sphere(0.5), position=(0.0, 0.5 + 1.01 * k, 0.0))
    run = make_peer(name, world, DT)
    try:
        steps_timed(run, 10)
        assert len(os.listdir(f"/proc/{run._proc.pid}/task")) == threads
    finally:
        run.close()
