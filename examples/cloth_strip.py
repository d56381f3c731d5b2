"""A plank and a log laid across strips of cloth: a body's edges meet a cloth where the cloth ends.

Two strips of cloth, each 1 m long and 0.3 m wide and a single quad (four vertices, two triangles), are held at
their corners 1 m up.  A plank 0.8 m long (a box) is dropped square across the first, and a log (a capsule of
radius 5 cm whose segment is 0.8 m long) across the second, turned by 0.5 rad.  Their ends stick out beyond the
strips and no vertex of a strip lies under them, so neither corners nor vertices can hold them: they rest on the
strips' long edges, where an edge of the box, or the capsule's segment, passes over the border of the cloth
(``deformables/corner_contacts.py``), half the cloth's thickness above it.

The script prints where they rest; ``--show`` opens the viewer, ``--record out.mp4`` writes a video.

Run:  python examples/cloth_strip.py [--show | --record out.mp4]
"""
import math
import sys

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
#: the strips: length, width, height (m), and the middles of the two (m, x and z)
LENGTH, WIDTH, HEIGHT = 1.0, 0.3, 1.0
MIDDLES = ((0.0, 0.0), (1.5, 0.0))
#: the plank's half extents (m); the log's radius and half length (m); their mass (kg) and drop (m)
PLANK_HALF = (0.05, 0.05, 0.4)
LOG_RADIUS, LOG_HALF_LENGTH = 0.05, 0.4
MASS, DROP = 1.0, 0.3
#: the log's turn about the vertical (rad) from square across its strip
LOG_YAW = 0.5


def build():
    """The world: ground, the two strips held at their corners, the plank and the log above them; returns
    ``(world, parts)``, ``parts`` a dict of their handles."""
    w = mb.World()
    w.add_static(mb.Plane())
    strips = []
    for x, z in MIDDLES:
        v, t = mb.cloth_grid(LENGTH, WIDTH, 2, 2)          # one quad along x
        strip = w.add_cloth(v, t, mass=0.1, position=(x, HEIGHT, z))
        strip.pin([0, 1, 2, 3])
        strips.append(strip)
    (x0, z0), (x1, z1) = MIDDLES
    plank = w.add_body(mb.Box(PLANK_HALF), position=(x0, HEIGHT + DROP, z0), mass=MASS)
    # the capsule's segment along its local y, laid along z, then turned about the vertical
    c, s = math.cos(0.5 * LOG_YAW), math.sin(0.5 * LOG_YAW)
    down = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
    log = w.add_body(mb.Capsule(LOG_RADIUS, LOG_HALF_LENGTH), position=(x1, HEIGHT + DROP, z1),
                     orientation=(c * down[0], c * down[1], s * down[0], -s * down[1]), mass=MASS)
    return w, dict(strips=strips, plank=plank, log=log)


def run(seconds=2.0):
    """Step the scene for ``seconds`` (s); returns a dict of how it ended: ``plank_height`` and ``log_height`` (m,
    their centres), ``plank_speed`` and ``log_speed`` (m/s), and ``thickness`` (m, the strips')."""
    w, parts = build()
    for _ in range(round(seconds / DT)):
        w.step(DT)
    plank, log = parts["plank"], parts["log"]
    return dict(plank_height=float(plank.position[1]), log_height=float(log.position[1]),
                plank_speed=float(np.linalg.norm(plank.velocity)), log_speed=float(np.linalg.norm(log.velocity)),
                thickness=float(parts["strips"][0].thickness))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    elif "--record" in sys.argv:
        print(mb.record(build()[0], sys.argv[sys.argv.index("--record") + 1], seconds=2.0, stats=True))
    else:
        r = run()
        rest = HEIGHT + 0.5 * r["thickness"]          # half the cloth's thickness above the strip
        for name, half in (("plank", PLANK_HALF[1]), ("log", LOG_RADIUS)):
            print(f"{name}: its centre {r[name + '_height']:.4f} m up, its underside "
                  f"{1e3 * (r[name + '_height'] - half - rest):+.3f} mm from half the cloth's thickness above the "
                  f"strip, moving at {r[name + '_speed']:.5f} m/s")
