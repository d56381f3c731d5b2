"""A Marbellous world in a WebAssembly engine run by node: Jolt Physics (``jolt-wasm``) or Rapier (``rapier-wasm``).

The world's bodies (``bodies_of``) are sent once, as one JSON line, to a node process running
``bench/peers/wasm/driver.mjs`` with the engine's backend (``jolt.mjs``, ``rapier.mjs``: each engine's
settings are listed there), which answers every request with one JSON line (the protocol is described in
``driver.mjs``).  The packages come from ``npm_cache``, installed on first use.

- Both engines are y-up like Marbellous: positions, orientations and velocities go across unchanged.
- Spheres, boxes, capsules, planes, triangle meshes (static) and convex hulls; compound bodies, shapes off
  their body's origin and height fields raise ``Unsupported``.
- Each body keeps its mass (the engine computes the inertia from the shape), friction and restitution,
  combined as Marbellous combines them: friction by geometric mean (Jolt's own rule; Rapier's colliders get
  ``sqrt(mu)`` under its "multiply" rule, as PyBullet's bodies do), restitution by maximum.  Neither engine
  has rolling or torsional friction: those lever arms are dropped, so the piles' spheres roll freely.
- No damping, as in Marbellous, and Jolt's cap on linear speed (500 m/s) lifted.  Rapier holds linear speed
  to 400 m/s times its length unit (1 m) and has no setting for it (a larger length unit would scale its
  contact and sleep tolerances too): the one-body scene's body, falling for 333 s, is held at 400 m/s from
  41 s on and fails its check there.  Each engine's defaults otherwise (solver iterations, sleeping, contact
  margins), one engine step per ``dt``.
- ``max_penetration`` is each engine's own contact query at the current poses, outside the clock.
- Steps are timed inside node (``performance.now()`` around each engine step), not from Python: a request
  through the pipe costs more than a small scene's whole step.  ``timed_steps`` returns those times, and
  ``bench.runs.timed_run`` counts them instead of its own clock.  Nothing is compiled while steps are timed:
  node compiles the whole engine when it loads it (``NODE_FLAGS``), and each engine steps a small scene of
  every shape (``driver.mjs``) before the scene is built, as the benchmark's warm-up compiles Marbellous'
  kernels before it times them.
"""
import json
import os
import subprocess
import tempfile

import numpy as np

from marbellous.shapes.hull import ConvexHull
from marbellous.shapes.mesh import TriangleMesh
from marbellous.shapes.primitives import Box, Capsule, Plane, Sphere

from . import Unsupported, bodies_of, single_shape
from .npm_cache import node_and_prefix

#: the node side: one engine behind line-delimited JSON
DRIVER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "wasm", "driver.mjs")
#: node's options: V8 compiles the engine's whole WebAssembly module with its optimising compiler when it loads
#: it (1.5 s for Jolt, 3.5 s for Rapier, before anything is timed) rather than function by function and again
#: once hot, on another thread, while steps are timed; ``gc()`` for the driver, which collects the build's
#: garbage before the steps
NODE_FLAGS = ("--no-liftoff", "--no-wasm-lazy-compilation", "--expose-gc")
#: seconds a closing engine is given to exit before it is killed
CLOSE_TIMEOUT = 10.0


def _shape(shape):
    """``(key, spec)``: the JSON-ready description of ``shape`` and a key equal for equal shapes."""
    if isinstance(shape, Sphere):
        spec = {"kind": "sphere", "radius": shape.radius}
    elif isinstance(shape, Box):
        spec = {"kind": "box", "half_extents": np.asarray(shape.half_extents, dtype=float).tolist()}
    elif isinstance(shape, Capsule):
        spec = {"kind": "capsule", "radius": shape.radius, "half_height": shape.half_height}
    elif isinstance(shape, Plane):
        spec = {"kind": "plane", "normal": shape.normal.tolist(), "offset": shape.offset}
    elif isinstance(shape, TriangleMesh):
        return ("mesh", id(shape)), {"kind": "mesh", "vertices": shape.vertices.ravel().tolist(),
                                     "triangles": shape.triangles.ravel().tolist()}
    elif isinstance(shape, ConvexHull):
        return ("hull", id(shape)), {"kind": "hull", "points": shape.vertices.ravel().tolist()}
    else:
        raise Unsupported(type(shape).__name__)
    return json.dumps(spec), spec


