"""A Marbellous world in PyBullet (DIRECT mode): spheres, boxes, planes and triangle meshes, and ball joints.

Settings, chosen to be PyBullet at its documented defaults and its fastest equivalent bodies:
- time step ``dt``, no sub-steps, 10 solver iterations (PyBullet's default), gravity along -z;
- free bodies as maximal-coordinate rigid bodies (``useMaximalCoordinates=True``, btRigidBody);
- no linear or angular damping (PyBullet's default is 0.04; Marbellous has none);
- Bullet multiplies the two bodies' friction (and restitution, rolling and spinning friction) coefficients
  where Marbellous takes the geometric mean, so each body gets ``sqrt(mu)``: the product then equals
  Marbellous' ``sqrt(mu_a mu_b)`` exactly (for rolling and torsional friction, which Marbellous combines
  by ``max``, when both bodies have the same; Bullet's rolling and spinning friction are lever arms as
  Marbellous' are: the torque impulse is at most the coefficient times the normal impulse);
- a ``TriangleMesh`` becomes a static concave ``GEOM_MESH`` (Bullet's BVH triangle mesh);
- shapes keep their local (body-frame) geometry; each body's orientation gets the quarter turn;
- sleeping (deactivation) left at Bullet's default, like Marbellous' own; off for every body
  (``ACTIVATION_STATE_DISABLE_SLEEPING``) when the world's ``sleeping`` is off;
- a ball joint becomes a ``JOINT_POINT2POINT`` constraint (Bullet's btPoint2PointConstraint between the two
  rigid bodies) holding the two bodies' anchors together, with no cap on its force (PyBullet's default is
  500 N; Marbellous' joints have none); the two bodies do not collide with each other, as in Marbellous.  A
  joint to the world holds its body to a static body without a shape at the origin (PyBullet refuses such a
  constraint to the world itself, -1, for a maximal-coordinate body).
"""
import math
import os
import tempfile

import numpy as np

from marbellous.shapes.mesh import TriangleMesh
from marbellous.shapes.primitives import Box, Plane, Sphere

from . import Unsupported, bodies_of, joints_of, local_point, single_shape
from .axes import from_peer, quat_from_peer, quat_to_peer, to_peer

#: the force (N) a point-to-point constraint may apply: no cap that a scene reaches
NO_FORCE_CAP = 1e9


def direct_client(dt, ground_friction=None):
    """A new PyBullet physics client in DIRECT mode at the settings above (time step ``dt`` s, no sub-steps,
    10 solver iterations, gravity 9.81 along -z): ``(pybullet module, keyword arguments naming the client)``.
    With ``ground_friction`` a ground plane too, whose coefficient Bullet multiplies by each body's."""
    import pybullet as p
    kw = {"physicsClientId": p.connect(p.DIRECT)}
    p.setGravity(*to_peer((0.0, -9.81, 0.0)), **kw)
    p.setPhysicsEngineParameter(fixedTimeStep=dt, numSolverIterations=10, numSubSteps=0, **kw)
    if ground_friction is not None:
        ground = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, **kw), **kw)
        p.changeDynamics(ground, -1, lateralFriction=ground_friction, **kw)
    return p, kw


def _xyzw(q):
    return [float(q[1]), float(q[2]), float(q[3]), float(q[0])]


def _mesh_shape(p, mesh, kw):
    """A static concave mesh shape; through an OBJ file when PyBullet refuses that many vertices in memory."""
    v = mesh.vertices        # in the body's frame, which the quarter turn of its orientation maps to z-up
    try:
        sid = p.createCollisionShape(p.GEOM_MESH, vertices=v.tolist(), indices=mesh.triangles.ravel().tolist(),
                                     flags=p.GEOM_FORCE_CONCAVE_TRIMESH, **kw)
    except p.error:
        sid = -1
    if sid >= 0:
        return sid
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "mesh.obj")
        with open(path, "w") as fh:
            np.savetxt(fh, v, fmt="v %.17g %.17g %.17g")
            np.savetxt(fh, mesh.triangles + 1, fmt="f %d %d %d")
        return p.createCollisionShape(p.GEOM_MESH, fileName=path, flags=p.GEOM_FORCE_CONCAVE_TRIMESH, **kw)


