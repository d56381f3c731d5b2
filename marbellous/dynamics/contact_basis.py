"""The contact basis of the lecture: the normal and two tangents spanning the contact plane.

    x = n,   y = normalize(n x (0, 0, 1)),   z = n x y

falling back to ``n x (1, 0, 0)`` when n is (nearly) parallel to z.  Deterministic: the same normal
always gives the same tangents, so friction impulses can be warm-started across steps.
"""
import math

from .._jit import njit


@njit
def contact_basis(n, t1, t2):
    """Write unit tangents ``t1``, ``t2`` with ``(n, t1, t2)`` right-handed and orthonormal."""
    # n x (0, 0, 1) = (n_y, -n_x, 0); n x (1, 0, 0) = (0, n_z, -n_y)
    if abs(n[2]) < 0.9:
        t1[0], t1[1], t1[2] = n[1], -n[0], 0.0
    else:
        t1[0], t1[1], t1[2] = 0.0, n[2], -n[1]
    s = 1.0 / math.sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2])
    t1[0] *= s
    t1[1] *= s
    t1[2] *= s
    t2[0] = n[1] * t1[2] - n[2] * t1[1]
    t2[1] = n[2] * t1[0] - n[0] * t1[2]
    t2[2] = n[0] * t1[1] - n[1] * t1[0]
