"""The narrow phase of the step against a slow reference: every shape pair of every candidate body pair
posed one at a time and handed to the public pair tests from Python.

``pipeline.collide.narrow_phase`` poses each shape once per call into scratch tables, sends a sphere
against a sphere, capsule, box or plane straight to its pair test with the poses in registers, and
writes those rows itself; everything else goes through ``collide_pair``.  None of that may change a
contact: the reference below is the plain loop (pose both shapes, order by type code, call the pair
test by name, negate the normals of a swapped pair), and the two must agree bit for bit, row by row,
in the same order, with the same bodies, shapes, features and sensor flags.
"""
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

import marbellous as mb
from marbellous.collision import shape_types as st
from marbellous.collision.mesh.heightfield_collide import collide_convex_heightfield
from marbellous.collision.mesh.mesh_collide import collide_convex_mesh
from marbellous.collision.pairs.box_box import collide_box_box
from marbellous.collision.pairs.capsule_box import collide_capsule_box
from marbellous.collision.pairs.capsule_capsule import collide_capsule_capsule
from marbellous.collision.pairs.plane_pairs import collide_box_plane, collide_capsule_plane, collide_sphere_plane
from marbellous.collision.pairs.sphere_box import collide_sphere_box
from marbellous.collision.pairs.sphere_capsule import collide_sphere_capsule
from marbellous.collision.pairs.sphere_sphere import collide_sphere_sphere
from marbellous.pipeline.collide import (narrow_phase_all, narrow_phase_ground, narrow_phase_meshes,
                                         narrow_phase_spheres, pose_tables, shape_pose, update_aabbs)
from marbellous.dynamics.soft import SOFT_DEPTH
from marbellous.state.world_state import scene_coverage
from marbellous.state import layout as L

DT = 1.0 / 60.0
SPECULATIVE = 0.02

#: the public pair test of each canonical (lower code first) pair of primitives
PRIMITIVE_TESTS = {
    (st.SPHERE, st.SPHERE): collide_sphere_sphere, (st.SPHERE, st.CAPSULE): collide_sphere_capsule,
    (st.SPHERE, st.BOX): collide_sphere_box, (st.SPHERE, st.PLANE): collide_sphere_plane,
    (st.CAPSULE, st.CAPSULE): collide_capsule_capsule, (st.CAPSULE, st.BOX): collide_capsule_box,
    (st.CAPSULE, st.PLANE): collide_capsule_plane, (st.BOX, st.BOX): collide_box_box,
    (st.BOX, st.PLANE): collide_box_plane,
}


def reference_pair(w, sa, a, sb, b, prediction, out_f, out_i, n):
    """Contacts of shape rows ``sa`` (body ``a``) and ``sb`` (body ``b``), normals from a to b, by the
    public pair test of the canonical order."""
    ta, tb = int(w._state.si[sa, L.S_TYPE]), int(w._state.si[sb, L.S_TYPE])
    if ta > tb:
        m = reference_pair(w, sb, b, sa, a, prediction, out_f, out_i, n)
        out_f[n:m, 3:6] *= -1.0
        return m
    pa, ra, pb, rb = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    shape_pose(w._state.bf, w._state.sf, sa, a, pa, ra)
    shape_pose(w._state.bf, w._state.sf, sb, b, pb, rb)
    par_a = w._state.sf[sa, L.S_PARAMS:L.S_PARAMS + st.N_SHAPE_PARAMS].copy()
    par_b = w._state.sf[sb, L.S_PARAMS:L.S_PARAMS + st.N_SHAPE_PARAMS].copy()
    if tb <= st.PLANE:
        if ta == st.PLANE:
            return n
        return PRIMITIVE_TESTS[(ta, tb)](pa, ra, par_a, pb, rb, par_b, prediction, out_f, out_i, n)
    if ta >= st.HEIGHTFIELD or ta == st.PLANE:
        return n
    test = collide_convex_heightfield if tb == st.HEIGHTFIELD else collide_convex_mesh
    return test(ta, pa, ra, par_a, pb, rb, par_b, w._state.geom_f, w._state.geom_i, int(w._state.si[sb, L.S_OFF_F]),
                int(w._state.si[sb, L.S_OFF_I]), prediction, out_f, out_i, n)


