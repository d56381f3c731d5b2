"""Peer engines for the benchmark: a Marbellous world translated body by body into PyBullet or MuJoCo.

Every peer run is built from the same Marbellous world (shapes, poses, velocities, masses, friction),
with the axes mapped (Marbellous is y-up, the peers z-up), and offers the same small interface as
``bench.runs.MarbellousRun``: ``step()``, ``positions()`` of the dynamic bodies in Marbellous axes,
``max_penetration()`` (m) and ``close()``.  ``make_peer(name, world)`` raises ``Unsupported`` when the
peer has no equivalent of a shape, and ``ImportError`` when it is not installed.
"""


class Unsupported(Exception):
    """The peer has no equivalent of a shape in the scene."""


def make_peer(name, world, dt):
    """A run of ``world`` in peer ``name`` (``"pybullet"`` or ``"mujoco"``) with time step ``dt`` (s)."""
    if name == "pybullet":
        from .pybullet_world import PyBulletRun
        return PyBulletRun(world, dt)
    if name == "mujoco":
        from .mujoco_world import MuJoCoRun
        return MuJoCoRun(world, dt)
    raise ValueError(f"name must be 'pybullet' or 'mujoco', got {name!r}")


def version(name):
    """Installed version string of a peer, or None when it is not installed."""
    try:
        if name == "pybullet":
            import pybullet
            return str(pybullet.getAPIVersion())
        import mujoco
        return mujoco.__version__
    except ImportError:
        return None


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
