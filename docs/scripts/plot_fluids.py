"""Figures for the lecture map's fluids page.

- ``cavity.png``: the lid-driven cavity's steady centre-line profiles (u along the vertical centre line, v along
  the horizontal one) at Re = 100 and 400 on 32^2, 64^2 and 128^2 grids, against the points of Ghia, Ghia &
  Shin (1982).
- ``taylor-green.png``: the Taylor-Green vortex's kinetic energy over one decay time at Re = 100 on 32^2, 64^2
  and 128^2 grids, against exp(-4 nu k^2 t).
- ``scene.png``: a world with a fluid: a ball floating in a pool, a dense box sinking, dye in the flow.

Prints the numbers it plots.  Run from the repository's root:  python docs/scripts/plot_fluids.py
"""
import math
import os

import matplotlib
import numpy as np

import marbellous as mb

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "fluids")

GHIA_Y = [1.0, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5, 0.4531, 0.2813, 0.1719, 0.1016,
          0.0703, 0.0625, 0.0547, 0.0]
GHIA_X = [1.0, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5, 0.2344, 0.2266, 0.1563, 0.0938,
          0.0781, 0.0703, 0.0625, 0.0]
GHIA_U = {100: [1.0, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090, -0.15662,
                -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.0],
          400: [1.0, 0.75837, 0.68439, 0.61756, 0.55892, 0.29093, 0.16256, 0.02135, -0.11477, -0.17119, -0.32726,
                -0.24299, -0.14612, -0.10338, -0.09266, -0.08186, 0.0]}
GHIA_V = {100: [0.0, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454, 0.17527,
                0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.0],
          400: [0.0, -0.12146, -0.15663, -0.19254, -0.22847, -0.23827, -0.44993, -0.38598, 0.05186, 0.30174,
                0.30203, 0.28124, 0.22965, 0.20920, 0.19713, 0.18360, 0.0]}
SCHEDULE = {100: [(32, 20.0), (64, 8.0), (128, 4.0)], 400: [(32, 30.0), (64, 15.0), (128, 5.0)]}


def cavity(reynolds):
    """Steady cavities at each resolution of the schedule, each started from the coarser one's flow."""
    out, previous = {}, None
    for cells, seconds in SCHEDULE[reynolds]:
        f = mb.Fluid((cells, cells), 1.0 / cells, viscosity=1.0 / reynolds, density=1.0)
        f.set_wall_velocity("y+", (1.0, 0.0))
        if previous is not None:
            ratio = cells // previous.shape[0]
            f.velocity = np.repeat(np.repeat(previous, ratio, 0), ratio, 1)
        for _ in range(round(seconds * cells)):
            f.step(1.0 / cells)
        out[cells], previous = f, f.velocity
    return out


def plot_cavity():
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    s = np.linspace(0.0, 1.0, 401)
    for ax, reynolds in zip(axes, (100, 400)):
        fluids = cavity(reynolds)
        for cells, f in fluids.items():
            u = f.velocity_at(np.stack([np.full_like(s, 0.5), s], 1))[:, 0]
            v = f.velocity_at(np.stack([s, np.full_like(s, 0.5)], 1))[:, 1]
            ax.plot(u, s, lw=1.2, label=f"u, {cells}$^2$")
            ax.plot(s, v, lw=1.2, ls="--", label=f"v, {cells}$^2$")
            gu = f.velocity_at(np.stack([np.full(17, 0.5), GHIA_Y], 1))[:, 0] - GHIA_U[reynolds]
            gv = f.velocity_at(np.stack([GHIA_X, np.full(17, 0.5)], 1))[:, 1] - GHIA_V[reynolds]
            print(f"Re {reynolds} {cells}^2: largest difference from Ghia u {np.abs(gu).max():.4f}, "
                  f"v {np.abs(gv).max():.4f} (v without x = 0.9063: {np.abs(np.delete(gv, 5)).max():.4f})")
        ax.plot(GHIA_U[reynolds], GHIA_Y, "ko", ms=4, mfc="none", label="Ghia et al. 1982")
        ax.plot(GHIA_X, GHIA_V[reynolds], "ks", ms=4, mfc="none")
        ax.set_title(f"Lid-driven cavity, Re = {reynolds}")
        ax.set_xlabel("u (at y) and x (for v)")
        ax.set_ylabel("y (for u) and v (at x)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "cavity.png"), dpi=110)


def plot_taylor_green():
    nu = 0.01
    duration = 1.0 / (4 * nu)
    fig, ax = plt.subplots(figsize=(6, 4))
    for cells in (32, 64, 128):
        f = mb.Fluid((cells, cells), 2 * math.pi / cells, viscosity=nu, density=1.0, boundary="periodic")
        f.set_velocity(lambda p: np.stack([np.sin(p[:, 0]) * np.cos(p[:, 1]),
                                           -np.cos(p[:, 0]) * np.sin(p[:, 1])], 1))
        start = f.kinetic_energy()
        steps = round(duration / (2.0 * f.cell_size))
        times, energy = [0.0], [1.0]
        for k in range(steps):
            f.step(duration / steps)
            times.append((k + 1) * duration / steps)
            energy.append(f.kinetic_energy() / start)
        print(f"Taylor-Green {cells}^2: energy after one decay time {energy[-1]:.5f}, exact {math.exp(-1):.5f} "
              f"({energy[-1] / math.exp(-1) - 1:+.2%})")
        ax.plot(times, energy, label=f"{cells}$^2$")
    t = np.linspace(0, duration, 100)
    ax.plot(t, np.exp(-4 * nu * t), "k--", label="exp(-4 nu k$^2$ t)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("kinetic energy / initial")
    ax.set_title("Taylor-Green vortex, Re = 100")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "taylor-green.png"), dpi=110)


def scene():
    w = mb.World()
    f = w.add_fluid(mb.Fluid((32, 16, 16), 0.125, origin=(-2.0, 0.0, -1.0), surface=1.2, viscosity=0.05))
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.3), position=(-1.0, 1.6, 0.0), density=500.0)
    w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(1.0, 1.6, 0.0), density=3000.0)
    w.add_kinematic(mb.Capsule(0.15, 0.5), position=(0.0, 1.0, 0.0), velocity=(0.6, 0.0, 0.0))
    dye = np.zeros((32, 16, 16))
    dye[12:16, 2:9, 6:10] = 1.0
    f.dye = dye
    for _ in range(90):
        w.step(1 / 60)
    import PIL.Image
    PIL.Image.fromarray(mb.render_image(w, size=(720, 400))).save(os.path.join(OUT, "scene.png"))


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    scene()
    plot_taylor_green()
    plot_cavity()
