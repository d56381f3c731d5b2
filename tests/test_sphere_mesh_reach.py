"""The sampled reach of a sphere and one triangle of a mesh or a height field
(``collision/toi/sphere_mesh_reach.py``) against the time-of-impact search it spares: whenever it says the sphere
reaches the triangle of one of its speculative contacts within the horizon, the search over the same motion
does not end in a MISS (which would have dropped the contact)."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import marbellous as mb
from marbellous.collision import shape_types as types
from marbellous.collision.mesh import mesh_layout as ml
from marbellous.collision.mesh.heightfield_collide import cell_triangle
from marbellous.collision.pairs.dispatch import collide_pair_covering
from marbellous.collision.toi.conservative_advancement import MISS, time_of_impact
from marbellous.collision.toi.sphere_mesh_reach import sphere_reaches_triangle
from marbellous.pipeline.impacts import HIT_TOLERANCE, TOUCH_TOLERANCE
from marbellous.state.layout import S_OFF_F, S_OFF_I, S_PARAMS, SHAPE_START

RADIUS = 0.3
#: the horizon of a speculative contact at 60 Hz with 4 sub-steps: the step and one sub-step beyond it (s)
HORIZON = 1.0 / 60.0 + 1.0 / 240.0
ROTATION = Rotation.from_euler("xyz", [0.3, -0.7, 0.2])
OFFSET = np.array([0.4, -0.2, 0.1])
IDENTITY = (1.0, 0.0, 0.0, 0.0)


def _bumpy_world(kind):
    """A static 5 x 5 grid of random heights over [-1, 1]^2 (convex and concave seams, edges and vertices to
    meet), as a triangle mesh or a height field (``kind``), turned and moved off the origin, and a sphere body:
    ``(world, ground_shape_row, sphere_shape_row)``."""
    rng = np.random.default_rng(7)
    heights = 0.15 * rng.standard_normal((5, 5))
    if kind == "mesh":
        xs, zs = np.meshgrid(np.linspace(-1.0, 1.0, 5), np.linspace(-1.0, 1.0, 5), indexing="ij")
        v = np.column_stack([xs.ravel(), heights.ravel(), zs.ravel()])
        tris = [[5 * i + j, 5 * i + j + 1, 5 * i + j + 6] for i in range(4) for j in range(4)]
        tris += [[5 * i + j, 5 * i + j + 6, 5 * i + j + 5] for i in range(4) for j in range(4)]
        shape = mb.TriangleMesh(v, tris)
    else:
        shape = mb.HeightField(heights, spacing=(0.5, 0.5), origin=(-1.0, 0.0, -1.0))
    w = mb.World()
    w.add_static(shape, position=OFFSET, orientation=ROTATION.as_quat(scalar_first=True))
    w.add_body(mb.Sphere(RADIUS), position=(0.0, 5.0, 0.0))
    state = w._state
    return w, state.bi[0, SHAPE_START], state.bi[1, SHAPE_START]


WORLDS = {kind: _bumpy_world(kind) for kind in ("mesh", "field")}
_speed = st.floats(-4.0, 4.0)


def _triangle(kind, state, ground, t):
    """Corners and unit normal of triangle ``t`` of the ground shape, in its frame (numpy arrays)."""
    sf, si = state.sf, state.si
    if kind == "mesh":
        corners = ml.triangle(state.geom_f, state.geom_i, int(si[ground, S_OFF_F]), int(si[ground, S_OFF_I]), t)
    else:
        i, j = divmod(t // 2, 4)
        corners = cell_triangle(sf[ground, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS], state.geom_f,
                                int(si[ground, S_OFF_F]), i, j, t % 2)
    return [np.array(p) for p in corners]


@pytest.mark.parametrize("kind", ["mesh", "field"])
@settings(max_examples=300, deadline=None)
@given(triangle=st.integers(0, 31), u=st.floats(0.0, 1.0), v=st.floats(0.0, 1.0), gap=st.floats(-0.01, 0.05),
       vx=_speed, vy=_speed, vz=_speed, push=st.floats(0.0, 30.0))
def test_a_triangle_the_samples_reach_is_reached_by_the_search(kind, triangle, u, v, gap, vx, vy, vz, push):
    # the sphere starts over a point of one triangle (barycentric u, v folded into it), its surface ``gap`` (m)
    # from that triangle's plane
    w, ground, sphere = WORLDS[kind]
    state = w._state
    sf, si, geom_f, geom_i = state.sf, state.si, state.geom_f, state.geom_i
    ground_type = types.MESH if kind == "mesh" else types.HEIGHTFIELD
    ground_params = sf[ground, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS]
    sphere_params = sf[sphere, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS]
    off_f, off_i = int(si[ground, S_OFF_F]), int(si[ground, S_OFF_I])
    m = ROTATION.as_matrix()
    a, b, c, normal = _triangle(kind, state, ground, triangle)
    if u + v > 1.0:
        u, v = 1.0 - u, 1.0 - v
    x0 = m @ (a + u * (b - a) + v * (c - a) + (RADIUS + gap) * normal) + OFFSET
    motion = (tuple(x0), (vx, vy, vz), (0.0, -9.81 - push, 0.0), IDENTITY, (0.0, 0.0, 0.0))
    still = (tuple(OFFSET), (0.0,) * 3, (0.0,) * 3, tuple(ROTATION.as_quat(scalar_first=True)), (0.0,) * 3)
    # the speculative contacts at the start, as the pair test reports them within the motion's reach: the stage
    # asks about those only (a triangle that touches is skipped by the search; one not reported, such as the far
    # side of a seam whose edge the Voronoi filter leaves to its neighbour, is no contact yet)
    reach = math.hypot(vx, vy, vz) * HORIZON + 0.5 * (9.81 + push) * HORIZON ** 2 + HIT_TOLERANCE
    out_f, out_i = np.empty((64, 7)), np.empty(64, np.int64)
    n = collide_pair_covering(types.COVER_GROUND, types.SPHERE, x0, np.eye(3), sphere_params, ground_type, OFFSET, m,
                              ground_params, geom_f, geom_i, 0, 0, off_f, off_i, reach, out_f, out_i, 0)
    speculative = [int(out_i[k]) // 16 for k in range(min(n, 64)) if -out_f[k, 6] > TOUCH_TOLERANCE]
    reached = [t for t in speculative if sphere_reaches_triangle(motion, RADIUS, tuple(OFFSET), tuple(m.ravel()),
                                                                  kind == "field", ground_params, geom_f, geom_i,
                                                                  off_f, off_i, t, HORIZON)]
    if not reached:
        return
    outcome, _ = time_of_impact(
        types.COVER_GROUND, types.SPHERE, sphere_params, 0, 0, motion, (0.0, 0.0, 0.0), IDENTITY, 0.0, ground_type,
        ground_params, off_f, off_i, still, (0.0, 0.0, 0.0), IDENTITY, 0.0, geom_f, geom_i, HORIZON, TOUCH_TOLERANCE,
        HIT_TOLERANCE, 0.1, np.empty((64, 7)), np.empty(64, np.int64), np.empty((2, 3)), np.empty((2, 3, 3)),
        np.empty(4), np.zeros(65, np.int64))
    assert outcome != MISS, reached


def test_the_samples_find_a_sphere_rolling_onto_the_next_triangle_and_not_one_leaving_it():
    # a flat quad of two triangles, the sphere resting on the first and rolling at 3 m/s towards the second
    # (its centre 2 cm from their seam: 5 cm in the horizon), then away from it
    w = mb.World()
    v = np.array([[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]])
    w.add_static(mb.TriangleMesh(v, [[0, 2, 1], [0, 3, 2]]))
    w.add_body(mb.Sphere(RADIUS), position=(0.0, 5.0, 0.0))
    state = w._state
    mesh = state.bi[0, SHAPE_START]
    off_f, off_i = int(state.si[mesh, S_OFF_F]), int(state.si[mesh, S_OFF_I])
    params = state.sf[mesh, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS]
    identity = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    # the seam is the diagonal x = z; the first triangle (0, 2, 1) lies where x > z
    d = 0.02 / math.sqrt(2.0)
    start = (d, RADIUS, -d)
    towards = (-3.0 / math.sqrt(2.0), 0.0, 3.0 / math.sqrt(2.0))
    for velocity, reaches in ((towards, True), (tuple(-c for c in towards), False)):
        motion = (start, velocity, (0.0, -9.81, 0.0), IDENTITY, (0.0, 0.0, 0.0))
        # (sinking under gravity from its resting height, the sphere touches the second triangle only once its
        # centre is over it: the edge between them is the first triangle's, the Voronoi filter says)
        assert sphere_reaches_triangle(motion, RADIUS, (0.0, 0.0, 0.0), identity, False, params, state.geom_f,
                                       state.geom_i, off_f, off_i, 1, HORIZON) is reaches
