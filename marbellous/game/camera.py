"""The follow camera: keeps the marble in view without following every small movement.

Three parts, each from a closed form:

* **Dead zone.**  The camera's anchor ``a`` stays put while the marble ``p`` is within ``dead_zone``
  metres of it; when the marble leaves, the anchor is dragged along to the nearest point that puts the
  marble back on the zone's edge:  ``a <- p - r (p - a) / |p - a|`` when ``|p - a| > r``.
* **Critically damped smoothing.**  The focus ``x`` follows the target ``g = a + lookahead`` like a
  mass on a critically damped spring, ``x'' = -omega^2 (x - g) - 2 omega x'``.  For a target that is
  constant over a step ``h`` the exact solution with ``e = x - g`` is

      e(h) = (e0 + (v0 + omega e0) h) exp(-omega h)
      v(h) = (v0 - omega (v0 + omega e0) h) exp(-omega h)

  so the camera never overshoots from rest and the step is exact for any frame time.
* **Look-ahead and no clipping.**  The target leads the marble by its horizontal velocity times
  ``lookahead`` seconds (at most ``max_lookahead`` metres); the yaw turns, with the same smoothing, to
  the direction of travel; and a ray cast from the marble to the eye pulls the eye in front of any
  level geometry in between (the marble is never inside the level, the smoothed focus may be).
"""
import math
from dataclasses import dataclass

import numpy as np

from ..render.view import CameraView


def critically_damped_step(x, v, target, omega, h):
    """Advance ``x'' = -omega^2 (x - target) - 2 omega x'`` exactly by ``h`` seconds.

    ``x``, ``v`` (position and velocity, scalars or arrays) and ``target`` in the same units;
    ``omega`` in rad/s.  Returns the new ``(x, v)``.
    """
    e0 = np.asarray(x, np.float64) - target
    v0 = np.asarray(v, np.float64)
    decay = math.exp(-omega * h)
    b = v0 + omega * e0
    return target + (e0 + b * h) * decay, (v0 - omega * b * h) * decay


def dead_zone_anchor(anchor, point, radius):
    """The anchor (m) moved the least distance that puts ``point`` within ``radius`` metres of it."""
    anchor = np.asarray(anchor, np.float64)
    d = np.asarray(point, np.float64) - anchor
    n = float(np.linalg.norm(d))
    if n <= radius:
        return anchor.copy()
    return anchor + d * ((n - radius) / n)


def _wrap(angle):
    """Angle in (-pi, pi]."""
    return math.remainder(angle, 2.0 * math.pi)


@dataclass
class FollowCamera:
    """A third-person camera behind and above the marble.

    Lengths in metres, times in seconds, angles in radians.  ``heading`` is the yaw about +y of the
    direction the camera looks (0 looks along +x, pi/2 along +z).
    """

    heading: float = 0.0
    distance: float = 6.0
    height: float = 2.8
    dead_zone: float = 0.6
    omega: float = 4.0
    lookahead: float = 0.35
    max_lookahead: float = 2.0
    heading_omega: float = 1.6
    turn_speed: float = 1.0
    margin: float = 0.25
    fov: float = math.radians(60.0)

    def __post_init__(self):
        self.anchor = None

    def reset(self, position, heading):
        """Put the camera at rest behind ``position`` (m), looking along ``heading`` (rad)."""
        self.anchor = np.array(position, np.float64)
        self.focus = self.anchor.copy()
        self.focus_velocity = np.zeros(3)
        self.heading = float(heading)
        self.heading_rate = 0.0
        self.eye = self.desired_eye()

    def forward(self):
        """Unit horizontal vector the camera looks along."""
        return np.array([math.cos(self.heading), 0.0, math.sin(self.heading)])

    def desired_eye(self):
        """Where the eye would be with nothing in the way: behind and above the focus."""
        return self.focus - self.distance * self.forward() + np.array([0.0, self.height, 0.0])

    def update(self, h, position, velocity, raycast=None):
        """Follow the marble at ``position`` (m) moving with ``velocity`` (m/s) for ``h`` seconds.

        ``raycast(origin, direction, max_distance)`` returns the distance (m) to the nearest level
        geometry along the unit ``direction``, or None; a ray from the marble to the eye keeps the eye
        ``margin`` in front of any geometry in between.
        Returns the :class:`CameraView`.
        """
        if self.anchor is None:
            self.reset(position, self.heading)
        self.anchor = dead_zone_anchor(self.anchor, position, self.dead_zone)
        v_flat = np.array([velocity[0], 0.0, velocity[2]], np.float64)
        speed = float(np.linalg.norm(v_flat))
        lead = v_flat * self.lookahead
        if speed * self.lookahead > self.max_lookahead:
            lead *= self.max_lookahead / (speed * self.lookahead)
        self.focus, self.focus_velocity = critically_damped_step(
            self.focus, self.focus_velocity, self.anchor + lead, self.omega, h)
        if speed > self.turn_speed:
            # smooth the yaw towards the direction of travel (the error is wrapped to (-pi, pi])
            goal = self.heading + _wrap(math.atan2(v_flat[2], v_flat[0]) - self.heading)
            self.heading, self.heading_rate = (float(c) for c in critically_damped_step(
                self.heading, self.heading_rate, goal, self.heading_omega, h))
        else:
            self.heading_rate = 0.0
        eye = self.desired_eye()
        if raycast is not None:
            eye = self.unblocked_eye(eye, raycast, position)
        self.eye = eye
        return self.view()

    def view(self):
        """The current :class:`CameraView` (copies)."""
        return CameraView(eye=self.eye.copy(), target=self.focus.copy(), fov=self.fov)

    def unblocked_eye(self, eye, raycast, origin):
        """``eye`` pulled towards ``origin`` (the marble, m) so that no geometry lies between them,
        with ``margin`` metres of clearance: the marble stays visible and the eye outside the level."""
        origin = np.asarray(origin, np.float64)
        d = eye - origin
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            return eye
        d /= length
        hit = raycast(origin, d, length + self.margin)
        if hit is None:
            return eye
        return origin + d * max(min(hit - self.margin, length), 0.0)
