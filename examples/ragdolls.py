"""Ragdolls down the stairs, and a marble on a rope bridge: ball joints and hinges with limits.

Each ragdoll is ten capsules and a head held by ball joints (neck, shoulders, hips) and hinges with limits
(elbows, knees); pushed off the landing, they tumble down a flight of ten steps.  Beside them a marble
drops onto a bridge of thirty planks hinged edge to edge.  The script prints where they ended and how far
the joints ever opened; with ``--show`` it opens the viewer instead.

Run:  python examples/ragdolls.py [--show]
"""
import sys

import numpy as np

import marbellous as mb
from marbellous.scenes import plank_bridge, ragdoll, stairs


def build(ragdolls=3):
    """The stairs with ``ragdolls`` ragdolls on the landing, and the bridge 4 m to the side with a marble
    above its middle; returns ``(world, parts, joints, marble)``."""
    w, top = stairs(mb.World())
    parts, joints = [], []
    for k in range(ragdolls):
        p, j = ragdoll(w, position=((k - (ragdolls - 1) / 2) * 0.8, top, -0.3 - 0.4 * k), velocity=(0.0, 0.0, 1.5))
        parts.append(p)
        joints += j
    _, planks, hinges = plank_bridge(w, origin=(4.0, 0.0, -2.0))
    marble = w.add_body(mb.Sphere(0.25), mass=5.0, position=planks[15].position + (0.1, 0.8, 0.0))
    return w, parts, joints + hinges, marble


def run(steps=300, dt=1.0 / 60.0):
    """Step the scene; returns (the torsos' final positions (m), the marble's (m), the widest joint gap (m))."""
    w, parts, joints, marble = build()
    worst = 0.0
    for _ in range(steps):
        w.step(dt)
        worst = max(worst, max(j.separation for j in joints))
    return [p["torso"].position for p in parts], marble.position, worst


if __name__ == "__main__":
    if "--show" in sys.argv:
        mb.show(build()[0])
    else:
        torsos, marble, worst = run()
        for k, t in enumerate(torsos):
            print(f"ragdoll {k}: torso at {np.round(t, 2)} m (the landing is 2 m high, its edge at z = 0)")
        print(f"marble at {np.round(marble, 2)} m, on the bridge (its anchors are 3 m high)")
        print(f"the widest any joint opened: {1e3 * worst:.2f} mm")
