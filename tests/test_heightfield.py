"""Height fields: height/normal queries against analytic surfaces, agreement with collisions and rays."""
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as hst

from marbellous.collision import shape_types as st
from marbellous.collision.mesh.heightfield_collide import collide_convex_heightfield, collide_sphere_heightfield
from marbellous.collision.mesh.mesh_collide import collide_convex_mesh
from marbellous.shapes.heightfield import HeightField
from marbellous.shapes.mesh import TriangleMesh


def run(kernel, shape, type_a, dims, pos, rot=np.eye(3), prediction=0.0, pos_b=np.zeros(3), rot_b=np.eye(3)):
    p = np.zeros(st.N_SHAPE_PARAMS)
    p[:len(dims)] = dims
    gf, gi = shape._geometry()
    out_f = np.zeros((64, 7))
    out_i = np.zeros(64, np.int64)
    n = kernel(type_a, np.asarray(pos, float), rot, p, pos_b, rot_b, shape._params(), gf, gi, 0, 0, prediction,
               out_f, out_i, 0)
    return out_f[:n], out_i[:n]


def sampled(f, nx, nz, dx, dz, x0, z0):
    xs = x0 + dx * np.arange(nx)[:, None]
    zs = z0 + dz * np.arange(nz)[None, :]
    return f(xs, zs)


def as_mesh(hf):
    """The same surface as a TriangleMesh with the same triangles in the same order."""
    nx, nz = hf.heights.shape
    i, j = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
    v = np.stack([hf.origin[0] + i.ravel() * hf.dx, hf.origin[1] + hf.heights.ravel(),
                  hf.origin[2] + j.ravel() * hf.dz], axis=1)
    tris = []
    for a in range(nx - 1):
        for b in range(nz - 1):
            p00, p10, p01, p11 = a * nz + b, (a + 1) * nz + b, a * nz + b + 1, (a + 1) * nz + b + 1
            tris += [[p00, p11, p10], [p00, p01, p11]]
    return TriangleMesh(v, np.array(tris), accel="brute")


PLANE = HeightField(sampled(lambda x, z: 0.3 * x - 0.2 * z + 1.0, 9, 7, 0.5, 0.75, -1.0, 2.0),
                    spacing=(0.5, 0.75), origin=(-1.0, 0.5, 2.0))
H = 0.05
WAVE = HeightField(sampled(lambda x, z: np.sin(x) * np.cos(z), 81, 81, H, H, 0.0, 0.0), spacing=(H, H))

xz = hst.tuples(hst.floats(0.0, 1.0), hst.floats(0.0, 1.0))


@settings(max_examples=300, deadline=None)
@given(xz)
def test_plane_height_and_normal_are_exact(f):
    x, z = -1.0 + 4.0 * f[0], 2.0 + 4.5 * f[1]
    assert PLANE.height_at(x, z) == pytest.approx(0.5 + 0.3 * x - 0.2 * z + 1.0, abs=1e-12)
    n = np.array([-0.3, 1.0, 0.2]) / np.linalg.norm([-0.3, 1.0, 0.2])
    assert np.allclose(PLANE.normal_at(x, z), n, atol=1e-12)


@settings(max_examples=300, deadline=None)
@given(xz)
def test_smooth_surface_within_interpolation_error(f):
    x, z = 4.0 * f[0], 4.0 * f[1]
    # Linear interpolation on a triangle of side h: |error| <= h^2 max|f''| (|f''| <= 1 here);
    # its gradient is off by at most 2 h max|f''|.
    assert abs(WAVE.height_at(x, z) - np.sin(x) * np.cos(z)) <= H * H
    n = np.array([-np.cos(x) * np.cos(z), 1.0, np.sin(x) * np.sin(z)])
    assert np.linalg.norm(WAVE.normal_at(x, z) - n / np.linalg.norm(n)) <= 2.0 * H


inside_triangle = hst.tuples(hst.integers(0, 79), hst.integers(0, 79), hst.floats(0.1, 0.9),
                             hst.floats(0.1, 0.9)).filter(lambda c: abs(c[2] - c[3]) > 0.1)


