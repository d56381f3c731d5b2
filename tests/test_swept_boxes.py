"""The broad phase of the cloths' contacts with themselves (swept_boxes.py): its grid against every pair of boxes,
the sweep's ends, and which pairs of a falling sheet it lets through."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.deformables import swept_boxes as sb
from marbellous.deformables.edge_contacts import edge_candidates
from marbellous.deformables.particle_layout import P_FORCE, P_INV_MASS, P_POS, P_VEL, PF_COLS
from marbellous.deformables.particle_pairs import edge_adjacency
from marbellous.deformables.triangle_contacts import triangle_candidates

DT = 1.0 / 60.0


def _boxes(data, count, scale):
    """``count`` random boxes: corners within ``scale`` of the origin, sizes from a thousandth of it to ten times
    it (some fast boxes of a grid are much wider than the rest), every fifth one empty."""
    lo = np.empty((count, 3))
    hi = np.empty((count, 3))
    for b in range(count):
        corner = np.array(data.draw(st.lists(st.floats(-scale, scale), min_size=3, max_size=3)))
        size = np.array(data.draw(st.lists(st.floats(1e-3 * scale, 10.0 * scale), min_size=3, max_size=3)))
        lo[b], hi[b] = corner, corner + size
        if data.draw(st.integers(0, 4)) == 0:
            lo[b], hi[b] = np.inf, -np.inf
    return lo, hi


def _brute(lo, hi, qlo, qhi, q, after):
    """The boxes ``b > after`` overlapping query ``q``, by testing every box."""
    return sorted(b for b in range(lo.shape[0]) if b > after and lo[b, 0] <= hi[b, 0]
                  and np.all(lo[b] <= qhi[q]) and np.all(qlo[q] <= hi[b]))


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_the_grid_finds_every_overlapping_box_once(data):
    count = data.draw(st.integers(1, 60))
    scale = data.draw(st.sampled_from([1e-3, 1.0, 50.0]))
    lo, hi = _boxes(data, count, scale)
    qlo, qhi = _boxes(data, data.draw(st.integers(1, 20)), scale)
    # (small tables share slots between many cells; the candidates' own table, ``box_table``, seldom does)
    table = data.draw(st.sampled_from([2, 17, 256, None]))
    cell_start = sb.box_table(count) if table is None else np.zeros(table + 1, np.int64)
    cell = sb.typical_extent(lo, hi, count)
    grid = sb.bin_boxes(lo, hi, count, cell, cell_start)
    found = np.empty(count, np.int64)
    for q in range(qlo.shape[0]):
        if qlo[q, 0] > qhi[q, 0]:
            continue
        after = data.draw(st.integers(-1, count))
        n = sb.overlapping(lo, hi, count, cell, cell_start, grid, qlo, qhi, q, after, found)
        assert sorted(found[:n]) == _brute(lo, hi, qlo, qhi, q, after)
    # a box's own query with ``after`` at its row lists each overlapping pair once
    pairs = [(b, int(c)) for b in range(count) if lo[b, 0] <= hi[b, 0]
             for c in found[:sb.overlapping(lo, hi, count, cell, cell_start, grid, lo, hi, b, b, found)]]
    assert len(pairs) == len(set(pairs)) and all(c > b for b, c in pairs)


def test_a_point_sweeps_along_its_velocity_relative_to_the_mean_and_its_force_and_may_turn():
    pf = np.zeros((1, PF_COLS))
    pf[0, P_POS:P_POS + 3] = (1.0, 2.0, 3.0)
    pf[0, P_VEL:P_VEL + 3] = (3.0, -1.0, 0.0)
    pf[0, P_INV_MASS] = 2.0
    pf[0, P_FORCE:P_FORCE + 3] = (0.0, 0.0, -36.0)
    mean = np.array([1.0, 1.0, 0.0])
    lo, hi = sb.empty_boxes(1)
    sb.sweep_point(pf, 0, mean, DT, lo, hi, 0)
    # from x to x + 2 (v - m) dt + w F dt^2, grown by half its speed relative to the mean times dt
    end = np.array([1.0 + 2 * 2.0 * DT, 2.0 + 2 * -2.0 * DT, 3.0 - 2.0 * 36.0 * DT * DT])
    pad = 0.5 * math.hypot(2.0, -2.0) * DT
    assert np.allclose(lo[0], np.minimum(pf[0, :3], end) - pad, rtol=0, atol=1e-15)
    assert np.allclose(hi[0], np.maximum(pf[0, :3], end) + pad, rtol=0, atol=1e-15)
    other = np.zeros((2, PF_COLS))
    other[0] = pf[0]
    other[1, P_VEL:P_VEL + 3] = (0.0, 2.0, 0.0)
    reach = sb.closing_reach(other, 0, 1, DT)
    assert math.isclose(reach, 2 * math.hypot(3.0, -3.0) * DT + 72.0 * DT * DT, rel_tol=1e-14)


def _sheet(n, velocity):
    """A cloth of n x n vertices, 1 m across, in a world of its own, every vertex at ``velocity`` (m/s): the
    particle tables, its triangles, edges and cloth rows as the candidate search reads them."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    c = w.add_cloth(*mb.cloth_grid(1.0, 1.0, n, n), mass=0.5, thickness=0.01, position=(0.0, 1.0, 0.0))
    c.velocities = np.tile(velocity, (len(c), 1))
    ps = w._state.particles
    tri, _, _, cloth_f = ps.kernel_cloth_tables()
    return ps.pf[:ps.n].copy(), ps.pi[:ps.n].copy(), ps.ei[:ps.ne].copy(), tri, cloth_f


