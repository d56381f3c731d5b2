"""The y-axis billboard (the lecture's exercise 8, 2.3) and the camera matrices."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from marbellous.render.billboard import billboard_y_matrix
from marbellous.render.transforms import look_at, perspective, quat_to_matrix

coord = st.floats(-100, 100, allow_nan=False)
vec3 = st.tuples(coord, coord, coord).map(np.array)


@settings(max_examples=400)
@given(pos=vec3, cam=vec3)
def test_billboard_keeps_y_and_faces_camera(pos, cam):
    r = billboard_y_matrix(pos, cam)
    assert np.allclose(r.T @ r, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)
    assert np.array_equal(r[:, 1], [0.0, 1.0, 0.0])
    to_cam = cam - pos
    to_cam[1] = 0.0
    if np.linalg.norm(to_cam) > 1e-6:
        # the quad's normal (local z) points horizontally at the camera
        assert np.allclose(r[:, 2], to_cam / np.linalg.norm(to_cam), atol=1e-9)
        # and the camera sees the quad's local x axis pointing to its right
        view = look_at(cam, pos) if np.linalg.norm(np.cross(pos - cam, [0, 1, 0])) > 1e-6 else None
        if view is not None:
            assert (view[:3, :3] @ r[:, 0])[0] > 0


def test_billboard_straight_above_faces_z():
    r = billboard_y_matrix((1.0, 0.0, 2.0), (1.0, 10.0, 2.0))
    assert np.allclose(r, np.eye(3))


@settings(max_examples=200)
@given(eye=vec3, target=vec3)
def test_look_at_puts_target_on_the_negative_z_axis(eye, target):
    if np.linalg.norm(target - eye) < 1e-3:
        return
    v = look_at(eye, target)
    assert np.allclose(v[:3, :3] @ v[:3, :3].T, np.eye(3), atol=1e-9)
    t = v @ np.append(target, 1.0)
    d = np.linalg.norm(target - eye)
    assert np.allclose(t[:3], [0.0, 0.0, -d], atol=1e-9 * (1 + d))


def test_perspective_maps_near_and_far_to_clip_depths():
    p = perspective(1.0, 16 / 9, 0.1, 100.0)
    for z, ndc in ((-0.1, -1.0), (-100.0, 1.0)):
        c = p @ np.array([0.0, 0.0, z, 1.0])
        assert c[2] / c[3] == pytest.approx(ndc)


@settings(max_examples=200)
@given(q=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_quaternion_matrix_rotates_like_the_quaternion(q):
    q = np.array(q) / np.linalg.norm(q)
    r = quat_to_matrix(q)
    v = np.array([0.3, -1.2, 0.7])
    w, u = q[0], q[1:]
    # v' = v + 2 w (u x v) + 2 u x (u x v)
    expect = v + 2 * w * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))
    assert np.allclose(r @ v, expect, atol=1e-12)
