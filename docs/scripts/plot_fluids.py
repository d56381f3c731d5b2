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
from marbellous.scenes.cavity import GHIA_U, GHIA_V, GHIA_X, GHIA_Y, ghia_differences, steady_cavities

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "fluids")

def plot_cavity():
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    s = np.linspace(0.0, 1.0, 401)
    for ax, reynolds in zip(axes, (100, 400)):
        fluids = steady_cavities(reynolds)
        for cells, f in fluids.items():
            u = f.velocity_at(np.stack([np.full_like(s, 0.5), s], 1))[:, 0]
            v = f.velocity_at(np.stack([s, np.full_like(s, 0.5)], 1))[:, 1]
            ax.plot(u, s, lw=1.2, label=f"u, {cells}$^2$")
            ax.plot(s, v, lw=1.2, ls="--", label=f"v, {cells}$^2$")
            u_error, v_error = ghia_differences(f, reynolds)
            print(f"Re {reynolds} {cells}^2: largest difference from Ghia u {u_error:.4f}, v {v_error:.4f}")
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
