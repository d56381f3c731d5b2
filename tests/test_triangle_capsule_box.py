"""Capsule-triangle and box-triangle tests against slow, obvious references."""
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as hst

from marbellous.collision.triangle.triangle_box import box_triangle
from marbellous.collision.triangle.triangle_capsule import capsule_triangle
from marbellous.collision.triangle.triangle_contact import MAX_ROWS, N_COLS

ZERO = (0.0, 0.0, 0.0)


def tup(v):
    return tuple(float(x) for x in v)


def point_triangle_distance(p, a, b, c):
    """Exact distance from the point(s) ``p`` (..., 3) to triangle abc: the plane distance where the
    projection falls inside, else the nearest of the three edges (clamped projection)."""
    p = np.asarray(p, float)
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    s = (p - a) @ n
    q = p - s[..., None] * n
    inside = np.ones(s.shape, bool)
    best = np.full(s.shape, np.inf)
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= np.cross(w - u, q - u) @ n >= 0
        e = w - u
        t = np.clip((p - u) @ e / (e @ e), 0, 1)
        best = np.minimum(best, np.linalg.norm(p - u - t[..., None] * e, axis=-1))
    return np.where(inside, np.abs(s), best)


def segment_triangle_distance(p0, p1, a, b, c):
    """Distance from the segment to the triangle.  Distance to a convex set is convex along the
    segment: sample it densely, then a ternary search around the best sample."""
    s = np.linspace(0.0, 1.0, 1001)
    f = lambda s: point_triangle_distance(p0 + np.multiply.outer(s, p1 - p0), a, b, c)  # noqa: E731
    k = int(np.argmin(f(s)))
    lo, hi = s[max(k - 1, 0)], s[min(k + 1, 1000)]
    for _ in range(50):
        m = np.array([lo + (hi - lo) / 3, hi - (hi - lo) / 3])
        d = f(m)
        if d[0] <= d[1]:
            hi = m[1]
        else:
            lo = m[0]
    return float(f(np.array([0.5 * (lo + hi)]))[0])


#: Fixed offsets that keep generated triangles from being slivers (hypothesis likes equal coordinates).
SPREAD_B = np.array([1.1, 0.3, -0.7])
SPREAD_C = np.array([-0.4, 1.3, 0.9])
coord = hst.floats(-2.0, 2.0, allow_subnormal=False)
point = hst.tuples(coord, coord, coord).map(np.array)


def good_triangle(a, b, c):
    cr = np.cross(b - a, c - a)
    longest = max(np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c))
    return longest > 0.2 and np.linalg.norm(cr) > 0.1 * longest ** 2


@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(point, point, point, point, point, hst.floats(0.05, 0.8), hst.floats(0.0, 0.3))
def test_capsule_depth_is_radius_minus_distance(a, b, c, p0, p1, r, prediction):
    b, c = b + SPREAD_B, c + SPREAD_C
    assume(good_triangle(a, b, c) and np.linalg.norm(p1 - p0) > 1e-3)
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    # Both ends in front of the one-sided face (mirrored there if generated behind it).
    p0 = p0 + 2.0 * max(0.0, -np.dot(p0 - a, n)) * n + 1e-6 * n
    p1 = p1 + 2.0 * max(0.0, -np.dot(p1 - a, n)) * n + 1e-6 * n
    scratch = np.zeros((MAX_ROWS, N_COLS))
    k = capsule_triangle(tup(p0), tup(p1), r, tup(a), tup(b), tup(c), tup(n), prediction, scratch)
    dist = segment_triangle_distance(p0, p1, a, b, c)
    if dist > r + prediction + 1e-9:
        assert k == 0
        return
    if dist < r + prediction - 1e-9:
        assert k >= 1
    if k == 0:
        return
    rows = scratch[:k]
    assert np.allclose(np.linalg.norm(rows[:, 3:6], axis=1), 1.0)
    assert np.max(rows[:, 6]) == pytest.approx(r - dist, abs=1e-7)
    for row in rows:
        # The point on the triangle is on it, and the capsule's axis point lies along -normal.
        assert point_triangle_distance(row[0:3], a, b, c) < 1e-9
        centre = row[8:11]
        t = np.dot(centre - p0, p1 - p0) / np.dot(p1 - p0, p1 - p0)
        assert -1e-9 <= t <= 1 + 1e-9
        assert np.allclose(centre + row[3:6] * (r - row[6]), row[0:3], atol=1e-9)


