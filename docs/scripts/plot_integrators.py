"""Figure for the lecture map: the energy of a mass on a spring under the four integrators.

A 1 kg ball on a Hooke spring of 100 N/m (no gravity, no damping: the energy should stay constant),
pulled 0.2 m from rest length and let go, stepped at 60 Hz with one sub-step for 10 s, once per
integrator.  Energy = kinetic + spring energy, relative to the start.  Writes
``docs/lecture/integrators/energy.png`` and prints the final ratios.

Run from the repository's root:  python docs/scripts/plot_integrators.py
"""
import os

import matplotlib
import numpy as np

import marbellous as mb

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "integrators", "energy.png")
INTEGRATORS = ("explicit_euler", "semi_implicit_euler", "verlet", "rk4")
COLOURS = {"explicit_euler": "C3", "semi_implicit_euler": "C0", "verlet": "C1", "rk4": "C2"}
K, MASS, REST, PULL = 100.0, 1.0, 1.0, 0.2      # N/m, kg, m, m
DT, SECONDS = 1.0 / 60.0, 10.0


def energy_curve(integrator):
    """Times (s) and energy / initial energy of the spring scene under ``integrator``."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator, substeps=1)
    ball = w.add_body(mb.Sphere(0.1), mass=MASS, position=(REST + PULL, 0.0, 0.0))
    w.add_spring(ball, None, rest_length=REST, stiffness=K, anchor_b=(0.0, 0.0, 0.0))

    def energy():
        stretch = np.linalg.norm(ball.position) - REST
        return 0.5 * MASS * float(ball.velocity @ ball.velocity) + 0.5 * K * stretch ** 2

    e0 = energy()
    times, ratios = [0.0], [1.0]
    for _ in range(round(SECONDS / DT)):
        w.step(DT)
        times.append(w.time)
        ratios.append(energy() / e0)
    return np.array(times), np.array(ratios)


def main():
    curves = {name: energy_curve(name) for name in INTEGRATORS}
    fig, (left, right) = plt.subplots(1, 2, figsize=(9.6, 3.6), dpi=100)
    for name, (t, e) in curves.items():
        left.semilogy(t, e, label=name, color=COLOURS[name], lw=1.0)
        if name != "explicit_euler":
            right.plot(t, e, label=name, color=COLOURS[name], lw=0.8)
        print(f"{name:20s} energy after {SECONDS:g} s: {e[-1]:.6g} x the start (min {e.min():.4f}, max {e.max():.4g})")
    left.set_title("all four (log scale)", fontsize=10)
    right.set_title("the three that stay bounded", fontsize=10)
    for ax in (left, right):
        ax.set_xlabel("time (s)")
        ax.set_ylabel("energy / initial energy")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", framealpha=0.9)
    right.set_ylim(0.85, 1.2)
    fig.suptitle("Mass on a spring, k = 100 N/m, m = 1 kg, h = 1/60 s (period 0.63 s)", fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    fig.savefig(OUT)
    print(OUT)


if __name__ == "__main__":
    main()
