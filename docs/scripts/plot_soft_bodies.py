"""Figures for the lecture map's soft-body page.

- ``ringing.png``: a fixed-free bar (1 m, E = 10 kPa, 1000 kg/m^3, Poisson's ratio 0), stretched uniformly by 1%
  and let go, stepped at 60 Hz: its free end's displacement against the exact solution of the wave equation,
  a triangle wave of period 4 L / c (c = sqrt(E / rho)), for 20 and 5 elements along the bar.
- ``cantilever.png``: a cantilever (1 m x 0.1 m x 0.1 m, E = 100 MPa) under its own weight: the free end's
  deflection over Euler-Bernoulli's q L^4 / (8 E I) as the mesh is refined (linear tetrahedra lock in
  bending).

Prints the numbers it plots.  Run from the repository's root:  python docs/scripts/plot_soft_bodies.py
"""
import os

import matplotlib
import numpy as np

import marbellous as mb

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "soft-bodies")
G = 9.81


def ringing(cells, seconds=5.0, length=1.0, E=1e4, rho=1000.0, strain=0.01):
    """Times (s) and the free end's displacement (m) of the stretched, released bar."""
    v, t = mb.tet_box((0.05, length / 2, 0.05), (1, cells, 1))
    w = mb.World(gravity=(0, 0, 0))
    s = w.add_soft_body(v, t, density=rho, young_modulus=E, poisson_ratio=0.0)
    s.pin(np.nonzero(v[:, 1] > length / 2 - 1e-9)[0])
    x = v.copy()
    x[:, 1] = length / 2 + (v[:, 1] - length / 2) * (1 + strain)
    s.positions = x
    end = v[:, 1] < -length / 2 + 1e-9
    times, tip = [0.0], [-strain * length]
    for k in range(round(seconds * 60)):
        w.step(1 / 60)
        times.append((k + 1) / 60)
        tip.append(s.positions[end, 1].mean() - v[end, 1].mean())
    return np.array(times), np.array(tip)


def triangle_wave(times, length=1.0, E=1e4, rho=1000.0, strain=0.01):
    """The exact free-end displacement of the bar: -strain L at t = 0, +strain L at half the period 4 L / c,
    linear in between (d'Alembert)."""
    period = 4 * length / np.sqrt(E / rho)
    phase = (times / period) % 1.0
    return -strain * length * (1 - 4 * np.minimum(phase, 1 - phase))


def cantilever(cells, length=1.0, depth=0.1, E=1e8, rho=1000.0):
    """The free end's deflection (m) of the cantilever after 2 s."""
    v, t = mb.tet_box((length / 2, depth / 2, depth / 2), cells)
    w = mb.World(gravity=(0, -G, 0))
    s = w.add_soft_body(v, t, density=rho, young_modulus=E, poisson_ratio=0.0, damping=0.002)
    s.pin(np.nonzero(v[:, 0] < -length / 2 + 1e-9)[0])
    for _ in range(120):
        w.step(1 / 60)
    tip = v[:, 0] > length / 2 - 1e-9
    return -(s.positions[tip, 1] - v[tip, 1]).mean()


def main():
    fig, ax = plt.subplots(figsize=(7, 3.2))
    times = np.linspace(0, 5, 2000)
    ax.plot(times, 1e3 * triangle_wave(times), "k-", lw=1, label="wave equation (exact)")
    for cells, colour in ((20, "C0"), (5, "C1")):
        t, tip = ringing(cells)
        ax.plot(t, 1e3 * tip, ".", color=colour, ms=3, label=f"{cells} elements along the bar, 60 Hz")
        print(f"ringing, {cells} cells: tip at 5 s {1e3 * tip[-1]:.2f} mm (exact {1e3 * triangle_wave(t)[-1]:.2f})")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("free end (mm)")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("A stretched bar let go: the free end against the wave equation")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "ringing.png"), dpi=110)

    beam = 1000.0 * G * 0.01 * 1.0 / (8 * 1e8 * 0.1 ** 4 / 12)
    meshes = [(4, 1, 1), (8, 1, 1), (12, 2, 2), (16, 2, 2), (24, 3, 3)]
    ratios = [cantilever(c) / beam for c in meshes]
    for c, r in zip(meshes, ratios):
        print(f"cantilever {c}: {r:.3f} of beam theory")
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.plot([np.prod(c) * 6 for c in meshes], ratios, "o-")
    ax.axhline(1.0, color="k", lw=1)
    ax.set_xscale("log")
    ax.set_xlabel("tetrahedra")
    ax.set_ylabel("deflection / q L^4 / (8 E I)")
    ax.set_ylim(0, 1.1)
    ax.set_title("A cantilever under its own weight")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "cantilever.png"), dpi=110)


if __name__ == "__main__":
    main()
