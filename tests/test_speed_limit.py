"""The speed limit: a body's speeds stay within the bound the API accepts, whatever a diverging solve makes of
them, and a speed that is not finite never reaches the poses."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import marbellous as mb
from marbellous.dynamics.integrators import SPEED_LIMIT, limit_speeds
from marbellous.state import layout as L

component = st.floats(min_value=-1e300, max_value=1e300, allow_nan=False)
vector = st.tuples(component, component, component)


def body_row(v, w):
    bf = np.zeros((1, L.BF_COLS))
    bf[0, L.VEL:L.VEL + 3] = v
    bf[0, L.OMEGA:L.OMEGA + 3] = w
    return bf


@given(vector, vector)
def test_a_speed_above_the_limit_is_scaled_to_it_along_its_own_direction(v, w):
    bf = body_row(v, w)
    limit_speeds.py_func(bf, 0)
    for col, before in ((L.VEL, np.array(v)), (L.OMEGA, np.array(w))):
        after = bf[0, col:col + 3]
        speed = math.hypot(*before)
        if speed <= SPEED_LIMIT:
            assert np.array_equal(after, before)          # untouched, bit for bit
        else:
            # |v min(1, v_max / |v|)| = v_max, to the rounding of the three products and the square root
            assert abs(math.hypot(*after) - SPEED_LIMIT) <= 4 * np.finfo(float).eps * SPEED_LIMIT
            assert np.allclose(after / SPEED_LIMIT, before / speed, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_speed_that_is_not_finite_becomes_zero(bad):
    bf = body_row((1.0, bad, 2.0), (bad, 0.0, 0.0))
    limit_speeds.py_func(bf, 0)
    assert np.array_equal(bf[0, L.VEL:L.VEL + 3], np.zeros(3))
    assert np.array_equal(bf[0, L.OMEGA:L.OMEGA + 3], np.zeros(3))


@pytest.mark.parametrize("integrator", ["explicit_euler", "semi_implicit_euler", "verlet", "rk4"])
@pytest.mark.parametrize("column, bad", [(L.VEL, math.nan), (L.VEL, 1e15), (L.OMEGA, math.inf), (L.OMEGA, 1e15)])
def test_a_diverged_body_keeps_a_finite_pose_and_its_speeds_within_the_limit(integrator, column, bad):
    """A body whose speeds a diverging solve made huge or NaN (written here straight into its row: the API
    refuses such speeds) moves on with finite poses and speeds within the limit, and so does its neighbour."""
    w = mb.World(integrator=integrator)
    w.add_static(mb.Plane())
    box = w.add_body(mb.Box((0.5, 0.2, 0.3)), position=(0.0, 0.3, 0.0))
    ball = w.add_body(mb.Sphere(0.4), position=(1.5, 0.5, 0.0))
    w.step(1 / 60)
    box._row()[column:column + 3] = (bad, -bad, 0.5 * bad)
    for _ in range(3):
        w.step(1 / 60)
        for b in (box, ball):
            for value in (b.position, b.orientation, b.velocity, b.angular_velocity):
                assert np.all(np.isfinite(value))
            assert np.linalg.norm(b.velocity) <= SPEED_LIMIT * (1 + 1e-12)
            assert np.linalg.norm(b.angular_velocity) <= SPEED_LIMIT * (1 + 1e-12)
