"""Drawing geometry of the engine's shapes (no OpenGL): meshes match the physics' shapes, bounds, the
orbit camera, instance matrices, and constraint anchors as the renderer reads them."""
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.render.body_solids import PLANE_SCALE, body_solids
from marbellous.render.bounds import shape_points, world_points
from marbellous.render.draw_lists import GRID, OCTANTS, PLAIN, WorldFrame
from marbellous.render.geometry import box_triangles, capsule_triangles, heightfield_triangles, indexed, uv_sphere
from marbellous.render.orbit_camera import OrbitCamera
from marbellous.render.shape_meshes import plane_frame, shape_mesh
from marbellous.render.transforms import look_at, perspective, quat_to_matrix, quats_to_matrices


def test_drawing_meshes_need_no_optional_package_and_log_nothing(caplog):
    # trimesh's vertex normals go through scipy (not a dependency) and log a traceback without it
    caplog.set_level("DEBUG")
    for pos, nrm in (capsule_triangles(0.3, 0.5), uv_sphere(1.0, 8, 16), box_triangles((1.0, 2.0, 3.0))):
        assert pos.shape == nrm.shape and np.allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-5)
    assert not [r for r in caplog.records if r.levelno >= 30], [r.getMessage() for r in caplog.records]
    pos, nrm = capsule_triangles(0.3, 0.5)
    axis = np.zeros_like(pos)
    axis[:, 1] = np.clip(pos[:, 1], -0.5, 0.5)
    assert np.allclose(np.linalg.norm(pos - axis, axis=1), 0.3, atol=1e-5)     # on the surface
    assert np.all(np.sum((pos - axis) * nrm, axis=1) > 0.299)                  # normals point out


def test_indexed_meshes_give_back_every_corner_and_share_equal_ones():
    for (pos, nrm), shared in ((uv_sphere(1.0, 16, 32), 898), (box_triangles((1.0, 2.0, 3.0)), 24)):
        vertices, indices = indexed(pos, nrm)
        assert vertices.dtype == np.float32 and indices.dtype == np.uint32 and len(indices) == len(pos)
        assert np.array_equal(vertices[indices, :3], pos) and np.array_equal(vertices[indices, 3:], nrm)
        # a box's faces keep their own normals: 4 corners each; the sphere's seam and poles stay split as
        # trimesh made them
        assert len(vertices) == shared
        assert np.all(np.diff(np.unique(indices, return_index=True)[1]) > 0)   # in the order of first use


def test_heightfield_triangles_lie_on_the_physics_surface():
    rng = np.random.default_rng(3)
    field = mb.HeightField(rng.uniform(0, 2, (5, 4)), spacing=(0.7, 1.3), origin=(-1.0, 0.5, 2.0))
    pos, nrm = heightfield_triangles(field.heights, (field.dx, field.dz), field.origin)
    tris = pos.reshape(-1, 3, 3).astype(np.float64)
    # every triangle's centroid (and any point inside it) is on the surface the collisions use
    for t in tris:
        c = t.mean(axis=0)
        assert c[1] == pytest.approx(field.height_at(c[0], c[2]), abs=1e-5)
    # counter-clockwise from above: the face normals point up
    face = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    assert np.all(face[:, 1] > 0)


@pytest.mark.parametrize("shape", [mb.Sphere(0.3), mb.Box((0.2, 0.5, 0.1)), mb.Capsule(0.2, 0.4),
                                   mb.ConvexHull(np.random.default_rng(0).normal(size=(15, 3)))], ids=repr)
def test_scaled_meshes_have_the_shape_s_size(shape):
    mesh = shape_mesh(shape)
    pos, nrm = mesh.triangles()
    scaled = pos * mesh.scale
    outline = shape_points(shape, np.zeros(3), np.eye(3))
    assert np.allclose(scaled.min(axis=0), outline.min(axis=0), atol=2e-3)
    assert np.allclose(scaled.max(axis=0), outline.max(axis=0), atol=2e-3)
    assert np.allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-5)


def test_hull_triangles_face_outwards():
    hull = mb.ConvexHull(np.random.default_rng(1).normal(size=(20, 3)))
    pos, nrm = shape_mesh(hull).triangles()
    centres = pos.reshape(-1, 3, 3).mean(axis=1)      # the centre of mass (the origin) is inside
    assert np.all(np.einsum("ij,ij->i", nrm.reshape(-1, 3, 3)[:, 0], centres) > 0.0)


def test_meshes_are_shared_by_kind_and_kept_per_shape():
    assert shape_mesh(mb.Sphere(0.1)).key == shape_mesh(mb.Sphere(2.0)).key
    assert shape_mesh(mb.Box((1, 2, 3))).key == shape_mesh(mb.Box((0.1, 0.1, 0.1))).key
    assert shape_mesh(mb.Capsule(0.1, 0.2)).key != shape_mesh(mb.Capsule(0.1, 0.3)).key
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 1]])
    a, b = mb.TriangleMesh(v, [[0, 2, 1]]), mb.TriangleMesh(v, [[0, 2, 1]])
    assert shape_mesh(a) is shape_mesh(a)
    assert shape_mesh(a).key != shape_mesh(b).key
    with pytest.raises(TypeError, match="shape"):
        shape_mesh("box")


def test_plane_frame_turns_y_to_the_normal():
    plane = mb.Plane((1.0, 2.0, -0.5), 0.7)
    rot, point = plane_frame(plane)
    assert np.allclose(rot.T @ rot, np.eye(3)) and np.linalg.det(rot) == pytest.approx(1.0)
    assert np.allclose(rot[:, 1], plane.normal)
    assert point @ plane.normal == pytest.approx(0.7)


