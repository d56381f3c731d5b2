"""Mesh construction: the check report on crafted bad meshes, malformed input, file loading."""
import warnings

import numpy as np
import pytest
import trimesh

from marbellous.collision import shape_types as st
from marbellous.shapes import mesh as mesh_module
from marbellous.shapes.mesh import TriangleMesh

QUAD = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 1]], float)


def quiet(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return TriangleMesh(*args, **kw)


def test_clean_open_mesh_gives_no_warning():
    m = quiet(QUAD, [[0, 1, 2], [2, 1, 3]])
    c = m.check().counts()
    assert c == {"triangles": 2, "degenerate": 0, "duplicate": 0, "flipped": 0, "open_edges": 4,
                 "non_manifold_edges": 0, "t_junction_edges": 0}
    assert not m.check().has_problems


def test_closed_box_is_clean():
    box = trimesh.creation.box(extents=(1, 2, 3))
    m = quiet(box.vertices, box.faces)
    assert m.check().counts()["open_edges"] == 0 and not m.check().has_problems


def test_degenerate_triangles_are_reported():
    v = np.vstack([QUAD, [[2, 0, 0], [3, 0, 0]]])
    with pytest.warns(UserWarning, match="2 degenerate"):
        m = TriangleMesh(v, [[0, 1, 2], [2, 4, 5], [1, 1, 3]])
    assert m.check().degenerate.tolist() == [1, 2]


def test_duplicate_triangles_are_reported_even_with_split_vertices():
    v = np.vstack([QUAD, QUAD[[0, 1, 2]]])          # vertices 4, 5, 6 repeat 0, 1, 2
    with pytest.warns(UserWarning, match="1 duplicate"):
        m = TriangleMesh(v, [[0, 1, 2], [2, 1, 3], [4, 5, 6]])
    assert m.check().duplicate.tolist() == [2]


def test_flipped_triangle_is_reported():
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 1], [2, 0, 0], [2, 0, 1]], float)
    tris = [[0, 1, 2], [2, 3, 1], [2, 3, 4], [4, 3, 5]]      # triangle 1 wound the other way
    with pytest.warns(UserWarning, match="1 flipped"):
        m = TriangleMesh(v, tris)
    assert m.check().flipped.tolist() == [1]


