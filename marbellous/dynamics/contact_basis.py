"""The contact basis of the lecture: the normal and two tangents spanning the contact plane.

    x = n,   y = normalize(n x (0, 0, 1)),   z = n x y

falling back to ``n x (1, 0, 0)`` when n is (nearly) parallel to z.  Deterministic: the same normal
always gives the same tangents, so friction impulses can be warm-started across steps.
"""
import math

from .._numba.jit import njit


@njit
def contact_basis(n):
    """Unit tangents ``(t1, t2)`` (3-tuples) with ``(n, t1, t2)`` right-handed and orthonormal."""
    # n x (0, 0, 1) = (n_y, -n_x, 0); n x (1, 0, 0) = (0, n_z, -n_y)
    if abs(n[2]) < 0.9:
        x, y, z = n[1], -n[0], 0.0
    else:
        x, y, z = 0.0, n[2], -n[1]
    s = 1.0 / math.sqrt(x * x + y * y + z * z)
    x *= s
    y *= s
    z *= s
    return (x, y, z), (n[1] * z - n[2] * y, n[2] * x - n[0] * z, n[0] * y - n[1] * x)
