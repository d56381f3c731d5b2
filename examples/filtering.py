"""Collision filtering: a marble rolls through a shower of debris that only the ground stops.

Each body has ``group`` bits (what it is) and ``mask`` bits (what it collides with); two bodies collide
only if each one's group meets the other's mask.  The debris here falls onto the ground and piles up, but
passes through the marble, and a ray cast with ``mask=GROUND`` measures the ground under the marble without
seeing the debris above it.

Run:  python examples/filtering.py
"""
import marbellous as mb

MARBLE, DEBRIS, GROUND = 1, 2, 4


def run(steps=240, dt=1.0 / 60.0):
    """Roll the marble through falling debris; returns (marble x after ``steps`` (m), its speed (m/s),
    lowest debris height (m), ground distance under the marble (m))."""
    w = mb.World()
    w.add_static(mb.Plane(), group=GROUND)
    marble = w.add_body(mb.Sphere(0.3), position=(-3.0, 0.3, 0.0), velocity=(2.0, 0.0, 0.0), group=MARBLE,
                        rolling_friction=0.0)
    debris = [w.add_body(mb.Box((0.1, 0.1, 0.1)), position=(-1.0 + 0.25 * k, 1.0 + 0.3 * k, 0.0),
                         group=DEBRIS, mask=GROUND | DEBRIS) for k in range(12)]
    for _ in range(steps):
        w.step(dt)
    below = w.raycast(marble.position + (0.0, 2.0, 0.0), (0.0, -1.0, 0.0), mask=GROUND)
    return (float(marble.position[0]), float(abs(marble.velocity[0])), min(float(d.position[1]) for d in debris),
            below.distance - 2.0)


if __name__ == "__main__":
    x, speed, lowest, ground = run()
    print(f"marble at x = {x:.2f} m, rolling at {speed:.4f} m/s: a ball launched sliding at 2 m/s rolls at 5/7 of "
          f"that ({2 * 5 / 7:.4f} m/s), untouched by the debris")
    print(f"lowest debris centre {lowest:.3f} m (a 0.1 m half-extent box resting on the ground: 0.1 m)")
    print(f"ground {ground:.3f} m below the marble's centre (its radius: 0.3 m), debris ignored by the ray")
