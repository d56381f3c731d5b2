"""Convex shapes against triangle meshes: acceleration equivalence, placement, ray casts."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

from marbellous.collision import shape_types as st
from marbellous.collision.mesh.mesh_collide import collide_convex_mesh
from marbellous.shapes.mesh import TriangleMesh

ACCELS = ("brute", "grid2d", "bvh")


def quat_matrix(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def params(type_a, dims):
    p = np.zeros(st.N_SHAPE_PARAMS)
    p[:len(dims)] = dims
    return p


def contacts(mesh, type_a, dims, pos, rot=np.eye(3), prediction=0.0, pos_b=np.zeros(3), rot_b=np.eye(3)):
    gf, gi = mesh._geometry()
    cap = 64
    while True:
        out_f = np.zeros((cap, 7))
        out_i = np.zeros(cap, np.int64)
        n = collide_convex_mesh(type_a, np.asarray(pos, float), rot, params(type_a, dims), pos_b, rot_b,
                                mesh._params(), gf, gi, 0, 0, prediction, out_f, out_i, 0)
        if n <= cap:
            return out_f[:n], out_i[:n]
        cap = n


def terrain(n, seed, jitter=0.3):
    rng = np.random.default_rng(seed)
    xs, zs = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    xs = xs + rng.uniform(-jitter, jitter, xs.shape) * (0 < xs) * (xs < n)
    zs = zs + rng.uniform(-jitter, jitter, zs.shape) * (0 < zs) * (zs < n)
    ys = rng.normal(0.0, 0.3, xs.shape)
    v = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    tris = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            b, c, d = a + 1, a + n + 1, a + n + 2
            tris += [[a, b, c], [c, b, d]] if rng.random() < 0.5 else [[a, b, d], [a, d, c]]
    return v, np.array(tris)


def soup(n_tri, seed):
    """Random triangles in a 6 m box, any orientation: overhangs, crossings, steep walls."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(0.0, 6.0, (n_tri, 1, 3))
    v = (centres + rng.normal(0.0, 0.6, (n_tri, 3, 3))).reshape(-1, 3)
    return v, np.arange(3 * n_tri).reshape(-1, 3)


@pytest.fixture(scope="module")
def meshes():
    return {name: {acc: TriangleMesh(v, t, accel=acc) for acc in ACCELS}
            for name, (v, t) in {"terrain": terrain(12, 1), "soup": soup(150, 2)}.items()}


shape_case = hst.sampled_from([(st.SPHERE, (0.5,)), (st.SPHERE, (0.15,)), (st.CAPSULE, (0.3, 0.6)),
                               (st.BOX, (0.4, 0.3, 0.5)), (st.BOX, (1.2, 0.2, 0.3))])
unit = hst.floats(0.0, 1.0)


@settings(max_examples=300, deadline=None)
@given(hst.sampled_from(["terrain", "soup"]), shape_case, unit, unit, unit,
       hst.tuples(hst.floats(-1, 1), hst.floats(-1, 1), hst.floats(-1, 1), hst.floats(-1, 1)),
       hst.floats(0.0, 0.2))
def test_brute_grid_bvh_give_identical_contacts(meshes, name, case, fx, fy, fz, q, prediction):
    type_a, dims = case
    q = np.array(q)
    rot = quat_matrix(q) if np.linalg.norm(q) > 0.1 else np.eye(3)
    m = meshes[name]["brute"]
    lo, hi = m.local_aabb()
    pos = lo - 0.5 + (hi - lo + 1.0) * np.array([fx, fy, fz])
    ref_f, ref_i = contacts(m, type_a, dims, pos, rot, prediction)
    for acc in ("grid2d", "bvh"):
        f, i = contacts(meshes[name][acc], type_a, dims, pos, rot, prediction)
        assert np.array_equal(f, ref_f) and np.array_equal(i, ref_i), acc
    assert np.all(np.isfinite(ref_f))
    assert np.allclose(np.linalg.norm(ref_f[:, 3:6], axis=1), 1.0)
    assert np.all(ref_f[:, 6] >= -prediction - 1e-12)


