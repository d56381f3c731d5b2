"""A Marbellous world in a WebAssembly engine run by node: Jolt Physics (``jolt-wasm``) or Rapier (``rapier-wasm``).

The world goes to a node process running ``bench/peers/wasm/driver.mjs`` with the engine's backend
(``jolt.mjs``, ``rapier.mjs``: each engine's settings are listed there) through ``pipe.PipeRun`` (one JSON line
per request; the translation of the shapes and the protocol are described there and in ``driver.mjs``).  The
packages come from ``npm_cache``, installed on first use.

- Both engines are y-up like Marbellous: positions, orientations and velocities go across unchanged.
- Spheres, boxes, capsules, planes, triangle meshes (static) and convex hulls; compound bodies, shapes off
  their body's origin and height fields raise ``Unsupported``.
- Ball joints: Jolt's point constraints, Rapier's spherical impulse joints, the two bodies of each not
  colliding with each other (as in Marbellous); any other constraint raises ``Unsupported``.
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
- Steps are timed inside node (``performance.now()`` around each engine step), not from Python.  Nothing is
  compiled while steps are timed: node compiles the whole engine when it loads it (``NODE_FLAGS``), and each
  engine steps a small scene of every shape (``driver.mjs``) before the scene is built, as the benchmark's
  warm-up compiles Marbellous' kernels before it times them.
"""
import os

from .npm_cache import node_and_prefix
from .pipe import PipeRun

#: the node side: one engine behind line-delimited JSON
DRIVER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "wasm", "driver.mjs")
#: node's options: V8 compiles the engine's whole WebAssembly module with its optimising compiler when it loads
#: it (1.5 s for Jolt, 3.5 s for Rapier, before anything is timed) rather than function by function and again
#: once hot, on another thread, while steps are timed; ``gc()`` for the driver, which collects the build's
#: garbage before the steps
NODE_FLAGS = ("--no-liftoff", "--no-wasm-lazy-compilation", "--expose-gc")


class WasmRun(PipeRun):
    """``world`` built in a node process running one WebAssembly engine, stepped ``dt`` s at a time.
    ``version`` is the engine package's version as the engine reports it."""

    #: the peer's name in the benchmark, its backend in ``driver.mjs`` and its npm package
    name = backend = package = None

    def command(self):
        node, prefix = node_and_prefix()
        return [node, *NODE_FLAGS, DRIVER, self.backend, prefix]


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
