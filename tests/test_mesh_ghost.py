"""No ghost collisions: shapes moving over internal edges, T-junctions and split vertices."""
import numpy as np
import pytest

from marbellous.collision import shape_types as st
from marbellous.collision.mesh.heightfield_collide import collide_convex_heightfield
from marbellous.collision.mesh.mesh_collide import collide_convex_mesh
from marbellous.shapes.heightfield import HeightField
from marbellous.shapes.mesh import TriangleMesh


def run(kernel, shape, type_a, dims, pos, rot=np.eye(3), prediction=0.0):
    p = np.zeros(st.N_SHAPE_PARAMS)
    p[:len(dims)] = dims
    gf, gi = shape._geometry()
    out_f = np.zeros((64, 7))
    out_i = np.zeros(64, np.int64)
    n = kernel(type_a, np.asarray(pos, float), rot, p, np.zeros(3), np.eye(3), shape._params(), gf, gi, 0, 0,
               prediction, out_f, out_i, 0)
    assert n <= 64
    return out_f[:n], out_i[:n]


def patchwork_floor(seed=0):
    """An 8 x 8 m floor at y = 0 from three kinds of patches that meet in T-junctions:
    x < 4: 1 m quads whose two triangles each have their own (split) vertex copies;
    x >= 4, z < 4: 2 m quads with shared vertices (their edges meet the 1 m edges at x = 4 in
    T-junctions); x >= 4, z >= 4: a fan of 8 triangles around a centre vertex."""
    rng = np.random.default_rng(seed)
    verts, tris = [], []

    def tri(a, b, c):
        base = len(verts)
        verts.extend([a, b, c])
        tris.append([base, base + 1, base + 2])

    def quad(x0, z0, s, flip):
        p00, p10 = (x0, 0.0, z0), (x0 + s, 0.0, z0)
        p01, p11 = (x0, 0.0, z0 + s), (x0 + s, 0.0, z0 + s)
        if flip:
            tri(p00, p01, p10)
            tri(p10, p01, p11)
        else:
            tri(p00, p11, p10)
            tri(p00, p01, p11)

    for i in range(4):
        for j in range(8):
            quad(float(i), float(j), 1.0, rng.random() < 0.5)
    for i in range(2):
        for j in range(2):
            quad(4.0 + 2 * i, 2.0 * j, 2.0, rng.random() < 0.5)
    centre = (6.0, 0.0, 6.0)
    ring = [(4, 4), (6, 4), (8, 4), (8, 6), (8, 8), (6, 8), (4, 8), (4, 6)]
    for k in range(8):
        a = (float(ring[k][0]), 0.0, float(ring[k][1]))
        b = (float(ring[(k + 1) % 8][0]), 0.0, float(ring[(k + 1) % 8][1]))
        # wind so the normal points up
        tri(centre, b, a) if np.cross(np.subtract(b, centre), np.subtract(a, centre))[1] > 0 else tri(centre, a, b)
    return np.array(verts), np.array(tris)


@pytest.mark.parametrize("accel", ["brute", "grid2d", "bvh"])
def test_sphere_sweep_over_patchwork_floor_only_sees_the_face(accel):
    v, t = patchwork_floor()
    mesh = TriangleMesh(v, t, accel=accel)
    rep = mesh.check()
    assert len(rep.t_junction_edges) > 0 and len(rep.flipped) == 0
    r = 0.5
    for depth, prediction in ((0.01, 0.0), (-0.03, 0.05)):
        y = r - depth
        for s in np.linspace(0.0, 1.0, 1501):
            x, z = 0.3 + 7.4 * s, 0.2 + 7.5 * s ** 1.3      # diagonal, crossing every kind of seam
            f, _ = run(collide_convex_mesh, mesh, st.SPHERE, (r,), (x, y, z), prediction=prediction)
            assert len(f) >= 1
            assert np.all(np.abs(f[:, 3:6] - [0.0, -1.0, 0.0]) <= 1e-9), (x, z, f)
            assert np.all(np.abs(f[:, 6] - depth) <= 1e-12)


def test_sphere_exactly_over_vertices_and_edges():
    v, t = patchwork_floor()
    mesh = TriangleMesh(v, t)
    for x, z in [(1.0, 1.0), (4.0, 1.0), (4.0, 2.0), (6.0, 6.0), (4.0, 4.0), (2.5, 3.0), (4.0, 3.0)]:
        f, _ = run(collide_convex_mesh, mesh, st.SPHERE, (0.5,), (x, 0.49, z))
        assert len(f) >= 1
        assert np.all(np.abs(f[:, 3:6] - [0.0, -1.0, 0.0]) <= 1e-9)


