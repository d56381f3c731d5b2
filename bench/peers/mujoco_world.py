"""A Marbellous world in MuJoCo: spheres, boxes and planes (triangle meshes are not equivalent).

MuJoCo collides a mesh as its convex hull (a concave terrain would need a convex decomposition, or
its ``hfield``, neither of which is the same surface), so a world with a ``TriangleMesh`` raises
``Unsupported``.  Settings: ``timestep = dt``, gravity along -z, the projected Gauss-Seidel solver with
10 iterations (the closest to sequential impulses and to PyBullet's 10 iterations; MuJoCo's default
Newton solver factors a Hessian over all degrees of freedom, seconds per step for a 1,000-sphere
pile), MuJoCo's defaults otherwise (Euler integrator, soft contacts, ``condim`` 3: sliding friction
only; ``condim`` 6, with torsional and rolling friction, for bodies that have them: MuJoCo's are lever arms,
as Marbellous' are).  MuJoCo's sleeping (``mjENBL_SLEEP``) is off by default and stays off: its
bodies are awake in every scene.  MuJoCo combines two geoms' friction by ``max`` where Marbellous takes the geometric
mean for sliding friction; the scenes give all bodies one coefficient, for which the two agree.  Free bodies
move on free joints.
"""
import numpy as np

from marbellous.shapes.primitives import Box, Plane, Sphere

from . import Unsupported, bodies_of, single_shape
from .axes import from_peer, quat_to_peer, to_peer


def mjcf_numbers(v):
    """The numbers of ``v`` (a scalar or array) as MJCF writes them: space-separated, to full precision."""
    return " ".join(f"{float(x):.17g}" for x in np.ravel(v))


_f = mjcf_numbers


def _friction(rec):
    """The MJCF friction of a body record: sliding only (``condim`` 3), or with its torsional and rolling
    lever arms (m; ``condim`` 6) where it has either."""
    torsion, rolling = rec["torsional_friction"], rec["rolling_friction"]
    if torsion == 0.0 and rolling == 0.0:
        return f'friction="{rec["friction"]:.17g} 0.005 0.0001"'
    return f'condim="6" friction="{rec["friction"]:.17g} {torsion:.17g} {rolling:.17g}"'


def _geom(shape, rec, mass=None):
    m = "" if mass is None else f' mass="{mass:.17g}"'
    fr = _friction(rec)
    if isinstance(shape, Sphere):
        return f'<geom type="sphere" size="{shape.radius:.17g}" {fr}{m}/>'
    if isinstance(shape, Box):
        return f'<geom type="box" size="{_f(shape.half_extents)}" {fr}{m}/>'
    raise Unsupported(type(shape).__name__)


class MuJoCoRun:
    """``world`` compiled into a MuJoCo model, stepped ``dt`` s at a time."""

    def __init__(self, world, dt):
        import mujoco

        self.mujoco = mujoco
        parts = []
        free = []
        records = bodies_of(world)
        for k, rec in enumerate(records):
            shape = single_shape(rec)
            pos = to_peer(rec["position"])
            if isinstance(shape, Plane):
                n = to_peer(shape.normal)
                parts.append(f'<geom type="plane" size="0 0 1" pos="{_f(pos + n * shape.offset)}" zaxis="{_f(n)}" '
                             f'{_friction(rec)}/>')
            elif rec["static"]:
                parts.append(_geom(shape, rec).replace(
                    "<geom ", f'<geom pos="{_f(pos)}" quat="{_f(quat_to_peer(rec["orientation"]))}" '))
            else:
                parts.append(f'<body name="b{k}" pos="{_f(pos)}" quat="{_f(quat_to_peer(rec["orientation"]))}">'
                             f'<freejoint/>{_geom(shape, rec, rec["mass"])}</body>')
                free.append(rec)
        g = to_peer(world.gravity)
        xml = (f'<mujoco><option timestep="{dt:.17g}" gravity="{_f(g)}" solver="PGS" iterations="10"/>'
               f'<size memory="1G"/>'
               f'<worldbody>{"".join(parts)}</worldbody></mujoco>')
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        for j, rec in enumerate(free):
            adr = self.model.jnt_dofadr[j]
            self.data.qvel[adr:adr + 3] = to_peer(rec["velocity"])
            # free-joint angular velocity is in the body frame: w_body = R^T w_world
            w_world = to_peer(rec["angular_velocity"])
            q = quat_to_peer(rec["orientation"])
            rot = np.empty(9)
            mujoco.mju_quat2Mat(rot, q)
            self.data.qvel[adr + 3:adr + 6] = rot.reshape(3, 3).T @ w_world
        mujoco.mj_forward(self.model, self.data)
        self.qpos_adr = np.array([self.model.jnt_qposadr[j] for j in range(len(free))], dtype=np.int64)

    def step(self):
        self.mujoco.mj_step(self.model, self.data)

    def positions(self):
        """Positions (m) of the free bodies, in Marbellous axes, shape (n, 3) (from ``qpos``: ``xpos`` is
        computed at the start of ``mj_step`` and lags one step behind)."""
        q = self.data.qpos
        return from_peer(np.column_stack([q[self.qpos_adr], q[self.qpos_adr + 1], q[self.qpos_adr + 2]]))

    def max_penetration(self):
        """Deepest overlap (m) among the current contacts (0 if none overlap)."""
        n = self.data.ncon
        return max(0.0, float(-self.data.contact.dist[:n].min())) if n else 0.0

    def close(self):
        pass
