"""Narrow-phase pair tests of the primitives against slow, obvious NumPy references.

References: support functions and signed distances written out directly, the separating-axis
overlap as ``max_A(L) - min_B(L)`` over the candidate axes (checked against random directions),
closest points by ternary search of convex functions.
"""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as hst

from marbellous.collision import shape_types as st
from marbellous.collision.pairs.box_box import collide_box_box
from marbellous.collision.pairs.dispatch import collide_convex_pair
from marbellous.collision.tolerances import CLIP_SLOP, FACE_BIAS, PARALLEL_SIN

# ----------------------------------------------------------------------------- references


def quat_matrix(q):
    """Rotation matrix of a quaternion: ``R = (w^2 - v.v) I + 2 v v^T + 2 w [v]x``."""
    q = np.asarray(q, float)
    q = q / np.linalg.norm(q)
    w, v = q[0], q[1:]
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return (w * w - v @ v) * np.eye(3) + 2.0 * np.outer(v, v) + 2.0 * w * k


class Shape:
    """A placed primitive: type code, kernel params, world position and rotation matrix."""

    def __init__(self, kind, dims, pos=(0.0, 0.0, 0.0), quat=(1.0, 0.0, 0.0, 0.0)):
        self.kind = kind
        self.params = np.zeros(8)
        self.params[: len(dims)] = dims
        self.pos = np.array(pos, float)
        self.rot = quat_matrix(quat)

    def __repr__(self):
        return f"Shape({st.NAMES[self.kind]}, {self.params.tolist()}, {self.pos.tolist()}, {self.rot.tolist()})"

    def moved(self, dpos=(0.0, 0.0, 0.0)):
        s = Shape.__new__(Shape)
        s.kind, s.params, s.rot = self.kind, self.params, self.rot
        s.pos = self.pos + np.asarray(dpos, float)
        return s

    # segment of a capsule, corners of a box, world plane
    def segment(self):
        u = self.rot[:, 1] * self.params[1]
        return self.pos - u, self.pos + u

    def corners(self):
        h = self.params[:3]
        return np.array([self.pos + self.rot @ (h * np.array(s)) for s in np.ndindex(2, 2, 2)
                         for s in [[2 * s[0] - 1, 2 * s[1] - 1, 2 * s[2] - 1]]])

    def plane(self):
        n = self.rot @ self.params[:3]
        return n, self.params[3] + n @ self.pos

    def support(self, d):
        """Farthest point of the shape along the unit direction ``d`` (not for planes)."""
        if self.kind == st.SPHERE:
            return self.pos + self.params[0] * d
        if self.kind == st.CAPSULE:
            u = self.rot[:, 1]
            return self.pos + math.copysign(self.params[1], u @ d) * u + self.params[0] * d
        local = self.rot.T @ d
        return self.pos + self.rot @ (self.params[:3] * np.where(local >= 0.0, 1.0, -1.0))

    def sdf(self, p):
        """Signed distance of the world point(s) ``p`` (..., 3) to the shape's surface (< 0 inside)."""
        p = np.asarray(p, float)
        if self.kind == st.SPHERE:
            return np.linalg.norm(p - self.pos, axis=-1) - self.params[0]
        if self.kind == st.CAPSULE:
            return point_segment_distance(p, *self.segment()) - self.params[0]
        if self.kind == st.BOX:
            q = np.abs((p - self.pos) @ self.rot) - self.params[:3]
            return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)
        n, off = self.plane()
        return p @ n - off


def point_segment_distance(p, a, b):
    """Distance of the point(s) ``p`` (..., 3) to the segment ``a b``."""
    d = b - a
    t = np.clip((p - a) @ d / (d @ d), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * d), axis=-1)


def ternary_min(f, iterations=100):
    """``min f(s)`` over ``s`` in [0, 1] for a convex ``f``; returns ``(s, f(s))``."""
    lo, hi = 0.0, 1.0
    for _ in range(iterations):
        m1 = lo + (hi - lo) / 3.0
        m2 = hi - (hi - lo) / 3.0
        if f(m1) <= f(m2):
            hi = m2
        else:
            lo = m1
    s = 0.5 * (lo + hi)
    return s, f(s)


def overlap(a, b, axis):
    """How far b must move along the unit ``axis`` to clear a: ``max_a(L) - min_b(L)``."""
    return axis @ (a.support(axis) - b.support(-axis))


