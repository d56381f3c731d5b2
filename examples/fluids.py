"""Fluids: a pool with a wave-maker, a floating ball, a sinking crate and a cloud of dye.

- The pool is a 4 m x 2 m x 2 m box of liquid (a Navier-Stokes grid of 32 x 16 x 16 cells, 12.5 cm each) whose
  surface is 1.2 m up; the liquid is as viscous as thin syrup (0.05 m^2/s) so that things settle in seconds.
- A paddle (a kinematic box) moves through it at 0.4 m/s: the liquid flows around the paddle and is pushed
  along by it.
- A ball of half the liquid's density, dropped in, floats with half of itself under the surface: its centre
  comes to rest at the surface.
- A crate three times as dense sinks to the floor.
- Dye let into the liquid near the paddle is carried and stirred by the flow.

The viewer draws the pool's box and surface, the dye as blue puffs and the flow on the middle slices as
arrows (the ``fluids`` and ``flow`` layers).

The script prints where things ended; ``--show`` opens the viewer instead, ``--record out.mp4`` writes a video.

Run:  python examples/fluids.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: the pool's cells and their side (m), its lower corner (m) and the surface's height (m)
CELLS, CELL, CORNER, SURFACE = (32, 16, 16), 0.125, (-2.0, 0.0, -1.0), 1.2
#: the paddle's half extents (m) and its speed (m/s)
PADDLE, PADDLE_SPEED = (0.05, 0.5, 0.5), 0.4


def build():
    """The pool and what is in it; returns ``(world, parts)``, ``parts`` a dict of their handles."""
    w = mb.World()
    w.add_static(mb.Plane())
    pool = w.add_fluid(mb.Fluid(CELLS, CELL, origin=CORNER, surface=SURFACE, viscosity=0.05))
    dye = np.zeros(CELLS)
    dye[8:12, 2:8, 6:10] = 1.0
    pool.dye = dye
    paddle = w.add_kinematic(mb.Box(PADDLE), position=(-1.5, 0.7, 0.0), velocity=(PADDLE_SPEED, 0.0, 0.0))
    ball = w.add_body(mb.Sphere(0.25), position=(0.8, 1.8, 0.7), density=500.0)
    crate = w.add_body(mb.Box((0.15, 0.15, 0.15)), position=(1.3, 1.6, -0.7), density=3000.0)
    return w, dict(pool=pool, paddle=paddle, ball=ball, crate=crate)


def run(seconds=6.0):
    """Step the pool for ``seconds`` (s); returns a dict: ``ball_height`` (m, the ball's centre over the
    surface), ``crate_height`` (m, its centre over the floor), ``dye_spread`` (m, the dye's spread, rms about
    its middle), ``largest_divergence`` (the most volume a cell gained or lost in any step, as a fraction)."""
    w, parts = build()
    pool = parts["pool"]
    worst = 0.0
    for _ in range(round(seconds / DT)):
        w.step(DT)
        worst = max(worst, float(np.abs(pool.divergence()).max()) * DT)
    dye = np.clip(pool.dye, 0.0, None)
    centres = np.stack(np.meshgrid(*[(np.arange(n) + 0.5) * CELL for n in CELLS], indexing="ij"), -1)
    middle = (centres * dye[..., None]).sum(axis=(0, 1, 2)) / dye.sum()
    spread = np.sqrt((((centres - middle) ** 2).sum(-1) * dye).sum() / dye.sum())
    return dict(ball_height=float(parts["ball"].position[1] - SURFACE),
                crate_height=float(parts["crate"].position[1]), dye_spread=float(spread), largest_divergence=worst)


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=6.0, stats=True))
    else:
        r = run()
        print(f"ball: its centre {1e3 * r['ball_height']:+.1f} mm from the surface (half-density: floats half in)")
        print(f"crate: its centre {r['crate_height']:.3f} m above the floor (sunk)")
        print(f"dye: spread {r['dye_spread']:.2f} m about its middle; no cell gained or lost more than "
              f"{r['largest_divergence']:.1e} of its volume in a step")