def moving(w, i):
    f = int(w._state.bi[i, L.FLAGS])
    return bool(f & L.F_ALIVE) and not f & L.F_STATIC and not f & L.F_SLEEPING


def reference_narrow_phase(w, pairs, sweep):
    """``(raw_f, raw_i, ci)`` of every contact, the plain way (see the module docstring)."""
    out_f, out_i = np.zeros((4096, 7)), np.zeros(4096, np.int64)
    rows = []
    n = 0
    for a, b in pairs:
        fa, fb = int(w._state.bi[a, L.FLAGS]), int(w._state.bi[b, L.FLAGS])
        sensor = bool((fa | fb) & L.F_SENSOR)
        if not (moving(w, a) or moving(w, b)):
            if not sensor or (fa & L.F_STATIC and fb & L.F_STATIC):
                continue
        prediction = 0.0 if sensor else SPECULATIVE + sweep[a] + sweep[b]
        bi = w._state.bi
        for sa in range(bi[a, L.SHAPE_START], bi[a, L.SHAPE_START] + bi[a, L.SHAPE_COUNT]):
            for sb in range(bi[b, L.SHAPE_START], bi[b, L.SHAPE_START] + bi[b, L.SHAPE_COUNT]):
                m = reference_pair(w, sa, a, sb, b, prediction, out_f, out_i, n)
                rows += [(a, b, sa, sb, out_i[c], L.CP_SENSOR if sensor else 0) for c in range(n, m)]
                n = m
    return out_f[:n].copy(), out_i[:n].copy(), np.array(rows, dtype=np.int64).reshape(n, 6)


def bump_mesh(rng, half=3.0, cells=6):
    """A bumpy square mesh of ``2 cells^2`` triangles around the origin at y = 0."""
    xs = np.linspace(-half, half, cells + 1)
    verts = np.array([[x, 0.2 * rng.standard_normal(), z] for x in xs for z in xs])
    tris = []
    for i in range(cells):
        for j in range(cells):
            p = i * (cells + 1) + j
            tris += [[p, p + 1, p + cells + 2], [p, p + cells + 2, p + cells + 1]]
    return mb.TriangleMesh(verts, np.array(tris), accel=["brute", "grid2d", "bvh"][rng.integers(3)])


def random_quat(rng):
    q = rng.standard_normal(4)
    return q / np.linalg.norm(q)


def random_shape(rng):
    kind = rng.integers(4)
    if kind == 0:
        return mb.Sphere(rng.uniform(0.15, 0.5))
    if kind == 1:
        return mb.Box(rng.uniform(0.1, 0.5, 3))
    if kind == 2:
        return mb.Capsule(rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.4))
    # a compound: an off-centre sphere, a turned box and a capsule
    return [(mb.Sphere(rng.uniform(0.1, 0.3)), rng.uniform(-0.4, 0.4, 3)),
            (mb.Box(rng.uniform(0.1, 0.3, 3)), rng.uniform(-0.4, 0.4, 3), random_quat(rng)),
            (mb.Capsule(0.1, 0.2), rng.uniform(-0.4, 0.4, 3), random_quat(rng))]