def build_request(world, dt):
    """The ``build`` request for ``world`` stepped ``dt`` s at a time: gravity (m/s^2), the distinct shapes,
    and per body its shape's index, ``static``, position (m), orientation (w, x, y, z), velocity (m/s),
    angular velocity (rad/s), mass (kg), friction and restitution.  Raises ``Unsupported``."""
    shapes, index, bodies = [], {}, []
    for rec in bodies_of(world):
        key, spec = _shape(single_shape(rec))
        if key not in index:
            index[key] = len(shapes)
            shapes.append(spec)
        static = bool(rec["static"])
        bodies.append({"shape": index[key], "static": static, "position": np.asarray(rec["position"]).tolist(),
                       "orientation": np.asarray(rec["orientation"]).tolist(),
                       "velocity": np.asarray(rec["velocity"]).tolist(),
                       "angular_velocity": np.asarray(rec["angular_velocity"]).tolist(),
                       "mass": 0.0 if static else float(rec["mass"]), "friction": rec["friction"],
                       "restitution": rec["restitution"]})
    return {"op": "build", "dt": float(dt), "gravity": np.asarray(world.gravity, dtype=float).tolist(),
            "shapes": shapes, "bodies": bodies}


class WasmRun:
    """``world`` built in a node process running one WebAssembly engine, stepped ``dt`` s at a time.
    ``version`` is the engine package's version as the engine reports it."""

    #: the peer's name in the benchmark, its backend in ``driver.mjs`` and its npm package
    name = backend = package = None

    def __init__(self, world, dt):
        request = build_request(world, dt)
        node, prefix = node_and_prefix()
        self._stderr = tempfile.TemporaryFile()
        self._proc = subprocess.Popen([node, *NODE_FLAGS, DRIVER, self.backend, prefix], stdin=subprocess.PIPE,
                                      stdout=subprocess.PIPE, stderr=self._stderr, text=True)
        try:
            self.version = self._ask(request)["version"]
        except BaseException:
            self.close()
            raise

    def _ask(self, request):
        """Send one request, return its answer; raises RuntimeError with the engine's message (and what it
        printed) when it failed or stopped."""
        try:
            self._proc.stdin.write(json.dumps(request) + "\n")
            self._proc.stdin.flush()
            line = self._proc.stdout.readline()
        except OSError:
            line = ""
        try:
            reply = json.loads(line) if line else {"error": "node stopped"}
        except ValueError:         # something else wrote to node's standard output: the driver cannot go on
            self._proc.kill()
            reply = {"error": f"not an answer: {line[:200]!r}"}
        if "error" in reply:
            self._wait()
            self._stderr.seek(0)
            printed = " ".join(self._stderr.read().decode(errors="replace").split())[-400:]
            raise RuntimeError(f"{self.name} failed: {reply['error']}" + (f" ({printed})" if printed else ""))
        return reply

    def timed_steps(self, n, budget=None):
        """Step ``n`` times, stopping early once the steps have taken more than ``budget`` seconds (None:
        no limit): the seconds each step took, timed inside node around the engine's step alone."""
        return self._ask({"op": "step", "n": int(n), "budget": budget})["seconds"]

    def step(self):
        self.timed_steps(1)

    def positions(self):
        """Positions (m) of the dynamic bodies, shape (n, 3)."""
        return np.array(self._ask({"op": "positions"})["positions"], dtype=np.float64).reshape(-1, 3)

    def max_penetration(self):
        """Deepest overlap (m) among the current contacts (0 if none overlap), as the engine measures it."""
        return float(self._ask({"op": "penetration"})["depth"])

    def _wait(self):
        """Wait for node to exit, killing it after ``CLOSE_TIMEOUT`` s."""
        try:
            self._proc.wait(CLOSE_TIMEOUT)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()

    def close(self):
        if self._proc.poll() is None:
            try:
                self._proc.stdin.write(json.dumps({"op": "close"}) + "\n")
                self._proc.stdin.flush()
            except OSError:
                pass
            self._wait()
        for f in (self._proc.stdin, self._proc.stdout, self._stderr):
            f.close()


class JoltWasmRun(WasmRun):
    """``world`` in Jolt Physics (npm ``jolt-physics``, its single-threaded WebAssembly build), at the settings
    of ``bench/peers/wasm/jolt.mjs``.  Jolt keeps 10,240 contact constraints and drops contacts past them (the
    package fixes its temporary allocator at 10 MB and its heap at 128 MB, which leave little room to raise
    that): a run with more pairs of bodies in contact at a sample (the 8,000-sphere pile) fails."""
    name, backend, package = "jolt-wasm", "jolt", "jolt-physics"


class RapierWasmRun(WasmRun):
    """``world`` in Rapier (npm ``@dimforge/rapier3d-compat``, WebAssembly), at the settings of
    ``bench/peers/wasm/rapier.mjs``."""
    name, backend, package = "rapier-wasm", "rapier", "@dimforge/rapier3d-compat"


#: the WebAssembly peers by their names in the benchmark
PEERS = {run.name: run for run in (JoltWasmRun, RapierWasmRun)}
