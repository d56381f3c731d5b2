"""The goal area, the race timer and the best time per level.

The goal is a box; the marble has reached it when the box and the marble's sphere touch, tested each
step with ``marbellous.collide(Box, Sphere)`` (the lecture's goal-area exercise).  Best times are kept
in a small JSON file in the user's data directory (never in the repository):
``$MARBELLOUS_DATA_DIR``, else ``$XDG_DATA_HOME/marbellous``, else ``~/.local/share/marbellous``.
"""
import json
import math
import os
import pathlib

import numpy as np

from ..query import collide, pair_test_call
from ..shapes import Box, Sphere


class GoalArea:
    """An axis-aligned goal box with ``center`` and ``half_extents`` (m)."""

    def __init__(self, center, half_extents):
        self.center = np.array(center, np.float64)
        self.half_extents = np.array(half_extents, np.float64)
        self._box = Box(self.half_extents)
        self._reach = float(np.linalg.norm(self.half_extents))   # no point of the box is farther from its centre

    def may_reach(self, positions, radius):
        """For each row of ``positions`` (N, 3) m: False when a sphere of ``radius`` (m) there cannot touch the
        box (the first test of :meth:`reached`, for many spheres at once), else True."""
        d = positions - self.center
        return d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2] <= (self._reach + radius) ** 2

    def test_call(self, position, radius):
        """``(kernel, arguments)``: the box-sphere test of :meth:`reached` for a sphere of ``radius`` (m) at
        ``position`` (m), for compiling it ahead (``World._compile_ahead``)."""
        return pair_test_call(self._box, Sphere(radius), self.center, np.eye(3), np.asarray(position, np.float64),
                              np.eye(3), 16)

    def reached(self, position, radius):
        """True when a sphere of ``radius`` (m) at ``position`` (m) touches or overlaps the box (a sphere
        whose centre is farther from the box's centre than the box's half diagonal plus its radius cannot
        touch it, and is not tested further)."""
        dx, dy, dz = (position - self.center).tolist()
        if dx * dx + dy * dy + dz * dz > (self._reach + radius) ** 2:
            return False
        contacts = collide(self._box, Sphere(radius), position_a=self.center, position_b=position)
        return any(c.depth >= 0.0 for c in contacts)


def data_dir():
    """The directory for the user's Marbellous data (created on first write)."""
    if os.environ.get("MARBELLOUS_DATA_DIR"):
        return pathlib.Path(os.environ["MARBELLOUS_DATA_DIR"])
    base = os.environ.get("XDG_DATA_HOME") or pathlib.Path.home() / ".local" / "share"
    return pathlib.Path(base) / "marbellous"


class BestTimes:
    """Best finishing time (s) per level key, stored as JSON in ``path`` (default in :func:`data_dir`).

    A missing or unreadable file counts as no records; it is rewritten on the next record.  With
    ``persistent=False`` the records live in memory only (for training runs and tests).
    """

    def __init__(self, path=None, *, persistent=True):
        self.path = pathlib.Path(path) if path is not None else data_dir() / "best_times.json"
        self.persistent = bool(persistent)
        self._memory = {}

    def _load(self):
        if not self.persistent:
            return dict(self._memory)
        try:
            data = json.loads(self.path.read_text())
        except (OSError, ValueError):
            return {}
        if not isinstance(data, dict):
            return {}
        return {k: float(v) for k, v in data.items()
                if isinstance(v, (int, float)) and math.isfinite(v) and v > 0}

    def get(self, key):
        """Best time (s) for level ``key``, or None."""
        return self._load().get(key)

    def record(self, key, seconds):
        """Record a finish in ``seconds``; returns True when it is a new best (and saves it)."""
        times = self._load()
        if key in times and times[key] <= seconds:
            return False
        times[key] = float(seconds)
        if not self.persistent:
            self._memory = times
            return True
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = self.path.with_suffix(".tmp")
            tmp.write_text(json.dumps(times, indent=1, sort_keys=True))
            tmp.replace(self.path)
        except OSError:
            pass  # a read-only home keeps the game playable; the record is just not kept
        return True


def format_time(seconds):
    """``m:ss.s`` for a time in seconds."""
    m, s = divmod(round(max(0.0, float(seconds)), 1), 60.0)
    return f"{int(m)}:{s:04.1f}"
