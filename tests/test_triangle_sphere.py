"""Sphere-triangle SAT against a slow, obvious closest-point reference."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

from marbellous.collision.triangle.triangle_sphere import (EDGE_AB, EDGE_BC, EDGE_CA, FACE, VERTEX_A, VERTEX_B,
                                                           VERTEX_C, closest_feature, sphere_triangle)


def reference_closest(p, a, b, c):
    """Closest point of triangle abc to p: the plane projection if it is inside, else the nearest
    of the three edges' closest points (each by clamped projection)."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    q = p - np.dot(p - a, n) * n
    inside = all(np.dot(np.cross(w - v, q - v), n) >= 0.0 for v, w in ((a, b), (b, c), (c, a)))
    if inside:
        return q, "face"
    best, kind = None, None
    for v, w, name in ((a, b, "AB"), (b, c, "BC"), (c, a, "CA")):
        e = w - v
        t = np.clip(np.dot(p - v, e) / np.dot(e, e), 0.0, 1.0)
        x = v + t * e
        if best is None or np.linalg.norm(p - x) < np.linalg.norm(p - best):
            best, kind = x, name
    return best, kind


def tup(v):
    return tuple(float(x) for x in v)


coord = hst.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False, allow_subnormal=False)
point = hst.tuples(coord, coord, coord).map(np.array)


def good_triangle(a, b, c):
    cr = np.cross(b - a, c - a)
    longest = max(np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c))
    return np.linalg.norm(cr) > 0.05 * longest ** 2 and longest > 0.1


@settings(max_examples=3000, deadline=None)
@given(point, point, point, point, hst.floats(0.05, 1.5), hst.floats(0.0, 0.3))
def test_sphere_triangle_matches_reference(a, b, c, p, r, prediction):
    if not good_triangle(a, b, c):
        return
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    q_ref, kind = reference_closest(p, a, b, c)
    dist = np.linalg.norm(p - q_ref)
    feature, q = closest_feature(tup(p), tup(a), tup(b), tup(c), tup(n))
    assert np.allclose(q, q_ref, atol=1e-7)
    if kind == "face":
        assert feature == FACE or abs(np.linalg.norm(p - np.array(q)) - dist) < 1e-7
    feature, q, normal, depth = sphere_triangle(tup(p), r, tup(a), tup(b), tup(c), tup(n), prediction)
    s = float(np.dot(p - a, n))
    got = None if feature == -1 else (depth, np.array(normal))
    assert got is None or abs(np.linalg.norm(normal) - 1.0) < 1e-12
    face = None if (s > r + prediction or s < -r) else (r - s, -n)
    if dist > r + prediction:
        edge = None
    elif dist <= 1e-12 * r:      # centre on the triangle: the face normal
        edge = (r, -n)
    else:
        edge = (r - dist, (q_ref - p) / dist)
    expected = face if kind == "face" else edge
    # Behind the one-sided face, depth jumps where the projection crosses the triangle's rim
    # (face: r - s; outside: r - |P - Q|); within rounding of the rim either answer is right.
    on_rim = s < 0.0 and rim_distance(p - s * n, a, b, c) < 1e-9
    assert matches(got, expected) or (on_rim and matches(got, face if kind != "face" else edge))


def rim_distance(x, a, b, c):
    """Distance from a point x in the triangle's plane to the triangle's boundary."""
    best = np.inf
    for u, w in ((a, b), (b, c), (c, a)):
        e = w - u
        t = np.clip(np.dot(x - u, e) / np.dot(e, e), 0.0, 1.0)
        best = min(best, np.linalg.norm(x - u - t * e))
    return best


def matches(got, expected):
    if got is None or expected is None:
        return got is None and expected is None
    return abs(got[0] - expected[0]) < 1e-6 and np.allclose(got[1], expected[1], atol=1e-6)


A = np.array([0.0, 0.0, 0.0])
B = np.array([0.0, 0.0, 1.0])
C = np.array([1.0, 0.0, 0.0])     # (B - A) x (C - A) = +y


@pytest.mark.parametrize("p, feature", [
    ((0.2, 0.3, 0.2), FACE),
    ((-0.3, 0.2, 0.5), EDGE_AB),
    ((0.6, 0.2, 0.6), EDGE_BC),
    ((0.5, 0.2, -0.3), EDGE_CA),
    ((-0.2, 0.1, -0.2), VERTEX_A),
    ((-0.1, 0.1, 1.3), VERTEX_B),
    ((1.3, 0.1, -0.1), VERTEX_C),
])
def test_every_region_reports_its_feature(p, feature):
    f, q, normal, depth = sphere_triangle(p, 0.5, tup(A), tup(B), tup(C), (0.0, 1.0, 0.0), 0.0)
    assert f == feature
    q_ref, _ = reference_closest(np.array(p), A, B, C)
    assert np.allclose(q, q_ref, atol=1e-12)
    assert depth == pytest.approx(0.5 - np.linalg.norm(np.array(p) - q_ref), abs=1e-12)


def test_face_contact_is_one_sided():
    # Centre 0.3 behind the face: still pushed out to the front, depth r - s = 0.8.
    f, q, normal, depth = sphere_triangle((0.2, -0.3, 0.2), 0.5, tup(A), tup(B), tup(C), (0.0, 1.0, 0.0), 0.0)
    assert f == FACE and normal == (-0.0, -1.0, -0.0) and depth == pytest.approx(0.8)
    # More than r behind: no contact.
    f, *_ = sphere_triangle((0.2, -0.6, 0.2), 0.5, tup(A), tup(B), tup(C), (0.0, 1.0, 0.0), 0.0)
    assert f == -1


def test_prediction_reports_gap():
    f, q, normal, depth = sphere_triangle((0.2, 0.7, 0.2), 0.5, tup(A), tup(B), tup(C), (0.0, 1.0, 0.0), 0.25)
    assert f == FACE and depth == pytest.approx(-0.2)
    f, *_ = sphere_triangle((0.2, 0.7, 0.2), 0.5, tup(A), tup(B), tup(C), (0.0, 1.0, 0.0), 0.1)
    assert f == -1