@settings(max_examples=300, deadline=None)
@given(inside_triangle)
def test_queries_agree_with_the_collision_surface(cell):
    """Well inside a triangle (the normal jumps across creases): the ray, the queries and the
    contact of a tiny sphere see one plane."""
    x, z = (cell[0] + cell[2]) * H, (cell[1] + cell[3]) * H
    y = WAVE.height_at(x, z)
    hit = WAVE.raycast((x, 5.0, z), (0.0, -1.0, 0.0))
    assert hit is not None
    assert abs(hit[1][1] - y) < 1e-12
    assert np.allclose(hit[2], WAVE.normal_at(x, z), atol=1e-12)
    # A tiny sphere resting on the surface at (x, z), pushed 1e-4 into it along the normal.
    n = WAVE.normal_at(x, z)
    r = 1e-3
    centre = np.array([x, y, z]) + n * (r - 1e-4)
    rows, _ = run(collide_convex_heightfield, WAVE, st.SPHERE, (r,), centre)
    assert len(rows) >= 1
    assert np.max(rows[:, 6]) == pytest.approx(1e-4, abs=1e-9)


@settings(max_examples=300, deadline=None)
@given(xz, hst.floats(0.05, 0.6), hst.floats(-0.3, 0.8), hst.sampled_from(["sphere", "capsule", "box"]))
# A buried box 0.0207 m (> prediction) under triangle 3248, whose cell-mate 3249 reaches into the box's
# bounding box: the box's 13 axes show no gap above the prediction, so only the triangle's own
# bounding-box test keeps the one-sided face from pushing it out.
@example((0.0, 0.103515625), 0.103515625, -0.15234375, "box")
def test_heightfield_matches_the_same_triangles_as_a_mesh(f, r, lift, kind):
    """Away from the border the height field and a mesh of its triangles give the same contacts
    (the field's border edges are continued flat, the mesh's are open)."""
    mesh = MESH_OF_WAVE
    x, z = 1.0 + 2.0 * f[0], 1.0 + 2.0 * f[1]
    centre = (x, WAVE.height_at(x, z) + lift, z)
    c, s = np.cos(0.7), np.sin(0.7)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    type_a, dims = {"sphere": (st.SPHERE, (r,)), "capsule": (st.CAPSULE, (r, 0.4)),
                    "box": (st.BOX, (r, 0.5 * r, 0.8 * r))}[kind]
    a, ia = run(collide_convex_heightfield, WAVE, type_a, dims, centre, rot, prediction=0.02)
    b, ib = run(collide_convex_mesh, mesh, type_a, dims, centre, rot, prediction=0.02)
    # Same triangles and contacts; the feature code may differ where a contact sits exactly on a
    # region boundary (e.g. a capsule axis through an edge), as the two compute normals apart.
    assert np.array_equal(ia // 16, ib // 16)
    assert np.allclose(a, b, atol=1e-9)


MESH_OF_WAVE = as_mesh(WAVE)


def test_placed_heightfield():
    rot_b = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])    # 90 degrees about y
    pos_b = np.array([10.0, 2.0, -3.0])
    local = np.array([1.0, PLANE.height_at(1.0, 4.0) + 0.45, 4.0])
    a, _ = run(collide_convex_heightfield, PLANE, st.SPHERE, (0.5,), local)
    b, _ = run(collide_convex_heightfield, PLANE, st.SPHERE, (0.5,), rot_b @ local + pos_b, pos_b=pos_b, rot_b=rot_b)
    assert len(a) == len(b) >= 1
    assert np.allclose(b[:, :3], a[:, :3] @ rot_b.T + pos_b, atol=1e-12)
    assert np.allclose(b[:, 3:6], a[:, 3:6] @ rot_b.T, atol=1e-12)
    assert np.allclose(b[:, 6], a[:, 6])


def test_ray_misses_and_grazes():
    assert PLANE.raycast((0.0, 10.0, 3.0), (0.0, 1.0, 0.0)) is None
    assert PLANE.raycast((-5.0, 10.0, 3.0), (0.0, -1.0, 0.0)) is None          # outside the field
    hit = PLANE.raycast((-3.0, 1.0, 3.0), (1.0, 0.0, 0.0))                        # sideways into the slope
    assert hit is not None
    assert hit[1][1] == pytest.approx(PLANE.height_at(hit[1][0], hit[1][2]), abs=1e-12)


