"""A parameter sweep in one batch: how far a crate slides at each friction coefficient.

Thirty-two worlds, one per coefficient ``mu`` from 0.1 to 0.8, each a crate launched at ``v0`` = 4 m/s along a
floor; ``mb.step_worlds`` steps all of them with one call per step.  Coulomb friction decelerates a sliding
crate at ``mu g``, so it stops after ``d = v0^2 / (2 mu g)`` (1.0 m at mu = 0.8, 8.2 m at 0.1); the table
compares the slide with that.  (Stepping the worlds one by one gives the same bits; the batch pays Python's
overhead once per step instead of once per world.)

Run:  python examples/many_worlds.py
"""
import numpy as np

import marbellous as mb

DT = 1.0 / 60.0
V0 = 4.0                  # m/s, the launch speed
G = 9.81                  # m/s^2


def sweep(coefficients, seconds=4.0, threads=1):
    """The slide (m) of the crate at each friction coefficient of ``coefficients`` after ``seconds`` (s)."""
    worlds, crates = [], []
    for mu in coefficients:
        w = mb.World()
        w.add_static(mb.Plane(), friction=float(mu))
        crates.append(w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.0, 0.2, 0.0), velocity=(V0, 0.0, 0.0),
                                 friction=float(mu)))
        worlds.append(w)
    for _ in range(round(seconds / DT)):
        mb.step_worlds(worlds, DT, threads=threads)
    return np.array([c.position[0] for c in crates])


def main():
    coefficients = np.linspace(0.1, 0.8, 32)
    slides = sweep(coefficients)
    print("   mu   slide (m)   v0^2 / (2 mu g) (m)")
    for mu, d in zip(coefficients[::4], slides[::4]):
        print(f"{mu:5.2f}   {d:9.3f}   {V0 ** 2 / (2 * mu * G):9.3f}")


if __name__ == "__main__":
    main()