@pytest.mark.parametrize("type_a, dims, angle", [(st.CAPSULE, (0.3, 0.6), 0.4), (st.BOX, (0.4, 0.3, 0.5), 0.7)])
def test_capsule_and_box_slide_over_seams_with_face_normals(type_a, dims, angle):
    v, t = patchwork_floor()
    mesh = TriangleMesh(v, t, accel="grid2d")
    c, s = np.cos(angle), np.sin(angle)
    rot_y = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    rot = rot_y @ (np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0.0]]) if type_a == st.CAPSULE else np.eye(3))
    height = dims[0] if type_a == st.CAPSULE else dims[1]
    for q in np.linspace(0.0, 1.0, 400):
        x, z = 1.2 + 5.6 * q, 1.1 + 5.7 * q
        f, _ = run(collide_convex_mesh, mesh, type_a, dims, (x, height - 0.02, z), rot)
        assert len(f) >= 2
        assert np.all(np.abs(f[:, 3:6] - [0.0, -1.0, 0.0]) <= 1e-9)
        assert np.all(np.abs(f[:, 6] - 0.02) <= 1e-9)


def test_convex_hill_contacts_are_all_true_closest_points():
    """On a convex, finely tessellated hill every reported contact is a true closest point (no
    edge contact pointing sideways): r - depth equals the exact distance to the mesh."""
    n = 24
    xs, zs = np.meshgrid(np.linspace(-3, 3, n + 1), np.linspace(-3, 3, n + 1), indexing="ij")
    ys = -0.15 * (xs ** 2 + zs ** 2)
    v = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    tris = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            tris += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    mesh = TriangleMesh(v, np.array(tris), accel="bvh")
    a, b, c = (v[np.array(tris)[:, k]] for k in range(3))
    rng = np.random.default_rng(3)
    count = 0
    for _ in range(300):
        x, z = rng.uniform(-2.0, 2.0, 2)
        ray = mesh.raycast((x, 5.0, z), (0, -1, 0))
        p = np.array([x, ray[1][1] + rng.uniform(0.3, 0.55), z])
        f, _ = run(collide_convex_mesh, mesh, st.SPHERE, (0.5,), p)
        dist = point_triangle_distance(p, a, b, c).min()
        for row in f:
            assert abs((0.5 - row[6]) - dist) < 1e-9
            count += 1
    assert count > 100


def point_triangle_distance(p, a, b, c):
    """Exact distance from p to each triangle (rows of a, b, c): the plane distance where the
    projection is inside, else the nearest edge (vectorised over triangles)."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    s = np.einsum("ij,ij->i", p - a, n)
    q = p - s[:, None] * n
    inside = np.ones(len(a), bool)
    best = np.full(len(a), np.inf)
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(w - u, q - u), n) >= 0
        e = w - u
        t = np.clip(np.einsum("ij,ij->i", p - u, e) / np.einsum("ij,ij->i", e, e), 0, 1)
        best = np.minimum(best, np.linalg.norm(p - u - t[:, None] * e, axis=1))
    return np.where(inside, np.abs(s), best)


def test_heightfield_tiles_have_no_seam():
    """Two height-field tiles of one tilted plane side by side: a sphere crossing the seam only
    ever sees the plane's normal."""
    slope = 0.1
    nx, nz = 6, 5
    xs = np.arange(nx)[:, None] * 1.0
    tile_a = HeightField(np.repeat(slope * xs, nz, axis=1), spacing=(1.0, 1.0), origin=(0.0, 0.0, 0.0))
    tile_b = HeightField(np.repeat(slope * (xs + 5.0), nz, axis=1), spacing=(1.0, 1.0), origin=(5.0, 0.0, 0.0))
    normal = np.array([slope, -1.0, 0.0]) / np.hypot(1.0, slope)      # from the sphere into the ground
    r = 0.4
    for x in np.linspace(3.0, 7.0, 801):
        centre = np.array([x, slope * x, 2.0]) - normal * (r - 0.01)
        rows = [run(collide_convex_heightfield, tile, st.SPHERE, (r,), centre)[0] for tile in (tile_a, tile_b)]
        f = np.concatenate(rows)
        assert len(f) >= 1
        assert np.all(np.abs(f[:, 3:6] - normal) <= 1e-9)
        assert np.all(np.abs(f[:, 6] - 0.01) <= 1e-9)


def test_marble_rolls_across_seams_without_hopping():
    """Through the public World: a marble rolling diagonally over the patchwork floor (split
    vertices, T-junctions, a fan) keeps a vertical velocity of zero (no hop at any seam)."""
    import marbellous as mb

    v, t = patchwork_floor()
    w = mb.World()
    w.add_static(mb.TriangleMesh(v, t))
    marble = w.add_body(mb.Sphere(0.3), position=(0.5, 0.3, 0.5), velocity=(3.0, 0.0, 2.6))
    for _ in range(240):
        w.step(1.0 / 120.0)
        assert abs(marble.velocity[1]) < 1e-9
        assert abs(marble.position[1] - 0.3) < 1e-3
    assert marble.position[0] > 4.0 and marble.position[2] > 4.0     # it crossed x = 4 and z = 4
