"""A Marbellous world in an engine running in another process, behind line-delimited JSON: the plumbing the
WebAssembly peers (``wasm_world.py``: Jolt and Rapier run by node) and the native Jolt peers
(``jolt_native_world.py``) share.

The world's bodies (``bodies_of``) are sent once, as one ``build`` request, to the engine's process, which
answers every request with one JSON line (the protocol is described in ``bench/peers/wasm/driver.mjs``; the
native Jolt driver, ``bench/peers/jolt_native/driver.cpp``, speaks it too):

- Spheres, boxes, capsules, planes, triangle meshes (static) and convex hulls; compound bodies, shapes off their
  body's origin and height fields raise ``Unsupported`` before the process is started.
- Ball joints (``joints_of``) as each joint's two bodies and its world anchor; any other constraint raises
  ``Unsupported`` before the process is started.
- Positions, orientations and velocities go across unchanged (the engines behind it are y-up like Marbellous),
  with each body's mass, friction and restitution.
- Steps are timed inside the engine's process around its step call alone, not from Python: a request through the
  pipe costs more than a small scene's whole step.  ``timed_steps`` returns those times, and
  ``bench.runs.timed_run`` counts them instead of its own clock.
"""
import json
import subprocess
import tempfile

import numpy as np

from marbellous.shapes.hull import ConvexHull
from marbellous.shapes.mesh import TriangleMesh
from marbellous.shapes.primitives import Box, Capsule, Plane, Sphere

from . import Unsupported, bodies_of, joints_of, single_shape

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
    """The ``build`` request for ``world`` stepped ``dt`` s at a time: gravity (m/s^2), whether resting bodies
    may sleep (``world.sleeping``), the distinct shapes, per body its shape's index, ``static``, position (m),
    orientation (w, x, y, z), velocity (m/s), angular velocity (rad/s), mass (kg), friction and restitution, and
    per ball joint its ``kind``, ``body_a``, ``body_b`` (indices into the bodies, -1: the world) and world
    ``anchor`` (m).  Raises ``Unsupported``."""
    joints = [{**j, "anchor": j["anchor"].tolist()} for j in joints_of(world)]
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
            "sleeping": bool(world.sleeping), "shapes": shapes, "bodies": bodies, "joints": joints}


class PipeRun:
    """``world`` built in an engine's own process, stepped ``dt`` s at a time.  ``version`` is the engine's
    version as the engine reports it.  A subclass names the peer and gives the command that starts the engine."""

    #: the peer's name in the benchmark
    name = None

    def command(self):
        """The engine's command line (a list); raises ImportError when the engine is not installed."""
        raise NotImplementedError

    def __init__(self, world, dt):
        request = build_request(world, dt)          # Unsupported before anything is started
        command = self.command()
        self._stderr = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
                                      text=True)
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
            reply = json.loads(line) if line else {"error": "the engine's process stopped"}
        except ValueError:         # something else wrote to the engine's standard output: it cannot go on
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
        no limit): the seconds each step took, timed inside the engine's process around its step alone."""
        return self._ask({"op": "step", "n": int(n), "budget": budget})["seconds"]

    def step(self):
        self.timed_steps(1)

    def positions(self):
        """Positions (m) of the dynamic bodies, shape (n, 3)."""
        return np.array(self._ask({"op": "positions"})["positions"], dtype=np.float64).reshape(-1, 3)

    def orientations(self):
        """Orientations (w, x, y, z) of the dynamic bodies, shape (n, 4)."""
        return np.array(self._ask({"op": "orientations"})["orientations"], dtype=np.float64).reshape(-1, 4)

    def max_penetration(self):
        """Deepest overlap (m) among the current contacts (0 if none overlap), as the engine measures it."""
        return float(self._ask({"op": "penetration"})["depth"])

    def _wait(self):
        """Wait for the engine's process to exit, killing it after ``CLOSE_TIMEOUT`` s."""
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
