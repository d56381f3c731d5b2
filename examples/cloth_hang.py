"""A sheet hung by two corners, solved as a whole sheet with its contacts with itself: it swings down, its free
edge curls and folds onto it, and it hangs.

A 1 m sheet of 50 x 50 vertices (0.5 kg, stretch stiffness 1e4 N/m), level at first, is pinned at the two
corners of one side 1.5 m up and let go.  Its springs and hinges are solved together each sub-step
(``w.cloth_stretch_passes = 1``), and so are its contacts with itself: a point pressed onto a triangle of the
sheet gets the force that stops it, and the whole sheet answers that force within the sub-step, where pushing the
one vertex apart would store many times the motion it stopped in its springs (a sheet like this one blew up that
way after 1.4 s).

The script prints the sheet's most stretched edge over the run, and its lowest and fastest vertex at the end;
``--show`` opens the viewer, ``--record out.mp4`` writes a video.

Run:  python examples/cloth_hang.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: vertices per side, side (m), mass (kg), stretch stiffness (N/m) and height (m) of the sheet
N, SIDE, MASS, STIFFNESS, HEIGHT = 50, 1.0, 0.5, 1.0e4, 1.5


def build():
    """The world and the sheet pinned at two corners; returns ``(world, sheet)``."""
    w = mb.World()
    w.cloth_stretch_passes = 1
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    sheet = w.add_cloth(v, t, mass=MASS, stretch_stiffness=STIFFNESS, position=(0.0, HEIGHT, 0.0))
    sheet.pin([0, N - 1])
    return w, sheet


def _edges():
    """The sheet's edges ``(E, 2)`` and their rest lengths (m)."""
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
    return e, np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)


def run(seconds=2.0):
    """The sheet for ``seconds`` (s); returns ``(stretch, lowest, fastest)``: its largest relative stretch of an
    edge over the run, its lowest vertex at the end (m) and its fastest vertex then (m/s)."""
    w, sheet = build()
    e, rest = _edges()
    most = 0.0
    for _ in range(round(seconds / DT)):
        w.step(DT)
        x = sheet.positions
        most = max(most, float(np.max(np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1) / rest)) - 1.0)
    return most, float(sheet.positions[:, 1].min()), float(np.linalg.norm(sheet.velocities, axis=1).max())


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=4.0, stats=True))
    else:
        stretch, lowest, fastest = run()
        print(f"most stretched edge {100 * stretch:.1f} %; lowest vertex {lowest:.3f} m; "
              f"fastest vertex {fastest:.2f} m/s")