def test_body_solids_place_every_shape():
    w = mb.World()
    w.add_static(mb.Plane())
    q = np.array([math.cos(0.3), 0.0, math.sin(0.3), 0.0])
    box = w.add_body([(mb.Box((0.5, 0.2, 0.1)), (0.3, 0.0, 0.0)), (mb.Sphere(0.25), (-0.6, 0.0, 0.0))],
                     position=(1.0, 2.0, 3.0), orientation=q)
    frame = WorldFrame(w, np.zeros(3), 10.0)
    solids = {s.mesh.key: s for s in body_solids(frame)}
    r = quat_to_matrix(q)
    for shape, local_pos, _ in box.shapes:
        s = solids[shape_mesh(shape).key]
        assert np.allclose(s.models[0][:3, 3], box.position + r @ local_pos)
        assert np.allclose(s.models[0][:3, :3], r * shape_mesh(shape).scale)
    assert solids[("sphere",)].patterns[0] == OCTANTS and solids[("box",)].patterns[0] == PLAIN
    plane = solids[("plane",)]
    assert plane.patterns[0] == GRID
    # a square of half side PLANE_SCALE camera distances, under the focus, facing up
    assert np.allclose(plane.models[0][:3, 3], 0.0)
    assert np.linalg.norm(plane.models[0][:3, 0]) == pytest.approx(PLANE_SCALE * 10.0)
    assert np.allclose(plane.models[0][:3, 1], [0.0, 1.0, 0.0])


def test_quats_to_matrices_match_one_at_a_time():
    q = np.random.default_rng(1).normal(size=(7, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    assert np.allclose(quats_to_matrices(q), [quat_to_matrix(x) for x in q])


def test_world_points_leave_out_planes_and_add_fixed_anchors():
    w = mb.World()
    w.add_static(mb.Plane())
    b = w.add_body(mb.Sphere(0.5), position=(0.0, 1.0, 0.0))
    w.add_spring(b, None, rest_length=1.0, stiffness=10.0, anchor_b=(0.0, 4.0, 0.0))
    pts = world_points(w)
    assert np.allclose(pts.min(axis=0), [-0.5, 0.5, -0.5]) and np.allclose(pts.max(axis=0), [0.5, 4.0, 0.5])


def test_meshes_and_fields_are_outlined_by_their_surface():
    q = np.array([math.cos(0.2), 0.0, 0.0, math.sin(0.2)])
    r = quat_to_matrix(q)
    field = mb.HeightField([[0.0, 1.0], [2.0, 0.5]], spacing=(3.0, 2.0), origin=(1.0, -1.0, 0.5))
    pts = shape_points(field, np.array([1.0, 2.0, 3.0]), r)
    local = np.array([[1.0, -1.0, 0.5], [1.0, 0.0, 2.5], [4.0, 1.0, 0.5], [4.0, -0.5, 2.5]])
    assert np.allclose(pts, local @ r.T + [1.0, 2.0, 3.0])
    v = np.array([[0.0, 0, 0], [1, 2, 0], [0, 0, 1]])
    assert np.allclose(shape_points(mb.TriangleMesh(v, [[0, 2, 1]]), np.zeros(3), r), v @ r.T)


def test_framing_shows_every_point_and_fills_the_view():
    pts = np.random.default_rng(2).uniform(-3, 3, (50, 3)) * [4.0, 1.0, 2.0]
    for aspect in (16 / 9, 1.0, 0.5):
        cam = OrbitCamera.framing(pts, aspect)
        v = cam.view()
        clip = (perspective(v.fov, aspect, 0.1, 1e3) @ look_at(v.eye, v.target) @ np.c_[pts, np.ones(len(pts))].T).T
        ndc = clip[:, :2] / clip[:, 3:]
        assert np.all(np.abs(ndc) <= 1.0) and np.abs(ndc).max() > 0.8


def test_orbit_camera_turns_zooms_and_pans():
    cam = OrbitCamera.looking((0.0, 3.0, 4.0), (0.0, 0.0, 0.0))
    assert np.allclose(cam.eye, [0.0, 3.0, 4.0]) and cam.distance == pytest.approx(5.0)
    cam.rotate(100, 0)
    assert np.linalg.norm(cam.eye - cam.target) == pytest.approx(5.0) and cam.eye[1] == pytest.approx(3.0)
    cam.rotate(0, -1e6)
    assert cam.pitch == pytest.approx(math.radians(89.0))
    cam.zoom(2)
    assert cam.distance == pytest.approx(5.0 * 0.88 ** 2)
    before = cam.view()
    cam.pan(10, 0, 400)
    right = look_at(before.eye, before.target)[0, :3]
    moved = cam.target - before.target
    assert moved @ right < 0 and np.allclose(np.cross(moved, right), 0.0, atol=1e-12)


def test_constraint_anchors_read_back():
    w = mb.World()
    a = w.add_body(mb.Sphere(0.2), position=(0.0, 1.0, 0.0))
    b = w.add_body(mb.Sphere(0.2), position=(1.0, 1.0, 0.0))
    rod = w.add_rod(a, b, anchor_a=(0.1, 0.0, 0.0), anchor_b=(-0.1, 0.0, 0.0))
    cable = w.add_cable(a, None, max_length=2.0, anchor_b=(0.0, 3.0, 0.0))
    assert np.allclose(rod.anchor_a, [0.1, 0.0, 0.0]) and np.allclose(rod.anchor_b, [-0.1, 0.0, 0.0])
    assert np.allclose(cable.anchor_a, 0.0) and np.allclose(cable.anchor_b, [0.0, 3.0, 0.0])
