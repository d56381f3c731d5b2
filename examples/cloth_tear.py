"""Cloth that tears: a heavy ball punches through a sheet pinned along its border, and a sheet hung by its
corners tears off its pins.

Two 1 m sheets of 20 x 20 vertices (0.2 kg, stretch stiffness 1e4 N/m, ``tear_strain=0.1``: an edge tears once
stretched by 10 %) are held 1 m up, and a 5 kg ball falls on each from 1 m.  The first is pinned all along
its border: the ball stretches the middle until its edges tear, the mesh splits along the tears, and the ball
drops through the hole with a few scraps.  The second hangs by its four corners: the edges at the corners carry
the whole load, their cracks run in from the border, and the sheet tears off its pins and falls with the ball,
each pin keeping a scrap.

The script prints, for each sheet, how many edges tore, how many pieces the cloth is in, and where the ball and
the largest piece are; ``--show`` opens the viewer on the first, ``--record out.mp4`` writes a video of it.

Run:  python examples/cloth_tear.py [--show | --record out.mp4]
"""
import sys

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

import marbellous as mb

DT = 1.0 / 60.0
#: vertices per side, side (m), mass (kg), height (m) and tear strain of the sheet; the ball's radius (m), mass
#: (kg) and drop above the sheet (m)
N, SIDE, SHEET_MASS, HEIGHT, TEAR = 20, 1.0, 0.2, 1.0, 0.1
RADIUS, BALL_MASS, DROP = 0.1, 5.0, 1.0


def build(hold):
    """The world with a sheet held by ``hold`` (``"border"`` or ``"corners"``) and the ball above its middle;
    returns ``(world, sheet, ball)``."""
    w = mb.World()
    w.add_static(mb.Plane())
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    sheet = w.add_cloth(v, t, mass=SHEET_MASS, tear_strain=TEAR, position=(0.0, HEIGHT, 0.0))
    index = np.arange(N * N).reshape(N, N)
    if hold == "border":
        sheet.pin(np.unique(np.concatenate([index[0], index[-1], index[:, 0], index[:, -1]])))
    else:
        sheet.pin([index[0, 0], index[0, -1], index[-1, 0], index[-1, -1]])
    ball = w.add_body(mb.Sphere(RADIUS), position=(0.05, HEIGHT + DROP, 0.05), mass=BALL_MASS)
    return w, sheet, ball


def pieces(sheet):
    """``(number of pieces, each vertex's piece)``: the cloth's connected parts by its triangles as they are now."""
    t = sheet.triangles
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    n = len(sheet)
    return connected_components(coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)), directed=False)


def run(seconds=1.5):
    """Both drops for ``seconds`` (s); returns ``{hold: (torn edges, pieces, the ball's height (m), the highest
    point of the largest piece (m), pinned vertices)}``."""
    out = {}
    for hold in ("border", "corners"):
        w, sheet, ball = build(hold)
        for _ in range(round(seconds / DT)):
            w.step(DT)
        count, label = pieces(sheet)
        largest = label == np.argmax(np.bincount(label))
        out[hold] = (sheet.torn, count, float(ball.position[1]), float(sheet.positions[largest, 1].max()),
                     int(np.count_nonzero(sheet.pinned)))
    return out


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build("border")[0])
    elif "--record" in sys.argv:
        print(mb.record(build("border")[0], sys.argv[sys.argv.index("--record") + 1], seconds=2.0, stats=True))
    else:
        for hold, (torn, count, ball_y, top, pinned) in run().items():
            print(f"held by its {hold}: {torn} edges torn, {count} pieces, {pinned} pins; ball at {ball_y:.2f} m, "
                  f"the largest piece's top at {top:.2f} m")
