"""Kinematic bodies: an elevator and a turntable carry crates by friction alone.

A kinematic body moves by its velocities only: gravity, forces and collisions do not move it, and it pushes
and carries dynamic bodies as if it were infinitely heavy.  The elevator follows ``y(t) = 1 + 0.5 sin t``
through ``move_to`` (the velocities that reach the next pose in one step); the turntable spins up to
1 rad/s over 2 s by its ``angular_velocity``.  Static friction holds the crates: the elevator's largest
acceleration is 0.5 m/s^2 and the turntable crate's at most ``omega^2 r`` = 0.6 m/s^2, far below
``mu g`` = 7.8 m/s^2.  (Started at full speed at once, the turntable would make its crate slip until
friction caught it up: a kinematic body's velocity may jump, a dynamic body's cannot.)

Known weakness: the turntable's crate creeps outwards by about ``(omega r dt)^2 / (2 r)`` per step
(5 mm/s here at 60 Hz): friction holds it at the contact points found when the step began, so within a
step it moves along the chord of its circle instead of the arc.

Run:  python examples/platforms.py
"""
import math

import numpy as np

import marbellous as mb

DT = 1.0 / 60.0


def elevator_height(t):
    """The elevator's height (m) at time ``t`` (s)."""
    return 1.0 + 0.5 * math.sin(t)


def run(seconds=6.0):
    """Ride for ``seconds`` (s); returns (the elevator crate's height above the elevator (m), the turntable
    crate's angle about the axis (rad), the turntable's angle (rad), their distance from the axis (m))."""
    w = mb.World()
    w.add_static(mb.Plane())
    elevator = w.add_kinematic(mb.Box((0.6, 0.1, 0.6)), position=(-3.0, elevator_height(0.0), 0.0), friction=0.8)
    rider = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(-3.0, elevator_height(0.0) + 0.3, 0.0), friction=0.8)
    table = w.add_kinematic(mb.Box((1.0, 0.1, 1.0)), position=(2.0, 0.5, 0.0), friction=0.8)
    passenger = w.add_body(mb.Box((0.15, 0.15, 0.15)), position=(2.6, 0.75, 0.0), friction=0.8)
    steps = round(seconds / DT)
    for k in range(steps):
        elevator.move_to((-3.0, elevator_height((k + 1) * DT), 0.0), (1.0, 0.0, 0.0, 0.0), DT)
        table.angular_velocity = (0.0, min(0.5 * (k + 1) * DT, 1.0), 0.0)
        w.step(DT)
    arm = passenger.position - table.position
    q = table.orientation
    return (float(rider.position[1] - elevator.position[1]), math.atan2(-arm[2], arm[0]),
            2.0 * math.atan2(q[2], q[0]), float(np.hypot(arm[0], arm[2])))


if __name__ == "__main__":
    above, crate_angle, table_angle, radius = run()
    print(f"the elevator's crate rides {above:.4f} m above it (0.3 m: resting on it)")
    print(f"the turntable turned {table_angle:.4f} rad and its crate {crate_angle:.4f} rad, "
          f"{radius:.4f} m from the axis (0.6 m at the start)")