def test_non_manifold_edge_is_reported():
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [-1, 0, 0], [0, 1, 0.5]], float)
    with pytest.warns(UserWarning, match="3 non-manifold"):
        m = TriangleMesh(v, [[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert len(m.check().non_manifold_edges) == 3


def test_t_junctions_are_found():
    # One long edge x = 1 (z 0..2) on the left, two short ones on the right.
    v = np.array([[0, 0, 0], [0, 0, 2], [1, 0, 0], [1, 0, 2], [1, 0, 1], [2, 0, 0], [2, 0, 2]], float)
    m = quiet(v, [[0, 1, 2], [2, 1, 3], [2, 4, 5], [4, 3, 6], [4, 6, 5]])
    rep = m.check()
    assert len(rep.t_junction_edges) == 3
    assert repr(rep).startswith("MeshReport(")


@pytest.mark.parametrize("vertices, triangles, kw, match", [
    (QUAD[:, :2], [[0, 1, 2]], {}, "vertices must have shape"),
    ([[0, 0, 0], [1, 0, np.nan], [0, 0, 1]], [[0, 1, 2]], {}, "vertices must be finite"),
    ([[0, 0, 0], [1, 0, 0]], [[0, 1, 1]], {}, "vertices must hold at least 3"),
    (QUAD, [[0, 1, 4]], {}, "triangles must index vertices 0..3"),
    (QUAD, [[0, -1, 2]], {}, "triangles must index"),
    (QUAD, [[0, 1, 2, 3]], {}, "triangles must have shape"),
    (QUAD, np.zeros((0, 3), int), {}, "triangles must not be empty"),
    (QUAD, [[0, 1, 2.5]], {}, "whole-number"),
    (QUAD, [["a", "b", "c"]], {}, "triangles"),
    (np.zeros((3, 3)), [[0, 1, 2]], {}, "no extent"),
    (QUAD, [[0, 1, 2]], {"accel": "octree"}, "accel must be one of"),
    (QUAD, [[0, 1, 2]], {"cell_size": -1.0}, "cell_size"),
    (QUAD, [[0, 1, 2]], {"weld_tolerance": np.nan}, "weld_tolerance"),
])
def test_malformed_input_raises_naming_the_argument(vertices, triangles, kw, match):
    with pytest.raises((ValueError, TypeError), match=match):
        TriangleMesh(vertices, triangles, **kw)


def test_shape_interface():
    m = quiet(QUAD * 2.0 + [1, 2, 3], [[0, 1, 2], [2, 1, 3]], accel="bvh")
    assert m._type == st.MESH and m.is_static_only
    p = m._params()
    assert p.shape == (st.N_SHAPE_PARAMS,) and p[0] == 4 and p[1] == 2 and p[2] == 2
    gf, gi = m._geometry()
    assert gf.dtype == np.float64 and gi.dtype == np.int64 and gf.ndim == gi.ndim == 1
    lo, hi = m.local_aabb()
    assert np.allclose(lo, [1, 2, 3]) and np.allclose(hi, [3, 2, 5])
    assert m.bounding_radius() == pytest.approx(np.linalg.norm([3, 2, 5]))


def terrain_mesh():
    rng = np.random.default_rng(4)
    n = 8
    xs, zs = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    v = np.stack([xs.ravel(), rng.normal(0, 0.2, xs.size), zs.ravel()], axis=1)
    t = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            t += [[a, a + 1, a + n + 1], [a + n + 1, a + 1, a + n + 2]]
    return v, np.array(t)


@pytest.mark.parametrize("ext", ["obj", "stl", "ply", "glb"])
def test_load_round_trip(tmp_path, ext):
    v, t = terrain_mesh()
    path = tmp_path / f"level.{ext}"
    trimesh.Trimesh(v, t, process=False).export(path)
    m = TriangleMesh.load(path, accel="bvh")
    assert m.accel == "bvh" and m.triangles.shape == t.shape
    # Same triangles (as corner coordinates, float32 files round to ~1e-7).
    got = np.sort(np.round(m.vertices[m.triangles], 5).reshape(len(t), -1), axis=0)
    want = np.sort(np.round(v[t], 5).reshape(len(t), -1), axis=0)
    assert np.allclose(got, want, atol=2e-5)
    assert not m.check().has_problems and len(m.check().open_edges) == 32
    hit = m.raycast((3.5, 5.0, 4.2), (0, -1, 0))
    ref = TriangleMesh(v, t).raycast((3.5, 5.0, 4.2), (0, -1, 0))
    assert abs(hit[0] - ref[0]) < 1e-5


def test_load_rejects_bad_files(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match="no such file"):
        TriangleMesh.load(tmp_path / "missing.obj")
    bad = tmp_path / "level.txt"
    bad.write_text("v 0 0 0")
    with pytest.raises(ValueError, match="path must name"):
        TriangleMesh.load(bad)
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"")
    with pytest.raises(ValueError, match="empty"):
        TriangleMesh.load(empty)
    garbage = tmp_path / "garbage.glb"
    garbage.write_bytes(b"glTF\x02\x00\x00\x00\xff\xff\xff\x7f" + bytes(range(256)) * 4)
    with pytest.raises(ValueError, match="path"):
        TriangleMesh.load(garbage)
    no_faces = tmp_path / "points.obj"
    no_faces.write_text("v 0 0 0\nv 1 0 0\nv 0 0 1\n")
    with pytest.raises(ValueError, match="no triangles"):
        TriangleMesh.load(no_faces)
    bad_index = tmp_path / "bad_index.obj"
    bad_index.write_text("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 9\n")
    with pytest.raises(ValueError, match="path"):
        TriangleMesh.load(bad_index)
    nan = tmp_path / "nan.obj"
    nan.write_text("v 0 0 0\nv 1 nan 0\nv 0 0 1\nf 1 2 3\n")
    with pytest.raises(ValueError, match="path"):
        TriangleMesh.load(nan)
    hostile = tmp_path / "hostile.ply"      # a header that promises a trillion vertices
    hostile.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\n"
                        b"property float x\nproperty float y\nproperty float z\nelement face 999999999\n"
                        b"property list uchar int vertex_indices\nend_header\n\x00\x00\x00\x00")
    with pytest.raises(ValueError, match="path"):
        TriangleMesh.load(hostile)
    v, t = terrain_mesh()
    big = tmp_path / "big.stl"
    trimesh.Trimesh(v, t, process=False).export(big)
    monkeypatch.setattr(mesh_module, "MAX_FILE_BYTES", 100)
    with pytest.raises(ValueError, match="more than the limit"):
        TriangleMesh.load(big)
