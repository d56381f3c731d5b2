"""The particles' step is compiled for the kinds of shape a world has (``COVER_SPHERES``, ``COVER_MESHES``,
``COVER_GROUND``): a world without height fields or hulls leaves their pair tests out, and its particles move
exactly as with every pair test."""
import numpy as np
import pytest

import marbellous as mb
from marbellous.collision import shape_types as st
from marbellous.deformables import particle_state
from marbellous.deformables.particle_layout import P_POS
from marbellous.deformables.particle_step import KERNELS


def _scene(seed, field):
    """Particles and a small cloth dropped onto a plane, a box, a bumpy mesh, a moving ball and (``field``) a
    height field."""
    rng = np.random.default_rng(seed)
    w = mb.World()
    w.add_static(mb.Plane(), friction=0.6)
    w.add_static(mb.Box((0.4, 0.2, 0.4)), position=(0.8, 0.2, 0.0))
    x, z = np.meshgrid(np.linspace(-1.0, 1.0, 5), np.linspace(-1.0, 1.0, 5))
    vertices = np.column_stack([x.ravel() - 1.2, 0.1 * rng.standard_normal(x.size) + 0.15, z.ravel()])
    faces = [(r * 5 + c, (r + 1) * 5 + c, r * 5 + c + 1) for r in range(4) for c in range(4)]
    faces += [(r * 5 + c + 1, (r + 1) * 5 + c, (r + 1) * 5 + c + 1) for r in range(4) for c in range(4)]
    w.add_static(mb.TriangleMesh(vertices, faces))
    if field:
        w.add_static(mb.HeightField(0.1 * rng.standard_normal((4, 4)), spacing=(0.5, 0.5), origin=(-0.75, 0.1, 1.0)))
    w.add_body(mb.Sphere(0.2), position=(0.0, 0.5, 0.0), velocity=rng.normal(0.0, 1.0, 3))
    w.add_particles(rng.uniform((-2.0, 0.3, -0.8), (1.2, 1.5, 1.8), (40, 3)), radius=0.03, restitution=0.3)
    vertices, triangles = mb.cloth_grid(0.8, 0.8, 6, 6)
    w.add_cloth(vertices, triangles, mass=0.2, self_collision=False, position=(-1.2, 1.0, 0.0))
    return w


def _run(w, steps=60):
    for _ in range(steps):
        w.step(1 / 60)
    return np.array(w._state.particles.pf[:w._state.particles.n])


@pytest.mark.parametrize("field", [False, True])
def test_the_particles_use_the_kernels_of_their_worlds_shapes_with_the_same_results(field):
    w = _scene(4, field)
    coverage = st.COVER_GROUND if field else st.COVER_MESHES
    assert w._state.sphere_coverage() == coverage
    kernels = w._state.particles._kernels(w._state)
    assert kernels is KERNELS[False][coverage]
    own = _run(w)
    with pytest.MonkeyPatch.context() as m:      # every sphere pair test
        m.setattr(particle_state, "KERNELS", tuple((row[st.COVER_GROUND],) * 3 for row in KERNELS))
        every = _run(_scene(4, field))
    assert np.array_equal(own, every)
    assert own[:, P_POS + 1].min() > -0.03         # (on the plane, not through it)


def test_a_world_without_meshes_uses_the_sphere_primitive_kernels():
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_particles([(0.0, 0.5, 0.0)], radius=0.05)
    w.step(1 / 60)
    assert w._state.sphere_coverage() == st.COVER_SPHERES
    assert w._state.particles._kernels(w._state) is KERNELS[False][st.COVER_SPHERES]
    w.add_static(mb.ConvexHull([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]), position=(3.0, 0, 0))
    assert w._state.sphere_coverage() == st.COVER_GROUND       # a hull: before the step packs again too
    w.step(1 / 60)
    assert w._state.particles._kernels(w._state) is KERNELS[False][st.COVER_GROUND]
