"""The autopilot: follows the level's course to the goal with the player's force controls.

Pure pursuit with a velocity controller: find the marble's progress ``s`` along the course, aim at
the course point ``lookahead + lead * speed`` metres further on, and ask for the velocity
``v* = v_target(s) d`` along that direction; the commanded acceleration ``gain (v* - v)`` (horizontal)
is turned into the same ``(forward, right)`` control input a player gives, relative to the camera.
"""
import numpy as np

from .controls import move_for_direction


class Autopilot:
    """Drives the marble along a :class:`~marbellous.game.course.CoursePath`.

    ``push`` (m/s^2) is the acceleration of a full control input; ``gain`` (1/s) the velocity loop's
    gain; ``lookahead`` (m) and ``lead`` (s) set how far ahead it aims.
    """

    def __init__(self, path, push, gain=3.0, lookahead=1.0, lead=0.3):
        self.path, self.push, self.gain = path, float(push), float(gain)
        self.lookahead, self.lead = float(lookahead), float(lead)
        self.progress = None

    def reset(self):
        """Forget the tracked progress (after a restart or respawn)."""
        self.progress = None

    def move(self, position, velocity, heading):
        """The control input ``(forward, right)`` for a marble at ``position`` (m) with ``velocity``
        (m/s) seen from a camera with ``heading`` (rad)."""
        self.progress = self.path.project(position, near=self.progress)
        v = np.array([velocity[0], 0.0, velocity[2]], np.float64)
        aim = self.path.point_at(self.progress + self.lookahead + self.lead * float(np.linalg.norm(v)))
        d = aim - np.asarray(position, np.float64)
        d[1] = 0.0
        n = float(np.linalg.norm(d))
        want = d / n * self.path.speed_at(self.progress) if n > 1e-6 else np.zeros(3)
        return move_for_direction(self.gain * (want - v) / self.push, heading)

    def step(self, game):
        """One physics step of ``game`` (a :class:`~marbellous.game.session.Game` on this autopilot's course)
        with this autopilot's input; after a fall back to the start it tracks the course afresh."""
        respawns = game.respawns
        b = game.marble
        game.step(self.move(b.position, b.velocity, game.camera.heading))
        if game.respawns != respawns:
            self.reset()
