"""Quick start: a ball on a spring swinging from a fixed point, integrated four ways.

Run:  python examples/quickstart.py
"""
import math

import marbellous as mb


def spring_period(integrator, k=100.0, m=1.0, dt=1.0 / 120.0):
    """Measure the period of a mass on a vertical Hooke spring (closed form ``2 pi sqrt(m/k)``)."""
    w = mb.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
    ball = w.add_body(mb.Sphere(0.1), mass=m, position=(0.0, -1.2, 0.0))
    w.add_spring(ball, None, rest_length=1.0, stiffness=k, anchor_b=(0.0, 0.0, 0.0))
    crossings, prev = [], ball.position[1] + 1.0
    while len(crossings) < 3 and w.time < 10.0:
        w.step(dt)
        y = ball.position[1] + 1.0
        if prev < 0.0 <= y:
            crossings.append(w.time - dt * y / (y - prev))
        prev = y
    return crossings[-1] - crossings[-2]


if __name__ == "__main__":
    exact = 2.0 * math.pi * math.sqrt(1.0 / 100.0)
    print(f"Hooke period, closed form: {exact:.5f} s")
    for name in ("explicit_euler", "semi_implicit_euler", "verlet", "rk4"):
        print(f"  {name:20s} {spring_period(name):.5f} s")
