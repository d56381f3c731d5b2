"""The world's state: slots reused after removal, revisions that make stale handles raise, geometry and
contacts freed with their body, and snapshots that restore only what this world could be in."""
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as hs

import marbellous as mb
from marbellous.scenes.terrain import terrain_mesh
from marbellous.state import layout as L
from marbellous.state.slots import Slots


# --- slots ---------------------------------------------------------------------------------------------
def test_slots_hand_out_the_lowest_free_rows_and_count_revisions():
    s = Slots()
    assert [s.allocate() for _ in range(4)] == [0, 1, 2, 3]
    s.free(1)
    s.free(2)
    assert s.end == 4 and s.count == 2
    assert s.revision[1] == s.revision[2] == 1 and s.revision[0] == 0
    assert s.allocate() == 1                 # the lowest free row
    assert s.allocate(2) == 4                # no run of two free rows below the end: past it
    s.free(4, 2)
    assert s.end == 4                        # free rows at the top lower the end
    s.free(3)
    assert s.end == 2                        # rows 2 and 3 are free and on top
    assert s.allocate(3) == 2                # a run that starts in the free top rows


@given(hs.lists(hs.tuples(hs.booleans(), hs.integers(1, 3)), max_size=60))
def test_slots_never_hand_out_a_row_in_use(ops):
    """Against a plain set of used rows: every allocation is a run of rows not in use, the lowest such run
    (or the first past the end), and the end is one past the highest used row."""
    s = Slots()
    used = set()
    blocks = []
    for alloc, n in ops:
        if alloc or not blocks:
            first = s.allocate(n)
            rows = set(range(first, first + n))
            assert not rows & used
            expected = next(r for r in range(max(used, default=-1) + 2)
                            if not set(range(r, r + n)) & used)
            assert first == expected
            used |= rows
            blocks.append((first, n))
        else:
            first, k = blocks.pop(len(blocks) // 2)
            s.free(first, k)
            used -= set(range(first, first + k))
        assert s.end == (max(used) + 1 if used else 0)
        assert s.count == len(used)
        assert all(s.in_use(r) == (r in used) for r in range(s.end + 2))


# --- bodies and handles ------------------------------------------------------------------------------------
def _two_live(cycles):
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.5), position=(0.0, 2.0, 0.0))
    for k in range(cycles):
        b = w.add_body(mb.Sphere(0.1), position=(3.0, 1.0 + 0.01 * (k % 7), 0.0))
        if k % 3 == 0:
            w.step(1 / 60)
        w.remove(b)
    return w, ball


def test_rows_are_reused_after_twenty_thousand_add_remove_cycles():
    w, ball = _two_live(20_000)
    st = w._state
    assert st.bodies.end == 2 and st.shapes.end == 2 and st.constraints.end == 0
    assert st.bf.shape[0] <= 8                    # the tables never grew
    assert st.bodies.revision[2] == 20_000        # the spawn row was freed 20,000 times
    snapshot = pickle.dumps(w.snapshot())
    fresh = pickle.dumps(mb.World().snapshot())
    assert len(snapshot) < len(fresh) + 4096       # a snapshot holds what is alive, not what was made
    assert w.bodies == [w.bodies[0], ball]


def test_a_stale_handle_raises_on_every_use_and_touches_nothing():
    w = mb.World()
    old = w.add_body(mb.Sphere(0.2), position=(0.0, 1.0, 0.0))
    w.remove(old)
    new = w.add_body(mb.Box((0.1, 0.1, 0.1)), position=(5.0, 1.0, 0.0))
    assert new._index == old._index                  # the row was reused
    before = w.state_hash()
    uses = [lambda: old.position, lambda: old.velocity, lambda: setattr(old, "position", (1, 2, 3)),
            lambda: old.apply_force((0, 10, 0)), lambda: old.apply_impulse((1, 0, 0)), lambda: old.mass,
            lambda: old.is_static, lambda: old.inertia, lambda: w.add_rod(old, new), lambda: w.remove(old)]
    for use in uses:
        with pytest.raises(ValueError, match="removed"):
            use()
    assert w.state_hash() == before
    assert repr(old) == "<Body removed>"
    np.testing.assert_array_equal(new.position, (5.0, 1.0, 0.0))