def sat_axes(a, b):
    """Candidate axes of the separating-axis test for boxes and capsule axes (unit, both signs)."""
    dirs_a = [a.rot[:, 1]] if a.kind == st.CAPSULE else [a.rot[:, k] for k in range(3)]
    dirs_b = [b.rot[:, 1]] if b.kind == st.CAPSULE else [b.rot[:, k] for k in range(3)]
    faces = ([] if a.kind == st.CAPSULE else dirs_a) + ([] if b.kind == st.CAPSULE else dirs_b)
    axes = list(faces)
    for u in dirs_a:
        for v in dirs_b:
            c = np.cross(u, v)
            if np.linalg.norm(c) > 1e-6:
                axes.append(c / np.linalg.norm(c))
    return [s * x for x in axes for s in (1.0, -1.0)]


def polytope_depth(a, b):
    """Least overlap over the separating axes: penetration depth (> 0) or minus a lower bound of the gap."""
    return min(overlap(a, b, axis) for axis in sat_axes(a, b))


def segment_box_depth(cap, box):
    """Penetration depth of a capsule and a box: ``r - dist`` apart, ``r + least axis overlap`` when
    the axis segment meets the box."""
    p0, p1 = cap.segment()
    _, dist = ternary_min(lambda s: box.sdf(p0 + s * (p1 - p0)))
    r = cap.params[0]
    if dist > 1e-9:
        return r - dist
    seg = Shape(st.CAPSULE, [0.0, cap.params[1]])
    seg.pos, seg.rot = cap.pos, cap.rot
    return r + polytope_depth(seg, box)


def reference_depth(a, b):
    """Exact penetration depth (> 0) or minus the gap of two primitives (box-box: SAT bound)."""
    if a.kind > b.kind:
        a, b = b, a
    if a.kind == st.SPHERE:
        return a.params[0] - b.sdf(a.pos)
    if b.kind == st.PLANE:
        if a.kind == st.CAPSULE:
            return a.params[0] - min(b.sdf(p) for p in a.segment())
        return -min(b.sdf(p) for p in a.corners())
    if a.kind == st.CAPSULE and b.kind == st.CAPSULE:
        a0, a1 = a.segment()
        b0, b1 = b.segment()
        _, dist = ternary_min(lambda s: point_segment_distance(a0 + s * (a1 - a0), b0, b1))
        return a.params[0] + b.params[0] - dist
    if a.kind == st.CAPSULE:
        return segment_box_depth(a, b)
    return polytope_depth(a, b)


def normal_overlap(a, b, normal):
    """Overlap along the contact normal (for a plane b: how deep a reaches below it)."""
    if b.kind == st.PLANE:
        n, off = b.plane()
        return off - n @ a.support(-n)
    if a.kind == st.PLANE:
        n, off = a.plane()
        return off - n @ b.support(-n)
    return overlap(a, b, normal)


def run(a, b, prediction=0.0, capacity=16):
    """Call the dispatcher; returns (count, rows of out_f, ids)."""
    out_f = np.full((capacity, 7), np.nan)
    out_i = np.full(capacity, -1, np.int64)
    n = collide_convex_pair(a.kind, a.pos, a.rot, a.params, b.kind, b.pos, b.rot, b.params,
                            prediction, out_f, out_i, 0)
    return n, out_f[: min(n, capacity)], out_i[: min(n, capacity)]


def check_manifold(a, b, rows, prediction=0.0):
    """Properties every contact has: finite, unit normal, depth within the overlap along its normal,
    both surface points inside (or on) their shapes."""
    assert np.all(np.isfinite(rows))
    for row in rows:
        point, normal, depth = row[:3], row[3:6], row[6]
        assert abs(np.linalg.norm(normal) - 1.0) < 1e-9
        assert depth >= -prediction - 1e-12
        assert depth <= normal_overlap(a, b, normal) + 1e-9
        assert a.sdf(point + 0.5 * depth * normal) <= 1e-8
        assert b.sdf(point - 0.5 * depth * normal) <= 1e-8


# ----------------------------------------------------------------------------- strategies

coord = hst.floats(-1.5, 1.5)
size = hst.floats(0.1, 1.2)
quat = hst.tuples(*[hst.floats(-1.0, 1.0)] * 4).filter(lambda q: sum(x * x for x in q) > 0.05)
position = hst.tuples(coord, coord, coord)


