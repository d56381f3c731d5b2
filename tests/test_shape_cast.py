"""``World.shape_cast``: the first body a sphere, box or capsule meets as it slides from start to end, against
closed forms.  The search stops within ``HIT_TOLERANCE`` (1e-7 m) of the surface, so along a sweep that
meets the surface at an angle whose cosine is at least 0.1 the distance is within 1e-6 m."""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb

TOL = 1e-6
unit = st.floats(-1.0, 1.0)


@settings(max_examples=40, deadline=None)
@given(x=st.floats(-5.0, 5.0), z=st.floats(-5.0, 5.0), height=st.floats(0.6, 10.0), r=st.floats(0.05, 0.5),
       dx=unit, dz=unit, length=st.floats(0.1, 30.0))
def test_a_sphere_falling_on_a_plane_stops_where_its_lowest_point_meets_it(x, z, height, r, dx, dz, length):
    """Swept along ``d`` (its downward part at least 0.1 of it), a sphere meets the plane y = 0 after
    ``(height - r) / (-d_y)`` of its unit sweep: if that is within ``length``, at that distance, the point
    below its centre and the normal up."""
    d = np.array([dx, -1.0, dz])
    d /= np.linalg.norm(d)
    assert -d[1] >= 0.1
    w = mb.World()
    ground = w.add_static(mb.Plane())
    start = np.array([x, height, z])
    hit = w.shape_cast(mb.Sphere(r), start, start + length * d)
    reach = (height - r) / -d[1]
    if reach > length + TOL:
        assert hit is None
    elif reach < length - TOL:
        assert hit.body is ground
        assert hit.distance == pytest.approx(reach, abs=TOL)
        centre = start + hit.distance * d
        np.testing.assert_allclose(hit.point, [centre[0], 0.0, centre[2]], atol=TOL)
        np.testing.assert_allclose(hit.normal, [0.0, 1.0, 0.0], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(offset=st.tuples(unit, unit), ra=st.floats(0.05, 1.0), rb=st.floats(0.05, 1.0))
def test_a_sphere_meets_a_sphere_where_the_ray_meets_the_radius_sum(offset, ra, rb):
    """A sphere of radius ``ra`` swept along +x from x = -10 past a sphere of radius ``rb`` at the origin,
    offset sideways by ``(oy, oz)``: it meets it where the ray of its centre meets a sphere of radius
    ``ra + rb``, ``10 - sqrt((ra + rb)^2 - oy^2 - oz^2)``, if the offset is within the sum (at least 0.1
    of it away from grazing, so that the sweep meets the surface at a cosine of 0.1 or more)."""
    oy, oz = offset
    w = mb.World()
    target = w.add_static(mb.Sphere(rb))
    hit = w.shape_cast(mb.Sphere(ra), (-10.0, oy, oz), (10.0, oy, oz))
    side = math.hypot(oy, oz)
    total = ra + rb
    if side > total:
        assert hit is None
    elif side < 0.99 * total:
        assert hit.body is target
        assert hit.distance == pytest.approx(10.0 - math.sqrt(total * total - side * side), abs=TOL)
        centre = np.array([-10.0 + hit.distance, oy, oz])
        np.testing.assert_allclose(hit.normal, centre / total, atol=1e-5)
        np.testing.assert_allclose(hit.point, centre * rb / total, atol=1e-5)


def test_a_box_meets_a_box_face_to_face_in_the_middle_of_their_faces():
    w = mb.World()
    wall = w.add_static(mb.Box((1.0, 1.0, 1.0)), position=(5.0, 1.0, 0.0))
    hit = w.shape_cast(mb.Box((0.5, 0.5, 0.5)), (0.0, 1.0, 0.0), (10.0, 1.0, 0.0))
    assert hit.body is wall
    assert hit.distance == pytest.approx(3.5, abs=TOL)
    np.testing.assert_allclose(hit.point, [4.0, 1.0, 0.0], atol=TOL)
    np.testing.assert_allclose(hit.normal, [-1.0, 0.0, 0.0], atol=1e-12)


def test_a_capsule_lands_on_its_end_or_its_side_as_it_is_turned():
    """A capsule of radius 0.2 and half height 0.5 (along its local y) dropped from y = 5: upright its lowest
    point is 0.7 below its centre and it falls 4.3 m; turned a quarter about z it lies on its side, 0.2
    below, and falls 4.8 m."""
    w = mb.World()
    w.add_static(mb.Plane())
    lying = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
    upright = w.shape_cast(mb.Capsule(0.2, 0.5), (0.0, 5.0, 0.0), (0.0, -5.0, 0.0))
    flat = w.shape_cast(mb.Capsule(0.2, 0.5), (0.0, 5.0, 0.0), (0.0, -5.0, 0.0), orientation=lying)
    assert upright.distance == pytest.approx(4.3, abs=TOL)
    assert flat.distance == pytest.approx(4.8, abs=TOL)
    np.testing.assert_allclose(upright.point, [0.0, 0.0, 0.0], atol=TOL)


def test_the_mask_skips_bodies_and_an_overlap_hits_at_once():
    w = mb.World()
    near = w.add_static(mb.Box((0.5, 2.0, 2.0)), position=(2.0, 0.0, 0.0), group=2)
    far = w.add_static(mb.Box((0.5, 2.0, 2.0)), position=(6.0, 0.0, 0.0), group=4)
    sweep = ((0.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    assert w.shape_cast(mb.Sphere(0.5), *sweep).body is near
    skip = w.shape_cast(mb.Sphere(0.5), *sweep, mask=4)
    assert skip.body is far and skip.distance == pytest.approx(5.0, abs=TOL)
    assert w.shape_cast(mb.Sphere(0.5), *sweep, mask=8) is None
    inside = w.shape_cast(mb.Sphere(0.5), (2.0, 0.0, 0.0), (3.0, 0.0, 0.0))
    assert inside.body is near and inside.distance == 0.0


@pytest.mark.parametrize("call, name", [
    (lambda w: w.shape_cast(mb.Plane(), (0, 0, 0), (1, 0, 0)), "shape"),
    (lambda w: w.shape_cast("ball", (0, 0, 0), (1, 0, 0)), "shape"),
    (lambda w: w.shape_cast(mb.Sphere(1.0), (0, float("nan"), 0), (1, 0, 0)), "start"),
    (lambda w: w.shape_cast(mb.Sphere(1.0), (0, 0, 0), (1, 0)), "end"),
    (lambda w: w.shape_cast(mb.Sphere(1.0), (0, 0, 0), (1, 0, 0), orientation=(0, 0, 0, 0)), "orientation"),
    (lambda w: w.shape_cast(mb.Sphere(1.0), (0, 0, 0), (1, 0, 0), mask=0.5), "mask"),
])
def test_a_bad_cast_is_refused_and_changes_nothing(call, name):
    w = mb.World()
    w.add_body(mb.Sphere(0.5))
    before = w.state_hash()
    with pytest.raises((ValueError, TypeError), match=name):
        call(w)
    assert w.state_hash() == before


@pytest.mark.parametrize("shape, below", [(mb.Sphere(0.3), 0.3), (mb.Box((0.2, 0.4, 0.2)), 0.4)])
def test_a_shape_lands_on_a_ramp_of_triangles_and_on_a_height_field(shape, below):
    """A flat height field at y = -1 is met by a shape dropped from y = 6 when its centre is ``below`` above
    it; a ramp of two triangles at 45 degrees (y = x) is met by a sphere dropped at x = 2 when its centre is
    ``r`` from the ramp's plane, ``r sqrt(2)`` above the ramp's height there: after ``6 - 2 - r sqrt(2)``."""
    w = mb.World()
    ramp = w.add_static(mb.TriangleMesh(np.array([[0, 0, -2], [4, 4, -2], [4, 4, 2], [0, 0, 2]], float),
                                        np.array([[0, 2, 1], [0, 3, 2]])))
    field = w.add_static(mb.HeightField(np.zeros((9, 9)), spacing=(1.0, 1.0)),
                         position=(-12.0, -1.0, -4.0))
    flat = w.shape_cast(shape, (-8.0, 6.0, 0.0), (-8.0, -6.0, 0.0))
    assert flat.body is field and flat.distance == pytest.approx(7.0 - below, abs=TOL)
    if isinstance(shape, mb.Sphere):
        hit = w.shape_cast(shape, (2.0, 6.0, 0.0), (2.0, -6.0, 0.0))
        assert hit.body is ramp
        assert hit.distance == pytest.approx(4.0 - 0.3 * math.sqrt(2.0), abs=TOL)
        np.testing.assert_allclose(hit.normal, [-math.sqrt(0.5), math.sqrt(0.5), 0.0], atol=1e-9)


def test_the_example_predicts_where_the_crate_lands():
    """examples/queries.py: the cast puts the crate's centre on the third step's top plus its half height
    (1.75 m); dropped, it first touches there (within the soft contact's sink, 1 mm); the box query finds
    the ground, the three steps the box reaches and the crate."""
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "queries.py"))["run"]
    predicted, touched, near, beside = run()
    assert predicted == pytest.approx(1.75, abs=TOL)
    assert touched == pytest.approx(predicted, abs=1e-3)
    assert [b.is_static for b in near] == [True, True, True, True, False]
    assert beside == pytest.approx(3.0, abs=1e-9)
