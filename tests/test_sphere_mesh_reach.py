"""The sampled reach of a sphere and a mesh triangle (``collision/toi/sphere_mesh_reach.py``) against the
time-of-impact search it spares: whenever it says a triangle the sphere does not touch yet is reached within the
horizon, the search over the same motion does not end in a MISS (it would have dropped the contact)."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import marbellous as mb
from marbellous.collision import shape_types as types
from marbellous.collision.mesh import mesh_layout as ml
from marbellous.collision.mesh.mesh_collide import collide_sphere_mesh
from marbellous.collision.toi.conservative_advancement import MISS, time_of_impact
from marbellous.collision.toi.sphere_mesh_reach import sphere_reaches_triangle
from marbellous.pipeline.impacts import HIT_TOLERANCE, TOUCH_TOLERANCE
from marbellous.state.layout import QUAT, S_OFF_F, S_OFF_I, S_PARAMS, SHAPE_START

RADIUS = 0.3
#: the horizon of a speculative contact at 60 Hz with 4 sub-steps: the step and one sub-step beyond it (s)
HORIZON = 1.0 / 60.0 + 1.0 / 240.0
ROTATION = Rotation.from_euler("xyz", [0.3, -0.7, 0.2])
OFFSET = np.array([0.4, -0.2, 0.1])


def _bumpy_world():
    """A static 5 x 5 grid mesh with random heights (convex and concave seams, edges and vertices to meet),
    turned and moved off the origin, and a sphere body: ``(world, mesh_shape_row, sphere_shape_row)``."""
    rng = np.random.default_rng(7)
    xs, zs = np.meshgrid(np.linspace(-1.0, 1.0, 5), np.linspace(-1.0, 1.0, 5))
    v = np.column_stack([xs.ravel(), 0.15 * rng.standard_normal(25), zs.ravel()])
    tris = [[5 * j + i, 5 * j + 5 + i, 5 * j + i + 1] for j in range(4) for i in range(4)]
    tris += [[5 * j + i + 1, 5 * j + 5 + i, 5 * j + 6 + i] for j in range(4) for i in range(4)]
    w = mb.World()
    w.add_static(mb.TriangleMesh(v, tris), position=OFFSET, orientation=ROTATION.as_quat(scalar_first=True))
    w.add_body(mb.Sphere(RADIUS), position=(0.0, 5.0, 0.0))
    state = w._state
    return w, state.bi[0, SHAPE_START], state.bi[1, SHAPE_START]


WORLD, MESH, SPHERE = _bumpy_world()
_speed = st.floats(-4.0, 4.0)


@settings(max_examples=300, deadline=None)
@given(triangle=st.integers(0, 31), u=st.floats(0.0, 1.0), v=st.floats(0.0, 1.0), gap=st.floats(-0.01, 0.05),
       vx=_speed, vy=_speed, vz=_speed, push=st.floats(0.0, 30.0))
def test_a_triangle_the_samples_reach_is_reached_by_the_search(triangle, u, v, gap, vx, vy, vz, push):
    # the sphere starts over a point of one triangle (barycentric u, v folded into it), its surface ``gap`` (m)
    # from that triangle's plane
    state = WORLD._state
    sf, si, geom_f, geom_i = state.sf, state.si, state.geom_f, state.geom_i
    m = ROTATION.as_matrix()
    off_f, off_i = int(si[MESH, S_OFF_F]), int(si[MESH, S_OFF_I])
    a, b, c, normal = (np.array(p) for p in ml.triangle(geom_f, geom_i, off_f, off_i, triangle))
    if u + v > 1.0:
        u, v = 1.0 - u, 1.0 - v
    x0 = tuple(m @ (a + u * (b - a) + v * (c - a) + (RADIUS + gap) * normal) + OFFSET)
    acceleration = (0.0, -9.81 - push, 0.0)
    motion = (x0, (vx, vy, vz), acceleration, (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    still = (tuple(OFFSET), (0.0,) * 3, (0.0,) * 3, tuple(state.bf[0, QUAT:QUAT + 4]), (0.0,) * 3)
    rot = tuple(m.ravel())
    # the speculative contacts at the start, as the mesh's pair test reports them within the motion's reach:
    # the stage asks about those only (a triangle that touches is skipped by the search; one not reported, such
    # as the far side of a seam whose edge the Voronoi filter leaves to its neighbour, is no contact yet)
    reach = math.hypot(vx, vy, vz) * HORIZON + 0.5 * (9.81 + push) * HORIZON ** 2 + HIT_TOLERANCE
    out_f, out_i = np.empty((64, 7)), np.empty(64, np.int64)
    n = collide_sphere_mesh(x0, RADIUS, tuple(OFFSET), rot, sf[MESH, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS],
                            geom_f, geom_i, off_f, off_i, reach, out_f, out_i, 0)
    speculative = [int(out_i[k]) // 16 for k in range(min(n, 64)) if -out_f[k, 6] > TOUCH_TOLERANCE]
    reached = [t for t in speculative if sphere_reaches_triangle(motion, RADIUS, tuple(OFFSET), rot, geom_f, geom_i,
                                                                  off_f, off_i, t, HORIZON)]
    if not reached:
        return
    outcome, _ = time_of_impact(
        types.COVER_MESHES, types.SPHERE, sf[SPHERE, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS], 0, 0, motion,
        (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, types.MESH, sf[MESH, S_PARAMS:S_PARAMS + types.N_SHAPE_PARAMS],
        off_f, off_i, still, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, geom_f, geom_i, HORIZON, TOUCH_TOLERANCE,
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
    identity = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    # the seam is the diagonal x = z; the first triangle (0, 2, 1) lies where x > z
    d = 0.02 / math.sqrt(2.0)
    start = (d, RADIUS, -d)
    towards = (-3.0 / math.sqrt(2.0), 0.0, 3.0 / math.sqrt(2.0))
    for velocity, reaches in ((towards, True), (tuple(-c for c in towards), False)):
        motion = (start, velocity, (0.0, -9.81, 0.0), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        # (falling under gravity from resting height, it sinks into the plane: the second triangle is reached
        # only when the centre crosses the seam, as it does at 3 m/s towards it)
        assert sphere_reaches_triangle(motion, RADIUS, (0.0, 0.0, 0.0), identity, state.geom_f, state.geom_i,
                                       off_f, off_i, 1, HORIZON) is reaches
