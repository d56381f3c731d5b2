"""The flag at the goal: a small cloth on a pole beside the goal box, flying in a light, gusty wind.

Where it stands follows from the goal's box (no level key): the pole rises beside the corner of the box
whose ground is nearest the box's bottom (a ray cast down the level at each corner; the box's bottom where
none hits), of those the one nearest the way the marble comes (so that the player sees it, not hidden behind
the box or the chequered flag), from that ground to :data:`RISE` above the box's top.  The flag hangs from the
pole's top on the side away from the box, its edge along the pole pinned to it (the pole itself is drawn, not
simulated: nothing of the level changes, and the marble meets only the flag).

The wind blows away from the box, along one of its sides or the diagonal between them, whichever turns the
flag's face most to the sun of the game's pictures (``render/sun.py``), with gusts that travel down the flag
and swing it side to side and up and down; it pushes each triangle of the flag as the pressure on a flat
plate across a flow:

    F = 1/2 rho C_D A (u . n) |u . n| n,        u = w(x, t) - v,
    w(x, t) = U (1 + G sin(omega_g t)) (d + S sin(omega t - k s) l + H sin(omega' t - k s) y)

(``rho`` the air's density, ``A`` the triangle's area and ``n`` its unit normal, ``v`` its velocity, ``d``
the wind's direction, ``l`` across it, ``y`` up, ``s`` the distance from the pole along ``d``), a third of
it on each corner.  The force is given each step as the velocity change it makes over the step,
``dv = F dt / m`` per vertex (one write of the flag's velocities, where a force per vertex would take a call
per vertex), and the pinned edge stays still.  The wind and its push are compiled kernels (:func:`gusts`,
:func:`plate_push`, which read this module's constants): written with NumPy over the flag's 154 triangles they
took 170-210 us a step, more than half as much as the flag's cloth itself (360-380 us).

The flag is the game world's only cloth, so it sets the world's particle sub-steps (:data:`SUBSTEPS`): 8 keep
its edges within 6 % of their length and its cost near half a millisecond a step (16: 3 % and 0.8 ms).
"""
import math

import numpy as np

from .._numba.jit import njit
from ..cloth import cloth_grid
from ..pipeline.precompile import await_kernel
from ..render.sun import SUN

#: The flag: length along the wind and height (m), vertices along each, and its mass (kg, a light canvas).
LENGTH, HEIGHT, COLUMNS, ROWS, MASS = 0.6, 0.4, 12, 8, 0.03
#: The world's particle sub-steps per step.
SUBSTEPS = 8
#: The pole: its radius (m), how far its top is above the goal box's top (m), and its gap to the box (m).
POLE_RADIUS, RISE, GAP = 0.03, 0.8, 0.1
#: Corners whose ground is this close (m) to the best one's are as good for the pole.
GROUND_TOLERANCE = 0.05
#: The air's density (kg/m^3) and a flat plate's drag coefficient across a flow.
AIR_DENSITY, DRAG = 1.2, 1.2
#: The mean wind (m/s); its gusts' strength (a fraction of it) and angular frequency (rad/s); the strength of
#: the waves across (S) and up (H) the wind, their angular frequencies (rad/s) and wave number along it (rad/m).
WIND, GUST, GUST_OMEGA = 5.0, 0.3, 1.3
ACROSS, UP, WAVE_OMEGA, UP_OMEGA, WAVE_NUMBER = 0.35, 0.15, 9.0, 5.5, 8.0


def flag_site(center, half_extents, ground=None, approach=None):
    """``(foot, top, direction)``: where the pole of the goal box ``center``, ``half_extents`` (m) stands, its
    foot and its top (m), and the wind's direction, a horizontal unit vector away from the box.  ``ground(x, z,
    y_from, depth)`` gives the height (m) of the level below a point, looking down from ``y_from`` at most
    ``depth`` metres, or None (no ground function: the box's bottom); ``approach`` (m) is a point the marble
    comes from (None: any)."""
    c = np.asarray(center, np.float64)
    h = np.asarray(half_extents, np.float64)
    bottom, top = c[1] - h[1], c[1] + h[1]
    corners = []
    for sx, sz in ((1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)):
        x, z = c[0] + sx * (h[0] + GAP), c[2] + sz * (h[2] + GAP)
        y = ground(x, z, top, 2.0 * h[1] + 1.0) if ground is not None else None
        y = bottom if y is None else y
        far = 0.0 if approach is None else math.hypot(x - approach[0], z - approach[2])
        corners.append((abs(y - bottom), far, y, x, z, sx, sz))
    level = min(k[0] for k in corners) + GROUND_TOLERANCE
    _, _, y, x, z, sx, sz = min(k for k in corners if k[0] <= level)
    # the flag's face is across the wind: up x direction
    ways = [np.array([sx, 0.0, 0.0]), np.array([0.0, 0.0, sz]), np.array([sx, 0.0, sz]) / math.sqrt(2.0)]
    direction = max(ways, key=lambda d: abs(np.cross((0.0, 1.0, 0.0), d) @ SUN))
    return np.array([x, y, z]), np.array([x, top + RISE, z]), direction


