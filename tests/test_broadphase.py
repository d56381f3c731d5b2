"""Every broad phase reports exactly the brute-force pair list, and its queries match brute force.

The reference here is the obvious definition evaluated for every pair (an n x n truth table): all pairs
i < j, both alive, not both static, filter bits passing, closed-interval overlap on all three axes.
"""
import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from marbellous.collision.broadphase import ALIVE, METHODS, STATIC, BroadPhase, find_pairs, make_state, state_sizes

ALL = list(METHODS)


def reference_pairs(aabbs, flags, groups, masks):
    """All pairs i < j, both alive, not both static, filters passing, boxes overlapping on all three
    axes (closed intervals), in row-major (lexicographic) order: an n x n truth table."""
    alive = (flags & ALIVE) != 0
    static = (flags & STATIC) != 0
    ok = alive[:, None] & alive[None, :] & ~(static[:, None] & static[None, :])
    ok &= ((groups[:, None] & masks[None, :]) != 0) & ((groups[None, :] & masks[:, None]) != 0)
    for k in range(3):
        ok &= (aabbs[:, None, k] <= aabbs[None, :, k + 3]) & (aabbs[None, :, k] <= aabbs[:, None, k + 3])
    i, j = np.nonzero(np.triu(ok, 1))
    return np.stack([i, j], axis=1).astype(np.int64)


def reference_box_query(aabbs, flags, lo, hi):
    return np.array([i for i in range(len(aabbs)) if flags[i] & ALIVE
                     and all(aabbs[i, k] <= hi[k] and lo[k] <= aabbs[i, k + 3] for k in range(3))],
                    dtype=np.int64)


def reference_ray_query(aabbs, flags, origin, direction, max_distance):
    d = np.asarray(direction, float) / math.sqrt(sum(x * x for x in direction))
    hits = []
    for i in range(len(aabbs)):
        if not flags[i] & ALIVE:
            continue
        t_near, t_far, hit = 0.0, max_distance, True
        for k in range(3):
            lo, hi = aabbs[i, k], aabbs[i, k + 3]
            if d[k] == 0.0:
                if origin[k] < lo or origin[k] > hi:
                    hit = False
            else:
                t1, t2 = sorted(((lo - origin[k]) / d[k], (hi - origin[k]) / d[k]))
                t_near, t_far = max(t_near, t1), min(t_far, t2)
                if t_near > t_far:
                    hit = False
        if hit:
            hits.append((t_near, i))
    return np.array([i for _, i in sorted(hits)], dtype=np.int64)


def boxes(centres, half):
    return np.hstack([centres - half, centres + half])


