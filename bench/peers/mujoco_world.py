"""A Marbellous world in MuJoCo: spheres, boxes and planes (triangle meshes are not equivalent), and ball joints.

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
move on free joints.  Ball-jointed bodies are MuJoCo's reduced-coordinate way: each set of bodies the joints join
is one kinematic tree of ``ball`` joints (hung from the world where a joint holds it there, else from a free
joint), so that its joints cannot open; joints that close a loop raise ``Unsupported``.  A run MuJoCo flags
unstable (NaN or huge accelerations: it then resets the state and steps on) fails at the next sample.
"""
import numpy as np

from marbellous.shapes.primitives import Box, Plane, Sphere

from . import Unsupported, bodies_of, joints_of, local_point, single_shape
from .axes import from_peer, quat_from_peer, quat_to_peer, to_peer


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


def _tree(records, joints):
    """MuJoCo's kinematic tree for the ball joints ``joints`` (``joints_of``) between the bodies ``records``
    (``bodies_of``): ``(parent, order)``, where ``parent`` maps each dynamic body a joint holds to ``(the body it
    hangs from, -1 for the world (static bodies are part of it), or None for a free body at the root of its tree;
    the joint's world anchor (m))`` and ``order`` lists those bodies each after its parent.  Raises ``Unsupported``
    for joints that close a loop (two joints to the world in one tree among them), which a tree cannot hold, and
    for jointed bodies that move at the start (a tree's velocities are its joints', relative to the parent)."""
    parent, links = {}, {}
    for n, j in enumerate(joints):
        a, b = (k if k >= 0 and not records[k]["static"] else -1 for k in (j["body_a"], j["body_b"]))
        a, b = (b, a) if a < 0 else (a, b)
        if a < 0:
            continue                        # between static bodies and the world: it holds nothing
        for k in (a, b):
            if k >= 0 and (np.any(records[k]["velocity"] != 0.0) or np.any(records[k]["angular_velocity"] != 0.0)):
                raise Unsupported("jointed bodies that move at the start")
        if b < 0:
            if a in parent:
                raise Unsupported("joints that close a loop")
            parent[a] = (-1, j["anchor"], n)
        else:
            links.setdefault(a, []).append((b, j["anchor"], n))
            links.setdefault(b, []).append((a, j["anchor"], n))
    order = []

    def grow(root):
        """Hang from ``root`` every body its joints reach, depth first."""
        stack = [root]
        while stack:
            body = stack.pop()
            order.append(body)
            for other, anchor, n in links.get(body, ()):
                if n == parent[body][2]:
                    continue                # the joint it hangs by
                if other in parent:
                    raise Unsupported("joints that close a loop")
                parent[other] = (body, anchor, n)
                stack.append(other)

    for root in list(parent):               # the bodies held by the world
        grow(root)
    for root in sorted(links):
        if root not in parent:              # reached from no world joint: a free root
            parent[root] = (None, None, None)
            grow(root)
    return {k: v[:2] for k, v in parent.items()}, order


def _relative_quat(mujoco, q_parent, q):
    """The orientation ``q`` (w, x, y, z) in the frame of orientation ``q_parent``: q_parent* q."""
    inverse, out = np.empty(4), np.empty(4)
    mujoco.mju_negQuat(inverse, q_parent)
    mujoco.mju_mulQuat(out, inverse, q)
    return out


