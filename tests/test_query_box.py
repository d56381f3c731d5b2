"""``World.query_box``: the bodies whose bounding boxes overlap a box, at their poses now, the same from
every broad phase as from a direct test of every body's box."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.math3d import quat_to_matrix_np

BROADPHASES = ("brute", "sap", "grid", "bvh", "octree", "kdtree", "bsp")
coord = st.floats(-20.0, 20.0)
size = st.floats(0.05, 3.0)


def _reference_box(body):
    """The body's bounding box from its shapes' geometry: a sphere's centre +- r, a box's centre +- |R| h."""
    shape, offset, _ = body.shapes[0]
    r = quat_to_matrix_np(body.orientation)
    centre = body.position + r @ offset
    if isinstance(shape, mb.Sphere):
        half = np.full(3, shape.radius)
    else:
        half = np.abs(r @ quat_to_matrix_np(body.shapes[0][2])) @ np.asarray(shape.half_extents)
    return centre - half, centre + half


@settings(max_examples=40, deadline=None)
@given(bodies=st.lists(st.tuples(st.booleans(), coord, coord, coord, size,
                                 st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(
                                     lambda q: sum(x * x for x in q) > 0.1)), min_size=1, max_size=12),
       corner=st.tuples(coord, coord, coord), extent=st.tuples(size, size, size),
       broadphase=st.sampled_from(BROADPHASES))
def test_the_bodies_found_are_those_whose_boxes_overlap(bodies, corner, extent, broadphase):
    """Every body whose box overlaps the query box by more than 1e-9 m is found, none that misses it by more
    than that (a box's corners are computed in a different order here: round-off at a touching face)."""
    w = mb.World(broadphase=broadphase, gravity=(0.0, 0.0, 0.0))
    made = []
    for is_sphere, x, y, z, s, q in bodies:
        shape = mb.Sphere(s) if is_sphere else mb.Box((s, 0.5 * s, 0.25 * s))
        made.append(w.add_body(shape, position=(x, y, z), orientation=q))
    lower = np.array(corner)
    upper = lower + np.array(extent)
    found = w.query_box(lower, upper)
    for body in made:
        lo, hi = _reference_box(body)
        gap = max(np.max(lo - upper), np.max(lower - hi))
        if gap < -1e-9:
            assert body in found
        elif gap > 1e-9:
            assert body not in found


@pytest.mark.parametrize("broadphase", BROADPHASES)
def test_a_pose_set_by_hand_counts_and_a_plane_overlaps_everything(broadphase):
    w = mb.World(broadphase=broadphase)
    ground = w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.5), position=(0.0, 3.0, 0.0))
    w.step(1.0 / 60.0)
    ball.position = (100.0, 3.0, 0.0)
    assert w.query_box((99.0, 2.0, -1.0), (101.0, 4.0, 1.0)) == [ground, ball]
    assert w.query_box((-1.0, 2.0, -1.0), (1.0, 4.0, 1.0)) == [ground]


@pytest.mark.parametrize("lower, upper, name", [
    ((1.0, 0.0, 0.0), (0.0, 1.0, 1.0), "lower"), ((0.0, float("nan"), 0.0), (1.0, 1.0, 1.0), "lower"),
    ((0.0, 0.0, 0.0), (1.0, 1.0), "upper"), ((0.0, 0.0, 0.0), "up", "upper"),
])
def test_a_bad_box_is_refused_and_changes_nothing(lower, upper, name):
    w = mb.World()
    w.add_body(mb.Sphere(0.5))
    before = w.state_hash()
    with pytest.raises((ValueError, TypeError), match=name):
        w.query_box(lower, upper)
    assert w.state_hash() == before