def test_a_stale_constraint_handle_raises():
    w = mb.World()
    a = w.add_body(mb.Sphere(0.2), position=(0.0, 1.0, 0.0))
    rod = w.add_rod(a, None, anchor_b=(0.0, 2.0, 0.0))
    w.remove(rod)
    spring = w.add_spring(a, None, rest_length=1.0, stiffness=10.0, anchor_b=(0.0, 2.0, 0.0))
    assert spring._index == rod._index
    with pytest.raises(ValueError, match="removed"):
        rod.force
    assert w.constraints == [spring]


def test_churn_before_building_changes_no_bit_of_the_run():
    """Rows freed before a scene is built are reused in the same order a fresh world would use, so the
    run is bit for bit the fresh world's."""
    def scene(w):
        w.add_static(mb.Plane())
        for k in range(6):
            w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.05 * k, 0.2 + 0.41 * k, 0.0))
        for _ in range(60):
            w.step(1 / 60)
        return w

    fresh = scene(mb.World())
    churned = mb.World()
    junk = [churned.add_body(mb.Sphere(0.1), position=(k, 5.0, 0.0)) for k in range(10)]
    churned.step(1 / 60)
    for b in junk:
        churned.remove(b)
    churned._state.ws[:] = 0.0          # (the clock ran one step: start it again for the comparison)
    scene(churned)
    assert churned.state_hash() == fresh.state_hash()


def test_removing_a_mesh_frees_its_geometry_and_the_other_mesh_still_holds():
    w = mb.World()
    first = w.add_static(terrain_mesh(cells=16, spacing=0.5), position=(0.0, 0.0, 0.0))
    second = w.add_static(terrain_mesh(cells=16, spacing=0.5), position=(20.0, 0.0, 0.0))
    size = w._state.geom_f.size
    w.remove(first)
    assert w._state.geom_f.size == size // 2
    ball = w.add_body(mb.Sphere(0.25), position=(20.0, 3.0, 0.0))
    for _ in range(120):
        w.step(1 / 60)
    hit = w.raycast((20.0, 10.0, 0.0), (0.0, -1.0, 0.0))
    assert hit is not None and hit.body is second
    # resting on the surface (within the contact tolerances), not fallen through
    assert abs(ball.position[1] - 0.25 - hit.point[1]) < 0.02


def test_contacts_right_after_a_removal_name_only_live_bodies():
    w = mb.World()
    w.add_static(mb.Plane())
    a = w.add_body(mb.Sphere(0.5), position=(0.0, 0.5, 0.0))
    b = w.add_body(mb.Sphere(0.5), position=(3.0, 0.5, 0.0))
    w.step(1 / 60)
    assert {c.body_b for c in w.contacts()} == {a, b}
    w.remove(a)
    assert [c.body_b for c in w.contacts()] == [b]


def test_bodies_resting_on_a_removed_body_wake_and_fall():
    w = mb.World()
    w.add_static(mb.Plane())
    base = w.add_body(mb.Box((1.0, 0.25, 1.0)), position=(0.0, 0.25, 0.0))
    top = w.add_body(mb.Box((0.25, 0.25, 0.25)), position=(0.0, 0.75, 0.0))
    for _ in range(240):
        w.step(1 / 60)
    assert top.is_sleeping
    w.remove(base)
    assert not top.is_sleeping
    for _ in range(60):
        w.step(1 / 60)
    assert top.position[1] == pytest.approx(0.25, abs=0.01)


def test_unknown_world_attributes_are_refused():
    w = mb.World()
    with pytest.raises(AttributeError):
        w.contact_hz = 1.0
    w.contact_hertz = 30.0
    assert w.contact_hertz == 30.0