def scene(kind, n, seed):
    """Seeded test scenes: (aabbs, flags, groups, masks)."""
    rng = np.random.default_rng(seed)
    flags = np.full(n, ALIVE, np.int64)
    groups = np.full(n, -1, np.int64)
    masks = np.full(n, -1, np.int64)
    if kind == "uniform":
        a = boxes(rng.uniform(0, 10, (n, 3)), rng.uniform(0.1, 0.6, (n, 3)))
    elif kind == "clustered":
        hubs = rng.uniform(0, 50, (5, 3))
        c = hubs[rng.integers(0, 5, n)] + rng.normal(0, 1.0, (n, 3))
        a = boxes(c, rng.uniform(0.1, 0.5, (n, 3)))
    elif kind == "sparse":
        a = boxes(rng.uniform(0, 1000, (n, 3)), rng.uniform(0.1, 0.5, (n, 3)))
        a[: n // 10] = boxes(rng.uniform(0, 3, (n // 10, 3)), np.full((n // 10, 3), 0.4))
    elif kind == "huge":
        a = boxes(rng.uniform(0, 20, (n, 3)), rng.uniform(0.1, 0.4, (n, 3)))
        a[n // 2] = [-5, 4, -5, 25, 6, 25]
    elif kind == "many_big":
        a = boxes(rng.uniform(0, 30, (n, 3)), rng.uniform(0.1, 0.4, (n, 3)))
        big = rng.random(n) < 0.15
        a[big] = boxes(rng.uniform(0, 30, (int(big.sum()), 3)), rng.uniform(1.5, 5, (int(big.sum()), 3)))
    elif kind == "infinite":
        # a plane's (here finite but enormous) box and two long walls among small boxes (the pile layout)
        a = boxes(rng.uniform(0, 10, (n, 3)), rng.uniform(0.1, 0.5, (n, 3)))
        a[0] = [-1e12, -1e12, -1e12, 1e12, 1e12, 1e12]
        a[1] = [-1, 0, -1, 0, 6, 11]
        a[2] = [10, 0, -1, 11, 6, 11]
        flags[:3] |= STATIC
    elif kind == "plane":
        c = rng.uniform(0, 10, (n, 3))
        c[:, 1] = 0.0
        a = boxes(c, rng.uniform(0.1, 0.5, (n, 3)))
    elif kind == "flat":
        c = rng.uniform(0, 10, (n, 3))
        c[:, 1] = 0.0
        a = boxes(c, np.hstack([rng.uniform(0.1, 0.5, (n, 1)), np.zeros((n, 1)),
                                rng.uniform(0.1, 0.5, (n, 1))]))
    elif kind == "touching":
        c = rng.integers(0, 6, (n, 3)).astype(float)
        a = boxes(c, np.full((n, 3), 0.5))
    elif kind == "points":
        a = boxes(rng.integers(0, 4, (n, 3)).astype(float), np.zeros((n, 3)))
    elif kind == "coincident":
        a = boxes(np.full((n, 3), 1.5), np.full((n, 3), 0.25))
    elif kind == "mixed":
        a = boxes(rng.uniform(0, 8, (n, 3)), rng.uniform(0.05, 0.8, (n, 3)))
        flags[rng.random(n) < 0.2] = 0
        flags[rng.random(n) < 0.3] |= STATIC
        groups = rng.integers(1, 8, n)
        masks = rng.integers(0, 8, n)
    else:
        raise AssertionError(kind)
    return a, flags, groups, masks


SCENES = ["uniform", "clustered", "sparse", "huge", "many_big", "infinite", "plane", "flat", "touching", "points",
          "coincident", "mixed"]


@functools.cache
def scene_and_pairs(kind):
    """A 300-body scene of ``kind`` and its reference pairs (computed once for all methods)."""
    a, flags, groups, masks = scene(kind, 300, seed=sum(map(ord, kind)))
    return a, flags, groups, masks, reference_pairs(a, flags, groups, masks)


@pytest.mark.parametrize("kind", SCENES)
@pytest.mark.parametrize("method", ALL)
def test_scene_pairs_match_brute_force(method, kind):
    a, flags, groups, masks, expected = scene_and_pairs(kind)
    got = BroadPhase(method, capacity=8).pairs(a, flags, groups, masks)
    np.testing.assert_array_equal(got, expected)


coords = st.integers(-6, 6).map(lambda v: v * 0.5)


@st.composite
def random_scenes(draw):
    n = draw(st.integers(0, 40))
    lo = np.array(draw(st.lists(st.tuples(coords, coords, coords), min_size=n, max_size=n)),
                  dtype=float).reshape(n, 3)
    size = np.array(draw(st.lists(st.tuples(*[st.sampled_from([0.0, 0.5, 1.0, 2.5, 12.0])] * 3),
                                  min_size=n, max_size=n)), dtype=float).reshape(n, 3)
    flags = np.array(draw(st.lists(st.sampled_from([ALIVE, ALIVE, ALIVE | STATIC, 0]),
                                   min_size=n, max_size=n)), dtype=np.int64)
    groups = np.array(draw(st.lists(st.sampled_from([1, 2, 3, -1]), min_size=n, max_size=n)),
                      dtype=np.int64)
    masks = np.array(draw(st.lists(st.sampled_from([1, 2, 3, -1, 0]), min_size=n, max_size=n)),
                     dtype=np.int64)
    return np.hstack([lo, lo + size]), flags, groups, masks


@settings(max_examples=250, deadline=None)
@given(random_scenes())
def test_random_scenes_match_brute_force_for_every_method(sc):
    a, flags, groups, masks = sc
    expected = reference_pairs(a, flags, groups, masks)
    for method in ALL:
        got = BroadPhase(method, capacity=4).pairs(a, flags, groups, masks)
        np.testing.assert_array_equal(got, expected, err_msg=method)


@pytest.mark.parametrize("method", ALL)
def test_repeated_updates_with_motion_births_and_deaths(method):
    """Incremental state (SAP order, BVH leaves) stays exact over many coherent and incoherent steps."""
    rng = np.random.default_rng(7)
    n = 400
    centres = rng.uniform(0, 12, (n, 3))
    half = rng.uniform(0.1, 0.5, (n, 3))
    velocity = rng.normal(0, 0.05, (n, 3))
    flags = np.full(n, ALIVE, np.int64)
    flags[::17] |= STATIC
    bp = BroadPhase(method, capacity=64)
    for step in range(40):
        live_n = 250 + 4 * step if step < 30 else n
        if step == 20:
            centres[rng.integers(0, n, 30)] = rng.uniform(0, 12, (30, 3))   # teleports
        if step % 7 == 3:
            flags[rng.integers(0, n, 10)] &= ~ALIVE                           # deaths
        if step % 7 == 5:
            flags[rng.integers(0, n, 10)] |= ALIVE                            # rebirths
        if step == 35:
            live_n = 200                                                      # fewer slots
        dynamic = (flags & STATIC) == 0
        centres[dynamic] += velocity[dynamic]
        a = boxes(centres, half)[:live_n]
        f = flags[:live_n]
        g = np.full(live_n, -1, np.int64)
        expected = reference_pairs(a, f, g, g)
        np.testing.assert_array_equal(bp.pairs(a, f), expected, err_msg=f"step {step}")
        np.testing.assert_array_equal(bp.pairs(a, f), expected, err_msg=f"repeat {step}")


@pytest.mark.parametrize("method", ALL)
def test_sorted_coherent_motion_with_reordering(method):
    """Boxes on a line that pass each other: the SAP order must be repaired by the insertion sort."""
    n = 120
    x = np.linspace(0, 60, n)
    v = np.where(np.arange(n) % 2 == 0, 0.3, -0.3)
    bp = BroadPhase(method)
    flags = np.full(n, ALIVE, np.int64)
    g = np.full(n, -1, np.int64)
    for _ in range(60):
        x += v
        c = np.stack([x, np.zeros(n), np.zeros(n)], axis=1)
        a = boxes(c, np.full((n, 3), 0.25))
        np.testing.assert_array_equal(bp.pairs(a), reference_pairs(a, flags, g, g))


@pytest.mark.parametrize("method", ALL)
def test_small_pair_buffer_returns_full_count_and_a_prefix(method):
    a, flags, groups, masks = scene("uniform", 200, seed=3)
    expected = reference_pairs(a, flags, groups, masks)
    assert len(expected) > 20
    code = METHODS[method]
    state_f, state_i = make_state(code, 200)
    out = np.full((20, 2), -7, np.int64)
    for _ in range(2):
        count = find_pairs(code, a, flags, groups, masks, 200, state_f, state_i, out)
        assert count == len(expected)
        np.testing.assert_array_equal(out, expected[:20])


@pytest.mark.parametrize("method", ALL)
def test_only_first_n_bodies_are_considered(method):
    a, flags, groups, masks = scene("uniform", 300, seed=5)
    code = METHODS[method]
    state_f, state_i = make_state(code, 300)
    out = np.empty((5000, 2), np.int64)
    count = find_pairs(code, a, flags, groups, masks, 150, state_f, state_i, out)
    np.testing.assert_array_equal(out[:count], reference_pairs(a[:150], flags[:150], groups[:150],
                                                               masks[:150]))


@pytest.mark.parametrize("kind", ["uniform", "clustered", "huge", "mixed", "touching"])
@pytest.mark.parametrize("method", ALL)
def test_box_and_ray_queries_match_brute_force(method, kind):
    a, flags, _, _ = scene(kind, 250, seed=11)
    rng = np.random.default_rng(12)
    bp = BroadPhase(method)
    bp.update(a, flags)
    lo_all, hi_all = a[:, :3].min(axis=0), a[:, 3:].max(axis=0)
    for _ in range(25):
        p, q = rng.uniform(lo_all - 1, hi_all + 1, (2, 3))
        lo, hi = np.minimum(p, q), np.maximum(p, q)
        np.testing.assert_array_equal(bp.query_aabb(a, lo, hi, flags),
                                      reference_box_query(a, flags, lo, hi))
        origin = rng.uniform(lo_all - 2, hi_all + 2)
        direction = rng.normal(size=3)
        if rng.random() < 0.3:
            direction[rng.integers(0, 3)] = 0.0
        max_distance = math.inf if rng.random() < 0.5 else float(rng.uniform(0, 20))
        np.testing.assert_array_equal(bp.query_ray(a, origin, direction, max_distance, flags),
                                      reference_ray_query(a, flags, origin, direction,
                                                          max_distance))


def test_ray_hits_are_sorted_by_entry_distance_then_index():
    a = np.array([[4, -1, -1, 5, 1, 1], [1, -1, -1, 2, 1, 1], [1, -2, -2, 3, 2, 2],
                  [-1, -1, -1, 1, 1, 1], [7, 5, 5, 8, 6, 6]], float)
    for method in ALL:
        hits = BroadPhase(method).query_ray(a, (0, 0, 0), (2, 0, 0))
        np.testing.assert_array_equal(hits, [3, 1, 2, 0], err_msg=method)
        np.testing.assert_array_equal(BroadPhase(method).query_ray(a, (0, 0, 0), (1, 0, 0), 1.5),
                                      [3, 1, 2], err_msg=method)


@pytest.mark.parametrize("method", ALL)
def test_empty_and_single_body_worlds(method):
    bp = BroadPhase(method)
    assert bp.pairs(np.zeros((0, 6))).shape == (0, 2)
    assert bp.pairs(np.array([[0, 0, 0, 1, 1, 1.0]])).shape == (0, 2)
    assert bp.query_aabb(np.zeros((0, 6)), (0, 0, 0), (1, 1, 1)).shape == (0,)
    dead = np.array([0, 0], np.int64)
    two = np.array([[0, 0, 0, 1, 1, 1.0], [0, 0, 0, 1, 1, 1.0]])
    assert bp.pairs(two, dead).shape == (0, 2)
    np.testing.assert_array_equal(bp.pairs(two), [[0, 1]])


def test_state_sizes_and_fresh_state():
    for method, code in METHODS.items():
        state_f, state_i = make_state(code, 100)
        nf, ni = state_sizes(code, 100)
        assert len(state_f) >= nf and len(state_i) >= ni
        assert state_i[2] == -1, method


def test_state_of_another_method_is_rejected():
    a, flags, groups, masks = scene("uniform", 10, seed=1)
    state_f, state_i = make_state(METHODS["bvh"], 10)
    with pytest.raises(ValueError, match="another method"):
        find_pairs(METHODS["sap"], a, flags, groups, masks, 10, state_f, state_i,
                   np.empty((10, 2), np.int64))
    with pytest.raises(ValueError, match="capacity"):
        find_pairs(METHODS["bvh"], a, flags, groups, masks, 11, state_f, state_i,
                   np.empty((10, 2), np.int64))


def test_bad_input_is_rejected_with_named_arguments():
    with pytest.raises(ValueError, match="method"):
        BroadPhase("quadtree")
    with pytest.raises(ValueError, match="capacity"):
        BroadPhase("sap", capacity=0)
    with pytest.raises(ValueError, match="method"):
        make_state(9, 10)
    bp = BroadPhase("bvh")
    good = np.array([[0, 0, 0, 1, 1, 1.0]])
    with pytest.raises(ValueError, match="aabbs"):
        bp.pairs(np.zeros((3, 5)))
    with pytest.raises(ValueError, match="aabbs"):
        bp.pairs(np.array([[0, 0, 0, np.nan, 1, 1]]))
    with pytest.raises(ValueError, match="aabbs"):
        bp.pairs(np.array([[2, 0, 0, 1, 1, 1.0]]))
    with pytest.raises(ValueError, match="flags"):
        bp.pairs(good, flags=[1, 1])
    with pytest.raises(TypeError, match="groups"):
        bp.pairs(good, groups=[0.5])
    with pytest.raises(ValueError, match="box_min"):
        bp.query_aabb(good, (0, 0, np.inf), (1, 1, 1))
    with pytest.raises(ValueError, match="box_min"):
        bp.query_aabb(good, (2, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match="direction"):
        bp.query_ray(good, (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="max_distance"):
        bp.query_ray(good, (0, 0, 0), (1, 0, 0), -1.0)


def test_find_pairs_is_callable_from_another_kernel():
    from marbellous._numba.jit import njit

    @njit
    def step_like(method, aabbs, flags, groups, masks, n, state_f, state_i, out):
        return find_pairs(method, aabbs, flags, groups, masks, n, state_f, state_i, out)

    a, flags, groups, masks = scene("mixed", 120, seed=2)
    expected = reference_pairs(a, flags, groups, masks)
    for code in METHODS.values():
        state_f, state_i = make_state(code, 120)
        out = np.empty((1000, 2), np.int64)
        count = step_like(code, a, flags, groups, masks, 120, state_f, state_i, out)
        np.testing.assert_array_equal(out[:count], expected)


@pytest.mark.parametrize("scale", [1.0, 0.1, 1e-3, 37.3])
@pytest.mark.parametrize("method", ALL)
def test_boxes_touching_at_corners_along_a_diagonal(method, scale):
    """Oblique principal direction (BSP planes along (1, 1, 1)): boxes that touch in a single corner
    point must still be reported, despite rounding in the plane projections."""
    edges = np.arange(201, dtype=float)[:, None] * scale
    a = np.hstack([np.repeat(edges[:-1], 3, axis=1), np.repeat(edges[1:], 3, axis=1)])
    rng = np.random.default_rng(int(scale * 1000))
    a = a[rng.permutation(len(a))]
    flags = np.full(len(a), ALIVE, np.int64)
    g = np.full(len(a), -1, np.int64)
    expected = reference_pairs(a, flags, g, g)
    assert len(expected) == 199
    np.testing.assert_array_equal(BroadPhase(method).pairs(a), expected)
    lo = a[:, :3].min(axis=0) + 50 * scale
    np.testing.assert_array_equal(BroadPhase(method).query_aabb(a, lo, lo),
                                  reference_box_query(a, flags, lo, lo))


def node_area_sum(bp):
    """Summed surface area of the current node boxes of a rebuilt-tree state (m^2)."""
    from marbellous.collision.broadphase._common import HEADER_F
    from marbellous.collision.broadphase.static_tree import I_N_NODES, tree_max_nodes

    m = tree_max_nodes(bp.capacity)
    bounds = bp.state_f[HEADER_F:HEADER_F + 6 * m].reshape(m, 6)[:bp.state_i[I_N_NODES]]
    d = bounds[:, 3:] - bounds[:, :3]
    return float(np.sum(2 * (d[:, 0] * d[:, 1] + d[:, 1] * d[:, 2] + d[:, 2] * d[:, 0])))


@pytest.mark.parametrize("method", ["octree", "kdtree"])
def test_trees_refit_for_small_motion_and_rebuild_when_it_spoils_them(method):
    from marbellous.collision.broadphase.static_tree import F_BUILT_AREA

    a, flags, groups, masks = scene("uniform", 500, seed=4)
    rng = np.random.default_rng(5)
    bp = BroadPhase(method, capacity=500)
    bp.pairs(a, flags, groups, masks)
    built = bp.state_f[F_BUILT_AREA]
    assert node_area_sum(bp) == pytest.approx(built)
    step = rng.normal(0, 0.02, (500, 3))
    nudged = a + np.hstack([step, step])
    np.testing.assert_array_equal(bp.pairs(nudged, flags, groups, masks),
                                  reference_pairs(nudged, flags, groups, masks))
    assert bp.state_f[F_BUILT_AREA] == built                 # partition kept,
    assert node_area_sum(bp) != pytest.approx(built)         # boxes refitted
    shuffled = a[rng.permutation(500)]                       # every body jumps elsewhere
    np.testing.assert_array_equal(bp.pairs(shuffled, flags, groups, masks),
                                  reference_pairs(shuffled, flags, groups, masks))
    assert node_area_sum(bp) == pytest.approx(bp.state_f[F_BUILT_AREA])   # rebuilt


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 2**40), max_size=3000), st.integers(0, 3))
def test_sort_keys_matches_numpy_sort(values, runs):
    """The radix sort of pair keys equals NumPy's sort, on random keys and on partly ordered runs."""
    from marbellous.collision.broadphase._common import sort_keys
    keys = np.array(values, dtype=np.int64)
    if runs and keys.size:
        keys = np.concatenate([np.sort(part) for part in np.array_split(keys, runs + 1)])
    np.testing.assert_array_equal(sort_keys(keys), np.sort(keys))
