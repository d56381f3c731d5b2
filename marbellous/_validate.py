"""Input validation for the public API: every number a user passes goes through here.

One rule for every argument: a number is an ``int`` or a ``float`` (NumPy's integer and floating
scalars too); ``bool``, ``str``, ``complex``, ``None`` and other objects are refused with a
``TypeError``.  A number must be finite and within the argument's bounds, or a ``ValueError`` names
the argument and the rule it broke.  Vectors are sequences (or arrays) of such numbers, checked item by
item; big arrays (vertices, heights) are checked by their dtype.  Every check happens before anything is
written, so a refused call changes nothing.

The bounds below keep the engine's arithmetic finite and clear of subnormal numbers: a size squared, a
mass inverted, an inertia ``m r^2`` and its inverse, a step ``dt / substeps`` squared all stay normal
floats.  They are generous for a game (a grain of sand to a mountain range):

=================  =====================  =====================================================
quantity           bounds                 used for
=================  =====================  =====================================================
size               1e-6 .. 1e6 m          radii, half extents, half heights, grid spacings
coordinate         |x| <= 1e12 m          positions, anchors, offsets, vertices, heights
offset in a body   |x| <= 1e6 m           positions of the parts of a compound body
speed              |v| <= 1e9 m/s         velocities (each component); angular ones in rad/s
acceleration       |g| <= 1e6 m/s^2       gravity (each component)
force              |F| <= 1e20 N          forces, torques (N m), impulses (N s)
mass               1e-30 .. 1e30 kg       given or computed from a density
density            1e-6 .. 1e6 kg/m^3     computed masses must also lie in the mass bounds
inertia            ratio <= 1e10          largest over smallest principal moment of a body
time step          1e-6 .. 1 s            ``World.step``, ``World.advance``
frequency          1e-3 .. 1e6 Hz         stiffness of contacts, joints, penalty springs
=================  =====================  =====================================================

A positive quantity is never *subnormal* (below 2.2e-308): dividing by it overflows.  Where zero is
allowed (coordinates, friction, speeds), subnormal values are taken as they are: they are harmless
there, and a value read from the engine can always be written back.  Directions (normals, ray directions, rotation axes,
quaternions) are normalised safely, by scaling before squaring, so any finite nonzero vector has a
direction, however large or small its components.
"""
import math
import numbers

import numpy as np

#: Smallest and largest size of a shape (m): radii, half extents, half heights, grid spacings.
MIN_SIZE = 1e-6
MAX_SIZE = 1e6
#: Largest magnitude of a coordinate (m): positions, anchors, plane offsets, vertices, heights.
MAX_COORD = 1e12
#: Largest magnitude of a speed component (m/s, or rad/s for angular velocities).
MAX_SPEED = 1e9
#: Largest magnitude of a gravity component (m/s^2).
MAX_ACCELERATION = 1e6
#: Largest magnitude of a force (N), torque (N m) or impulse (N s) component.
MAX_FORCE = 1e20
#: Smallest and largest mass of a body (kg).
MIN_MASS = 1e-30
MAX_MASS = 1e30
#: Smallest and largest density (kg/m^3).
MIN_DENSITY = 1e-6
MAX_DENSITY = 1e6
#: Largest ratio of a body's largest to smallest principal moment of inertia: a thinner body (a box
#: more than ~1e5 times longer than it is thick) turns the rounding of its world inertia into runaway
#: spin in float64.
MAX_INERTIA_RATIO = 1e10
#: Shortest and longest time step (s).
MIN_DT = 1e-6
MAX_DT = 1.0
#: Lowest and highest stiffness frequency (Hz).
MIN_HERTZ = 1e-3
MAX_HERTZ = 1e6
#: Largest stiffness (N/m) or damping (N s/m) of a spring, and largest friction coefficient.
MAX_STIFFNESS = 1e15
MAX_FRICTION = 1e3
#: Largest linear or angular damping rate (1/s).
MAX_DAMPING = 1e6
#: Smallest normal float64: nonzero magnitudes below it are subnormal.
TINY = float(np.finfo(np.float64).tiny)

_SCALAR_TYPES = (numbers.Real, np.integer, np.floating)