@pytest.mark.parametrize("kw, match", [
    (dict(heights=[1.0, 2.0]), "heights"),
    (dict(heights=[[1.0, 2.0]]), "heights"),
    (dict(heights=[[1.0, np.nan], [0.0, 0.0]]), "heights"),
    (dict(heights=[["a", "b"], ["c", "d"]]), "heights"),
    (dict(heights=np.zeros((2, 2)), spacing=(0.0, 1.0)), "spacing"),
    (dict(heights=np.zeros((2, 2)), spacing=(1.0,)), "spacing"),
    (dict(heights=np.zeros((2, 2)), origin=(0.0, np.inf, 0.0)), "origin"),
])
def test_bad_input_names_the_argument(kw, match):
    with pytest.raises((ValueError, TypeError), match=match):
        HeightField(**kw)


def test_queries_outside_raise():
    with pytest.raises(ValueError, match="x must lie"):
        PLANE.height_at(-2.0, 3.0)
    with pytest.raises(ValueError, match="z must lie"):
        PLANE.normal_at(0.0, 100.0)
    with pytest.raises(ValueError, match="x"):
        PLANE.height_at(np.nan, 3.0)


def test_shape_interface():
    p = PLANE._params()
    assert p.shape == (st.N_SHAPE_PARAMS,) and PLANE._type == st.HEIGHTFIELD and PLANE.is_static_only
    lo, hi = PLANE.local_aabb()
    assert np.allclose(lo, [-1.0, 0.5 + PLANE.heights.min(), 2.0])
    assert np.allclose(hi, [3.0, 0.5 + PLANE.heights.max(), 6.5])
    assert PLANE.bounding_radius() >= np.linalg.norm(hi)


@settings(max_examples=100, deadline=None)
@given(xz, hst.floats(0.05, 0.6), hst.floats(-0.3, 0.8))
def test_a_spheres_own_height_field_test_is_the_general_one(f, r, lift):
    # the sphere's kernel (particles, and the pairs of worlds whose moving shapes are spheres) compiles the
    # general body for the sphere alone: the same contacts, bit for bit
    x, z = 1.0 + 2.0 * f[0], 1.0 + 2.0 * f[1]
    centre = (x, WAVE.height_at(x, z) + lift, z)
    a, ia = run(collide_convex_heightfield, WAVE, st.SPHERE, (r,), centre, prediction=0.02)
    b, ib = run(lambda _type, *rest: collide_sphere_heightfield(*rest[:7], rest[8], *rest[10:]), WAVE, st.SPHERE,
                (r,), centre, prediction=0.02)
    assert np.array_equal(a, b) and np.array_equal(ia, ib)


def test_the_spheres_height_field_test_compiles_no_other_shapes_triangle_test(tmp_path):
    code = ("import numpy as np\n"
            "import marbellous as mb\n"
            "from marbellous.collision import shape_types as st\n"
            "from marbellous.collision.mesh.heightfield_collide import collide_sphere_heightfield\n"
            "from marbellous.collision.triangle import triangle_box, triangle_capsule, triangle_hull\n"
            "hf = mb.HeightField(np.zeros((4, 4)), spacing=(1.0, 1.0))\n"
            "gf, gi = hf._geometry()\n"
            "p = np.zeros(st.N_SHAPE_PARAMS); p[0] = 0.5\n"
            "out_f, out_i = np.zeros((64, 7)), np.zeros(64, np.int64)\n"
            "n = collide_sphere_heightfield(np.array([1.5, 0.4, 1.5]), np.eye(3), p, np.zeros(3), np.eye(3),\n"
            "                               hf._params(), gf, 0, 0.0, out_f, out_i, 0)\n"
            "print(n > 0, len(triangle_box.box_triangle.signatures)\n"
            "      + len(triangle_capsule.capsule_triangle.signatures)\n"
            "      + len(triangle_hull.hull_triangle.signatures))\n")
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path), MARBELLOUS_PROGRESS="0")
    run_ = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert run_.returncode == 0, run_.stderr
    assert run_.stdout.split() == ["True", "0"]
