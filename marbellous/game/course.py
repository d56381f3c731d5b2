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
        self._d = np.diff(self.points, axis=0)
        self.seg_len = np.linalg.norm(self._d, axis=1)
        self._len2 = np.maximum(self.seg_len ** 2, 1e-18)
        self.s = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.length = float(self.s[-1])
        self.speeds = (np.full(len(self.points), default_speed) if speeds is None
                       else np.array(speeds, np.float64).reshape(len(self.points)))

    def project(self, position, near=None, window=6.0):
        """Arc length (m) of the point of the path nearest to ``position``.

        With ``near`` (a previous arc length) only the part of the path within ``window`` metres of
        it is searched, so progress is tracked along the course where it passes close to itself.
        """
        near = None if near is None else np.array([near], np.float64)
        return float(self.project_many(np.asarray(position, np.float64).reshape(1, 3), near, window)[0])

    def project_many(self, positions, near=None, window=6.0):
        """:meth:`project` of each row of ``positions`` (N, 3) m, with ``near`` None or (N,) m: (N,) m.
        Each row's answer is the same, bit for bit, as projecting it alone.

        For segment ``a -> b`` (``d = b - a``) the nearest point to ``p`` is ``a + t d`` with
        ``t = clip((p - a) . d / |d|^2, 0, 1)``, with ``t`` also kept within the window's part of the segment
        when ``near`` is given; the answer is the arc length of the nearest of those points.  With ``near``,
        only the segments that meet each window are looked at (a run of them: the arc lengths grow along the
        path), so the work grows with the window, not with the course.
        """
        n_segments = len(self.seg_len)
        if near is None:
            seg = np.arange(n_segments)[None, :]                 # (1, S): every segment for every row
        else:
            start, end = near - window, near + window
            first = np.searchsorted(self.s[1:], start, side="left")      # the first segment ending at or after start
            stop = np.searchsorted(self.s[:-1], end, side="right")       # the first one starting after end
            empty = stop <= first                                       # (no segment: the first one's answer,
            first, stop = np.where(empty, 0, first), np.where(empty, 0, stop)   # at infinite distance)
            seg = first[:, None] + np.arange(max(int((stop - first).max()), 1))
            searched = seg < stop[:, None]
            seg = np.minimum(seg, n_segments - 1)
        p = positions[:, None, :]                                # (N, 1, 3) against the segments (N or 1, W, 3)
        a, d, s0, length = self.points[:-1][seg], self._d[seg], self.s[:-1][seg], self.seg_len[seg]
        pa = p - a
        t = np.clip((pa[..., 0] * d[..., 0] + pa[..., 1] * d[..., 1] + pa[..., 2] * d[..., 2]) / self._len2[seg],
                    0.0, 1.0)
        if near is not None:
            start, end = start[:, None], end[:, None]
            scale = np.maximum(length, 1e-300)
            t_start, t_end = np.clip((start - s0) / scale, 0.0, 1.0), np.clip((end - s0) / scale, 0.0, 1.0)
            t = np.minimum(np.maximum(t, t_start), t_end)
        e = a + t[..., None] * d - p
        dist2 = e[..., 0] * e[..., 0] + e[..., 1] * e[..., 1] + e[..., 2] * e[..., 2]
        if near is not None:
            dist2 = np.where(searched, dist2, np.inf)
        s = s0 + t * length
        s = np.broadcast_to(s, dist2.shape)
        return s[np.arange(len(s)), np.argmin(dist2, axis=1)]

    def point_at(self, s):
        """Position (m) at arc length ``s`` (clamped to the path)."""
        s = min(max(float(s), 0.0), self.length)
        return np.array([np.interp(s, self.s, self.points[:, k]) for k in range(3)])

    def speed_at(self, s):
        """Target speed (m/s) at arc length ``s``."""
        return float(np.interp(s, self.s, self.speeds))