def mixed_world(seed, bodies=24, moving=None, ground=True, heightfield=True):
    """Bodies of every kind crowded over a plane, a static box, a bumpy mesh and a height field, some
    of them moving, asleep or sensors: many overlaps and near misses.  ``moving``: a function of the
    random generator giving each moving body's shape (every kind by default); without ``ground``, no
    mesh and no height field; without ``heightfield``, no height field."""
    rng = np.random.default_rng(seed)
    moving = random_shape if moving is None else moving
    w = mb.World()
    w.add_static(mb.Plane((0.0, 1.0, 0.0), -0.3))
    if ground:
        w.add_static(bump_mesh(rng))
        heights = 0.2 * rng.standard_normal((5, 5))
        if heightfield:
            w.add_static(mb.HeightField(heights, spacing=(0.75, 0.75), origin=(-1.5, -0.1, -1.5)))
    w.add_static(mb.Box((0.5, 0.3, 0.5)), position=rng.uniform(-1.0, 1.0, 3), orientation=random_quat(rng))
    w.add_static(mb.Sphere(0.4), position=rng.uniform(-1.0, 1.0, 3), sensor=True)
    for k in range(bodies):
        body = w.add_body(moving(rng), position=rng.uniform(-1.5, 1.5, 3) * (1.0, 0.4, 1.0) + (0, 0.3, 0),
                          orientation=random_quat(rng), velocity=rng.normal(0.0, 1.0, 3),
                          angular_velocity=rng.normal(0.0, 2.0, 3), sensor=k % 11 == 5)
        if k % 7 == 3:
            w._state.bi[body._index, L.FLAGS] |= L.F_SLEEPING
    if ground:
        # a second mesh after the bodies: its pairs have the mesh second (the first mesh's have it first)
        w.add_static(bump_mesh(rng), position=(0.0, 0.3, 0.0))
    return w


def collide_input(w):
    """Sweeps from ``update_aabbs`` and every body pair ``a < b`` (far ones too: rejections are tested)."""
    nb = w._state.bodies.end
    aabbs = np.zeros((nb, 6))
    sweep = np.empty(nb)
    pos_t, rot_t, _, q = pose_tables(w._state.sf.shape[0])
    st = w._state
    update_aabbs(st.bf, st.bi, st.sf, st.si, nb, aabbs, sweep, DT, 9.81, SPECULATIVE, pos_t, rot_t, q)
    pairs = np.array([(a, b) for a in range(nb) for b in range(a + 1, nb)], dtype=np.int64)
    return pairs, sweep


def run_narrow_phase(w, pairs, sweep, capacity, narrow_phase=narrow_phase_all):
    raw_f = np.zeros((capacity, 7))
    raw_i = np.zeros(capacity, np.int64)
    ci = np.zeros((capacity, L.CI_COLS), np.int64)
    st = w._state
    cf = np.zeros((capacity, L.CF_COLS))
    n = narrow_phase(st.bf, st.bi, st.sf, st.si, st.geom_f, st.geom_i, pairs, len(pairs), sweep, SPECULATIVE,
                     raw_f, raw_i, ci, cf, cf[:0], ci[:0], 0, *pose_tables(w._state.sf.shape[0]))
    return n, raw_f, raw_i, ci


@settings(max_examples=25, deadline=None)
@given(hs.integers(0, 2 ** 31))
def test_narrow_phase_matches_the_plain_loop_bit_for_bit(seed):
    w = mixed_world(seed)
    pairs, sweep = collide_input(w)
    ref_f, ref_i, ref_ci = reference_narrow_phase(w, pairs, sweep)
    n, raw_f, raw_i, ci = run_narrow_phase(w, pairs, sweep, 4096)
    assert n == len(ref_f)
    assert np.array_equal(raw_f[:n], ref_f)
    assert np.array_equal(raw_i[:n], ref_i)
    assert np.array_equal(ci[:n, :6], ref_ci)


def _sphere(rng):
    return mb.Sphere(float(rng.uniform(0.1, 0.35)))


