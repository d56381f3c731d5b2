"""A Marbellous world in Jolt Physics compiled natively from its C++ source: ``jolt-native`` (one thread) and
``jolt-native-2t`` (two).

The world goes through ``pipe.PipeRun``, as to the WebAssembly peers, to a program linking Jolt,
``bench/peers/jolt_native/driver.cpp``, built on first use from a Jolt checkout the user names
(``jolt_build.py``: ``python -m bench --jolt-source PATH`` or ``$MARBELLOUS_JOLT_SOURCE``; without one the peers
are "not installed").  It speaks the protocol of ``bench/peers/wasm/driver.mjs`` and sets Jolt up as
``bench/peers/wasm/jolt.mjs`` sets up ``jolt-wasm``, so that the native and the WebAssembly Jolt differ in how
Jolt is compiled and threaded, not in what it computes:

- y-up like Marbellous; spheres, boxes (convex radius 5 cm, less for thinner boxes), capsules, planes (Jolt's
  ``PlaneShape``), static triangle meshes and convex hulls; each body's mass (the inertia from its shape),
  friction (combined by geometric mean) and restitution (by maximum); no damping, no cap on linear speed; no
  rolling or torsional friction, which Jolt does not have; ball joints as point constraints (``PointConstraint``,
  to ``Body::sFixedToWorld`` for a joint to the world), the two bodies of each not colliding with each other.
- Jolt's defaults otherwise (10 velocity and 2 position iterations, sleeping unless the world's is off,
  speculative contacts), two object layers, static and moving, and jolt-physics' sizes: room for 10,240 bodies
  (or the scene's), 65,536 body pairs and 10,240 contact constraints, a 10 MB temporary allocator.  A step past
  them fails, where Jolt would drop contacts (the 8,000-sphere pile, as in ``jolt-wasm``).
- One ``PhysicsSystem::Update`` with one collision step per ``dt``, timed inside the program
  (``std::chrono::steady_clock`` around ``Update`` alone).  ``jolt-native`` runs Jolt's jobs on the stepping
  thread (``JobSystemSingleThreaded``), as the single-threaded WebAssembly build does; ``jolt-native-2t`` gives
  them a ``JobSystemThreadPool`` of one worker, the stepping thread working too (two threads, as ``marbellous-2t``).
- ``max_penetration`` is Jolt's own contact query at the current poses, outside the clock (as in ``jolt.mjs``).
- The program steps a small scene of every shape before the scene is built (``driver.mjs``' warm-up).
"""
from .jolt_build import driver_and_version
from .pipe import PipeRun


class JoltNativeRun(PipeRun):
    """``world`` in native Jolt Physics with one thread, stepped ``dt`` s at a time; ``version`` is Jolt's
    version and commit (``jolt_build.jolt_version``)."""
    name, threads = "jolt-native", 1

    def command(self):
        program, _ = driver_and_version()
        return [program, "--threads", str(self.threads)]


class JoltNative2tRun(JoltNativeRun):
    """``world`` in native Jolt Physics with two threads (the stepping thread and one worker)."""
    name, threads = "jolt-native-2t", 2


#: the native Jolt peers by their names in the benchmark
PEERS = {run.name: run for run in (JoltNativeRun, JoltNative2tRun)}
