"""Soft bodies: a jelly cube dropped on the floor, a plank held at one end that bends under its own weight, and a
ball that lands on a soft block (a bumper).

- The jelly (20 cm, E = 20 kPa, Poisson's ratio 0.45: nearly incompressible) falls 40 cm, squashes, bounces
  a little and comes to rest keeping its volume.
- The plank (1.2 m x 6 cm x 12 cm, E = 2 MPa, like a rubber board) is pinned at one end to a post and
  bends under its own weight, bouncing until it settles.
- The ball (1 kg) falls 1 m onto a 40 x 20 x 40 cm block (E = 50 kPa) and is caught: the block dents and
  pushes it back up (two ways: what the ball loses, the block gains).

Each body is a mesh of tetrahedra (``mb.tet_box``; ``mb.tetrahedralize`` fills any closed mesh), each a
linear finite element with its rotation removed; the world advances the nodes by implicit (backward Euler)
steps, so stiff materials are stable at 60 Hz.  The viewer draws a soft body as its surface (pink).

The script prints how things came to rest; ``--show`` opens the viewer instead, ``--record out.mp4`` writes a
video.

Run:  python examples/soft_bodies.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
G = 9.81
#: the plank: length, depth (vertical) and width (m), Young's modulus (Pa), density (kg/m^3), cells along it
PLANK_L, PLANK_H, PLANK_W, PLANK_E, PLANK_RHO, PLANK_CELLS = 1.2, 0.06, 0.12, 2e6, 600.0, (20, 2, 2)
#: the plank's fixed end (m)
PLANK_ROOT = np.array([-3.0, 1.0, 0.0])


def build():
    """The three scenes side by side; returns ``(world, parts)``, ``parts`` a dict of their handles."""
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane(), friction=0.8)
    vertices, tets = mb.tet_box((0.1, 0.1, 0.1), 4)
    jelly = w.add_soft_body(vertices, tets, density=1100.0, young_modulus=2e4, poisson_ratio=0.45, damping=0.002,
                            position=(0.0, 0.5, 0.0), orientation=(0.96, 0.2, 0.0, 0.2))
    vertices, tets = mb.tet_box((PLANK_L / 2, PLANK_H / 2, PLANK_W / 2), PLANK_CELLS)
    plank = w.add_soft_body(vertices, tets, density=PLANK_RHO, young_modulus=PLANK_E, poisson_ratio=0.0,
                            damping=0.002, position=PLANK_ROOT + (PLANK_L / 2, 0.0, 0.0))
    post = w.add_static(mb.Box((0.1, 0.5, 0.1)), position=PLANK_ROOT - (0.1, 0.5, 0.0))
    plank.pin(np.nonzero(vertices[:, 0] < -PLANK_L / 2 + 1e-9)[0])
    vertices, tets = mb.tet_box((0.2, 0.1, 0.2), (4, 2, 4))
    block = w.add_soft_body(vertices, tets, density=300.0, young_modulus=5e4, poisson_ratio=0.3, damping=0.01,
                            position=(3.0, 0.1 + 0.0125, 0.0))
    ball = w.add_body(mb.Sphere(0.1), mass=1.0, position=(3.0, 1.3, 0.0))
    return w, dict(jelly=jelly, plank=plank, post=post, block=block, ball=ball)


def run(seconds=4.0):
    """Step the scenes for ``seconds`` (s); returns a dict of how they ended: ``jelly_volume`` (its volume over
    its rest volume), ``jelly_lowest`` (m, its lowest node), ``jelly_speed`` (m/s, its fastest node),
    ``plank_tip`` (m, how far the free end came down), ``ball_height`` (m, the ball's centre), ``ball_speed``
    (m/s) and ``block_dent`` (m, how far the block's top middle is below the top's corners)."""
    w, parts = build()
    for _ in range(round(seconds / DT)):
        w.step(DT)
    jelly, plank, block, ball = parts["jelly"], parts["plank"], parts["block"], parts["ball"]
    x = plank.positions
    tip = x[:, 0] > x[:, 0].max() - 1e-3
    top = block.positions[block.positions[:, 1] > block.positions[:, 1].max() - 0.05]
    middle = np.linalg.norm(top[:, [0, 2]] - (3.0, 0.0), axis=1) < 0.06
    corners = np.linalg.norm(top[:, [0, 2]] - (3.0, 0.0), axis=1) > 0.25
    return dict(jelly_volume=jelly.volume / jelly.rest_volume, jelly_lowest=float(jelly.positions[:, 1].min()),
                jelly_speed=float(np.linalg.norm(jelly.velocities, axis=1).max()),
                plank_tip=float(PLANK_ROOT[1] - x[tip, 1].mean()),
                ball_height=float(ball.position[1]), ball_speed=float(np.linalg.norm(ball.velocity)),
                block_dent=float(top[corners, 1].mean() - top[middle, 1].mean()))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=4.0, stats=True))
    else:
        r = run()
        print(f"jelly: {100 * r['jelly_volume']:.1f} % of its rest volume, lowest node "
              f"{1e3 * r['jelly_lowest']:.1f} mm up, fastest node at {r['jelly_speed']:.4f} m/s")
        print(f"plank: its free end {1e3 * r['plank_tip']:.1f} mm down")
        print(f"ball on the block: its centre {r['ball_height']:.3f} m up at {r['ball_speed']:.3f} m/s, the block's "
              f"top dented {1e3 * r['block_dent']:.1f} mm under it")