def test_identical_contacts_on_dense_sweep(meshes):
    """Many spheres placed near the terrain surface (where contacts are): all accels agree."""
    rng = np.random.default_rng(5)
    m = meshes["terrain"]
    total = 0
    for _ in range(400):
        x, z = rng.uniform(0.0, 12.0, 2)
        ray = m["brute"].raycast((x, 5.0, z), (0.0, -1.0, 0.0))
        y = ray[1][1] + rng.uniform(0.0, 0.5) if ray else 0.0
        ref = contacts(m["brute"], st.SPHERE, (0.4,), (x, y, z), prediction=0.05)
        total += len(ref[0])
        for acc in ("grid2d", "bvh"):
            got = contacts(m[acc], st.SPHERE, (0.4,), (x, y, z), prediction=0.05)
            assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
    assert total > 300


def test_contacts_follow_the_mesh_placement(meshes):
    """A mesh placed at (p, R) gives the contacts of its vertices moved there, to rounding."""
    v, t = terrain(6, 3)
    rot_b = quat_matrix(np.array([0.9, 0.2, -0.3, 0.1]))
    pos_b = np.array([1.0, -2.0, 0.5])
    placed = TriangleMesh(v, t, accel="bvh")
    moved = TriangleMesh(v @ rot_b.T + pos_b, t, accel="brute")
    rng = np.random.default_rng(7)
    found = 0
    for _ in range(200):
        local = rng.uniform([0, -0.5, 0], [6, 0.8, 6])
        world = rot_b @ local + pos_b
        for type_a, dims in ((st.SPHERE, (0.5,)), (st.CAPSULE, (0.3, 0.5)), (st.BOX, (0.3, 0.4, 0.5))):
            a = distinct(contacts(placed, type_a, dims, world, rot_b, 0.0, pos_b, rot_b)[0])
            b = distinct(contacts(moved, type_a, dims, world, rot_b, 0.0)[0])
            assert len(a) == len(b)
            assert np.allclose(a, b, atol=1e-9)
            found += len(a)
    assert found > 50


def distinct(rows, tol=1e-9):
    """Rows without near repeats (exact repeats are merged by the kernel, rounding-level ones may
    not be), in their order."""
    keep = []
    for row in rows:
        if not any(np.allclose(row, k, atol=tol) for k in keep):
            keep.append(row)
    return np.array(keep).reshape(-1, 7)


def test_exact_repeats_are_reported_once():
    v, t = terrain(4, 0, jitter=0.0)
    m = TriangleMesh(v * [1, 0, 1], t)
    f, i = contacts(m, st.SPHERE, (0.5,), (2.0, 0.4, 2.0))      # right over a vertex of six triangles
    assert len(f) == 1 and f[0, 6] == pytest.approx(0.1) and np.array_equal(f[0, 3:6], [0.0, -1.0, 0.0])


def test_buffer_capacity_is_respected():
    v, t = terrain(4, 0, jitter=0.0)
    m = TriangleMesh(v * [1, 0, 1], t)       # flat floor: a big box touches many triangles
    full_f, full_i = contacts(m, st.BOX, (1.5, 0.5, 1.5), (2.0, 0.45, 2.0))
    assert len(full_f) > 4
    out_f = np.full((3, 7), 7.0)
    out_i = np.zeros(3, np.int64)
    gf, gi = m._geometry()
    n = collide_convex_mesh(st.BOX, np.array([2.0, 0.45, 2.0]), np.eye(3), params(st.BOX, (1.5, 0.5, 1.5)),
                            np.zeros(3), np.eye(3), m._params(), gf, gi, 0, 0, 0.0, out_f[:2], out_i[:2], 0)
    assert n == len(full_f)
    assert np.array_equal(out_f[:2], full_f[:2]) and np.all(out_f[2] == 7.0)


