"""Input validation for the public API: every check names the argument and the rule it broke."""
import math
import numbers

import numpy as np


def as_vec3(name, value):
    """Return ``value`` as a new float64 array of 3 finite numbers, or raise naming ``name``."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be 3 finite numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ValueError(f"{name} must have exactly 3 components, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {value!r}")
    return arr


def as_quat(name, value):
    """Return ``value`` as a unit (w, x, y, z) quaternion (normalised), or raise naming ``name``."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be 4 finite numbers (w, x, y, z), got {value!r}") from None
    if arr.shape != (4,):
        raise ValueError(f"{name} must have exactly 4 components (w, x, y, z), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {value!r}")
    n = float(np.sqrt(np.dot(arr, arr)))
    if n < 1e-9:
        raise ValueError(f"{name} must be a non-zero quaternion, got {value!r}")
    return arr / n


def as_float(name, value, *, positive=False, nonnegative=False, lo=None, hi=None, allow_inf=False):
    """Return ``value`` as a float, checking it is finite and within the stated range."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise TypeError(f"{name} must be a number, got {value!r}")
    v = float(value)
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {value!r}")
    if positive and not v > 0.0:
        raise ValueError(f"{name} must be > 0, got {v!r}")
    if nonnegative and not v >= 0.0:
        raise ValueError(f"{name} must be >= 0, got {v!r}")
    if lo is not None and v < lo:
        raise ValueError(f"{name} must be >= {lo}, got {v!r}")
    if hi is not None and v > hi:
        raise ValueError(f"{name} must be <= {hi}, got {v!r}")
    return v


def as_int(name, value, *, lo=None, hi=None):
    """Return ``value`` as an int within the stated range, or raise naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if lo is not None and v < lo:
        raise ValueError(f"{name} must be >= {lo}, got {v!r}")
    if hi is not None and v > hi:
        raise ValueError(f"{name} must be <= {hi}, got {v!r}")
    return v


def as_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices`` (strings), else raise listing them."""
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(repr(c) for c in choices)}; got {value!r}")
    return value