@hst.composite
def shapes(draw, kind):
    if kind == st.SPHERE:
        dims = [draw(size)]
    elif kind == st.CAPSULE:
        dims = [draw(size), draw(size)]
    elif kind == st.BOX:
        dims = [draw(size), draw(size), draw(size)]
    else:
        n = np.array(draw(hst.tuples(coord, coord, coord)))
        assume(np.linalg.norm(n) > 0.1)
        dims = list(n / np.linalg.norm(n)) + [draw(coord)]
    return Shape(kind, dims, draw(position), draw(quat))


CONVEX = [st.SPHERE, st.CAPSULE, st.BOX]
PAIRS = [(a, b) for a in range(4) for b in range(a, 4) if not (a == b == st.PLANE)]
#: pairs whose deepest contact is exactly the penetration depth
EXACT = {(st.SPHERE, st.SPHERE), (st.SPHERE, st.CAPSULE), (st.SPHERE, st.BOX), (st.SPHERE, st.PLANE),
         (st.CAPSULE, st.PLANE), (st.BOX, st.PLANE)}


def size_of(s):
    return min(v for v in s.params[:3] if v > 0.0) if s.kind == st.BOX else s.params[0]


# ----------------------------------------------------------------------------- random poses


@pytest.mark.parametrize("kinds", PAIRS, ids=lambda k: f"{st.NAMES[k[0]]}-{st.NAMES[k[1]]}")
@settings(max_examples=250, deadline=None)
@given(data=hst.data())
def test_random_poses_against_reference(kinds, data):
    verify_against_reference(kinds, data.draw(shapes(kinds[0])), data.draw(shapes(kinds[1])))


def normal_rounding(a, b, pd):
    """Bound on how far the overlap along a sphere's contact normal can stray from the depth by rounding.

    The normal is the unit vector from the other shape's core (a capsule's segment, a box) to the sphere's
    centre, a vector of length ``d``; its coordinates carry rounding of about ``eps * scale`` (``scale``:
    the size of the coordinates), so its direction is off by up to ~``4 eps scale / d`` radians.  A
    sphere's support does not change to first order with the direction, but a capsule's (along its axis,
    by its half height) and a box's (by its half extents) do.  Zero where the normal is exact (planes,
    a centre inside the box) or the error is second order (two spheres)."""
    if a.kind > b.kind:
        a, b = b, a
    if a.kind != st.SPHERE or b.kind not in (st.CAPSULE, st.BOX):
        return 0.0
    core = a.params[0] + (b.params[0] if b.kind == st.CAPSULE else 0.0)
    d = core - pd
    if d <= 0.0:
        return 0.0
    extent = b.params[1] if b.kind == st.CAPSULE else float(np.linalg.norm(b.params[:3]))
    scale = np.abs(a.pos).max() + np.abs(b.pos).max() + a.params[0] + b.params[:3].max()
    return extent * 4.0 * np.finfo(float).eps * scale / d


def verify_against_reference(kinds, a, b):
    """The manifold of a and b checked against the reference penetration depth."""
    pd = reference_depth(a, b)
    n, rows, ids = run(a, b)
    check_manifold(a, b, rows)
    if pd > 1e-7:
        assert n >= 1
    elif pd < -1e-7:
        assert n == 0
    if n == 0:
        return
    deepest = rows[np.argmax(rows[:, 6])]
    normal = deepest[3:6]
    bias = FACE_BIAS * min(size_of(a), size_of(b))
    if kinds in EXACT:
        assert deepest[6] == pytest.approx(pd, abs=1e-9)
        assert normal_overlap(a, b, normal) == pytest.approx(pd, abs=1e-9 + normal_rounding(a, b, pd))
    elif kinds == (st.CAPSULE, st.CAPSULE):
        assert deepest[6] <= pd + 1e-9
        if n == 1:
            assert deepest[6] == pytest.approx(pd, abs=1e-9)
        else:
            assert deepest[6] >= pd - 2.0 * PARALLEL_SIN * (a.params[1] + b.params[1])
    elif kinds == (st.CAPSULE, st.BOX) and np.abs(b.rot.T @ normal).max() > 1.0 - 1e-12 \
            and abs(a.rot[:, 1] @ normal) < PARALLEL_SIN:
        # a capsule lying along a face: the face normal, within PARALLEL_SIN of the best one
        assert deepest[6] <= pd + bias + 1e-9
        reach = a.params[1] + np.linalg.norm(b.params[:3]) + a.params[0]
        assert normal_overlap(a, b, normal) <= pd + bias + 2.0 * PARALLEL_SIN * reach
    else:
        # capsule-box and box-box: the normal's overlap is the least overlap up to the face bias
        assert normal_overlap(a, b, normal) <= pd + bias + 1e-9
    if kinds == (st.BOX, st.BOX):
        # and the deepest clipped point reaches that overlap
        assert pd - 1e-9 <= deepest[6] <= pd + bias + 1e-9
    # every manifold point is a real point of both shapes when they overlap
    assert len(set(ids.tolist())) == n


