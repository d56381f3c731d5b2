"""Chains of ball-jointed boxes, the scene of ``bench/bench_joints.py`` and of ``python -m bench``'s ``chains``:
where the links and joints go, the Marbellous world, and the gap between a joint's two anchors measured from the
bodies' poses (the same measure for every engine).

``chains`` chains of ``links`` boxes (0.2 kg, 8 cm long, 2 cm apart at their ends, so that neighbours never
touch), each hanging from the world by a ball joint and joined to the next at the middle of the gap, let go at
0.5 rad from the vertical so that they swing under gravity (9.81 m/s^2); sleeping off.
"""
import math

import numpy as np

import marbellous as mb

HALF = (0.02, 0.04, 0.02)       # a link's half extents (m): 8 cm along the chain
PITCH = 0.1                     # link centres 10 cm apart (m); the joints halfway between the ends
MASS = 0.2                      # a link's mass (kg)
TILT = 0.5                      # the chains' angle from the vertical when let go (rad)
TOP = 3.0                       # height of the chains' world joints (m)
SPACING = 0.5                   # distance between neighbouring chains along z (m)
#: widest gap (m) between a joint's two anchors at which the joint still holds: a quarter of a link's length
#: (8 cm), which is also the clearance between neighbouring links' ends.  A joint opened that far has let its
#: links slide a visible fraction of a link apart (the chain of twenty would be up to 40 cm, a fifth, longer);
#: a joint solver that holds keeps the gap to millimetres (Marbellous: under 1 mm on this scene)
MAX_GAP = 0.02


def layout(chains, links):
    """For each chain: its links' centres (m, Marbellous axes), their common orientation (w, x, y, z: the
    chain's tilt about z), and each joint's world anchor (m; the first on the world, the others between links)."""
    s, c = math.sin(TILT), math.cos(TILT)
    q = (math.cos(TILT / 2), 0.0, 0.0, math.sin(TILT / 2))
    out = []
    for n in range(chains):
        top = np.array([0.0, TOP, SPACING * n])
        down = np.array([s, -c, 0.0])
        centres = [top + down * PITCH * (k + 0.5) for k in range(links)]
        anchors = [top + down * PITCH * k for k in range(links)]
        out.append((centres, q, anchors))
    return out


def chain_joints(chains, links):
    """Each joint as ``(body, parent, anchor)``: the link it holds and the link above it (-1: the world), both
    numbered chain by chain and link by link (the order ``chain_world`` adds them in), and its world anchor (m)."""
    out = []
    for n, (_, _, anchors) in enumerate(layout(chains, links)):
        for k in range(links):
            body = n * links + k
            out.append((body, body - 1 if k > 0 else -1, anchors[k]))
    return out


def chain_world(chains, links):
    """The chains in a Marbellous world with sleeping off: ``(world, joints)``, the ``BallJoint`` handles in
    ``chain_joints``' order (each made by ``add_ball_joint(link, link above or None, anchor=...)``)."""
    world = mb.World(sleeping=False)
    bodies = [world.add_body(mb.Box(HALF), mass=MASS, position=centres[k], orientation=q)
              for centres, q, _ in layout(chains, links) for k in range(links)]
    joints = [world.add_ball_joint(bodies[b], None if parent < 0 else bodies[parent], anchor=anchor)
              for b, parent, anchor in chain_joints(chains, links)]
    return world, joints


def _turn(q, v):
    """The vectors ``v`` (n, 3) turned by the unit quaternions ``q`` (n, 4; w, x, y, z)."""
    w, u = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _conjugate(q):
    """The conjugates (inverse turns) of the unit quaternions ``q`` (n, 4; w, x, y, z)."""
    return q * np.array([1.0, -1.0, -1.0, -1.0])


class JointGaps:
    """The distance between each joint's two anchors, the joints given as ``(body, other body or -1 for the world,
    world anchor)`` and made at the poses ``positions`` (n, 3; m) and ``orientations`` (n, 4; w, x, y, z) of the
    bodies they number: each joint holds a point fixed in its body's frame on a point fixed in the other's (or in
    the world), both where the anchor was then."""

    def __init__(self, joints, positions, orientations):
        self.a = np.array([j[0] for j in joints], dtype=np.int64)
        self.b = np.array([j[1] for j in joints], dtype=np.int64)
        anchor = np.array([j[2] for j in joints], dtype=np.float64).reshape(-1, 3)
        self.local_a = self._local(anchor, self.a, positions, orientations)
        self.local_b = np.where((self.b >= 0)[:, None], self._local(anchor, self.b, positions, orientations), anchor)

    @staticmethod
    def _local(point, body, positions, orientations):
        """``point`` (m, world) in the frames of the bodies ``body`` (those of -1: any frame, unused)."""
        p, q = np.asarray(positions, dtype=np.float64), np.asarray(orientations, dtype=np.float64)
        return _turn(_conjugate(q[body]), point - p[body])

    def __call__(self, positions, orientations):
        """Each joint's gap (m) with the bodies at ``positions`` (n, 3; m) and ``orientations`` (n, 4)."""
        p, q = np.asarray(positions, dtype=np.float64), np.asarray(orientations, dtype=np.float64)
        on_a = p[self.a] + _turn(q[self.a], self.local_a)
        on_b = np.where((self.b >= 0)[:, None], p[self.b] + _turn(q[self.b], self.local_b), self.local_b)
        return np.linalg.norm(on_a - on_b, axis=1)
