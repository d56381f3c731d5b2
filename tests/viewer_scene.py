"""The viewer tests' world: a stack of boxes on a triangle-mesh floor, a ball hanging from a rod, a ball
on a spring, a bar on a hinge, and a sensor box (imported by the tests, and run by the window test's
subprocess)."""
import numpy as np

import marbellous as mb

#: Where the rod and the spring hang from (m).
ROD_ANCHOR = np.array([1.8, 3.2, -1.0])
SPRING_ANCHOR = np.array([1.5, 2.6, 1.5])
#: Where the bar's hinge is (m); the bar reaches 1 m along +x from it, held up by the hinge's limits.
HINGE_ANCHOR = np.array([-0.6, 3.0, -1.0])
#: A fixed camera that sees all of it: (eye, target) (m).
CAMERA = (np.array([5.0, 4.5, 8.0]), np.array([0.0, 1.0, 0.0]))


def floor_mesh(half=4.0, cells=8):
    """A flat square of triangles at y = 0, ``2 half`` metres across, ``cells`` cells per side."""
    n = cells + 1
    xs, zs = np.meshgrid(np.linspace(-half, half, n), np.linspace(-half, half, n), indexing="ij")
    vertices = np.stack([xs.ravel(), np.zeros(n * n), zs.ravel()], axis=1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    return mb.TriangleMesh(vertices, np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)]))


def build():
    """``(world, parts)``: the world and a dict of its parts (``stack``, ``floor``, ``bob``, ``rod``,
    ``ball``, ``spring``, ``bar``, ``hinge``, ``sensor``)."""
    w = mb.World()
    floor = w.add_static(floor_mesh())
    stack = [w.add_body(mb.Box((0.4, 0.3, 0.4)), position=(-1.5, 0.3 + 0.6 * k, 0.0)) for k in range(3)]
    bob = w.add_body(mb.Sphere(0.25), position=ROD_ANCHOR - (0.0, 1.5, 0.0))
    rod = w.add_rod(bob, None, anchor_b=ROD_ANCHOR)
    ball = w.add_body(mb.Sphere(0.2), position=(1.5, 0.2, 1.5))
    spring = w.add_spring(ball, None, rest_length=2.0, stiffness=30.0, damping=2.0, anchor_b=SPRING_ANCHOR)
    bar = w.add_body(mb.Box((0.5, 0.05, 0.05)), position=HINGE_ANCHOR + (0.5, 0.0, 0.0))
    hinge = w.add_hinge(bar, None, anchor=HINGE_ANCHOR, axis=(0.0, 0.0, 1.0), limits=(-0.05, 0.05))
    sensor = w.add_static(mb.Box((0.5, 0.5, 0.5)), position=(-0.5, 0.5, 2.5), sensor=True)
    return w, dict(stack=stack, floor=floor, bob=bob, rod=rod, ball=ball, spring=spring, bar=bar, hinge=hinge,
                   sensor=sensor)
