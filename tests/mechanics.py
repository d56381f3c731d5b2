"""Closed-form experiments shared by the solver tests (sequential impulses, LCP, penalty): a 20 degree
incline, a head-on collision of two spheres, a rod pendulum.  Each builds the scene in a given world
configuration and returns what the tests compare with mechanics."""
import math

import numpy as np

import marbellous as mb

G = 9.81
DT = 1.0 / 60.0
THETA = math.radians(20.0)
# An incline through the origin: its normal, and the downhill direction in the x-y plane.
N_INCLINE = np.array([-math.sin(THETA), math.cos(THETA), 0.0])
DOWNHILL = np.array([-math.cos(THETA), -math.sin(THETA), 0.0])
Q_INCLINE = np.array([math.cos(THETA / 2), 0.0, 0.0, math.sin(THETA / 2)])  # rotates +y onto N_INCLINE
ROLLING_ACCELERATION = 5.0 / 7.0 * G * math.sin(THETA)   # a solid sphere rolling without slipping


def sliding_acceleration(mu):
    """A box sliding down the incline with dynamic friction ``mu``: g (sin - mu cos) (m/s^2)."""
    return G * (math.sin(THETA) - mu * math.cos(THETA))


def acceleration_downhill(w, b, t0=0.5, t1=1.5, dt=DT):
    """Mean acceleration along the incline between t0 and t1 (s), from the velocities."""
    while w.time < t0 - 1e-9:
        w.step(dt)
    v0, s0 = b.velocity @ DOWNHILL, w.time
    while w.time < t1 - 1e-9:
        w.step(dt)
    return (b.velocity @ DOWNHILL - v0) / (w.time - s0)


def sphere_on_incline(w, r=0.5, friction=0.8):
    """A sphere of radius ``r`` resting on the incline of world ``w``; returns the sphere."""
    w.add_static(mb.Plane(N_INCLINE, 0.0), friction=friction)
    return w.add_body(mb.Sphere(r), position=N_INCLINE * r, friction=friction)


def box_on_incline(w, mu, mu_s=None):
    """A unit box resting flat on the incline of world ``w``; returns the box."""
    w.add_static(mb.Plane(N_INCLINE, 0.0), friction=mu, static_friction=mu_s)
    return w.add_body(mb.Box((0.5, 0.5, 0.5)), position=N_INCLINE * 0.5, orientation=Q_INCLINE, friction=mu,
                      static_friction=mu_s)


def box_on_slope(solver, degrees, mu_s=0.6, mu_d=0.4):
    """A 0.4 m box released at rest, face down, on a plane tilted ``degrees`` about z; both bodies have
    static friction ``mu_s`` and dynamic ``mu_d``.  Returns the world, the box and the downhill direction."""
    a = math.radians(degrees)
    w = mb.World(solver=solver, sleeping=False)
    w.add_static(mb.Plane((-math.sin(a), math.cos(a), 0.0), 0.0), friction=mu_d, static_friction=mu_s)
    up = np.array([-math.sin(a), math.cos(a), 0.0])
    box = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=tuple(0.2 * up), friction=mu_d, static_friction=mu_s,
                     orientation=(math.cos(a / 2), 0.0, 0.0, math.sin(a / 2)))
    return w, box, np.array([-math.cos(a), -math.sin(a), 0.0])


def sliding_past_static_angle(solver, excess=0.2, mu_s=0.6, mu_d=0.4):
    """A box released at rest ``excess`` degrees past atan(mu_s) (:func:`box_on_slope`): ``(measured, expected)``
    downhill acceleration (m/s^2) between its 60th and 120th steps, and dynamic friction's g (sin - mu_d cos)."""
    angle = math.degrees(math.atan(mu_s)) + excess
    w, box, downhill = box_on_slope(solver, angle, mu_s, mu_d)
    for _ in range(60):
        w.step(DT)
    v1 = box.velocity @ downhill
    for _ in range(60):
        w.step(DT)
    a = math.radians(angle)
    return (box.velocity @ downhill - v1) / (60 * DT), G * (math.sin(a) - mu_d * math.cos(a))


HEAD_ON = (2.0, 3.0, 4.0, -1.0)   # masses m1, m2 (kg) and velocities u1, u2 (m/s) along x


def head_on_collision(w, e, steps=120):
    """Two spheres of world ``w`` (no gravity) meet head on with restitution ``e``; returns the two bodies
    after ``steps`` steps of DT."""
    m1, m2, u1, u2 = HEAD_ON
    a = w.add_body(mb.Sphere(0.5), mass=m1, position=(-2, 0, 0), velocity=(u1, 0, 0), restitution=e)
    b = w.add_body(mb.Sphere(0.5), mass=m2, position=(2, 0, 0), velocity=(u2, 0, 0), restitution=e)
    for _ in range(steps):
        w.step(DT)
    return a, b


def rod_pendulum(w, length=2.0, amp=0.2, steps=600):
    """A 1 kg bob on a rod of ``length`` (m) from the origin, released at ``amp`` (rad) in world ``w``.

    Returns ``(largest length error (m), mean period measured (s), exact period (s))``; the exact
    finite-amplitude period is T0 (1 + amp^2 / 16 + 11 amp^4 / 3072 + ...).
    """
    bob = w.add_body(mb.Sphere(0.1), mass=1.0, position=(length * math.sin(amp), -length * math.cos(amp), 0))
    w.add_rod(bob, None, anchor_b=(0, 0, 0))
    xs, worst = [], 0.0
    for _ in range(steps):
        w.step(DT)
        worst = max(worst, abs(np.linalg.norm(bob.position) - length))
        xs.append(bob.position[0])
    xs = np.array(xs)
    t = (np.arange(len(xs)) + 1) * DT
    i = np.where((xs[:-1] < 0) & (xs[1:] >= 0))[0]
    crossings = t[i] + DT * (-xs[i]) / (xs[i + 1] - xs[i])
    exact = 2 * math.pi * math.sqrt(length / G) * (1 + amp ** 2 / 16 + 11 * amp ** 4 / 3072)
    return worst, float(np.diff(crossings).mean()), exact