def _short(value, limit=80):
    """``repr(value)``, cut to ``limit`` characters (a hostile value can have a huge or deep repr)."""
    try:
        text = repr(value)
    except Exception:   # noqa: BLE001  (a value whose repr fails or recurses too deeply)
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _scalar(name, value):
    """``value`` as a Python float if it is a real number (not a bool); raise TypeError otherwise,
    ValueError if it does not fit a float (an int over 1.8e308)."""
    if type(value) is float:        # (the common case, first)
        return value
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, _SCALAR_TYPES) \
            or isinstance(value, (complex, np.complexfloating)):
        raise TypeError(f"{name} must be a real number (int or float), got {_short(value)}")
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{name} is too large: {_short(value)} does not fit a float") from None
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number (int or float), got {_short(value)}") from None


def _check_range(name, v, raw, lo, hi, positive, nonnegative, allow_inf, unit):
    u = f" {unit}" if unit else ""
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {_short(raw)}")
    if positive and not v > 0.0:
        raise ValueError(f"{name} must be > 0, got {v!r}")
    if positive and v < TINY:
        raise ValueError(f"{name} must be > 0 and not subnormal (at least {TINY:.3g}), got {v!r}")
    if nonnegative and not v >= 0.0:
        raise ValueError(f"{name} must be >= 0, got {v!r}")
    if lo is not None and v < lo:
        raise ValueError(f"{name} must be >= {lo:g}{u}, got {v!r}")
    if hi is not None and v > hi:
        raise ValueError(f"{name} must be <= {hi:g}{u}, got {v!r}")
    return v


def as_float(name, value, *, positive=False, nonnegative=False, lo=None, hi=None, allow_inf=False, unit=""):
    """Return ``value`` (a real number, not a bool) as a float, finite (``allow_inf``: or ``+-inf``),
    normal or zero, and within the stated bounds; else raise TypeError or ValueError naming ``name``."""
    v = _scalar(name, value)
    return _check_range(name, v, value, lo, hi, positive, nonnegative, allow_inf, unit)


def as_size(name, value):
    """A size (m) in [MIN_SIZE, MAX_SIZE]: a radius, half extent, half height or grid spacing."""
    return as_float(name, value, lo=MIN_SIZE, hi=MAX_SIZE, unit="m")


def as_int(name, value, *, lo=None, hi=None):
    """Return ``value`` (an int or NumPy integer, not a bool) within ``[lo, hi]``; else raise naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {_short(value)}")
    v = int(value)
    if lo is not None and v < lo:
        raise ValueError(f"{name} must be >= {lo}, got {v!r}")
    if hi is not None and v > hi:
        raise ValueError(f"{name} must be <= {hi}, got {v!r}")
    return v


def as_filter_bits(name, value):
    """Return ``value``, collision filter bits (a ``group`` or ``mask``), as a 64-bit signed integer; else
    raise naming ``name``.  Negative values are the two's-complement bit patterns (-1: every bit)."""
    return as_int(name, value, lo=-(2 ** 63), hi=2 ** 63 - 1)


def as_flag(name, value):
    """``value`` if it is ``True`` or ``False``; else raise TypeError naming ``name``."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {_short(value)}")
    return bool(value)


def as_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices`` (strings), else raise listing them."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {', '.join(repr(c) for c in choices)}; got {_short(value)}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(repr(c) for c in choices)}; got {_short(value)}")
    return value


def as_vector(name, value, n, *, bound=None, unit=""):
    """Return ``value`` (a sequence or array of ``n`` real numbers) as a new float64 array of shape
    ``(n,)``, every component finite and, with ``bound``, at most ``bound`` in magnitude."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf":
            raise TypeError(f"{name} must be {n} real numbers, got an array of dtype {value.dtype}")
        if value.shape != (n,):
            raise ValueError(f"{name} must have exactly {n} components, got shape {value.shape}")
        arr = value.astype(np.float64)
        items = arr.tolist()
    else:
        if isinstance(value, (str, bytes, dict, set, frozenset)) or not hasattr(value, "__len__") \
                or not hasattr(value, "__getitem__"):
            raise TypeError(f"{name} must be {n} real numbers, got {_short(value)}")
        if len(value) != n:
            raise ValueError(f"{name} must have exactly {n} components, got {len(value)}: {_short(value)}")
        items = [_scalar(f"{name}[{k}]", value[k]) for k in range(n)]
        arr = np.array(items, dtype=np.float64)
    # (the components as Python floats: a few of them are checked faster one by one than as an array)
    if not all(map(math.isfinite, items)):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {_short(value)}")
    if bound is not None and items and max(map(abs, items)) > bound:
        u = f" {unit}" if unit else ""
        raise ValueError(f"{name} must have every component within +-{bound:g}{u}, got {_short(value)}")
    return arr


