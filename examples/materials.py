"""Materials changed while the world runs: a spinning top slowed by torsional friction, a crate that slides
once its slope turns to ice, and a drifting probe stopped by damping.

- The top is a ball spinning about the vertical on the floor.  Its one contact point cannot slow that spin
  by sliding friction; ``torsional_friction`` (a lever arm, m) does, at the rate ``tau m g / I``.
- The crate rests on a 30 degree slope (friction 1 > tan 30 deg) and falls asleep.  Setting the slope's
  ``friction`` and ``static_friction`` to 0.05 wakes it; the contact combines the crate's 1 with the
  slope's 0.05 by geometric mean, ``mu = sqrt(0.05) = 0.224 < tan 30 deg``, and the crate slides at
  ``g (sin 30 - mu cos 30)``.
- The probe drifts through empty space; once its ``linear_damping`` is switched on, its speed decays as
  ``exp(-c t)``.

Run:  python examples/materials.py
"""
import math

import marbellous as mb

DT = 1.0 / 60.0
SLOPE = math.radians(30.0)
ICE = 0.05


def run(settle=1.5, seconds=1.0):
    """Let the crate fall asleep for ``settle`` s, turn the slope to ice and damp the probe, and run on for
    ``seconds`` s; returns (the top's spin (rad/s), the crate's speed (m/s), the probe's speed (m/s))."""
    w = mb.World()
    w.add_static(mb.Plane(), torsional_friction=0.01)
    top = w.add_body(mb.Sphere(0.5), position=(0.0, 0.5, 0.0), mass=2.0, angular_velocity=(0.0, 10.0, 0.0))
    tilt = (math.cos(SLOPE / 2), 0.0, 0.0, math.sin(SLOPE / 2))
    slope = w.add_static(mb.Box((3.0, 0.1, 1.0)), position=(6.0, 2.0, 0.0), orientation=tilt, friction=1.0)
    up = (-math.sin(SLOPE), math.cos(SLOPE), 0.0)
    crate = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(6.0 + 0.3 * up[0], 2.0 + 0.3 * up[1], 0.0),
                       orientation=tilt, friction=1.0)
    space = mb.World(gravity=(0.0, 0.0, 0.0))
    probe = space.add_body(mb.Sphere(0.1), velocity=(2.0, 0.0, 0.0))
    for _ in range(round(settle / DT)):
        w.step(DT)
        space.step(DT)
    assert crate.is_sleeping, "the crate should rest on the rough slope"
    slope.friction = slope.static_friction = ICE
    probe.linear_damping = 0.5
    for _ in range(round(seconds / DT)):
        w.step(DT)
        space.step(DT)
    return (float(top.angular_velocity[1]), float(math.hypot(*crate.velocity)),
            float(math.hypot(*probe.velocity)))


if __name__ == "__main__":
    spin, crate, probe = run()
    print(f"top spins at {spin:.3f} rad/s after 2.5 s (10 - tau g t / (0.4 r^2) = {10 - 0.01 * 9.81 * 2.5 / 0.1:.3f})")
    mu = math.sqrt(ICE * 1.0)
    print(f"crate slides at {crate:.3f} m/s 1 s after the ice (g (sin 30 - {mu:.3f} cos 30) t = "
          f"{9.81 * (math.sin(SLOPE) - mu * math.cos(SLOPE)):.3f})")
    print(f"probe drifts at {probe:.4f} m/s 1 s after its damping came on (2 exp(-0.5) = {2 * math.exp(-0.5):.4f})")
