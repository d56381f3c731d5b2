"""A box on a trampoline of stiff cloth, solved as a whole sheet: it bounces, and comes to rest where box and sheet
have their least energy.

A 1 m sheet of 21 x 21 vertices (0.2 kg, stretch stiffness 1e4 N/m) is pinned all round 1 m up, and a 2 kg box
(0.28 m square, 0.1 m high) falls onto it from 0.5 m.  The sheet's springs are solved together each sub-step
(``w.cloth_stretch_passes = 1``: one backward-Euler step of the whole sheet), and so are the box's contacts with
it: a push on one vertex moves the whole sheet within the sub-step, and the box gets the force that holds the
sheet, not the pull of the one vertex it pressed.  The box bounces lower each time (the sheet's damping) and
settles on the sagging sheet.

The script prints the box's height at each bounce's top and where it rests; ``--show`` opens the viewer,
``--record out.mp4`` writes a video.

Run:  python examples/cloth_trampoline.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: vertices per side, side (m), mass (kg) and height (m) of the sheet; the box's half extents (m), mass (kg) and
#: drop above the sheet (m)
N, SIDE, SHEET_MASS, HEIGHT = 21, 1.0, 0.2, 1.0
HALF, BOX_MASS, DROP = (0.14, 0.05, 0.14), 2.0, 0.5


def build():
    """The world: ground, the sheet pinned along its border, the box above its middle; returns ``(world, sheet,
    box)``."""
    w = mb.World()
    w.cloth_stretch_passes = 1
    w.add_static(mb.Plane())
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    sheet = w.add_cloth(v, t, mass=SHEET_MASS, position=(0.0, HEIGHT, 0.0), damping=2.0, self_collision=False)
    index = np.arange(N * N).reshape(N, N)
    sheet.pin(np.unique(np.concatenate([index[0], index[-1], index[:, 0], index[:, -1]])))
    box = w.add_body(mb.Box(HALF), position=(0.0, HEIGHT + HALF[1] + DROP, 0.0), mass=BOX_MASS)
    return w, sheet, box


def run(seconds=6.0):
    """The drop for ``seconds`` (s); returns ``(tops, rest, fastest)``: the box's height (m) at the top of each
    bounce, where it rests at the end (m), and the sheet's fastest vertex then (m/s)."""
    w, sheet, box = build()
    heights = []
    for _ in range(round(seconds / DT)):
        w.step(DT)
        heights.append(float(box.position[1]))
    h = np.array(heights)
    tops = [float(h[i]) for i in range(1, len(h) - 1) if h[i - 1] < h[i] >= h[i + 1] and h[i] > h[i - 1] + 1e-4]
    return tops, float(box.position[1]), float(np.linalg.norm(sheet.velocities, axis=1).max())


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=4.0, stats=True))
    else:
        tops, rest, fastest = run()
        print("bounce tops (m):", ", ".join(f"{top:.3f}" for top in tops))
        print(f"rests at {rest:.4f} m, {100 * (HEIGHT + HALF[1] - rest):.1f} cm into the sheet; "
              f"fastest vertex {fastest:.4f} m/s")
