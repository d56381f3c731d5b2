"""3-vectors as tuples ``(x, y, z)`` of floats, for the narrow-phase kernels.

Tuples live in registers: the pair tests compute with them without allocating.  Rotation
matrices are (3, 3) arrays mapping local to world coordinates (their columns are the local axes).
"""
import math

from .._numba.jit import njit
from ..math3d import tensor_vec


@njit
def add(a, b):
    """``a + b``."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit
def sub(a, b):
    """``a - b``."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit
def scale(a, s):
    """``s a``."""
    return (a[0] * s, a[1] * s, a[2] * s)


@njit
def madd(a, s, b):
    """``a + s b``."""
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


@njit
def dot(a, b):
    """``a . b``."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def cross(a, b):
    """``a x b``."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit
def length(a):
    """Euclidean length ``|a|``."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit
def load(arr):
    """The first three entries of a float64 array as a tuple."""
    return (arr[0], arr[1], arr[2])


@njit
def column(rot, k):
    """Column ``k`` of the rotation matrix: the shape's local axis ``k`` in world coordinates."""
    return (rot[0, k], rot[1, k], rot[2, k])


@njit
def matrix(rot):
    """The (3, 3) rotation matrix array as a row-major 9-tuple ``(r00, r01, r02, r10, ..., r22)``.

    Pair tests that take their poses in registers (no array arguments, so no reference counting)
    use rotations in this form with ``mat_column``, ``mat_to_world`` and ``mat_to_local``.
    """
    return (rot[0, 0], rot[0, 1], rot[0, 2], rot[1, 0], rot[1, 1], rot[1, 2], rot[2, 0], rot[2, 1], rot[2, 2])


@njit
def mat_column(m, k):
    """Column ``k`` of the row-major 9-tuple rotation ``m``."""
    return (m[k], m[3 + k], m[6 + k])


@njit
def mat_to_world(m, v):
    """``R v`` for the row-major 9-tuple rotation ``m``."""
    return tensor_vec(m, v)


@njit
def mat_to_local(m, v):
    """``R^T v`` for the row-major 9-tuple rotation ``m``."""
    return (m[0] * v[0] + m[3] * v[1] + m[6] * v[2],
            m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
            m[2] * v[0] + m[5] * v[1] + m[8] * v[2])


@njit
def to_world(rot, v):
    """``R v``: a local direction in world coordinates."""
    return mat_to_world(matrix(rot), v)


@njit
def to_local(rot, v):
    """``R^T v``: a world direction in the shape's local coordinates."""
    return mat_to_local(matrix(rot), v)


@njit
def any_perpendicular(a):
    """A unit vector perpendicular to the non-zero vector ``a`` (a fixed choice for each ``a``).

    Crosses ``a`` with the world axis least aligned with it.
    """
    ax, ay, az = abs(a[0]), abs(a[1]), abs(a[2])
    if ax <= ay and ax <= az:
        p = (0.0, a[2], -a[1])
    elif ay <= az:
        p = (-a[2], 0.0, a[0])
    else:
        p = (a[1], -a[0], 0.0)
    return scale(p, 1.0 / length(p))