QUARTER_TURNS = [(1.0, 0.0, 0.0, 0.0), (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0),
                 (math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)), (0.5, 0.5, 0.5, 0.5)]


@pytest.mark.parametrize("kinds", [(st.CAPSULE, st.CAPSULE), (st.CAPSULE, st.BOX), (st.BOX, st.BOX),
                                   (st.CAPSULE, st.PLANE), (st.BOX, st.PLANE)],
                         ids=lambda k: f"{st.NAMES[k[0]]}-{st.NAMES[k[1]]}")
@settings(max_examples=300, deadline=None)
@given(data=hst.data(), turn=hst.sampled_from(QUARTER_TURNS), axis=hst.tuples(coord, coord, coord),
       angle=hst.sampled_from([0.0, 1e-9, 1e-4, 0.01, 0.03, 0.05]), offset=hst.tuples(coord, coord, coord))
def test_nearly_parallel_features(kinds, data, turn, axis, angle, offset):
    """Parallel and nearly parallel faces and axes (stacks, lying capsules): the clipping and
    two-point paths, against the same reference."""
    a = data.draw(shapes(kinds[0]))
    b = data.draw(shapes(kinds[1]))
    axis = np.array(axis) if np.linalg.norm(axis) > 0.1 else np.array([0.0, 1.0, 0.0])
    tilt = quat_matrix(axis_angle(axis, angle)) @ quat_matrix(turn)
    if b.kind == st.PLANE:
        a.rot = tilt @ quat_matrix(QUARTER_TURNS[1])     # a capsule lying in x-z, a box's face down
        b.params[:4] = (0.0, 1.0, 0.0, 0.0)
        b.rot = np.eye(3)
    else:
        b.rot = a.rot @ tilt
        b.pos = a.pos + 0.5 * a.rot @ np.array(offset)
    verify_against_reference(kinds, a, b)


@pytest.mark.parametrize("kinds", PAIRS, ids=lambda k: f"{st.NAMES[k[0]]}-{st.NAMES[k[1]]}")
@settings(max_examples=150, deadline=None)
@given(data=hst.data())
def test_swapping_shapes_negates_normals(kinds, data):
    a = data.draw(shapes(kinds[0]))
    b = data.draw(shapes(kinds[1]))
    n_ab, rows_ab, ids_ab = run(a, b)
    n_ba, rows_ba, ids_ba = run(b, a)
    check_manifold(b, a, rows_ba)
    if kinds[0] != kinds[1]:
        # the dispatcher runs the same pair test and flips the normals
        assert n_ab == n_ba
        np.testing.assert_array_equal(rows_ab[:, :3], rows_ba[:, :3])
        np.testing.assert_array_equal(rows_ab[:, 3:6], -rows_ba[:, 3:6])
        np.testing.assert_array_equal(rows_ab[:, 6], rows_ba[:, 6])
        np.testing.assert_array_equal(ids_ab, ids_ba)
        return
    assert (n_ab == 0) == (n_ba == 0)
    if n_ab == 0:
        return
    # two equal kinds at one centre have no preferred direction: each side picks its fixed fallback
    assume(np.linalg.norm(a.pos - b.pos) > 1e-9)
    if kinds == (st.CAPSULE, st.CAPSULE):
        # nor do two capsules on one line
        ua, off = a.rot[:, 1], b.pos - a.pos
        assume(np.linalg.norm(np.cross(ua, b.rot[:, 1])) > 1e-9 or np.linalg.norm(off - (off @ ua) * ua) > 1e-9)
    deep_ab = rows_ab[np.argmax(rows_ab[:, 6])]
    deep_ba = rows_ba[np.argmax(rows_ba[:, 6])]
    if kinds == (st.BOX, st.BOX):
        # the same axis is found from both sides unless two different axes are within the face bias
        overlaps = np.array([overlap(a, b, x) for x in sat_axes(a, b)])
        bias = FACE_BIAS * min(size_of(a), size_of(b))
        near = [x for x, o in zip(sat_axes(a, b), overlaps) if o <= overlaps.min() + 3.0 * bias]
        assume(all(abs(x @ near[0]) > 1.0 - 1e-12 for x in near))
    if kinds == (st.CAPSULE, st.CAPSULE) and max(n_ab, n_ba) == 2:
        # nearly parallel axes: the two points sit on the first capsule's axis, each with its own
        # normal, so the two orders agree only within the parallel tolerance
        assert deep_ab[3:6] @ deep_ba[3:6] <= -1.0 + 2.0 * PARALLEL_SIN
        return
    # (faces parallel to within 1.4e-6 rad may serve as the reference from either side)
    np.testing.assert_allclose(deep_ab[3:6], -deep_ba[3:6], atol=2e-6)
    if n_ab == 1 and n_ba == 1:
        assert deep_ab[6] == pytest.approx(deep_ba[6], abs=1e-9)
        np.testing.assert_allclose(deep_ab[:3], deep_ba[:3], atol=1e-9)


