"""Towers of cubes: the solver's pass count and pass order, the lecture's two remedies for tall stacks.

A tower of twenty cubes (0.5 m, 62.5 kg each) stands on the ground for five seconds at 60 Hz, three times:
with the defaults (at most 4 sequential-impulse passes per sub-step, contacts in coloured bundles), with
``adaptive_iterations`` (more passes for deeper stacks) and with ``solve_order = "bottom_up"`` (the same 4
passes, contacts one by one from the ground up: "in order of importance").  The script prints how far the
top cube walked off the tower's axis, and the time per step; ``--show MODE`` (``default``, ``adaptive`` or
``bottom_up``) opens the viewer on that tower instead.

Run:  python examples/stacks.py [--show MODE]
"""
import math
import sys
import time

import marbellous as mb

DT = 1.0 / 60.0
HALF = 0.25
MODES = {"default": {}, "adaptive": {"adaptive_iterations": True}, "bottom_up": {"solve_order": "bottom_up"}}


def build(mode, cubes=20):
    """A world with a tower of ``cubes`` cubes, solved as ``MODES[mode]`` says; returns ``(world, bodies)``."""
    w = mb.World(sleeping=False)
    for name, value in MODES[mode].items():
        setattr(w, name, value)
    w.add_static(mb.Plane(), friction=0.6)
    tower = [w.add_body(mb.Box((HALF, HALF, HALF)), position=(0.0, HALF * (2 * k + 1), 0.0), density=500,
                        friction=0.6) for k in range(cubes)]
    return w, tower


def run(mode, seconds=5.0):
    """Stand the tower for ``seconds`` (s); returns (its top cube's distance from the axis (m), ms per step)."""
    w, tower = build(mode)
    steps = round(seconds / DT)
    w.step(DT)                  # (the first step loads the compiled kernels: not timed)
    start = time.perf_counter()
    for _ in range(steps - 1):
        w.step(DT)
    ms = 1e3 * (time.perf_counter() - start) / (steps - 1)
    x, _, z = tower[-1].position
    return math.hypot(x, z), ms


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build(sys.argv[sys.argv.index("--show") + 1])[0])
    else:
        for mode in MODES:
            drift, ms = run(mode)
            print(f"{mode:>9s}: top cube {100 * drift:5.1f} cm off the axis after 5 s, {ms:.3f} ms per step")
