"""Closest points of segments: the building block of capsule and box-edge contacts.

A segment is ``p + s d`` for ``s`` in ``[0, 1]`` (points and directions are 3-tuples, metres).
"""
from ..._numba.jit import njit
from ..vec3 import dot, sub


@njit
def _clamp01(x):
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x


@njit
def closest_on_segment(p, d, q):
    """Parameter ``s`` in [0, 1] of the point of segment ``p + s d`` closest to ``q``.

    ``s = clamp((q - p).d / d.d, 0, 1)``; 0 for a degenerate segment.
    """
    dd = dot(d, d)
    if dd <= 0.0:
        return 0.0
    return _clamp01(dot(sub(q, p), d) / dd)


@njit
def closest_segment_params(p, d1, q, d2):
    """Parameters ``(s, t)`` of the closest points ``p + s d1`` and ``q + t d2`` of two segments.

    Minimises ``|p + s d1 - q - t d2|^2`` over the unit square (Ericson, Real-Time Collision
    Detection, 5.1.9): the unconstrained line solution ``s = (b f - c e) / (a e - b^2)`` with
    ``a = d1.d1, b = d1.d2, c = d1.(p - q), e = d2.d2, f = d2.(p - q)``, then clamped in turn.
    For parallel segments (``a e - b^2`` at rounding level) any minimiser may be returned; it
    starts from ``s = 0``.
    """
    r = sub(p, q)
    a = dot(d1, d1)
    e = dot(d2, d2)
    f = dot(d2, r)
    if a <= 0.0 and e <= 0.0:
        return 0.0, 0.0
    if a <= 0.0:
        return 0.0, _clamp01(f / e)
    c = dot(d1, r)
    if e <= 0.0:
        return _clamp01(-c / a), 0.0
    b = dot(d1, d2)
    denom = a * e - b * b
    s = 0.0
    if denom > 1e-14 * a * e:
        s = _clamp01((b * f - c * e) / denom)
    t = (b * s + f) / e
    if t < 0.0:
        return _clamp01(-c / a), 0.0
    if t > 1.0:
        return _clamp01((b - c) / a), 1.0
    return s, t