@pytest.mark.parametrize("kinds", [(a, b) for a in CONVEX for b in CONVEX if a <= b])
@settings(max_examples=60, deadline=None)
@given(data=hst.data())
def test_coincident_centres_give_finite_contacts(kinds, data):
    a = data.draw(shapes(kinds[0]))
    b = data.draw(shapes(kinds[1]))
    b.pos = a.pos.copy()
    if data.draw(hst.booleans()):
        b.rot = a.rot.copy()
    n, rows, _ = run(a, b)
    assert n >= 1
    check_manifold(a, b, rows)
    assert rows[:, 6].max() > 0.0


@pytest.mark.parametrize("kinds", PAIRS, ids=lambda k: f"{st.NAMES[k[0]]}-{st.NAMES[k[1]]}")
@settings(max_examples=100, deadline=None)
@given(data=hst.data())
def test_prediction_reports_small_gaps(kinds, data):
    """Moving b away by a gap g along the deepest normal: a contact of depth ~ -g while g <= prediction."""
    a = data.draw(shapes(kinds[0]))
    b = data.draw(shapes(kinds[1]))
    n, rows, _ = run(a, b)
    assume(n >= 1)
    deepest = rows[np.argmax(rows[:, 6])]
    gap = data.draw(hst.floats(0.001, 0.1))
    b2 = b.moved(deepest[3:6] * (deepest[6] + gap)) if b.kind != st.PLANE else None
    if b2 is None:
        a2 = a.moved(-deepest[3:6] * (deepest[6] + gap))
        pair = (a2, b)
    else:
        pair = (a, b2)
    pd = reference_depth(*pair)
    assume(pd < -1e-6)
    n2, rows2, _ = run(*pair, prediction=2.0 * gap)
    check_manifold(*pair, rows2, prediction=2.0 * gap)
    if n2:
        assert rows2[:, 6].max() <= 1e-9
    if -pd > 2.0 * gap:
        assert n2 == 0
    elif kinds != (st.BOX, st.BOX) and -pd < 2.0 * gap - 1e-9:
        assert n2 >= 1
    if kinds in EXACT and n2:
        assert rows2[:, 6].max() == pytest.approx(pd, abs=1e-9)
    assert run(*pair, prediction=0.0)[0] == 0


# ----------------------------------------------------------------------------- constructed cases


def yaw(angle):
    return (math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0)


