"""Free bodies: many spheres far apart, falling under gravity and never touching (10,000 by default).

It measures the per-body cost of a step with no contacts: integration, bounding boxes, broad phase.
Sphere k starts on a cubic lattice of pitch ``spacing`` with a seeded random velocity; every sphere
follows  x(t) = x0 + v0 t + g t^2 / 2  (``free_fall_positions``).
"""
import numpy as np

from ..shapes.primitives import Sphere
from ..world import World


def free_bodies_start(count=10000, *, radius=0.25, spacing=2.0, speed=0.25, seed=0):
    """Start positions (m) and velocities (m/s), each ``(count, 3)``: a lattice ``ceil(count^(1/3))`` wide,
    lifted 1000 m up, velocities uniform in ``[-speed, speed]`` per axis."""
    side = int(np.ceil(count ** (1.0 / 3.0)))
    k = np.arange(count)
    lattice = np.column_stack([k % side, (k // side) % side, k // (side * side)]).astype(np.float64)
    positions = lattice * spacing + np.array([0.0, 1000.0, 0.0])
    velocities = np.random.default_rng(seed).uniform(-speed, speed, (count, 3))
    return positions, velocities


def free_bodies(world=None, *, count=10000, radius=0.25, spacing=2.0, speed=0.25, seed=0):
    """``count`` spheres of ``radius`` (m) at ``free_bodies_start``; they never meet while
    ``2 sqrt(3) speed t < spacing - 2 radius`` (1.7 s by default).  Returns ``(world, spheres)``."""
    w = World() if world is None else world
    positions, velocities = free_bodies_start(count, radius=radius, spacing=spacing, speed=speed, seed=seed)
    spheres = [w.add_body(Sphere(radius), position=p, velocity=v) for p, v in zip(positions, velocities)]
    return w, spheres


def free_fall_positions(positions, velocities, gravity, t):
    """Closed-form positions (m) after ``t`` s of free fall:  x0 + v0 t + g t^2 / 2."""
    return positions + velocities * t + 0.5 * np.asarray(gravity) * t * t