def as_vec3(name, value, *, bound=MAX_COORD, unit="m"):
    """Return ``value`` as a new float64 array of 3 finite numbers each at most ``bound`` in magnitude
    (default: a coordinate, ``MAX_COORD`` m), or raise naming ``name``."""
    return as_vector(name, value, 3, bound=bound, unit=unit)


def safe_norm(v):
    """Euclidean length of the finite vector ``v``, computed without overflow or underflow (scaled by
    its largest component before squaring)."""
    m = float(np.max(np.abs(v))) if v.size else 0.0
    if m == 0.0:
        return 0.0
    s = v / m
    return m * math.sqrt(float(np.dot(s, s)))


def normalized(name, v, what="vector"):
    """The unit vector along the finite array ``v``, scaled before squaring so that any nonzero finite
    ``v`` (1e300 or 1e-320 components alike) has one; raise ValueError naming ``name`` if ``v`` is zero."""
    m = float(np.max(np.abs(v)))
    if m == 0.0:
        raise ValueError(f"{name} must be a non-zero {what}, got {tuple(float(x) for x in v)}")
    s = v / m
    return s / math.sqrt(float(np.dot(s, s)))


def as_direction(name, value):
    """A unit 3-vector along ``value`` (any finite nonzero vector, normalised safely)."""
    return normalized(name, as_vector(name, value, 3), "vector")


def as_limits(name, value, bounds, unit):
    """``(lower, upper)`` from a pair of finite numbers with ``bounds[0] <= lower <= upper <= bounds[1]``
    (rad or m, ``unit``); or raise naming ``name``."""
    v = as_vector(name, value, 2, bound=max(abs(bounds[0]), abs(bounds[1])), unit=unit)
    lower, upper = float(v[0]), float(v[1])
    if not bounds[0] <= lower <= upper <= bounds[1]:
        raise ValueError(f"{name} must be (lower, upper) with {bounds[0]:.6g} <= lower <= upper <= {bounds[1]:.6g}"
                         f" {unit}, got {_short(value)}")
    return lower, upper


def as_motor_speed(value, unit):
    """A joint motor's target speed (``unit`` per second: rad/s or m/s) within +-``MAX_SPEED``."""
    return as_float("motor_speed", value, lo=-MAX_SPEED, hi=MAX_SPEED, unit=unit + "/s")


def as_quat(name, value):
    """Return ``value`` (4 finite numbers, not all zero) as a unit (w, x, y, z) quaternion, normalised
    safely; or raise naming ``name``."""
    return normalized(name, as_vector(name, value, 4), "quaternion (w, x, y, z)")


def as_real_array(name, value, *, ndim=None):
    """``value`` (an array or nested sequences of real numbers) as a new float64 NumPy array with
    ``ndim`` dimensions.  Arrays of bools, strings, complex numbers or objects, ragged nesting, and
    sequences holding bools or non-numbers are refused (TypeError)."""
    if isinstance(value, np.ndarray):
        arr = value
    else:
        if isinstance(value, (str, bytes, dict, set, frozenset)) or value is None:
            raise TypeError(f"{name} must be an array of real numbers, got {_short(value)}")
        try:
            arr = np.asarray(value)
        except (TypeError, ValueError, OverflowError):
            raise TypeError(f"{name} must be a (non-ragged) array of real numbers, got {_short(value)}") from None
        if arr.dtype.kind in "iuf" and _holds_bool(value):
            raise TypeError(f"{name} must hold real numbers, not bools")
    if arr.dtype == object:
        # Python ints too large for int64 (or mixed objects): every item must be a real number.
        arr = np.array([_scalar(f"{name} item", x) for x in arr.reshape(-1)], np.float64).reshape(arr.shape)
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must be a {ndim}-D array, got shape {arr.shape}")
    return np.array(arr, dtype=np.float64)


def _holds_bool(value, depth=0):
    """True if the nested sequence ``value`` holds a bool anywhere (lists of up to 3 levels)."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if depth > 3 or isinstance(value, (str, bytes, np.ndarray)):
        return isinstance(value, np.ndarray) and value.dtype == np.bool_
    if isinstance(value, (list, tuple)):
        return any(_holds_bool(x, depth + 1) for x in value)
    return False