@settings(max_examples=15, deadline=None)
@given(hs.integers(0, 2 ** 31), hs.sampled_from([st.COVER_SPHERES, st.COVER_MESHES, st.COVER_GROUND]))
def test_the_narrow_phase_of_a_coverage_matches_the_plain_loop_in_its_worlds(seed, expected):
    # moving spheres over a plane, a box and a sphere sensor, meshes (from COVER_MESHES) and a height field
    # (COVER_GROUND): the narrow phase compiled for the world's coverage, without the pair tests it cannot
    # meet, finds every contact the full one does
    w = mixed_world(seed, moving=_sphere, ground=expected != st.COVER_SPHERES, heightfield=expected == st.COVER_GROUND)
    coverage = scene_coverage(w._state.bi, w._state.si, w._state.bodies.end)
    assert coverage == expected
    pairs, sweep = collide_input(w)
    ref_f, ref_i, ref_ci = reference_narrow_phase(w, pairs, sweep)
    kernel = {st.COVER_SPHERES: narrow_phase_spheres, st.COVER_MESHES: narrow_phase_meshes,
              st.COVER_GROUND: narrow_phase_ground}[expected]
    n, raw_f, raw_i, ci = run_narrow_phase(w, pairs, sweep, 4096, kernel)
    assert n == len(ref_f) > 0
    assert np.array_equal(raw_f[:n], ref_f)
    assert np.array_equal(raw_i[:n], ref_i)
    assert np.array_equal(ci[:n, :6], ref_ci)


def test_a_world_has_the_coverage_of_its_moving_shapes():
    w = mb.World()
    coverage = lambda: scene_coverage(w._state.bi, w._state.si, w._state.bodies.end)   # noqa: E731
    assert coverage() == st.COVER_SPHERES
    w.add_static(mb.Box((1.0, 1.0, 1.0)))               # a static box meets only moving spheres
    w.add_body(mb.Sphere(0.5), position=(0.0, 3.0, 0.0))
    assert coverage() == st.COVER_SPHERES
    w.add_static(mb.TriangleMesh([(0, 0, 0), (1, 0, 0), (0, 0, 1)], [(0, 2, 1)]), position=(5.0, 0.0, 0.0))
    assert coverage() == st.COVER_MESHES
    field = w.add_static(mb.HeightField(np.zeros((3, 3)), spacing=(1.0, 1.0)), position=(0.0, -5.0, 0.0))
    assert coverage() == st.COVER_GROUND                # a height field
    w.remove(field)
    assert coverage() == st.COVER_MESHES
    hull = w.add_static(mb.ConvexHull([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]),
                        position=(-5.0, 0.0, 0.0))
    assert coverage() == st.COVER_GROUND                # and a static hull
    w.remove(hull)
    capsule = w.add_body(mb.Capsule(0.2, 0.5), position=(0.0, 6.0, 0.0))
    assert coverage() == st.COVER_ALL
    w.remove(capsule)
    assert coverage() == st.COVER_MESHES
    w.add_body([mb.Sphere(0.2), (mb.Box((0.1, 0.1, 0.1)), (0.5, 0.0, 0.0))], position=(3.0, 6.0, 0.0))
    assert coverage() == st.COVER_ALL


def test_a_sphere_world_that_gains_a_moving_box_steps_with_every_pair_test():
    # the step compiled for spheres has no box pair test; the next step after adding a box uses the step
    # of the new coverage, so the box lands on the plane as in a world that had it from the start
    def run(box_first):
        w = mb.World()
        w.add_static(mb.Plane())
        if box_first:
            box = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0))
        w.add_body(mb.Sphere(0.5), position=(3.0, 0.5, 0.0))
        w.step(DT)
        if not box_first:
            box = w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0))
        for _ in range(60):
            w.step(DT)
        return box.position[1]
    assert run(False) == pytest.approx(0.5, abs=1e-3)
    assert run(True) == pytest.approx(0.5, abs=1e-3)


def test_a_sphere_lands_on_a_static_hull():
    # moving spheres only, but the hull's pair test is needed: it lands on the hull's top face (y = 0.5)
    w = mb.World()
    w.add_static(mb.ConvexHull([(x, y, z) for x in (-1, 1) for y in (-0.5, 0.5) for z in (-1, 1)]))
    ball = w.add_body(mb.Sphere(0.25), position=(0.0, 2.0, 0.0))
    for _ in range(120):
        w.step(1 / 60)
    assert ball.position[1] == pytest.approx(0.75, abs=SOFT_DEPTH)


