"""Convex hulls: rocks poured into a bowl of triangles, and a tower of ten hexagonal pucks.

Each rock is the convex hull of a dozen random points (``mb.ConvexHull``), with its exact mass and inertia;
twenty of them fall into a bowl that is a triangle mesh, tumble, and come to rest on its faces.  Beside it
ten hexagonal prisms (hulls too) stand in a tower on the ground plane.  The script prints how far the rocks
sank into the bowl (the contacts' give, about a millimetre) and where the top puck ended; with ``--show``
it opens the viewer instead.

Run:  python examples/hulls.py [--show]
"""
import math
import sys

import numpy as np

import marbellous as mb
from marbellous.scenes.terrain import bowl

DT = 1.0 / 60.0
PUCK_HALF_HEIGHT = 0.1


def rock(rng, size=0.25):
    """The convex hull of twelve random points about ``size`` (m) across."""
    return mb.ConvexHull(rng.normal(size=(12, 3)) * size * rng.uniform(0.6, 1.0, 3))


def puck(radius=0.3, half_height=PUCK_HALF_HEIGHT):
    """A hexagonal prism lying on its hexagon faces."""
    a = np.arange(6) * math.pi / 3.0
    ring = np.column_stack([radius * np.cos(a), np.zeros(6), radius * np.sin(a)])
    return mb.ConvexHull(np.vstack([ring - (0, half_height, 0), ring + (0, half_height, 0)]))


def build(rocks=20, pucks=10, seed=4):
    """The bowl with ``rocks`` rocks above it, and a tower of ``pucks`` pucks 4 m to the side; returns
    ``(world, bowl mesh, rock bodies, puck bodies)``."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.7)
    surface = bowl()
    w.add_static(surface, friction=0.7)
    stones = [w.add_body(rock(rng), position=(0.6 * (k % 4 - 1.5), 1.5 + 0.6 * (k // 4), 0.6 * (k % 3 - 1)),
                         orientation=rng.normal(size=4), density=2500, friction=0.7) for k in range(rocks)]
    shape = puck()
    tower = [w.add_body(shape, position=(4.0, PUCK_HALF_HEIGHT * (2 * k + 1) + 0.001 * k, 0.0), density=800,
                        friction=0.7) for k in range(pucks)]
    return w, surface, stones, tower


def run(seconds=5.0):
    """Pour and stack for ``seconds`` (s); returns (the deepest any rock's corner lies below the bowl's triangles
    (m), the fastest rock's speed (m/s), the top puck's height (m) and sideways drift (m))."""
    from marbellous.math3d import quat_to_matrix_np

    w, surface, stones, tower = build()
    for _ in range(round(seconds / DT)):
        w.step(DT)
    sink = 0.0
    for b in stones:
        hull = b.shapes[0][0]
        for x, y, z in hull.vertices @ quat_to_matrix_np(b.orientation).T + b.position:
            hit = surface.raycast((x, 10.0, z), (0.0, -1.0, 0.0))     # the bowl's surface under the corner
            if hit is not None:
                sink = max(sink, (10.0 - hit[0]) - y)
    fastest = max(float(np.linalg.norm(b.velocity)) for b in stones)
    top = tower[-1]
    return sink, fastest, float(top.position[1]), float(np.hypot(top.position[0] - 4.0, top.position[2]))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    else:
        sink, fastest, top, drift = run()
        print(f"rocks at most {1e3 * sink:.2f} mm into the bowl's triangles, the fastest moving at {fastest:.4f} m/s")
        print(f"top puck at {top:.4f} m ({PUCK_HALF_HEIGHT * 19:.2f} m: the tower standing), {1e3 * drift:.2f} mm "
              f"from the tower's axis")
