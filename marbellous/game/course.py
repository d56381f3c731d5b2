"""The way to the goal as a polyline with arc length: progress for rewards, targets for the autopilot."""
import numpy as np


class CoursePath:
    """A polyline through ``points`` (N, 3) m with optional target ``speeds`` (N,) m/s.

    Arc length ``s`` (m) runs from 0 at the first point to :attr:`length` at the last.
    """

    def __init__(self, points, speeds=None, default_speed=3.0):
        self.points = np.array(points, np.float64).reshape(-1, 3)
        if len(self.points) < 2:
            raise ValueError(f"points must hold at least 2 points, got {len(self.points)}")
        seg = np.diff(self.points, axis=0)
        self.seg_len = np.linalg.norm(seg, axis=1)
        self.s = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.length = float(self.s[-1])
        self.speeds = (np.full(len(self.points), default_speed) if speeds is None
                       else np.array(speeds, np.float64).reshape(len(self.points)))

    def project(self, position, near=None, window=6.0):
        """Arc length (m) of the point of the path nearest to ``position``.

        With ``near`` (a previous arc length) only the part of the path within ``window`` metres of
        it is searched, so progress is tracked along the course where it passes close to itself.
        """
        p = np.asarray(position, np.float64)
        a, b = self.points[:-1], self.points[1:]
        d = b - a
        t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(self.seg_len ** 2, 1e-18), 0.0, 1.0)
        q = a + t[:, None] * d
        dist = np.linalg.norm(q - p, axis=1)
        s = self.s[:-1] + t * self.seg_len
        if near is not None:
            dist = np.where(np.abs(s - near) <= window, dist, np.inf)
        return float(s[np.argmin(dist)])

    def point_at(self, s):
        """Position (m) at arc length ``s`` (clamped to the path)."""
        s = min(max(float(s), 0.0), self.length)
        return np.array([np.interp(s, self.s, self.points[:, k]) for k in range(3)])

    def speed_at(self, s):
        """Target speed (m/s) at arc length ``s``."""
        return float(np.interp(s, self.s, self.speeds))
