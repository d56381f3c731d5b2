"""Wide floats (marbellous/_numba/wide.py): every operation gives, lane by lane and bit for bit, what the same
scalar operation gives (NumPy here), compiled and as plain Python; gathers and scatters move the same
values as NumPy's fancy indexing, with the last lane winning where two lanes name one row."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from marbellous._numba.wide import (LANES, abs_w, gather_w, load_w, max_w, min_w, scatter_w, splat_w, sqrt_w, store_w,
                                    where_gt)

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False, width=64)
lanes = st.lists(finite, min_size=LANES, max_size=LANES).map(np.array)


def _expression(a, b, out):
    """Every operation once, with wide and scalar operands mixed (out: 2 blocks of lanes)."""
    x, y = load_w(a, 0), load_w(b, 0)
    z = x * y + 2.5 - x / (abs_w(y) + 1.0)
    z = max_w(z, splat_w(0.5)) + min_w(x, y) * -abs_w(x) + sqrt_w(abs_w(y))
    store_w(out, 0, where_gt(x, y, z, 3.0 - z))
    store_w(out, LANES, 1.0 / (2.0 + abs_w(x)) - y)


_compiled_expression = njit(_expression)


def _numpy_expression(x, y):
    z = x * y + 2.5 - x / (np.abs(y) + 1.0)
    z = np.where(0.5 > z, 0.5, z) + np.where(y < x, y, x) * -np.abs(x) + np.sqrt(np.abs(y))  # Python's max, min
    return np.concatenate([np.where(x > y, z, 3.0 - z), 1.0 / (2.0 + np.abs(x)) - y])


@settings(max_examples=200)
@given(lanes, lanes)
def test_operations_round_as_scalar_ones(a, b):
    compiled, plain = np.zeros(2 * LANES), np.zeros(2 * LANES)
    _compiled_expression(a, b, compiled)
    _expression(a, b, plain)
    expected = _numpy_expression(a, b)
    assert np.array_equal(compiled, expected)
    assert np.array_equal(plain, expected)


def _move(table, rows, velocity, masses):
    """Gather columns 3..8 (6) and 0..9 (10) of the lanes' rows; scatter the 6 to columns 13..18 and two
    of the 10 to columns 0 and 1 (blocks of lanes in ``velocity`` and ``masses``)."""
    u = gather_w(table, rows, 2, 3, 6)
    m = gather_w(table, rows, 2, 0, 10)
    for k in range(6):
        store_w(velocity, k * LANES, u[k])
    for k in range(10):
        store_w(masses, k * LANES, m[k])
    scatter_w(table, rows, 2, 13, u)
    scatter_w(table, rows, 2, 0, (m[9], m[8]))


_compiled_move = njit(_move)


@settings(max_examples=100)
@given(st.lists(st.integers(0, 11), min_size=LANES + 3, max_size=LANES + 3), st.integers(0, 2 ** 32 - 1))
def test_gather_and_scatter_move_rows_like_fancy_indexing(row_list, seed):
    table = np.random.default_rng(seed).standard_normal((12, 24))
    rows = np.array(row_list, dtype=np.int64)
    picked = rows[2:2 + LANES]
    expected = table.copy()
    for row in picked:       # lanes in order: a row named twice keeps the last lane's
        expected[row, 13:19] = table[row, 3:9]
    for row in picked:
        expected[row, 0], expected[row, 1] = table[row, 9], table[row, 8]
    for move in (_compiled_move, _move):
        t = table.copy()
        velocity, masses = np.zeros(6 * LANES), np.zeros(10 * LANES)
        move(t, rows, velocity, masses)
        assert np.array_equal(velocity.reshape(6, LANES), table[picked, 3:9].T)
        assert np.array_equal(masses.reshape(10, LANES), table[picked, 0:10].T)
        assert np.array_equal(t, expected)
