"""A heavy crate on a light sheet: the particles' step takes the sub-steps the load needs.

A 1 m sheet of 21 x 21 vertices and 0.2 kg is held at its four corners 1 m up, and a 10 kg crate (0.3 x 0.1 x
0.3 m) falls onto it from 0.5 m: fifty times the sheet's mass.  Each sub-step solves the sheet's springs one pass at
a time, and a contact hands the crate a share of its push that shrinks with the ratio of the crate's mass to that
of the vertices under it: the crate presses into them by ``g h^2 r`` at sub-steps of ``h``, and at the default 16
this crate would go through the sheet within a fifth of a second.  Left automatic (``World.particle_substeps`` is
None by default), the step finds the crate lying on the sheet and takes ``dt sqrt(g r / LOAD_SAG)`` sub-steps (57
once it rests, up to 128 for a step as it lands on an edge; ``deformables/load_substeps.py``): the crate bounces
on the sheet and comes to rest on it.

The script prints the sub-steps taken and where the crate rests; ``--show`` opens the viewer, ``--record out.mp4``
writes a video.

Run:  python examples/cloth_load.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: vertices per side, side (m), mass (kg) and height (m) of the sheet; the crate's half extents (m), mass (kg)
#: and drop above the sheet (m)
N, SIDE, SHEET_MASS, HEIGHT = 21, 1.0, 0.2, 1.0
HALF, CRATE_MASS, DROP = (0.15, 0.05, 0.15), 10.0, 0.5


def build():
    """The world: ground, the sheet held at its corners, the crate above its middle; returns ``(world, sheet,
    crate)``."""
    w = mb.World()
    w.add_static(mb.Plane())
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    sheet = w.add_cloth(v, t, mass=SHEET_MASS, position=(0.0, HEIGHT, 0.0), damping=1.0)
    sheet.pin([0, N - 1, N * (N - 1), N * N - 1])
    crate = w.add_body(mb.Box(HALF), position=(0.0, HEIGHT + HALF[1] + DROP, 0.0), mass=CRATE_MASS)
    return w, sheet, crate


def run(seconds=6.0):
    """The drop for ``seconds`` (s); returns a dict: ``substeps`` (the most the particles' step took),
    ``gap`` (m: the crate's underside above the sheet's middle vertex), ``speed`` (m/s, the crate's) and
    ``thickness`` (m, the sheet's)."""
    w, sheet, crate = build()
    most = 0
    for _ in range(round(seconds / DT)):
        w.step(DT)
        most = max(most, w.particle_substeps_taken)
    middle = sheet.positions[(N // 2) * N + N // 2]
    return dict(substeps=most, gap=float(crate.position[1] - HALF[1] - middle[1]),
                speed=float(np.linalg.norm(crate.velocity)), thickness=float(sheet.thickness))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=6.0, stats=True))
    else:
        r = run()
        print(f"the particles' step took up to {r['substeps']} sub-steps; the crate rests "
              f"{1e3 * r['gap']:.1f} mm above the sheet's middle (its thickness {1e3 * r['thickness']:.0f} mm), "
              f"moving at {r['speed']:.4f} m/s")
