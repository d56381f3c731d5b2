"""The step's record of the tables (pipeline/tables.py): it always holds the world's current arrays, and
growing a buffer in the middle of a run changes nothing but memory."""
import numpy as np
import pytest
from numba import njit

import marbellous as mb
from marbellous._numba.jit import borrow
from marbellous.pipeline import step as S
from marbellous.pipeline.tables import TABLE_FIELDS, pack_tables, record_at

TABLE_NAMES = [name for name, _ in TABLE_FIELDS]


@njit
def _addresses(t):
    """Data addresses of the record's tables, in the order of TABLE_NAMES (a slow, test-only reader)."""
    return np.array([t.bf.ctypes.data, t.bi.ctypes.data, t.sf.ctypes.data, t.si.ctypes.data, t.kf.ctypes.data,
                     t.ki.ctypes.data, t.ws.ctypes.data, t.geom_f.ctypes.data, t.geom_i.ctypes.data,
                     t.aabbs.ctypes.data, t.bp_f.ctypes.data, t.bp_i.ctypes.data, t.pairs.ctypes.data,
                     t.raw_f.ctypes.data, t.raw_i.ctypes.data, t.cf.ctypes.data, t.ci.ctypes.data,
                     t.pcf.ctypes.data, t.pci.ctypes.data, t.params_f.ctypes.data, t.params_i.ctypes.data,
                     t.stats.ctypes.data, t.nb, t.nk], dtype=np.int64)


@njit
def _addresses_at(address):
    """``_addresses`` of the record at ``address``, as the World's step entry reads it."""
    return _addresses(record_at(address))


def _assert_in_sync(w):
    """The record the last step ran on holds exactly the world's arrays and counts, and the address the
    World passes to the step is that record's."""
    got = _addresses(w._tables)
    want = [getattr(w, "_" + name).ctypes.data for name in TABLE_NAMES] + [w._nb, w._nk]
    assert list(got) == want
    assert list(_addresses_at(w._step_argument)) == want


@njit
def _borrowed_view(a):
    b = borrow(a)
    b[1] = 7.0
    return b.shape[0], b.strides[0], b.ctypes.data, b[:, 2].sum()


def test_a_borrowed_array_is_the_same_array():
    a = np.arange(12.0).reshape(4, 3)
    n, stride, data, column = _borrowed_view(a)
    assert (n, stride, data, column) == (4, 24, a.ctypes.data, 2.0 + 7.0 + 8.0 + 11.0)
    assert np.array_equal(a[1], [7.0, 7.0, 7.0])


def _pile(n, buffers=None):
    w = mb.World()
    w.add_static(mb.Plane())
    for k in range(n):
        # layers of 4 x 2 spheres 1 cm apart (speculative contacts with their neighbours), slightly off
        w.add_body(mb.Sphere(0.25), position=(0.51 * (k % 4) + 0.01 * (k // 8), 0.26 + 0.51 * (k // 8),
                                              0.51 * ((k // 4) % 2)))
    if buffers is not None:
        w._grow_contacts(buffers)
        w._pairs = np.zeros((buffers, 2), dtype=np.int64)
        w._tables = None
    return w


def test_record_follows_every_replacement_of_a_table():
    w = _pile(3)
    w.step(1 / 60)
    _assert_in_sync(w)
    b = w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(3.0, 1.0, 0.0))    # tables grow
    w.step(1 / 60)
    _assert_in_sync(w)
    w.add_rod(b, None, anchor_b=(3.0, 2.0, 0.0))                          # constraint tables grow
    w.step(1 / 60)
    _assert_in_sync(w)
    snap = w.snapshot()
    w.broadphase = "bvh"                                                 # new broad-phase state
    w.step(1 / 60)
    _assert_in_sync(w)
    w.restore(snap)                                                      # every table replaced
    w.step(1 / 60)
    _assert_in_sync(w)
    for k in range(40):                                                  # contact buffers grow
        w.add_body(mb.Sphere(0.2), position=(5.0 + 0.3 * k, 0.2, 0.0))
    w.step(1 / 60)
    _assert_in_sync(w)
    assert w._stats[S.S_CONTACTS] > 64


def test_growing_buffers_mid_run_changes_no_bit():
    """A world whose pair and contact buffers start at 64 rows and grow during the run moves exactly as one
    given room for everything from the start."""
    small, roomy = _pile(40), _pile(40, buffers=4096)
    for _ in range(90):
        small.step(1 / 60)
        roomy.step(1 / 60)
    assert small._pcf.shape[0] > 64                # it did grow (from 64 rows), and reran a step
    n = small._nb
    assert np.array_equal(small._bf[:n], roomy._bf[:n])
    assert small._npc == roomy._npc > 64
    assert np.array_equal(small._pcf[:small._npc], roomy._pcf[:roomy._npc])


def test_contacts_are_those_of_the_last_step_after_each_swap():
    w = _pile(8)
    for _ in range(30):
        w.step(1 / 60)
        assert len(w.contacts()) == w._stats[S.S_CONTACTS] == w._npc


def test_pack_tables_refuses_a_table_of_the_wrong_kind():
    w = _pile(2)
    w.step(1 / 60)
    args = [getattr(w, "_" + name) for name in TABLE_NAMES] + [w._nb, w._nk]
    bad = list(args)
    bad[TABLE_NAMES.index("bf")] = np.asfortranarray(w._bf)
    with pytest.raises(TypeError, match="bf must be a C-contiguous float64"):
        pack_tables(*bad)
    bad = list(args)
    bad[TABLE_NAMES.index("ci")] = w._ci.astype(np.int32)
    with pytest.raises(TypeError, match="ci must be"):
        pack_tables(*bad)


def test_both_contact_tables_keep_one_capacity_through_restore():
    """The tables swap roles every step, so the step's scratch is sized for either: a snapshot taken while
    they were small, restored into a world whose tables grew, leaves them at one capacity."""
    w = _pile(4)
    w.step(1 / 60)
    snap = w.snapshot()                      # 64-row tables
    for k in range(60):
        w.add_body(mb.Sphere(0.2), position=(5.0 + 0.3 * k, 0.2, 0.0))
    w.step(1 / 60)
    assert w._pcf.shape[0] > 64
    for _ in range(3):
        w.restore(snap)
        assert w._cf.shape[0] == w._pcf.shape[0] == w._raw_f.shape[0]
        w.step(1 / 60)
        _assert_in_sync(w)


def test_a_refused_restore_changes_nothing():
    w = _pile(3)
    snap = w.snapshot()
    w.remove(w.bodies[-1])
    w.step(1 / 60)
    before = w.state_hash()
    with pytest.raises(ValueError, match="removed since"):
        w.restore(snap)
    assert w.state_hash() == before
    w.step(1 / 60)
    _assert_in_sync(w)
