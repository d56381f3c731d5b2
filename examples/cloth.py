"""Cloth: a sheet hung by its corners that catches a ball, and a tablecloth dropped over a sphere.

- A 40 x 40 sheet, 1.6 m square, hangs by its four corners 2 m up, pinned 1.2 m apart so that it sags into a
  bag.  A 1 kg ball dropped into it bounces on the sheet and is caught: it rolls to and fro at the bottom of
  the bag (the sheet pushes the ball and the ball pushes the sheet: two ways).  (Hung by two opposite corners
  only, a sheet falls into a narrow fold along the line between them, and a ball glances off it.)
- A 30 x 30 sheet, 1.2 m square, falls flat onto a sphere on the ground 3 m away and drapes over it: its middle
  rests on top of the sphere, its corners fall to the floor.

Each vertex of a cloth is a point mass, each edge of its triangles a stiff spring and each pair of triangles a
hinge that resists bending; the triangles keep the sheet ``thickness`` away from the shapes, from other cloths
and from itself.  The viewer draws a cloth as a surface in its own colour (chartreuse).

The script prints how things came to rest; ``--show`` opens the viewer instead, ``--record out.mp4`` writes a
video.

Run:  python examples/cloth.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: the bag: vertices per side, side (m), height of its corners (m), how much closer its corners are pinned than
#: the sheet is wide, and how deep it starts (m)
BAG_N, BAG_SIDE, BAG_HEIGHT, BAG_SQUEEZE, BAG_DEPTH = 40, 1.6, 2.0, 0.75, 0.4
#: the ball dropped into it: radius (m), mass (kg), where it starts (m)
BALL_RADIUS, BALL_MASS, BALL_START = 0.15, 1.0, (0.0, 3.0, 0.0)
#: the sphere the tablecloth falls on: radius (m), centre (m); the tablecloth's vertices per side and side (m)
TABLE_RADIUS, TABLE_CENTRE = 0.35, np.array([3.0, 0.35, 0.0])
CLOTH_N, CLOTH_SIDE = 30, 1.2


def build():
    """The two scenes side by side; returns ``(world, parts)``, ``parts`` a dict of their handles."""
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.6)
    # the bag: a flat sheet in the x-z plane (vertex i n + j at column i along x, row j along z) ...
    n = BAG_N
    v, t = mb.cloth_grid(BAG_SIDE, BAG_SIDE, n, n)
    bag = w.add_cloth(v, t, mass=0.4, position=(0.0, BAG_HEIGHT, 0.0), damping=1.0)
    # ... moved into a rough bag (squeezed sideways, its middle lowered), which it settles from in its first
    # steps, and pinned there by its four corners (each vertex held where it is when pinned)
    across, along = v[:, 0] / (0.5 * BAG_SIDE), v[:, 2] / (0.5 * BAG_SIDE)     # -1 .. 1 over the sheet
    sag = BAG_DEPTH * (1.0 - across ** 2) * (1.0 - along ** 2)
    bag.positions = np.column_stack([BAG_SQUEEZE * v[:, 0], BAG_HEIGHT - sag, BAG_SQUEEZE * v[:, 2]])
    bag.pin([0, n - 1, n * (n - 1), n * n - 1])
    ball = w.add_body(mb.Sphere(BALL_RADIUS), position=BALL_START, mass=BALL_MASS, restitution=0.1)
    # the tablecloth, 0.5 m above the top of the sphere
    table = w.add_static(mb.Sphere(TABLE_RADIUS), position=TABLE_CENTRE, friction=0.6)
    v, t = mb.cloth_grid(CLOTH_SIDE, CLOTH_SIDE, CLOTH_N, CLOTH_N)
    top = TABLE_CENTRE + (0.0, TABLE_RADIUS + 0.5, 0.0)
    tablecloth = w.add_cloth(v, t, mass=0.3, position=top, friction=0.6, damping=0.5)
    return w, dict(bag=bag, ball=ball, table=table, tablecloth=tablecloth)


def edge_strain(cloth, rest):
    """The largest relative stretch of the cloth's edges: length now over length at rest (``rest``, the
    vertices as made), less one."""
    t = cloth.triangles
    e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
    x = cloth.positions
    return float(np.max(np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
                        / np.linalg.norm(rest[e[:, 0]] - rest[e[:, 1]], axis=1)) - 1.0)


def run(seconds=4.0):
    """Step the scenes for ``seconds`` (s); returns a dict of how they ended: ``ball_speed`` (m/s),
    ``ball_height`` (m, its centre), ``ball_in_bag`` (m: the ball's centre above the bag's lowest vertex),
    ``ball_off_axis`` (m: the ball's centre from the vertical line through the bag's middle), ``bag_strain``
    (its most stretched edge), ``cloth_in_sphere`` (m: how deep the tablecloth's deepest
    vertex is inside the sphere), ``cloth_top`` (m: the tablecloth's highest vertex), ``cloth_lowest`` (m) and
    ``cloth_speed`` (m/s, its fastest vertex)."""
    w, parts = build()
    for _ in range(round(seconds / DT)):
        w.step(DT)
    ball, bag, tablecloth = parts["ball"], parts["bag"], parts["tablecloth"]
    x = tablecloth.positions
    rest, _ = mb.cloth_grid(BAG_SIDE, BAG_SIDE, BAG_N, BAG_N)
    return dict(
        ball_speed=float(np.linalg.norm(ball.velocity)),
        ball_height=float(ball.position[1]),
        ball_in_bag=float(ball.position[1] - bag.positions[:, 1].min()),
        ball_off_axis=float(np.hypot(ball.position[0], ball.position[2])),
        bag_strain=edge_strain(bag, rest),
        cloth_in_sphere=float(max(0.0, TABLE_RADIUS - np.linalg.norm(x - TABLE_CENTRE, axis=1).min())),
        cloth_top=float(x[:, 1].max()),
        cloth_lowest=float(x[:, 1].min()),
        cloth_speed=float(np.linalg.norm(tablecloth.velocities, axis=1).max()))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=4.0, stats=True))
    else:
        r = run()
        print(f"bag: the ball is {r['ball_height']:.3f} m up, {r['ball_in_bag']:.3f} m above the bag's lowest "
              f"point and {r['ball_off_axis']:.3f} m from its middle, rolling at {r['ball_speed']:.2f} m/s; the "
              f"bag's most stretched edge {100 * r['bag_strain']:.1f} % over its length")
        print(f"tablecloth: its top {r['cloth_top']:.3f} m up (the sphere's top at {2 * TABLE_RADIUS:.2f} m), its "
              f"lowest point {1e3 * r['cloth_lowest']:.1f} mm, {1e3 * r['cloth_in_sphere']:.2f} mm deep in the "
              f"sphere at most; its fastest vertex at {r['cloth_speed']:.4f} m/s")
