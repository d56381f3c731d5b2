"""Peer engines for the benchmark: a Marbellous world translated body by body into PyBullet, MuJoCo, Jolt
Physics compiled natively from its C++ source (``jolt_native_world.py``), or Jolt Physics or Rapier in
WebAssembly (run by node, ``wasm_world.py``); the last three run in a process of their own (``pipe.py``).

Every peer run is built from the same Marbellous world (shapes, poses, velocities, masses, friction, ball
joints), with the axes mapped where they differ (Marbellous is y-up, PyBullet and MuJoCo z-up; Jolt and Rapier
are y-up), and offers the same small interface as ``bench.runs.MarbellousRun``: ``step()``, ``positions()``
and ``orientations()`` of the dynamic bodies in Marbellous axes, ``max_penetration()`` (m) and ``close()``; the
peers in a process of their own also ``timed_steps(n, budget)``, their steps timed inside that process.
``make_peer(name, world)`` raises ``Unsupported`` when the peer has no equivalent of a shape or of a
constraint (any but unbreakable ball joints), and ``ImportError`` when it is not installed (for the
WebAssembly peers: node or npm missing, or the first install of their npm packages failed; for native Jolt: no
Jolt checkout named, CMake or a compiler missing, or its first build failed).
"""
import numpy as np


class Unsupported(Exception):
    """The peer has no equivalent of a shape, or of a constraint, in the scene."""


#: the native Jolt peers' names (one thread, two threads)
JOLT_NATIVE = ("jolt-native", "jolt-native-2t")
#: every peer's name
NAMES = ("pybullet", "mujoco", *JOLT_NATIVE, "jolt-wasm", "rapier-wasm")


def make_peer(name, world, dt):
    """A run of ``world`` in peer ``name`` (one of ``NAMES``) with time step ``dt`` (s)."""
    if name == "pybullet":
        from .pybullet_world import PyBulletRun
        return PyBulletRun(world, dt)
    if name == "mujoco":
        from .mujoco_world import MuJoCoRun
        return MuJoCoRun(world, dt)
    if name in JOLT_NATIVE:
        from .jolt_native_world import PEERS
        return PEERS[name](world, dt)
    if name in NAMES:
        from .wasm_world import PEERS
        return PEERS[name](world, dt)
    raise ValueError(f"name must be one of {', '.join(NAMES)}, got {name!r}")


def version(name):
    """Installed version string of a peer, or None when it is not installed.  For a WebAssembly peer, its npm
    package's version, once node is found and the package is in place (installed now on first use); for native
    Jolt, Jolt's version and commit, once its driver is built (now, on first use)."""
    try:
        if name == "pybullet":
            import pybullet
            return str(pybullet.getAPIVersion())
        if name == "mujoco":
            import mujoco
            return mujoco.__version__
        if name in JOLT_NATIVE:
            from .jolt_build import driver_and_version
            return driver_and_version()[1]
        from .npm_cache import PACKAGES, node_and_prefix
        from .wasm_world import PEERS
        node_and_prefix()
        return PACKAGES[PEERS[name].package]
    except ImportError:
        return None


def single_shape(rec):
    """The one shape of a body record (``bodies_of``), centred on the body's origin and unturned; raises
    ``Unsupported`` for compound bodies and offset shapes, which the peers do not translate."""
    if len(rec["shapes"]) != 1:
        raise Unsupported("compound bodies")
    shape, lp, lq = rec["shapes"][0]
    if np.any(lp != 0.0) or np.any(lq != np.array([1.0, 0.0, 0.0, 0.0])):
        raise Unsupported("shapes offset from their body's origin")
    return shape


def bodies_of(world):
    """The world's bodies as plain records for a translator: dicts with ``static``, ``shapes`` (list of
    ``(shape, local_position, local_orientation)``), ``position``, ``orientation``, ``velocity``,
    ``angular_velocity``, ``mass``, ``friction``, ``restitution``, ``rolling_friction``, ``torsional_friction``
    (the last two lever arms, m)."""
    from marbellous.state import layout as L

    out = []
    for b in world.bodies:
        row = world._state.bf[b._index]
        out.append({"static": b.is_static, "shapes": b.shapes, "position": b.position,
                     "orientation": b.orientation, "velocity": b.velocity, "angular_velocity": b.angular_velocity,
                     "mass": b.mass, "friction": float(row[L.FRICTION]), "restitution": float(row[L.RESTITUTION]),
                     "rolling_friction": float(row[L.ROLLING]), "torsional_friction": float(row[L.TORSION])})
    return out


def joints_of(world):
    """The world's constraints as plain records for a translator: one dict per ball joint, with ``kind``
    ("ball"), ``body_a`` and ``body_b`` (indices into ``world.bodies``, the order of ``bodies_of``; ``body_b`` -1
    for the world) and ``anchor``, the world point (m) where the joint holds ``body_a`` now (where it was made,
    in a world not yet stepped).  Raises ``Unsupported`` for any other constraint (springs, rods, cables, hinges,
    sliders, fixed joints, particle networks) and for ball joints with a breaking force, which the peers'
    joints do not have."""
    from marbellous.constraints import BallJoint
    from marbellous.state import layout as L

    index = {b: k for k, b in enumerate(world.bodies)}
    out = []
    for c in world.constraints:
        if type(c) is not BallJoint:
            raise Unsupported(type(c).__name__)
        if np.isfinite(world._state.kf[c._index, L.K_BREAKING]):     # (no public reading of the breaking force)
            raise Unsupported("breakable joints")
        out.append({"kind": "ball", "body_a": index[c.body_a], "body_b": -1 if c.body_b is None else index[c.body_b],
                    "anchor": np.asarray(c.anchor, dtype=np.float64)})
    return out


def local_point(rec, point):
    """The world point ``point`` (m) in the frame of the body of record ``rec`` (``bodies_of``), m."""
    from marbellous.math3d import quat_to_matrix_np

    return quat_to_matrix_np(rec["orientation"]).T @ (np.asarray(point, dtype=np.float64) - rec["position"])