@njit
def plate_push(x, v, triangles, wind, pressure, inverse_mass, dt):
    """The velocities (m/s, (V, 3)) of a cloth at positions ``x`` (m) and velocities ``v`` (m/s) after a step of
    ``dt`` (s) of the pressure drag of the air moving at ``wind`` (m/s, (T, 3): at each of the ``triangles``'
    centres) across each triangle as across a flat plate, a third of it on each corner:

        F = pressure A (u . n) |u . n| n,        u = wind - (v_a + v_b + v_c) / 3

    (``pressure`` = 1/2 rho C_D, kg/m^3; ``A`` the triangle's area and ``n`` its unit normal); each vertex
    changes by its share of the forces times ``inverse_mass`` (1/kg, (V,)) and ``dt``.  A degenerate triangle
    is pushed by nothing."""
    out = v.copy()
    for t in range(triangles.shape[0]):
        a, b, c = triangles[t, 0], triangles[t, 1], triangles[t, 2]
        e = (x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2])
        f = (x[c, 0] - x[a, 0], x[c, 1] - x[a, 1], x[c, 2] - x[a, 2])
        # e x f: the normal times twice the area
        m = (e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2], e[0] * f[1] - e[1] * f[0])
        twice_area = math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        if twice_area == 0.0:
            continue
        un = 0.0
        for k in range(3):
            un += (wind[t, k] - (v[a, k] + v[b, k] + v[c, k]) / 3.0) * m[k] / twice_area
        # a third of F on each corner: pressure (2 A / 2) un |un| n / 3
        share = pressure * 0.5 * un * abs(un) * dt / 3.0
        for k in range(3):
            push = share * m[k]
            out[a, k] += push * inverse_mass[a]
            out[b, k] += push * inverse_mass[b]
            out[c, k] += push * inverse_mass[c]
    return out


@njit
def gusts(points, t, top, direction, across, out):
    """The wind (m/s) at ``points`` (K, 3) (m) at time ``t`` (s) into ``out`` (K, 3): the module docstring's
    ``w(x, t)`` for a flag whose pole's top is ``top`` (m), blown along ``direction`` (a horizontal unit vector)
    with ``across`` = y x ``direction``."""
    strength = WIND * (1.0 + GUST * math.sin(GUST_OMEGA * t))
    for i in range(points.shape[0]):
        s = ((points[i, 0] - top[0]) * direction[0] + (points[i, 1] - top[1]) * direction[1]
             + (points[i, 2] - top[2]) * direction[2])
        side = ACROSS * math.sin(WAVE_OMEGA * t - WAVE_NUMBER * s)
        up = UP * math.sin(UP_OMEGA * t - WAVE_NUMBER * s)
        for k in range(3):
            out[i, k] = strength * (direction[k] + side * across[k])
        out[i, 1] += strength * up


@njit
def blow_flag(x, v, triangles, t, dt, top, direction, across, inverse_mass):
    """:func:`plate_push` of the :func:`gusts` at the triangles' centres at time ``t`` (s) over a step of
    ``dt`` (s): the flag's velocities (m/s) after the wind's push."""
    centres = np.empty((triangles.shape[0], 3))
    for i in range(triangles.shape[0]):
        for k in range(3):
            centres[i, k] = (x[triangles[i, 0], k] + x[triangles[i, 1], k] + x[triangles[i, 2], k]) / 3.0
    wind = np.empty_like(centres)
    gusts(centres, t, top, direction, across, wind)
    return plate_push(x, v, triangles, wind, 0.5 * AIR_DENSITY * DRAG, inverse_mass, dt)


def blow_call():
    """``(kernel, arguments)``: :func:`blow_flag` with arguments of the types :meth:`GoalFlag.blow` passes, for
    compiling it ahead (``World._compile_ahead``)."""
    x = np.zeros((3, 3))
    return blow_flag, (x, x.copy(), np.array([[0, 1, 2]], np.int64), 0.0, 0.01, np.zeros(3), np.array([1.0, 0.0, 0.0]),
                       np.array([0.0, 0.0, 1.0]), np.ones(3))


class GoalFlag:
    """The flag of the goal box ``center``, ``half_extents`` (m), added to ``world`` as a cloth (see the
    module docstring; it sets ``world.particle_substeps``); ``ground`` and ``approach`` as for
    :func:`flag_site`.  :meth:`blow` before each step."""

    def __init__(self, world, center, half_extents, ground=None, approach=None):
        self.foot, self.top, self.direction = flag_site(center, half_extents, ground, approach)
        self.across = np.cross((0.0, 1.0, 0.0), self.direction)
        self.radius = POLE_RADIUS
        # the sheet of cloth_grid: column i (x) runs along the wind, row j (z) down from the pole's top
        v, self.triangles = cloth_grid(LENGTH, HEIGHT, COLUMNS, ROWS)
        along, down = v[:, 0] + 0.5 * LENGTH + POLE_RADIUS, v[:, 2] + 0.5 * HEIGHT
        rest = self.top + along[:, None] * self.direction - down[:, None] * np.array([0.0, 1.0, 0.0])
        self.cloth = world.add_cloth(rest, self.triangles, mass=MASS, self_collision=False, damping=0.2)
        self.cloth.pin(np.arange(ROWS))                          # column 0: the edge along the pole
        world.particle_substeps = SUBSTEPS
        # (the pinned edge's inverse masses 0: it stays still)
        self._inverse_mass = np.where(self.cloth.pinned, 0.0, 1.0 / self.cloth.mass)

    def wind(self, points, t):
        """The wind (m/s) at ``points`` (K, 3) (m) at time ``t`` (s)."""
        out = np.empty((len(points), 3))
        gusts(np.asarray(points, np.float64), t, self.top, self.direction, self.across, out)
        return out

    def blow(self, t, dt):
        """Give the flag the velocity change of the wind's push at time ``t`` (s) over a step of ``dt`` (s)."""
        await_kernel(blow_flag)         # (compiled ahead on a first run: Game's _compile_ahead)
        self.cloth.velocities = blow_flag(self.cloth.positions, self.cloth.velocities, self.triangles, t, dt,
                                          self.top, self.direction, self.across, self._inverse_mass)
