"""Stiff, fine cloth: the same sheet draped over a sphere with its springs solved one at a time and all at once.

Two 1 m sheets of 64 x 64 vertices (0.5 kg, stretch stiffness 1e4 N/m) fall 0.5 m onto a sphere of radius
0.3 m, in two worlds at 60 Hz with 16 particle sub-steps.  In the first each spring pulls its two vertices in
turn (position-based, a pass per sub-step): a load crosses the sheet one spring per pass, and so fine and stiff
a sheet stretches where it hangs over the sphere.  In the second (``w.cloth_stretch_passes = 1``) each sub-step
takes one backward-Euler step of all its springs and hinges at once, a linear solve with a matrix factored when
the sheet is made: its edges stay within a few per cent of their length.  (Self collision is off in both, to
keep the comparison about the stretch.)

The script prints each sheet's most stretched edge and fastest vertex; ``--show`` opens the viewer on the
second, ``--record out.mp4`` writes a video of it.

Run:  python examples/cloth_stiff.py [--show | --record out.mp4]
"""
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: vertices per side, side (m), mass (kg); the sphere's radius (m); the drop above its top (m)
N, SIDE, MASS, RADIUS, DROP = 64, 1.0, 0.5, 0.3, 0.5


def build(passes):
    """A world with the sphere on the ground and the sheet above it, its stretch solved with ``passes`` whole-cloth
    passes per sub-step (0: a spring at a time); returns ``(world, sheet)``."""
    w = mb.World()
    w.cloth_stretch_passes = passes
    w.add_static(mb.Plane(), friction=0.5)
    w.add_static(mb.Sphere(RADIUS), position=(0.0, RADIUS, 0.0), friction=0.5)
    v, t = mb.cloth_grid(SIDE, SIDE, N, N)
    sheet = w.add_cloth(v, t, mass=MASS, position=(0.0, 2 * RADIUS + DROP, 0.0), self_collision=False)
    return w, sheet


def stretch(sheet):
    """The largest relative stretch of the sheet's edges (length over rest length, less one)."""
    rest, t = mb.cloth_grid(SIDE, SIDE, N, N)
    e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
    x = sheet.positions
    return float(np.max(np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
                        / np.linalg.norm(rest[e[:, 0]] - rest[e[:, 1]], axis=1)) - 1.0)


def run(seconds=2.0):
    """Both sheets for ``seconds`` (s); returns ``{passes: (largest stretch, fastest vertex (m/s), lowest vertex
    (m))}`` for passes 0 and 1."""
    out = {}
    for passes in (0, 1):
        w, sheet = build(passes)
        for _ in range(round(seconds / DT)):
            w.step(DT)
        out[passes] = (stretch(sheet), float(np.linalg.norm(sheet.velocities, axis=1).max()),
                       float(sheet.positions[:, 1].min()))
    return out


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build(1)[0])
    elif "--record" in sys.argv:
        print(mb.record(build(1)[0], sys.argv[sys.argv.index("--record") + 1], seconds=3.0, stats=True))
    else:
        for passes, (most, fastest, lowest) in run().items():
            how = "all at once" if passes else "one at a time"
            print(f"springs {how}: most stretched edge {100 * most:.1f} %, fastest vertex {fastest:.2f} m/s, "
                  f"lowest vertex {100 * lowest:.1f} cm up")