def _candidates(pf, pi, ei, tri, cloth_f):
    """The (point, triangle) and (edge, edge) candidates of one step of ``DT`` (no gravity, no slack)."""
    n, ne = pf.shape[0], ei.shape[0]
    mean = pf[:, P_VEL:P_VEL + 3].mean(axis=0)
    start, adjacent = np.zeros(n + 1, np.int64), np.zeros(2 * ne, np.int64)
    edge_adjacency(ei, ne, n, start, adjacent)
    triangles, edges = np.zeros((20000, 3), np.int64), np.zeros((20000, 3), np.int64)
    n_tri = triangle_candidates(pf, pi, n, tri, tri.shape[0], cloth_f, mean, DT, 0.0, start, adjacent, triangles)
    n_edge = edge_candidates(pf, pi, ei, ne, cloth_f, mean, DT, 0.0, edges)
    return triangles[:n_tri], edges[:n_edge]


def test_a_sheet_moving_as_a_whole_has_no_candidates_however_fast():
    for speed in (0.0, 3.0, 100.0):
        triangles, edges = _candidates(*_sheet(12, (0.3 * speed, -speed, 0.1 * speed)))
        assert len(triangles) == 0 and len(edges) == 0


def test_a_fold_closing_on_itself_is_a_candidate_and_one_opening_is_not():
    # a 12 x 12 sheet (9.1 cm spacing) whose right half is lifted 10 cm and slid back over its left half: the
    # upper layer moving down at 4 m/s closes 13 cm in the step, moving up it opens
    for speed, closes in ((-4.0, True), (4.0, False)):
        pf, pi, ei, tri, cloth_f = _sheet(12, (0.0, 0.0, 0.0))
        right = pf[:, P_POS] > 0.0
        pf[right, P_POS] = -pf[right, P_POS]
        pf[right, P_POS + 1] += 0.1
        pf[right, P_VEL + 1] = speed
        triangles, edges = _candidates(pf, pi, ei, tri, cloth_f)
        points = set(int(p) for p in triangles[:, 0])
        upper_over_lower = {p for p in np.flatnonzero(right) if pf[p, P_POS] < -0.1}
        assert upper_over_lower <= points if closes else not points & upper_over_lower
