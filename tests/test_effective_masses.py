"""A contact's three effective masses at once (``solver_bodies.effective_masses``) are, bit for bit, those of
``effective_mass_along`` along its normal and tangents, for bodies whose inverse inertia is a multiple of the
identity (the written-out path), bodies whose is not, and bodies that cannot move; and they are the closed form
``1 / (1/m_a + 1/m_b + (r_a x d) I_a^-1 (r_a x d) + (r_b x d) I_b^-1 (r_b x d))``."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from marbellous.dynamics.contact_basis import contact_basis
from marbellous.dynamics.solver_bodies import effective_mass_along, effective_masses
from marbellous.state.layout import SB_COLS, SB_INV_I, SB_INV_MASS, SB_ISO


@njit
def _both(sb, ra, rb, n):
    t1, t2 = contact_basis(n)
    a, b = 0, 1
    at_once = effective_masses(sb, a, ra, b, rb, n, t1, t2)
    one_by_one = (effective_mass_along(sb, a, ra, b, rb, n), effective_mass_along(sb, a, ra, b, rb, t1),
                  effective_mass_along(sb, a, ra, b, rb, t2))
    return at_once, one_by_one, (n, t1, t2)


def _body(sb, i, kind, mass, inertia, rotation):
    """Row ``i``: ``kind`` 0 cannot move, 1 isotropic (I = inertia E), 2 a rotated diagonal inertia."""
    if kind == 0:
        return
    sb[i, SB_INV_MASS] = 1.0 / mass
    if kind == 1:
        sb[i, SB_ISO] = 1.0 / inertia[0]
        sb[i, SB_INV_I:SB_INV_I + 9] = (np.eye(3) / inertia[0]).ravel()
    else:
        sb[i, SB_ISO] = -1.0
        sb[i, SB_INV_I:SB_INV_I + 9] = (rotation @ np.diag(1.0 / np.asarray(inertia)) @ rotation.T).ravel()


vectors = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3)
positive = st.floats(0.01, 100.0)


@settings(max_examples=300, deadline=None)
@given(kinds=st.tuples(st.integers(0, 2), st.integers(0, 2)), masses=st.tuples(positive, positive),
       inertia_a=st.lists(positive, min_size=3, max_size=3), inertia_b=st.lists(positive, min_size=3, max_size=3),
       ra=vectors, rb=vectors, normal=vectors, seed=st.integers(0, 2**32 - 1))
def test_the_three_masses_at_once_are_each_direction_s_bit_for_bit(kinds, masses, inertia_a, inertia_b, ra, rb, normal,
                                                                   seed):
    n = np.asarray(normal)
    if np.linalg.norm(n) < 1e-3:
        n = np.array([0.0, 1.0, 0.0])
    n = n / np.linalg.norm(n)
    rotations = [np.linalg.qr(np.random.default_rng(seed + k).normal(size=(3, 3)))[0] for k in range(2)]
    sb = np.zeros((2, SB_COLS))
    for i, (kind, mass, inertia) in enumerate(zip(kinds, masses, (inertia_a, inertia_b))):
        _body(sb, i, kind, mass, inertia, rotations[i])
    at_once, one_by_one, directions = _both(sb, tuple(ra), tuple(rb), tuple(n))
    assert at_once == one_by_one
    for m, d in zip(at_once, directions):
        d = np.asarray(d)
        k = size = 0.0
        for i, r in enumerate((ra, rb)):
            c = np.cross(r, d)
            inverse_inertia = sb[i, SB_INV_I:SB_INV_I + 9].reshape(3, 3)
            k += sb[i, SB_INV_MASS] + c @ inverse_inertia @ c
            size += sb[i, SB_INV_MASS] + np.abs(c) @ np.abs(inverse_inertia) @ np.abs(c)
        if k == 0.0:            # nothing can move
            assert m == 0.0
            continue
        expected = 1.0 / k
        # the sums of products round to within a few units of 2^-53 of the sum of their magnitudes (Higham's
        # bound for a dot product), and 1 / k keeps k's relative error
        assert abs(m - expected) <= 16 * 2.0**-53 * size / k * expected