def axis_angle(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return (math.cos(angle / 2), *(math.sin(angle / 2) * axis))


@settings(max_examples=200, deadline=None)
@given(angle=hst.floats(-math.pi, math.pi), dx=hst.floats(-0.3, 0.3), dz=hst.floats(-0.3, 0.3),
       depth=hst.floats(1e-6, 0.05))
def test_box_resting_on_box_gives_four_equal_depths(angle, dx, dz, depth):
    ground = Shape(st.BOX, [2.0, 0.5, 2.0], (0.0, -0.5, 0.0))
    top = Shape(st.BOX, [0.5, 0.25, 0.5], (dx, 0.25 - depth, dz), yaw(angle))
    for a, b, sign in ((ground, top, 1.0), (top, ground, -1.0)):
        n, rows, ids = run(a, b)
        assert n == 4
        np.testing.assert_allclose(rows[:, 6], depth, atol=1e-12)
        np.testing.assert_allclose(rows[:, 3:6], [[0.0, sign, 0.0]] * 4, atol=1e-12)
        bottom = top.corners()[top.corners()[:, 1] < top.pos[1]]
        # Clipping keeps a vertex up to CLIP_SLOP times the smallest half extent (0.25) outside a plane.
        np.testing.assert_allclose(np.sort(rows[:, 0]), np.sort(bottom[:, 0]), atol=CLIP_SLOP * 0.25)
        np.testing.assert_allclose(rows[:, 1], -0.5 * depth, atol=1e-12)
        check_manifold(a, b, rows)


@settings(max_examples=200, deadline=None)
@given(angle=hst.floats(-math.pi, math.pi), dx=hst.floats(-0.2, 0.2), dz=hst.floats(-0.2, 0.2),
       depth=hst.floats(0.001, 0.05), tilt=hst.floats(-0.02, 0.02))
def test_feature_ids_are_stable_under_tiny_motion(angle, dx, dz, depth, tilt):
    ground = Shape(st.BOX, [1.0, 0.5, 1.0], (0.0, -0.5, 0.0))
    top = Shape(st.BOX, [0.5, 0.25, 0.5], (dx, 0.25 - depth, dz), yaw(angle))
    top.rot = quat_matrix(axis_angle((1.0, 0.0, 0.3), tilt)) @ top.rot
    n, rows, ids = run(ground, top)
    assert n >= 1
    for step in ((1e-7, 0.0, 0.0), (0.0, 1e-7, 1e-7), (-1e-7, -1e-8, 1e-7)):
        n2, rows2, ids2 = run(ground, top.moved(step))
        assert n2 == n
        np.testing.assert_array_equal(ids2, ids)
        np.testing.assert_allclose(rows2[:, 6], rows[:, 6], atol=1e-6)


def test_box_stacked_on_equal_box_keeps_corner_ids():
    """Equal boxes stacked exactly: the corners lie on the side planes; tiny drift keeps their ids."""
    a = Shape(st.BOX, [0.5, 0.5, 0.5], (0.0, 0.0, 0.0))
    b = Shape(st.BOX, [0.5, 0.5, 0.5], (0.0, 0.999, 0.0))
    n, rows, ids = run(a, b)
    assert n == 4
    for d in ((1e-12, 0.0, 0.0), (0.0, 0.0, -1e-12), (3e-11, 0.0, 2e-11)):
        n2, _, ids2 = run(a, b.moved(d))
        assert n2 == 4
        assert sorted(ids2.tolist()) == sorted(ids.tolist())


@settings(max_examples=100, deadline=None)
@given(gap=hst.floats(-0.1, -0.001), ya=hst.floats(-0.3, 0.3), xb=hst.floats(-0.3, 0.3))
def test_crossed_edges_give_one_point(gap, ya, xb):
    """Box a with a ridge along z, box b above with a ridge along x: edge on edge."""
    a = Shape(st.BOX, [0.5, 0.5, 1.0], (0.0, ya, 0.0), axis_angle((0, 0, 1), math.pi / 4))
    # a's ridge is at ya + 0.5 sqrt(2), b's lowest edge at b.y - 0.5 sqrt(2): gap apart
    b = Shape(st.BOX, [1.0, 0.5, 0.5], (xb, ya + math.sqrt(2.0) + gap, 0.0), axis_angle((1, 0, 0), math.pi / 4))
    for first, second, sign in ((a, b, 1.0), (b, a, -1.0)):
        n, rows, ids = run(first, second)
        assert n == 1
        np.testing.assert_allclose(rows[0, 3:6], [0.0, sign, 0.0], atol=1e-12)
        assert rows[0, 6] == pytest.approx(-gap, abs=1e-12)
        np.testing.assert_allclose(rows[0, :3], [0.0, ya + 0.5 * math.sqrt(2.0) + 0.5 * gap, 0.0],
                                   atol=1e-12)
        check_manifold(first, second, rows)


def test_capsules_lying_side_by_side_give_two_points():
    lying = axis_angle((0, 0, 1), math.pi / 2)
    a = Shape(st.CAPSULE, [0.5, 1.0], (0.0, 0.0, 0.0), lying)
    b = Shape(st.CAPSULE, [0.3, 0.5], (0.7, 0.75, 0.0), lying)
    n, rows, ids = run(a, b)
    assert n == 2
    np.testing.assert_allclose(rows[:, 3:6], [[0.0, 1.0, 0.0]] * 2, atol=1e-12)
    np.testing.assert_allclose(rows[:, 6], 0.05, atol=1e-12)
    np.testing.assert_allclose(sorted(rows[:, 0]), [0.2, 1.0], atol=1e-12)
    assert sorted(ids.tolist()) == [1, 2]
    check_manifold(a, b, rows)


def test_capsule_lying_on_box_and_plane_gives_two_points():
    lying = axis_angle((0, 0, 1), math.pi / 2)
    cap = Shape(st.CAPSULE, [0.25, 0.5], (0.2, 0.24, 0.1), lying)
    box = Shape(st.BOX, [2.0, 0.5, 2.0], (0.0, -0.5, 0.0))
    ground = Shape(st.PLANE, [0.0, 1.0, 0.0, 0.0])
    for other in (box, ground):
        n, rows, ids = run(cap, other)
        assert n == 2
        np.testing.assert_allclose(rows[:, 3:6], [[0.0, -1.0, 0.0]] * 2, atol=1e-12)
        np.testing.assert_allclose(rows[:, 6], 0.01, atol=1e-12)
        np.testing.assert_allclose(sorted(rows[:, 0]), [-0.3, 0.7], atol=1e-12)
        np.testing.assert_allclose(rows[:, 1], -0.005, atol=1e-12)


def test_box_on_plane_gives_four_deepest_corners():
    box = Shape(st.BOX, [0.5, 0.25, 0.5], (1.0, 0.2, -1.0), yaw(0.3))
    ground = Shape(st.PLANE, [0.0, 1.0, 0.0, 0.0])
    n, rows, ids = run(box, ground)
    assert n == 4
    np.testing.assert_allclose(rows[:, 6], 0.05, atol=1e-12)
    assert sorted(ids.tolist()) == [0, 1, 4, 5]
    # a tilted plane placed with its own pose: only the lowest corner touches
    tilted = Shape(st.PLANE, [0.0, 1.0, 0.0, 0.0], (0.0, -0.2, 0.0), axis_angle((1, 0, 1), 0.3))
    box.pos = np.array([0.0, 0.2, 0.0])
    n, rows, _ = run(box, tilted)
    assert n == 1
    assert rows[0, 6] == pytest.approx(reference_depth(box, tilted), abs=1e-12)


def test_goal_area_sphere_inside_and_outside_box():
    goal = Shape(st.BOX, [1.0, 0.5, 2.0], (3.0, 0.5, 0.0))
    inside = Shape(st.SPHERE, [0.2], (3.2, 0.4, 0.5))
    n, rows, _ = run(goal, inside)
    assert n == 1
    # least penetration: the bottom face (0.4 above it) -> pushed along -y from the box
    np.testing.assert_allclose(rows[0, 3:6], [0.0, -1.0, 0.0])
    assert rows[0, 6] == pytest.approx(0.2 + 0.4)
    outside = Shape(st.SPHERE, [0.2], (4.3, 0.5, 0.0))
    assert run(goal, outside)[0] == 0
    corner = Shape(st.SPHERE, [0.2], (4.1, 1.1, 2.1))
    n, rows, _ = run(goal, corner)
    assert n == 1
    assert rows[0, 6] == pytest.approx(0.2 - math.sqrt(0.03))
    np.testing.assert_allclose(rows[0, 3:6], np.ones(3) / math.sqrt(3.0))


def test_plane_pair_has_no_contacts():
    p = Shape(st.PLANE, [0.0, 1.0, 0.0, 0.0])
    assert run(p, p)[0] == 0


def test_full_buffer_returns_the_whole_count_and_writes_only_capacity():
    a = Shape(st.BOX, [1.0, 0.5, 1.0], (0.0, -0.5, 0.0))
    b = Shape(st.BOX, [0.5, 0.5, 0.5], (0.0, 0.45, 0.0), yaw(0.2))
    n_full, rows_full, ids_full = run(a, b)
    assert n_full == 4
    out_f = np.full((3, 7), 7.0)
    out_i = np.full(3, 7, np.int64)
    n = collide_box_box(a.pos, a.rot, a.params, b.pos, b.rot, b.params, 0.0, out_f, out_i, 1)
    assert n == 5
    np.testing.assert_array_equal(out_f[0], 7.0)
    np.testing.assert_array_equal(out_f[1:], rows_full[:2])
    np.testing.assert_array_equal(out_i[1:], ids_full[:2])


def test_swapped_rows_flip_only_the_rows_added():
    a = Shape(st.SPHERE, [0.5], (0.0, 0.0, 0.0))
    b = Shape(st.BOX, [0.5, 0.5, 0.5], (0.0, 0.9, 0.0))
    out_f = np.zeros((4, 7))
    out_f[0, 3:6] = (1.0, 2.0, 3.0)
    out_i = np.zeros(4, np.int64)
    n = collide_convex_pair(b.kind, b.pos, b.rot, b.params, a.kind, a.pos, a.rot, a.params, 0.0,
                            out_f, out_i, 1)
    assert n == 2
    np.testing.assert_array_equal(out_f[0, 3:6], (1.0, 2.0, 3.0))
    np.testing.assert_allclose(out_f[1, 3:6], (0.0, -1.0, 0.0), atol=1e-15)
    assert out_f[1, 6] == pytest.approx(0.1)


@settings(max_examples=100, deadline=None)
@given(data=hst.data())
def test_sat_axes_are_enough(data):
    """No random direction gives overlapping boxes less overlap than the 15 axes (the reference's
    own check: the penetration depth is the least overlap over those axes)."""
    a = data.draw(shapes(st.BOX))
    b = data.draw(shapes(st.BOX))
    b.pos = a.pos + 0.3 * (b.pos - a.pos)
    rng = np.random.default_rng(data.draw(hst.integers(0, 2 ** 32 - 1)))
    dirs = rng.normal(size=(200, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    pd = polytope_depth(a, b)
    assume(pd > 0.0)
    assert min(overlap(a, b, d) for d in dirs) >= pd - 1e-12


def polygon_area(points_2d):
    """Area of a convex polygon given by its vertices in any order (shoelace after angular sort)."""
    c = points_2d.mean(axis=0)
    order = np.argsort(np.arctan2(points_2d[:, 1] - c[1], points_2d[:, 0] - c[0]))
    p = points_2d[order]
    return 0.5 * abs(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


@settings(max_examples=100, deadline=None)
@given(tilt=hst.floats(-1e-3, 1e-3), axis=hst.tuples(coord, coord), angle=hst.floats(0.3, 1.2))
def test_eight_clipped_points_reduce_to_a_spread_four(tilt, axis, angle):
    """Equal boxes, the top one turned about y: the overlap is an octagon; four points keep the
    deepest corner and most of its area."""
    a = Shape(st.BOX, [1.0, 0.5, 1.0], (0.0, 0.0, 0.0))
    b = Shape(st.BOX, [1.0, 0.5, 1.0], (0.0, 0.99, 0.0), yaw(angle))
    axis = np.array([axis[0], 0.0, axis[1]])
    assume(np.linalg.norm(axis) > 0.1)
    b.rot = quat_matrix(axis_angle(axis, tilt)) @ b.rot
    n, rows, ids = run(a, b)
    assert n == 4
    assert len(set(ids.tolist())) == 4
    check_manifold(a, b, rows)
    pd = reference_depth(a, b)
    assert pd - 1e-9 <= rows[:, 6].max() <= pd + FACE_BIAS * 0.5 + 1e-9
    # area of the octagon (the two squares' intersection) by sampling a grid over a's square
    g = np.linspace(-1.0, 1.0, 201)
    xx, zz = np.meshgrid(g, g)
    c, s = math.cos(angle), math.sin(angle)
    local = np.stack([xx.ravel(), zz.ravel()], axis=1) @ np.array([[c, -s], [s, c]])
    octagon_area = 4.0 * (np.abs(local) <= 1.0).all(axis=1).mean()
    assert polygon_area(rows[:, [0, 2]]) >= 0.6 * octagon_area


def test_box_box_normal_flips_with_the_order_when_centres_are_square_to_the_axis():
    """Two boxes stacked in y whose least overlap is along z, with their centres level in z: the overlap is
    the same towards +z and -z, and the normal must still flip when the boxes swap (hypothesis found it)."""
    flipped = (0.0, 0.0, 0.0, 1.0)           # 180 degrees about z
    a = Shape(st.BOX, [1.0, 1.0, 0.5], (0.0, 1.0, 0.0), flipped)
    b = Shape(st.BOX, [1.0, 1.0, 0.25], (0.0, 0.0, 0.0), flipped)
    n_ab, rows_ab, _ = run(a, b)
    n_ba, rows_ba, _ = run(b, a)
    assert n_ab > 0 and n_ba > 0
    deep_ab = rows_ab[np.argmax(rows_ab[:, 6])]
    deep_ba = rows_ba[np.argmax(rows_ba[:, 6])]
    assert deep_ab[6] == pytest.approx(0.75) and deep_ba[6] == pytest.approx(0.75)
    np.testing.assert_array_equal(deep_ab[3:6], -deep_ba[3:6])