def test_degenerate_triangles_never_collide():
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [2, 0, 0], [3, 0, 0], [0.5, 0, 0.5]], float)
    t = np.array([[0, 1, 2], [2, 3, 4], [0, 0, 1], [0, 5, 5]])
    with pytest.warns(UserWarning, match="degenerate"):
        m = TriangleMesh(v, t, accel="grid2d")
    f, i = contacts(m, st.SPHERE, (0.5,), (2.5, 0.2, 0.0), prediction=0.5)
    assert np.all(np.isfinite(f))
    assert set(i // 16) <= {0}


@settings(max_examples=200, deadline=None)
@given(hst.sampled_from(["terrain", "soup"]), unit, unit, unit,
       hst.tuples(hst.floats(-1, 1), hst.floats(-1, 1), hst.floats(-1, 1)).filter(lambda d: np.linalg.norm(d) > 0.1))
def test_raycast_identical_across_accels_and_matches_brute_reference(meshes, name, fx, fy, fz, d):
    m = meshes[name]["brute"]
    lo, hi = m.local_aabb()
    o = lo - 1.0 + (hi - lo + 2.0) * np.array([fx, fy, fz])
    d = np.array(d) / np.linalg.norm(d)
    hits = [meshes[name][acc].raycast(o, d) for acc in ACCELS]
    # Reference: every triangle by the parametric plane intersection, barycentric inside test.
    best = np.inf
    for tri in m.triangles:
        a, b, c = m.vertices[tri]
        nrm = np.cross(b - a, c - a)
        den = np.dot(nrm, d)
        if abs(den) < 1e-14:
            continue
        t = np.dot(nrm, a - o) / den
        if t < 0:
            continue
        x = o + t * d
        if all(np.dot(np.cross(w - u, x - u), nrm) >= -1e-12 * np.dot(nrm, nrm)
               for u, w in ((a, b), (b, c), (c, a))):
            best = min(best, t)
    if best == np.inf:
        assert all(h is None for h in hits)
        return
    for h in hits:
        assert h is not None and abs(h[0] - best) < 1e-9
        assert np.dot(h[2], d) <= 0.0
    for h in hits[1:]:
        assert h[0] == hits[0][0] and np.array_equal(h[2], hits[0][2])


def test_raycast_misses_and_max_distance():
    v, t = terrain(4, 0, jitter=0.0)
    m = TriangleMesh(v * [1, 0, 1], t, accel="grid2d")
    assert m.raycast((2.0, 3.0, 2.0), (0, 1, 0)) is None
    assert m.raycast((2.0, 3.0, 2.0), (0, -1, 0), max_distance=2.5) is None
    hit = m.raycast((2.0, 3.0, 2.0), (0, -2, 0))
    assert hit[0] == pytest.approx(3.0) and np.allclose(hit[1], [2, 0, 2]) and np.allclose(hit[2], [0, 1, 0])
    with pytest.raises(ValueError, match="direction"):
        m.raycast((0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="origin"):
        m.raycast((0, np.nan, 0), (0, 1, 0))


def test_world_simulation_is_bit_identical_for_every_accel():
    """Spheres and a box tumbling over a bumpy terrain: the same state bit for bit whichever
    acceleration the mesh uses."""
    import marbellous as mb

    v, t = terrain(12, 1)
    finals = []
    for acc in ACCELS:
        w = mb.World()
        w.add_static(mb.TriangleMesh(v, t, accel=acc))
        bodies = [w.add_body(mb.Sphere(0.3), position=(2 + i, 2.0, 3 + 0.5 * i), velocity=(1.0, 0, 0.5))
                  for i in range(4)]
        bodies.append(w.add_body(mb.Box((0.3, 0.2, 0.4)), position=(6, 2.5, 6)))
        for _ in range(200):
            w.step(1 / 120)
        finals.append(np.array([np.r_[b.position, b.velocity] for b in bodies]))
    assert np.all(np.isfinite(finals[0]))
    assert all(np.array_equal(finals[0], f) for f in finals[1:])