def test_a_sphere_world_compiles_no_box_or_mesh_pair_test():
    code = ("import marbellous as mb\n"
            "from marbellous.collision.pairs import box_box, capsule_box\n"
            "from marbellous.collision.mesh import mesh_collide, heightfield_collide\n"
            "w = mb.World(); w.add_static(mb.Plane()); w.add_static(mb.Box((1.0, 1.0, 1.0)))\n"
            "w.add_body(mb.Sphere(0.5), position=(0.0, 3.0, 0.0), velocity=(0.0, -50.0, 0.0))\n"
            "for _ in range(30): w.step(1 / 60)\n"
            "print(len(box_box.collide_box_box.signatures) + len(capsule_box.collide_capsule_box.signatures)\n"
            "      + len(mesh_collide.collide_sphere_mesh.signatures)\n"
            "      + len(mesh_collide.collide_convex_mesh.signatures)\n"
            "      + len(heightfield_collide.collide_convex_heightfield.signatures))\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "0"


def test_mixed_world_exercises_every_kind_of_pair():
    """The random scenes above really contain the pairs the fast paths and the general path serve."""
    kinds = set()
    ordered = set()
    for seed in range(6):
        w = mixed_world(seed)
        pairs, sweep = collide_input(w)
        n, raw_f, raw_i, ci = run_narrow_phase(w, pairs, sweep, 4096)
        for c in range(n):
            ta = int(w._state.si[ci[c, L.C_SHAPE_A], L.S_TYPE])
            tb = int(w._state.si[ci[c, L.C_SHAPE_B], L.S_TYPE])
            kinds.add((min(ta, tb), max(ta, tb)))
            ordered.add((ta, tb))
    # the sphere-mesh fast path in both orders (the mesh's body first, and second)
    assert (st.MESH, st.SPHERE) in ordered and (st.SPHERE, st.MESH) in ordered
    for pair in [(st.SPHERE, st.SPHERE), (st.SPHERE, st.BOX), (st.SPHERE, st.CAPSULE), (st.SPHERE, st.PLANE),
                 (st.SPHERE, st.MESH), (st.BOX, st.BOX), (st.BOX, st.PLANE), (st.CAPSULE, st.BOX),
                 (st.BOX, st.MESH)]:
        assert pair in kinds


@settings(max_examples=10, deadline=None)
@given(hs.integers(0, 2 ** 31), hs.integers(0, 40))
def test_a_full_buffer_keeps_its_rows_and_still_counts(seed, capacity):
    """With too small a buffer the count is the same and the rows that fit are the same rows."""
    w = mixed_world(seed)
    pairs, sweep = collide_input(w)
    n_big, big_f, big_i, big_ci = run_narrow_phase(w, pairs, sweep, 4096)
    n, raw_f, raw_i, ci = run_narrow_phase(w, pairs, sweep, capacity)
    assert n == n_big
    k = min(n, capacity)
    assert np.array_equal(raw_f[:k], big_f[:k])
    assert np.array_equal(raw_i[:k], big_i[:k])
    assert np.array_equal(ci[:k], big_ci[:k])


def test_sphere_pile_contacts_match_the_plain_loop():
    """A settled pile (spheres on a floor between walls: the fast paths' own scene)."""
    from marbellous.scenes import sphere_pile

    w, _ = sphere_pile(count=120)
    for _ in range(40):
        w.step(DT)
    pairs, sweep = collide_input(w)
    ref_f, ref_i, ref_ci = reference_narrow_phase(w, pairs, sweep)
    n, raw_f, raw_i, ci = run_narrow_phase(w, pairs, sweep, 4096)
    assert n == len(ref_f) > 100
    assert np.array_equal(raw_f[:n], ref_f)
    assert np.array_equal(ci[:n, :6], ref_ci)
    assert np.allclose(np.linalg.norm(raw_f[:n, 3:6], axis=1), 1.0, atol=1e-12)
