"""``marbellous.query.collide``: the public contact query between two placed shapes."""
import math

import numpy as np
import pytest

from marbellous.query import ContactPoint, collide
from marbellous.shapes.heightfield import HeightField
from marbellous.shapes.primitives import Box, Capsule, Plane, Sphere


def test_contact_points_are_fresh_float_arrays():
    contacts = collide(Sphere(1.0), Sphere(0.5), position_b=(0.0, 1.2, 0.0))
    assert len(contacts) == 1
    c = contacts[0]
    assert isinstance(c, ContactPoint)
    for v in (c.point, c.normal):
        assert isinstance(v, np.ndarray) and v.shape == (3,) and v.dtype == np.float64
    assert isinstance(c.depth, float)
    np.testing.assert_allclose(c.normal, (0.0, 1.0, 0.0))
    assert c.depth == pytest.approx(0.3)
    # the midpoint between the surfaces: a's surface at y = 1, b's at y = 0.7
    np.testing.assert_allclose(c.point, (0.0, 0.85, 0.0))
    c.point[0] = 99.0
    assert collide(Sphere(1.0), Sphere(0.5), position_b=(0.0, 1.2, 0.0))[0].point[0] == 0.0


def test_goal_area_query():
    goal = Box((1.0, 0.5, 1.0))
    assert collide(goal, Sphere(0.2), position_a=(5.0, 0.5, 0.0), position_b=(5.5, 0.3, 0.2))
    assert collide(goal, Sphere(0.2), position_a=(5.0, 0.5, 0.0), position_b=(6.3, 0.3, 0.2)) == []
    # turned by 90 degrees about y the goal is 2 m wide along x
    turned = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)
    assert collide(Box((2.0, 0.5, 0.5)), Sphere(0.2), orientation_a=turned, position_b=(0.0, 0.0, 1.5))


def test_swapping_shapes_flips_normals():
    args = dict(position_a=(0.0, 0.0, 0.0), position_b=(0.3, 0.9, 0.1), orientation_b=(0.9, 0.1, 0.3, 0.2))
    ab = collide(Capsule(0.3, 0.5), Box((0.5, 0.4, 0.6)), **args)
    ba = collide(Box((0.5, 0.4, 0.6)), Capsule(0.3, 0.5), position_a=args["position_b"],
                 orientation_a=args["orientation_b"], position_b=args["position_a"])
    assert len(ab) == len(ba) >= 1
    for p, q in zip(ab, ba):
        np.testing.assert_array_equal(p.point, q.point)
        np.testing.assert_array_equal(p.normal, -q.normal)
        assert p.depth == q.depth


def test_orientations_are_normalised():
    a = collide(Box((0.5, 0.5, 0.5)), Box((0.5, 0.5, 0.5)), position_b=(0.2, 0.9, 0.0),
                orientation_b=(2.0, 0.0, 0.4, 0.0))
    b = collide(Box((0.5, 0.5, 0.5)), Box((0.5, 0.5, 0.5)), position_b=(0.2, 0.9, 0.0),
                orientation_b=np.array([2.0, 0.0, 0.4, 0.0]) / math.hypot(2.0, 0.4))
    assert len(a) == len(b) == 4
    for p, q in zip(a, b):
        np.testing.assert_allclose(p.point, q.point, atol=1e-14)


def test_only_overlapping_or_touching_points():
    assert collide(Sphere(1.0), Plane(), position_a=(0.0, 1.0 + 1e-9, 0.0)) == []
    touching = collide(Sphere(1.0), Plane(), position_a=(0.0, 1.0, 0.0))
    assert len(touching) == 1 and touching[0].depth == 0.0
    # a capsule tilted over a plane: only the lower end touches
    tilt = (math.cos(0.2), 0.0, 0.0, math.sin(0.2))
    contacts = collide(Capsule(0.2, 1.0), Plane(), position_a=(0.0, 0.5, 0.0), orientation_a=tilt)
    assert len(contacts) == 1
    assert contacts[0].depth == pytest.approx(0.2 - (0.5 - math.cos(0.4)))


def test_static_shapes_are_allowed():
    assert collide(Plane(), Plane()) == []
    field = HeightField(np.zeros((4, 4)), spacing=(1.0, 1.0), origin=(-1.5, 0.0, -1.5))
    down = collide(Sphere(0.5), field, position_a=(0.1, 0.4, 0.2))
    up = collide(field, Sphere(0.5), position_b=(0.1, 0.4, 0.2))
    assert len(down) == len(up) >= 1
    assert max(c.depth for c in down) == pytest.approx(0.1)
    np.testing.assert_allclose(down[0].normal, (0.0, -1.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(up[0].normal, (0.0, 1.0, 0.0), atol=1e-12)


@pytest.mark.parametrize("kwargs, error, name", [
    (dict(position_a=(0.0, float("nan"), 0.0)), ValueError, "position_a"),
    (dict(position_b=(0.0, 1.0)), ValueError, "position_b"),
    (dict(position_b="abc"), TypeError, "position_b"),
    (dict(orientation_a=(0.0, 0.0, 0.0, 0.0)), ValueError, "orientation_a"),
    (dict(orientation_b=(1.0, 0.0, float("inf"), 0.0)), ValueError, "orientation_b"),
])
def test_bad_poses_name_the_argument(kwargs, error, name):
    with pytest.raises(error, match=name):
        collide(Sphere(1.0), Box((1.0, 1.0, 1.0)), **kwargs)


def test_shapes_must_be_shapes():
    with pytest.raises(TypeError, match="shape_a"):
        collide("sphere", Sphere(1.0))
    with pytest.raises(TypeError, match="shape_b"):
        collide(Sphere(1.0), None)