class MuJoCoRun:
    """``world`` compiled into a MuJoCo model, stepped ``dt`` s at a time."""

    def __init__(self, world, dt):
        import mujoco

        self.mujoco = mujoco
        parts = []
        free = []
        records = bodies_of(world)
        parent, order = _tree(records, joints_of(world))
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
            elif k not in parent:
                parts.append(f'<body name="b{k}" pos="{_f(pos)}" quat="{_f(quat_to_peer(rec["orientation"]))}">'
                             f'<freejoint/>{_geom(shape, rec, rec["mass"])}</body>')
                free.append(k)
        parts += self._trees(records, parent, order)
        g = to_peer(world.gravity)
        xml = (f'<mujoco><option timestep="{dt:.17g}" gravity="{_f(g)}" solver="PGS" iterations="10"/>'
               f'<size memory="1G"/>'
               f'<worldbody>{"".join(parts)}</worldbody></mujoco>')
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        for k in free:
            rec = records[k]
            adr = self.model.jnt_dofadr[self.model.body_jntadr[self.model.body(f"b{k}").id]]
            self.data.qvel[adr:adr + 3] = to_peer(rec["velocity"])
            # free-joint angular velocity is in the body frame: w_body = R^T w_world
            w_world = to_peer(rec["angular_velocity"])
            q = quat_to_peer(rec["orientation"])
            rot = np.empty(9)
            mujoco.mju_quat2Mat(rot, q)
            self.data.qvel[adr + 3:adr + 6] = rot.reshape(3, 3).T @ w_world
        mujoco.mj_forward(self.model, self.data)
        self.ids = np.array([self.model.body(f"b{k}").id for k, rec in enumerate(records) if not rec["static"]],
                            dtype=np.int64)

    def _trees(self, records, parent, order):
        """The MJCF of the jointed bodies (``_tree``), one nested ``<body>`` per tree: each body placed in its
        parent's frame and held by a ball joint at the anchor, in its own frame (m); a free root on a free
        joint.  MuJoCo does not collide a body with its parent, as Marbellous does not collide jointed bodies."""
        mujoco, xml, children = self.mujoco, {}, {}
        for k in order:
            children.setdefault(parent[k][0], []).append(k)
        for k in reversed(order):                       # children before their parents
            rec = records[k]
            up, anchor = parent[k]
            inner = _geom(single_shape(rec), rec, rec["mass"]) + "".join(xml.pop(c) for c in children.get(k, ()))
            q = quat_to_peer(rec["orientation"])
            if up is None or up < 0:
                pos = to_peer(rec["position"])
            else:       # the parent's frame: the same numbers in either axes, as body frames do not turn
                pos = local_point(records[up], rec["position"])
                q = _relative_quat(mujoco, quat_to_peer(records[up]["orientation"]), q)
            joint = ("<freejoint/>" if up is None else
                     f'<joint type="ball" pos="{_f(local_point(rec, anchor))}"/>')
            xml[k] = f'<body name="b{k}" pos="{_f(pos)}" quat="{_f(q)}">{joint}{inner}</body>'
        return [xml[k] for k in order if k in xml]

    def step(self):
        self.mujoco.mj_step(self.model, self.data)

    def _poses(self):
        """``(xpos, xquat)`` of the dynamic bodies, in MuJoCo's axes, with the frames computed from the current
        ``qpos`` (``mj_step`` computes them at its start: they lag one step behind, and are recomputed there).
        Raises RuntimeError once MuJoCo has flagged the run unstable (NaN or huge accelerations), after which it
        resets the state to the model's initial one and steps on."""
        if self.data.warning[self.mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
            raise RuntimeError("MuJoCo flagged the run unstable (NaN or huge accelerations) and reset it")
        self.mujoco.mj_kinematics(self.model, self.data)
        return self.data.xpos[self.ids], self.data.xquat[self.ids]

    def positions(self):
        """Positions (m) of the dynamic bodies, in Marbellous axes, shape (n, 3)."""
        return from_peer(self._poses()[0])

    def orientations(self):
        """Orientations (w, x, y, z) of the dynamic bodies, in Marbellous axes, shape (n, 4)."""
        return quat_from_peer(self._poses()[1])

    def max_penetration(self):
        """Deepest overlap (m) among the current contacts (0 if none overlap)."""
        n = self.data.ncon
        return max(0.0, float(-self.data.contact.dist[:n].min())) if n else 0.0

    def close(self):
        pass
