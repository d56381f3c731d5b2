"""The step context (pipeline/context.py): it always holds the world's current arrays, and growing a buffer
in the middle of a run changes nothing but memory."""
import numpy as np
import pytest
from numba import njit

import marbellous as mb
from marbellous._numba.jit import borrow
from marbellous.pipeline.context import TABLE_FIELDS, context_at, pack_context
from marbellous.state import layout as L

TABLE_NAMES = [name for name, _ in TABLE_FIELDS]


@njit
def _addresses(t):
    """Data addresses of the context's tables, in the order of TABLE_NAMES (a slow, test-only reader)."""
    return np.array([t.bf.ctypes.data, t.bi.ctypes.data, t.sf.ctypes.data, t.si.ctypes.data, t.kf.ctypes.data,
                     t.ki.ctypes.data, t.ws.ctypes.data, t.geom_f.ctypes.data, t.geom_i.ctypes.data,
                     t.aabbs.ctypes.data, t.bp_f.ctypes.data, t.bp_i.ctypes.data, t.pairs.ctypes.data,
                     t.raw_f.ctypes.data, t.raw_i.ctypes.data, t.cf.ctypes.data, t.ci.ctypes.data,
                     t.pcf.ctypes.data, t.pci.ctypes.data, t.params_f.ctypes.data, t.params_i.ctypes.data,
                     t.stats.ctypes.data, t.nb, t.nk], dtype=np.int64)


@njit
def _addresses_at(address):
    """``_addresses`` of the context at ``address``, as the state's step entry reads it."""
    return _addresses(context_at(address))


def _tables(st):
    """The state's tables in the order of TABLE_NAMES (the contact tables by their roles)."""
    roles = {"cf": st.contact_table_f(False), "ci": st.contact_table_i(False), "pcf": st.cache_f,
             "pci": st.cache_i}
    return [roles[name] if name in roles else getattr(st, name) for name in TABLE_NAMES]


def _assert_in_sync(w):
    """The context the last step ran on holds exactly the state's arrays and counts, and the address the
    state passes to the step is that context's."""
    st = w._state
    got = _addresses(st.context)
    want = [t.ctypes.data for t in _tables(st)] + [st.bodies.end, st.constraints.end]
    assert list(got) == want
    assert list(_addresses_at(st.addresses[0])) == want


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
        w._state.grow_contacts(buffers)
        w._state.pairs = np.zeros((buffers, 2), dtype=np.int64)
        w._state.invalidate()
    return w


def test_context_follows_every_replacement_of_a_table():
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
    assert w._state.stats[L.STAT_CONTACTS] > 64


def test_growing_buffers_mid_run_changes_no_bit():
    """A world whose pair and contact buffers start at 64 rows and grow during the run moves exactly as one
    given room for everything from the start."""
    small, roomy = _pile(40), _pile(40, buffers=4096)
    for _ in range(90):
        small.step(1 / 60)
        roomy.step(1 / 60)
    s, r = small._state, roomy._state
    assert s.cache_f.shape[0] > 64                 # it did grow (from 64 rows), and reran a step
    n = s.bodies.end
    assert np.array_equal(s.bf[:n], r.bf[:n])
    assert s.n_cached == r.n_cached > 64
    assert np.array_equal(s.cache_f[:s.n_cached], r.cache_f[:r.n_cached])


def test_contacts_are_those_of_the_last_step_after_each_swap():
    w = _pile(8)
    for _ in range(30):
        w.step(1 / 60)
        assert len(w.contacts()) == w._state.stats[L.STAT_CONTACTS] == w._state.n_cached


def test_pack_context_refuses_a_table_of_the_wrong_kind():
    w = _pile(2)
    w.step(1 / 60)
    st = w._state
    args = _tables(st) + [st.bodies.end, st.constraints.end]
    bad = list(args)
    bad[TABLE_NAMES.index("bf")] = np.asfortranarray(st.bf)
    with pytest.raises(TypeError, match="bf must be a C-contiguous float64"):
        pack_context(*bad)
    bad = list(args)
    bad[TABLE_NAMES.index("ci")] = st.contact_table_i(False).astype(np.int32)
    with pytest.raises(TypeError, match="ci must be"):
        pack_context(*bad)


def test_both_contact_tables_keep_one_capacity_through_restore():
    """The tables swap roles every step, so the step's scratch is sized for either: a snapshot taken while
    they were small, restored into a world whose tables grew, leaves them at one capacity."""
    w = _pile(4)
    w.step(1 / 60)
    snap = w.snapshot()                      # 64-row tables
    for k in range(60):
        w.add_body(mb.Sphere(0.2), position=(5.0 + 0.3 * k, 0.2, 0.0))
    w.step(1 / 60)
    assert w._state.cache_f.shape[0] > 64
    for _ in range(3):
        w.restore(snap)
        st = w._state
        assert st.contact_table_f(False).shape[0] == st.cache_f.shape[0] == st.raw_f.shape[0]
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
