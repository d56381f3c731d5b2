"""The benchmark's axis mapping to z-up peers (bench/peers/axes.py) is one proper rotation, applied
alike to vectors and orientations."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as hst

from bench.peers.axes import R, from_peer, quat_to_peer, to_peer
from marbellous.math3d import quat_to_matrix_np

finite = hst.floats(-10.0, 10.0)


def test_y_up_becomes_z_up():
    assert np.allclose(to_peer([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0])
    assert np.allclose(R @ R.T, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)


@settings(max_examples=200, deadline=None)
@given(hst.tuples(finite, finite, finite))
def test_vectors_round_trip(v):
    assert np.allclose(from_peer(to_peer(v)), v)


@settings(max_examples=200, deadline=None)
@given(hst.tuples(finite, finite, finite, finite).filter(lambda q: np.linalg.norm(q) > 1e-3))
def test_orientations_turn_with_the_axes(q):
    q = np.array(q) / np.linalg.norm(q)
    assert np.allclose(quat_to_matrix_np(quat_to_peer(q)), R @ quat_to_matrix_np(q), atol=1e-12)
