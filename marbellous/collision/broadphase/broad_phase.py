"""``BroadPhase``: a Python handle over one broad-phase method, for scripts, tests and benchmarks.

It validates the boxes, owns the state arrays (remade when more bodies arrive than they hold) and the
pair buffer (grown and the call repeated when too small).  The step kernel calls the kernels in
``dispatch`` directly instead.
"""
import math

import numpy as np

from marbellous.collision.broadphase._common import ALIVE
from marbellous.collision.broadphase.dispatch import METHODS, find_pairs, make_state, query_aabb, query_ray, update


def _as_int_column(name, value, n, default):
    """``value`` as an (n,) int64 array (``default`` everywhere if None), or raise naming ``name``."""
    if value is None:
        return np.full(n, default, np.int64)
    arr = np.asarray(value)
    if arr.dtype.kind not in "iub":
        raise TypeError(f"{name} must be integers, got dtype {arr.dtype}")
    if arr.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},) to match aabbs, got {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.int64)


def _as_point(name, value):
    """``value`` as 3 finite float64 numbers, or raise naming ``name``."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.shape != (3,):
        raise ValueError(f"{name} must have 3 components, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    return np.ascontiguousarray(arr)


class BroadPhase:
    """One broad-phase method with its persistent state.

    ``method``: one of ``"brute"``, ``"sap"``, ``"grid"``, ``"bvh"``, ``"octree"``, ``"kdtree"``,
    ``"bsp"``.  ``capacity``: body slots to allocate for at first (grows on demand).
    """

    def __init__(self, method="sap", capacity=64):
        if not isinstance(method, str) or method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(map(repr, METHODS))}; got {method!r}")
        if isinstance(capacity, bool) or not isinstance(capacity, (int, np.integer)) or capacity < 1:
            raise ValueError(f"capacity must be an integer >= 1, got {capacity!r}")
        self.method = method
        self.code = METHODS[method]
        self.capacity = int(capacity)
        self.state_f, self.state_i = make_state(self.code, self.capacity)
        self._pairs = np.empty((max(16, self.capacity), 2), np.int64)

    def _prepare(self, aabbs, flags):
        """Validate ``aabbs`` (n, 6) and ``flags``; grow the state if n exceeds the capacity."""
        boxes = np.asarray(aabbs, dtype=np.float64)
        if boxes.ndim != 2 or boxes.shape[1] != 6:
            raise ValueError(f"aabbs must have shape (n, 6), got {boxes.shape}")
        if not np.all(np.isfinite(boxes)):
            raise ValueError("aabbs must be finite (no NaN or inf)")
        if np.any(boxes[:, :3] > boxes[:, 3:]):
            raise ValueError("aabbs must have min <= max on every axis")
        n = boxes.shape[0]
        flag_arr = _as_int_column("flags", flags, n, ALIVE)
        if n > self.capacity:
            self.capacity = max(n, 2 * self.capacity)
            self.state_f, self.state_i = make_state(self.code, self.capacity)
        return np.ascontiguousarray(boxes), flag_arr, n

    def pairs(self, aabbs, flags=None, groups=None, masks=None):
        """Overlapping pairs of the boxes ``aabbs`` (n, 6) rows ``[min xyz, max xyz]`` (m), as an
        (P, 2) int64 array of ``(i, j)``, ``i < j``, sorted.  ``flags`` (n,) bit 0 alive, bit 1
        static (default: all alive, dynamic); ``groups``, ``masks`` (n,) filter bits (default all)."""
        boxes, flag_arr, n = self._prepare(aabbs, flags)
        group_arr = _as_int_column("groups", groups, n, -1)
        mask_arr = _as_int_column("masks", masks, n, -1)
        while True:
            count = find_pairs(self.code, boxes, flag_arr, group_arr, mask_arr, n,
                               self.state_f, self.state_i, self._pairs)
            if count <= self._pairs.shape[0]:
                return self._pairs[:count].copy()
            self._pairs = np.empty((2 * count, 2), np.int64)

    def update(self, aabbs, flags=None):
        """Bring the structure up to date with the boxes (before queries after the boxes changed)."""
        boxes, flag_arr, n = self._prepare(aabbs, flags)
        update(self.code, boxes, flag_arr, n, self.state_f, self.state_i)

    def query_aabb(self, aabbs, box_min, box_max, flags=None):
        """Indices of the live bodies whose box overlaps ``[box_min, box_max]`` (m), ascending."""
        boxes, flag_arr, n = self._prepare(aabbs, flags)
        lo = _as_point("box_min", box_min)
        hi = _as_point("box_max", box_max)
        if np.any(lo > hi):
            raise ValueError("box_min must be <= box_max on every axis")
        update(self.code, boxes, flag_arr, n, self.state_f, self.state_i)
        out = np.empty(n, np.int64)
        count = query_aabb(self.code, boxes, flag_arr, n, self.state_f, self.state_i, lo, hi, out)
        return out[:count].copy()

    def query_ray(self, aabbs, origin, direction, max_distance=math.inf, flags=None):
        """Indices of the live bodies whose box the ray from ``origin`` along ``direction`` enters
        within ``max_distance`` (m), sorted by entry distance, ties by index."""
        boxes, flag_arr, n = self._prepare(aabbs, flags)
        o = _as_point("origin", origin)
        d = _as_point("direction", direction)
        if not np.any(d != 0.0):
            raise ValueError("direction must be non-zero")
        if isinstance(max_distance, bool) or not isinstance(max_distance, (int, float, np.number)) \
                or math.isnan(max_distance) or max_distance < 0:
            raise ValueError(f"max_distance must be a number >= 0, got {max_distance!r}")
        update(self.code, boxes, flag_arr, n, self.state_f, self.state_i)
        out = np.empty(n, np.int64)
        count = query_ray(self.code, boxes, flag_arr, n, self.state_f, self.state_i, o, d,
                          float(max_distance), out)
        return out[:count].copy()
