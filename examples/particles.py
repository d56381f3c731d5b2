"""Particles and particle networks: a net that catches balls, a rope that carries a crate, a heap of grain.

- A net of 15 x 15 particles (knots 12 cm across) joined by springs, pinned along its border 1.5 m up,
  catches three balls and a box dropped onto it; they bounce, and come to rest in the sagging net (the net
  pushes the bodies and the bodies push the net: two ways).
- A rope of 30 beads joined by rods hangs from a fixed point; its last bead is pinned to a 2.7 kg crate,
  which swings on it (the rope's 3 kg of beads keep the load's ratio low: one position pass per sub-step
  hands a heavy load up a chain of light beads slowly, and the rope would stretch).
- 600 grains (particles that collide with each other) pour into a bowl of triangles and settle into a heap.

The script prints where things came to rest; ``--show`` opens the viewer instead.

Run:  python examples/particles.py [--show]
"""
import sys

import numpy as np

import marbellous as mb
from marbellous.scenes.terrain import bowl
from marbellous.math3d import quat_to_matrix_np

DT = 1.0 / 60.0


def grid_edges(n):
    """The edges of an ``n`` x ``n`` grid of particles numbered row by row: rows, columns and both
    diagonals (the diagonals resist shearing)."""
    index = np.arange(n * n).reshape(n, n)
    pairs = [(index[:, :-1], index[:, 1:]), (index[:-1, :], index[1:, :]), (index[:-1, :-1], index[1:, 1:]),
             (index[:-1, 1:], index[1:, :-1])]
    return np.vstack([np.column_stack([a.ravel(), b.ravel()]) for a, b in pairs])


def build(seed=2):
    """The three scenes side by side; returns ``(world, parts)``, ``parts`` a dict of their handles."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.6)
    # the net, centred on the origin
    n, size = 15, 2.0
    g = np.linspace(-0.5 * size, 0.5 * size, n)
    xs, zs = np.meshgrid(g, g, indexing="ij")
    # (the net is its particles: bodies touch them, not the springs, so the knots are large enough that the gaps
    # between them stay narrower than the balls as the net stretches)
    net = w.add_particles(np.column_stack([xs.ravel(), np.full(n * n, 1.5), zs.ravel()]), mass=0.02, radius=0.06,
                          damping=2.0)
    w.add_network(net, grid_edges(n), kind="spring", stiffness=4000.0, damping=40.0)
    index = np.arange(n * n).reshape(n, n)
    net.pin(np.concatenate([index[0], index[-1], index[:, 0], index[:, -1]]))
    drops = [w.add_body(mb.Sphere(0.15), position=(x, 2.2 + 0.5 * k, z), density=200.0, restitution=0.3)
             for k, (x, z) in enumerate([(0.0, 0.0), (0.4, 0.3), (-0.3, -0.4)])]
    drops.append(w.add_body(mb.Box((0.15, 0.1, 0.2)), position=(-0.4, 3.8, 0.3), density=200.0))
    # the rope, 4 m to the side
    beads = 30
    top = np.array([4.0, 3.0, 0.0])
    rope = w.add_particles([top + (0.08 * k, 0.0, 0.0) for k in range(beads + 1)], mass=0.1, radius=0.02)
    w.add_network(rope, np.column_stack([np.arange(beads), np.arange(1, beads + 1)]), kind="rod")
    crate = w.add_body(mb.Box((0.15, 0.15, 0.15)), position=top + (0.08 * beads, -0.15, 0.0), density=100.0)
    rope.pin([0])
    rope.pin([beads], body=crate)
    # the grain, 4 m the other way
    surface = bowl(radius=1.5, depth=0.8)
    w.add_static(surface, position=(-4.5, 0.0, 0.0), friction=0.6)
    lattice = np.stack(np.meshgrid(np.arange(10), np.arange(6), np.arange(10), indexing="ij"), -1).reshape(-1, 3)
    grain = w.add_particles(lattice * 0.09 + (-4.9, 1.0, -0.4) + rng.uniform(-0.01, 0.01, (600, 3)), mass=0.01,
                            radius=0.04, friction=0.6, collide_particles=True)
    return w, dict(net=net, drops=drops, rope=rope, crate=crate, top=top, grain=grain)


def run(seconds=6.0):
    """Step the scenes for ``seconds`` (s); returns a dict of how they ended: ``fastest_drop`` (m/s, the
    fastest dropped body), ``drops_above_net`` (m, the lowest dropped body's bottom above the net's lowest
    particle's centre), ``net_lowest`` (m), ``rope_stretch`` (the longest rope link over its length, - 1),
    ``crate_hangs`` (m, the crate's top below the rope's last bead: 0 when it hangs on it), ``grain_overlap``
    (m, the deepest overlap of two grains), ``grain_spilled`` (grains outside the bowl) and ``fastest_grain``
    (m/s)."""
    w, parts = build()
    for _ in range(round(seconds / DT)):
        w.step(DT)
    net = parts["net"].positions
    drops = parts["drops"]
    rope = parts["rope"].positions
    grain = parts["grain"].positions
    d = np.linalg.norm(grain[:, None] - grain[None], axis=-1) + np.eye(len(grain))
    crate = parts["crate"]
    return dict(
        fastest_drop=max(float(np.linalg.norm(b.velocity)) for b in drops),
        drops_above_net=min(float(b.position[1]) - 0.15 for b in drops) - float(net[:, 1].min()),
        net_lowest=float(net[:, 1].min()),
        rope_stretch=float(np.max(np.linalg.norm(np.diff(rope, axis=0), axis=1)) / 0.08 - 1.0),
        crate_hangs=float(np.linalg.norm(crate.position + quat_to_matrix_np(crate.orientation) @ (0.0, 0.15, 0.0)
                                          - rope[-1])),
        grain_overlap=float(max(0.0, 0.08 - d.min())),
        grain_spilled=int(np.sum(np.hypot(grain[:, 0] + 4.5, grain[:, 2]) > 1.5)),
        fastest_grain=float(np.abs(parts["grain"].velocities).max()))


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    else:
        r = run()
        print(f"net: lowest point {r['net_lowest']:.3f} m (pinned at 1.5 m); the dropped bodies rest on it, the "
              f"fastest at {r['fastest_drop']:.4f} m/s")
        print(f"rope: its longest link {100 * r['rope_stretch']:.3f} % over its length; the crate "
              f"{1e3 * r['crate_hangs']:.2f} mm from the rope's end")
        print(f"grain: deepest overlap {1e3 * r['grain_overlap']:.2f} mm, {r['grain_spilled']} spilled, the fastest "
              f"grain at {r['fastest_grain']:.4f} m/s")
