"""The 2D grid over a level mesh: every candidate list holds every triangle whose x-z footprint meets the
query box, ascending and without repeats, whether one grown cell answers or several cells are merged."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as hst

from marbellous.collision.mesh import mesh_layout as ml
from marbellous.collision.mesh.grid2d import FAT_MARGIN, grid_candidates
from marbellous.shapes.mesh import TriangleMesh


def footprint_meets_box(a, b, c, lo, hi):
    """Slow reference: does triangle abc projected to x-z meet the rectangle lo..hi (x, z)?  Separating
    axes of two convex polygons: the rectangle's two axes and the triangle's three edge normals."""
    tri = np.array([[a[0], a[2]], [b[0], b[2]], [c[0], c[2]]])
    rect = np.array([[lo[0], lo[2]], [hi[0], lo[2]], [hi[0], hi[2]], [lo[0], hi[2]]])
    axes = [np.array([1.0, 0.0]), np.array([0.0, 1.0])]
    for k in range(3):
        e = tri[(k + 1) % 3] - tri[k]
        axes.append(np.array([-e[1], e[0]]))
    for axis in axes:
        p, q = tri @ axis, rect @ axis
        if p.max() < q.min() or q.max() < p.min():
            return False
    return True


def jagged_terrain(n, seed):
    rng = np.random.default_rng(seed)
    xs, zs = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    xs = xs + rng.uniform(-0.3, 0.3, xs.shape)
    zs = zs + rng.uniform(-0.3, 0.3, zs.shape)
    v = np.stack([xs.ravel(), rng.normal(0.0, 0.3, xs.size), zs.ravel()], axis=1)
    t = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            t += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    return v, np.array(t)


MESH = TriangleMesh(*jagged_terrain(10, 3), accel="grid2d")


def candidates(lo, hi):
    gf, gi = MESH._geometry()
    arr, first, count = grid_candidates(MESH._params(), gi, 0, lo, hi)
    return arr[first:first + count].copy(), arr is gi


@settings(max_examples=400, deadline=None)
@given(hst.floats(-1.0, 11.0), hst.floats(-1.0, 11.0), hst.floats(0.0, 1.0), hst.floats(0.0, 1.0))
def test_candidates_hold_every_triangle_under_the_box(x, z, fx, fz):
    cell = MESH._grid[2]
    # half-extents from tiny to several cells: both the grown-cell path and the merge path
    hx, hz = 3.0 * cell * fx ** 2, 3.0 * cell * fz ** 2
    lo, hi = (x - hx, -5.0, z - hz), (x + hx, 5.0, z + hz)
    got, _ = candidates(lo, hi)
    assert np.all(np.diff(got) > 0)                       # ascending, no repeats
    gf, gi = MESH._geometry()
    expected = [t for t in range(MESH.triangles.shape[0])
                if footprint_meets_box(*ml.triangle(gf, gi, 0, 0, t)[:3], lo, hi)]
    assert set(expected) <= set(got.tolist())


def test_a_box_within_the_margin_reads_one_grown_cell():
    x0, z0, cell, nx, nz = MESH._grid
    half = 0.9 * FAT_MARGIN * cell
    centre = (x0 + 2.3 * cell, z0 + 1.6 * cell)
    lo, hi = (centre[0] - half, -5.0, centre[1] - half), (centre[0] + half, 5.0, centre[1] + half)
    got, single = candidates(lo, hi)
    assert single and got.size > 0
    _, single = candidates((centre[0] - 2 * cell, -5.0, lo[2]), (centre[0] + 2 * cell, 5.0, hi[2]))
    assert not single