def test_capsule_lying_on_a_face_gives_two_points():
    a, b, c = np.array([-5.0, 0, -5]), np.array([0.0, 0, 5]), np.array([5.0, 0, -5])
    scratch = np.zeros((MAX_ROWS, N_COLS))
    k = capsule_triangle((-1.0, 0.28, 0.0), (1.0, 0.28, 0.0), 0.3, tup(a), tup(b), tup(c), (0.0, 1.0, 0.0),
                         0.0, scratch)
    assert k == 2
    assert np.allclose(scratch[:2, 6], 0.02) and np.allclose(scratch[:2, 3:6], [0, -1, 0])
    assert np.allclose(sorted(scratch[:2, 0]), [-1.0, 1.0])


def rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def box_corners(c, rot, h):
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    return c + (signs * h) @ rot.T


quat = hst.tuples(hst.floats(-1, 1), hst.floats(-1, 1), hst.floats(-1, 1), hst.floats(-1, 1)).filter(
    lambda q: np.linalg.norm(q) > 0.2).map(np.array)
half = hst.tuples(hst.floats(0.1, 0.8), hst.floats(0.1, 0.8), hst.floats(0.1, 0.8)).map(np.array)


@settings(max_examples=500, deadline=None)
@given(quat, half, hst.floats(-1.0, 1.0), hst.floats(-1.0, 1.0), hst.floats(1e-6, 0.25))
def test_box_on_a_big_triangle_touches_with_its_lowest_corners(q, h, x, z, sink):
    """A box over the middle of a big triangle: its contacts are its corners below the face, with
    depth = how far each is below, and the deepest equals the lowest corner's."""
    a, b, c = np.array([-20.0, 0, -20]), np.array([0.0, 0, 20]), np.array([20.0, 0, -20])
    rot = rotation(q)
    corners0 = box_corners(np.zeros(3), rot, h)
    centre = np.array([x, -corners0[:, 1].min() - sink, z])
    assume(centre[1] > 1e-9)            # the box's centre in front of the one-sided face
    scratch = np.zeros((MAX_ROWS, N_COLS))
    k = box_triangle(tup(centre), rot, h, tup(a), tup(b), tup(c), (0.0, 1.0, 0.0), ZERO, ZERO, ZERO, 0.0, scratch)
    assert k >= 1
    rows = scratch[:k]
    assert np.allclose(rows[:, 3:6], [0, -1, 0], atol=1e-12)
    assert np.max(rows[:, 6]) == pytest.approx(sink, abs=1e-9)
    corners = box_corners(centre, rot, h)
    for row in rows:
        # each contact is a point of the box (a corner or on its face) at its depth below y = 0
        assert row[6] == pytest.approx(-row[9], abs=1e-9)
        local = (row[8:11] - centre) @ rot
        assert np.all(np.abs(local) <= h + 1e-9)
    assert np.min(corners[:, 1]) == pytest.approx(-sink, abs=1e-9)


def box_distance(p, c, rot, h):
    local = (p - c) @ rot
    return np.linalg.norm(np.maximum(np.abs(local) - h, 0.0), axis=-1)


@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(point, point, point, point, quat, half, hst.floats(0.0, 0.2))
def test_box_triangle_separation_against_sampling(a, b, c, centre, q, h, prediction):
    """Sampled reference: a triangle point inside the box means contact; all sampled points farther
    than ``prediction`` plus the sampling step means none."""
    b, c = b + SPREAD_B, c + SPREAD_C
    assume(good_triangle(a, b, c))
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    centre = centre + 2.0 * max(0.0, -np.dot(centre - a, n)) * n    # box centre in front of the face
    rot = rotation(q)
    m = 60
    u, v = np.meshgrid(np.linspace(0, 1, m + 1), np.linspace(0, 1, m + 1))
    keep = u + v <= 1
    samples = a + u[keep, None] * (b - a) + v[keep, None] * (c - a)
    step = max(np.linalg.norm(b - a), np.linalg.norm(c - a)) / m
    d = box_distance(samples, centre, rot, h).min()
    scratch = np.zeros((MAX_ROWS, N_COLS))
    k = box_triangle(tup(centre), rot, h, tup(a), tup(b), tup(c), tup(n), ZERO, ZERO, ZERO, prediction, scratch)
    if d - step > prediction + 1e-9:
        assert k == 0
    if d == 0.0:
        assert k >= 1
    rows = scratch[:k]
    assert np.all(np.isfinite(rows))
    assert np.allclose(np.linalg.norm(rows[:, 3:6], axis=1), 1.0)
    assert np.all(rows[:, 6] >= -prediction - 1e-9)