# --- snapshots ------------------------------------------------------------------------------------------------
def _scene():
    w = mb.World()
    w.add_static(mb.Plane())
    a = w.add_body(mb.Sphere(0.3), position=(0.0, 0.3, 0.0), velocity=(1.0, 0.0, 0.0))
    b = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(1.0, 0.2, 0.0))
    w.add_rod(a, b)
    for _ in range(5):
        w.step(1 / 60)
    return w, a, b


def test_a_snapshot_after_a_removal_restores_without_the_removed_body():
    w, a, b = _scene()
    w.remove(b)
    snap = w.snapshot()
    h = w.state_hash()
    for _ in range(10):
        w.step(1 / 60)
    late = w.add_body(mb.Sphere(0.1), position=(4.0, 1.0, 0.0))
    w.restore(snap)
    assert w.state_hash() == h
    assert w.bodies == [w.bodies[0], a]
    assert w.constraints == []
    with pytest.raises(ValueError, match="removed"):
        late.position
    # the row the late body had is handed out again, and the late handle stays stale
    again = w.add_body(mb.Sphere(0.1), position=(4.0, 1.0, 0.0))
    assert again._index == late._index
    with pytest.raises(ValueError, match="removed"):
        late.position


def _edited(snap, name, edit):
    tables = {k: v.copy() for k, v in snap.tables.items()}
    tables[name] = edit(tables[name])
    return mb.Snapshot(tables, snap.accumulator)


def _set(index, value):
    def edit(t):
        t[index] = value
        return t
    return edit


EDITS = {
    "nan position": ("bf", _set((1, L.POS), np.nan)),
    "inf velocity": ("bf", _set((2, L.VEL), np.inf)),
    "float32 bodies": ("bf", lambda t: t.astype(np.float32)),
    "truncated bodies": ("bf", lambda t: t[:-1]),
    "non-unit quaternion": ("bf", _set((1, L.QUAT), 2.0)),
    "changed mass": ("bf", _set((1, L.INV_MASS), 5.0)),
    "shape index out of range": ("bi", _set((1, L.SHAPE_START), 10 ** 9)),
    "unknown flag": ("bi", _set((1, L.FLAGS), 1 << 40)),
    "dead body alive": ("bi", _set((1, L.FLAGS), 0)),
    "island out of range": ("bi", _set((1, L.ISLAND), 999)),
    "constraint to nowhere": ("ki", _set((0, L.K_BODY_B), 77)),
    "unknown constraint type": ("ki", _set((0, L.K_TYPE), 9)),
    "contact of a missing body": ("cache_i", _set((0, L.C_BODY_A), -5)),
    "contact of another's shape": ("cache_i", _set((0, L.C_SHAPE_B), 0)),
    "nan contact": ("cache_f", _set((0, L.C_LAMBDA_N), np.nan)),
    "changed shape": ("sf", _set((1, L.S_PARAMS), 9.0)),
    "free list past the end": ("body_slots", lambda t: np.array([3, 1, 7])),
    "clock is nan": ("ws", _set(L.W_TIME, np.nan)),
}


@pytest.mark.parametrize("case", sorted(EDITS))
def test_restore_refuses_an_edited_snapshot_and_changes_nothing(case):
    w, a, b = _scene()
    snap = w.snapshot()
    assert snap.tables["cache_i"].shape[0] > 0
    w.step(1 / 60)
    before = w.state_hash()
    name, edit = EDITS[case]
    bad = _edited(snap, name, edit)
    with pytest.raises(ValueError, match="snapshot"):
        w.restore(bad)
    assert w.state_hash() == before
    w.restore(snap)            # the untouched snapshot still restores
    w.step(1 / 60)


def test_restore_refuses_what_is_not_a_snapshot():
    w, _, _ = _scene()
    with pytest.raises(TypeError, match="snapshot"):
        w.restore({"bf": None})
    snap = w.snapshot()
    del snap.tables["ki"]
    with pytest.raises(ValueError, match="ki"):
        w.restore(snap)