class PyBulletRun:
    """``world`` built in a new PyBullet DIRECT client, stepped ``dt`` s at a time."""

    def __init__(self, world, dt):
        import pybullet as p

        joints = joints_of(world)           # Unsupported before a client is started
        self.p = p
        self.cid = p.connect(p.DIRECT)
        kw = {"physicsClientId": self.cid}
        g = to_peer(world.gravity)
        p.setGravity(*g, **kw)
        p.setPhysicsEngineParameter(fixedTimeStep=dt, numSolverIterations=10, numSubSteps=0, **kw)
        self.ids = []
        shape_cache = {}
        records = bodies_of(world)
        batches = {}
        for rec in records:
            shape = single_shape(rec)
            if isinstance(shape, Sphere):
                key = ("sphere", shape.radius)
                make = lambda s=shape: p.createCollisionShape(p.GEOM_SPHERE, radius=s.radius, **kw)
            elif isinstance(shape, Box):
                key = ("box", tuple(shape.half_extents))
                make = lambda s=shape: p.createCollisionShape(p.GEOM_BOX, halfExtents=list(s.half_extents), **kw)
            elif isinstance(shape, Plane):
                key = ("plane", tuple(shape.normal))
                make = lambda s=shape: p.createCollisionShape(p.GEOM_PLANE, planeNormal=list(s.normal), **kw)
            elif isinstance(shape, TriangleMesh):
                key = ("mesh", id(shape))
                make = lambda s=shape: _mesh_shape(p, s, kw)
            else:
                raise Unsupported(type(shape).__name__)
            if key not in shape_cache:
                shape_cache[key] = make()
            pos = to_peer(rec["position"])
            orn = quat_to_peer(rec["orientation"])
            if isinstance(shape, Plane):
                if np.any(rec["orientation"] != np.array([1.0, 0.0, 0.0, 0.0])):
                    raise Unsupported("turned planes")
                pos = to_peer(rec["position"] + shape.normal * shape.offset)
            mass = 0.0 if rec["static"] else rec["mass"]
            # Bodies sharing a shape, mass and material are created in one batch call.
            batch_key = (shape_cache[key], mass, rec["friction"], rec["restitution"], rec["rolling_friction"],
                         rec["torsional_friction"])
            batches.setdefault(batch_key, []).append((len(self.ids), rec, pos, orn))
            self.ids.append(None)
        for (sid, mass, mu, e, roll, spin), members in batches.items():
            positions = [list(m[2]) for m in members]
            if len(members) == 1:
                ids = [p.createMultiBody(mass, sid, basePosition=positions[0], useMaximalCoordinates=True, **kw)]
            else:
                ids = p.createMultiBody(mass, sid, batchPositions=positions, useMaximalCoordinates=True, **kw)
            for (slot, rec, pos, orn), bid in zip(members, ids):
                self.ids[slot] = bid
                p.resetBasePositionAndOrientation(bid, list(pos), _xyzw(orn), **kw)
                p.changeDynamics(bid, -1, lateralFriction=math.sqrt(mu), restitution=math.sqrt(e),
                                 rollingFriction=math.sqrt(roll), spinningFriction=math.sqrt(spin), linearDamping=0.0,
                                 angularDamping=0.0, **kw)
                if mass > 0.0 and not world.sleeping:
                    p.changeDynamics(bid, -1, activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING, **kw)
                if mass > 0.0:
                    p.resetBaseVelocity(bid, list(to_peer(rec["velocity"])), list(to_peer(rec["angular_velocity"])),
                                        **kw)
        self.dynamic = [bid for bid, rec in zip(self.ids, records) if not rec["static"]]
        self.kw = kw
        ground = None
        for j in joints:
            if j["body_b"] < 0 and ground is None:
                ground = p.createMultiBody(0.0, -1, useMaximalCoordinates=True, **kw)
            self._ball_joint(records, j, ground)

    def _ball_joint(self, records, joint, ground):
        """A point-to-point constraint for the ball joint record ``joint`` (``joints_of``), whose bodies do not
        collide with each other; a joint to the world holds its body to ``ground``, a static body whose frame is
        the world's."""
        p, kw = self.p, self.kw
        a, b = joint["body_a"], joint["body_b"]
        on_a = list(local_point(records[a], joint["anchor"]))      # in the body's frame, which the axes do not turn
        if b < 0:
            c = p.createConstraint(self.ids[a], -1, ground, -1, p.JOINT_POINT2POINT, [0, 0, 0], on_a,
                                   list(to_peer(joint["anchor"])), **kw)
        else:
            c = p.createConstraint(self.ids[a], -1, self.ids[b], -1, p.JOINT_POINT2POINT, [0, 0, 0], on_a,
                                   list(local_point(records[b], joint["anchor"])), **kw)
            p.setCollisionFilterPair(self.ids[a], self.ids[b], -1, -1, 0, **kw)
        p.changeConstraint(c, maxForce=NO_FORCE_CAP, **kw)

    def step(self):
        self.p.stepSimulation(physicsClientId=self.cid)

    def positions(self):
        """Positions (m) of the dynamic bodies, in Marbellous axes, shape (n, 3)."""
        get = self.p.getBasePositionAndOrientation
        return from_peer(np.array([get(b, **self.kw)[0] for b in self.dynamic]).reshape(-1, 3))

    def orientations(self):
        """Orientations (w, x, y, z) of the dynamic bodies, in Marbellous axes, shape (n, 4)."""
        get = self.p.getBasePositionAndOrientation
        xyzw = np.array([get(b, **self.kw)[1] for b in self.dynamic]).reshape(-1, 4)
        return quat_from_peer(xyzw[:, [3, 0, 1, 2]])

    def max_penetration(self):
        """Deepest overlap (m) among the current contact points (0 if none overlap)."""
        pts = self.p.getContactPoints(**self.kw)
        return max([0.0] + [-c[8] for c in pts])

    def close(self):
        self.p.disconnect(self.cid)
