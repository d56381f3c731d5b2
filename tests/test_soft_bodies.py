"""Soft bodies by finite elements, checked against elasticity's closed forms.

Linear tetrahedra reproduce a uniform strain exactly (the patch test), and along a bar of Poisson's ratio 0
under a body force their nodal displacements are exact, so the bar tests below are limited only by how near
equilibrium the run has come.  The contact tests carry the splitting error of a contact with a moving body
(it shrinks in proportion to the sub-step, as the test shows).
"""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import polar
from scipy.spatial.transform import Rotation

import marbellous as mb
from marbellous.deformables import particle_layout as P
from marbellous.deformables.soft_elements import add_element_forces, deformation_gradient, update_rotation
from marbellous.deformables.soft_state import element_rows, lame

G = 9.81


def _bar(half, cells, **kw):
    """``(world, soft body, its rest vertices)``: a bar ``tet_box(half, cells)`` alone in a world of the given
    ``gravity`` (none by default); the other keywords go to ``add_soft_body``."""
    gravity = kw.pop("gravity", (0.0, 0.0, 0.0))
    vertices, tets = mb.tet_box(half, cells)
    w = mb.World(gravity=gravity)
    return w, w.add_soft_body(vertices, tets, **kw), vertices


# --- meshing ----------------------------------------------------------------------------------------------
def test_tet_box_fills_the_box_face_to_face():
    vertices, tets = mb.tet_box((0.3, 0.2, 0.1), (3, 2, 4))
    assert vertices.shape == (4 * 3 * 5, 3) and tets.shape == (6 * 3 * 2 * 4, 4)
    x0 = vertices[tets[:, 0]]
    volumes = np.linalg.det(np.stack([vertices[tets[:, k]] - x0 for k in (1, 2, 3)], axis=2)) / 6
    assert np.all(volumes > 0)
    assert volumes.sum() == pytest.approx(0.6 * 0.4 * 0.2, rel=1e-12)
    # conforming: every face is shared by two tetrahedra, except the boundary's, which tile the box's surface
    faces = np.sort(np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]], tets[:, [0, 1, 3]], tets[:, [0, 1, 2]]]),
                    axis=1)
    _, count = np.unique(faces, axis=0, return_counts=True)
    assert set(count) == {1, 2}
    w = mb.World()
    s = w.add_soft_body(vertices, tets)
    tri = s.surface_triangles
    a, b, c = (vertices[tri[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    assert 0.5 * np.linalg.norm(cross, axis=1).sum() == pytest.approx(2 * (0.6 * 0.4 + 0.6 * 0.2 + 0.4 * 0.2))
    # wound outwards: the divergence theorem gives the volume back
    assert np.sum(np.einsum("ij,ij->i", a, cross)) / 6 == pytest.approx(0.6 * 0.4 * 0.2)


def test_tetrahedralize_fills_a_closed_surface():
    pytest.importorskip("pytetwild")
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.5)
    vertices, tets = mb.tetrahedralize(sphere.vertices, sphere.faces, max_volume=0.002)
    x0 = vertices[tets[:, 0]]
    volumes = np.linalg.det(np.stack([vertices[tets[:, k]] - x0 for k in (1, 2, 3)], axis=2)) / 6
    assert np.all(volumes > 0)
    # the mesher keeps the surface within 0.1% of the box's diagonal: the volume within 3 * 0.001 * 1.7 / 0.5
    assert volumes.sum() == pytest.approx(sphere.volume, rel=0.011)
    assert np.max(volumes) < 0.002 * 4        # about the size asked for
    w = mb.World()
    s = w.add_soft_body(vertices, tets)
    assert s.rest_volume == pytest.approx(volumes.sum())


# --- the element --------------------------------------------------------------------------------------------
def _element_energy(rest, x, lam, mu):
    """Slow reference: V (mu |S - I|^2 + lam/2 tr(S - I)^2), S the stretch of F = R S (corotated linear)."""
    dm = np.stack([rest[k] - rest[0] for k in (1, 2, 3)], axis=1)
    ds = np.stack([x[k] - x[0] for k in (1, 2, 3)], axis=1)
    _, stretch = polar(ds @ np.linalg.inv(dm))
    eps = stretch - np.eye(3)
    return abs(np.linalg.det(dm)) / 6 * (mu * np.sum(eps * eps) + 0.5 * lam * np.trace(eps) ** 2)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), nu=st.floats(0.0, 0.45))
def test_element_forces_are_minus_the_gradient_of_its_energy(seed, nu):
    rng = np.random.default_rng(seed)
    rest = rng.normal(size=(4, 3))
    rest[1:] = rest[0] + np.linalg.qr(rng.normal(size=(3, 3)))[0] @ np.diag(rng.uniform(0.5, 1.5, 3))
    tets = np.array([[0, 1, 2, 3]])
    if np.linalg.det(np.stack([rest[k] - rest[0] for k in (1, 2, 3)], axis=1)) < 0:
        tets = np.array([[0, 1, 3, 2]])
    tf, ti, _ = element_rows(rest, tets, 1000.0, 1e5, nu, 0.0, np.array([1.0, 0, 0, 0]))
    lam, mu = lame(1e5, nu)
    # a rotated, stretched and sheared placement (strains up to 10%)
    turn = Rotation.random(random_state=seed % 1000).as_matrix()
    x = (rest - rest[0]) @ (turn @ (np.eye(3) + rng.uniform(-0.1, 0.1, (3, 3)))).T + rng.normal(size=3)
    f = np.zeros((3, 3))
    rot = np.zeros((1, 9))
    tf[0, P.S_QUAT:P.S_QUAT + 4] = Rotation.from_matrix(turn).as_quat(scalar_first=True)
    deformation_gradient(x, tf, ti, 0, f)
    update_rotation(tf, 0, f, np.zeros((3, 3)), rot)
    forces = np.zeros((4, 3))
    add_element_forces(x, tf, ti, 0, rot, True, -1.0, forces)
    # central differences of the energy (its third derivative bounds the error: O(step^2))
    step = 1e-6
    numeric = np.zeros((4, 3))
    order = ti[0, :4]
    for i in range(4):
        for k in range(3):
            up, down = x.copy(), x.copy()
            up[order[i], k] += step
            down[order[i], k] -= step
            numeric[order[i], k] = -(_element_energy(rest[order], up[order], lam, mu)
                                     - _element_energy(rest[order], down[order], lam, mu)) / (2 * step)
    scale = np.abs(numeric).max()
    assert np.allclose(forces, numeric, atol=1e-6 * scale), np.abs(forces - numeric).max() / scale
    assert np.allclose(forces.sum(axis=0), 0.0, atol=1e-12 * scale)      # no net force


@settings(max_examples=5, deadline=None)
@given(q=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1),
       velocity=st.lists(st.floats(-3, 3), min_size=3, max_size=3))
def test_a_turned_body_moving_as_a_whole_is_not_strained(q, velocity):
    vertices, tets = mb.tet_box((0.2, 0.1, 0.3), (2, 1, 3))
    w = mb.World(gravity=(0, 0, 0))
    s = w.add_soft_body(vertices, tets, young_modulus=1e7, orientation=q, position=(1, 2, 3))
    s.velocities = np.repeat([velocity], len(s), axis=0)
    start = s.positions
    for _ in range(10):
        w.step(1 / 60)
    expected = start + np.asarray(velocity) * 10 / 60
    assert np.abs(s.positions - expected).max() < 1e-9
    assert s.volume == pytest.approx(s.rest_volume, rel=1e-9)


# --- elasticity's closed forms ----------------------------------------------------------------------------
def test_a_bar_hanging_under_gravity_stretches_by_rho_g_l2_over_2e():
    length, E, rho = 1.0, 1e5, 1000.0
    w, s, v = _bar((0.05, length / 2, 0.05), (2, 20, 2), gravity=(0, -G, 0), density=rho, young_modulus=E,
                   poisson_ratio=0.0, damping=0.01)
    s.pin(np.where(v[:, 1] > length / 2 - 1e-9)[0])
    for _ in range(600):
        w.step(1 / 60)
    bottom = v[:, 1] < -length / 2 + 1e-9
    stretch = -(s.positions[bottom, 1] - v[bottom, 1]).mean()
    assert stretch == pytest.approx(rho * G * length ** 2 / (2 * E), rel=0.01)


def test_an_end_load_stretches_by_fl_over_ea_and_narrows_by_poissons_ratio():
    length, side, E, nu, force = 1.0, 0.1, 1e5, 0.3, 20.0
    w, s, v = _bar((side / 2, length / 2, side / 2), (1, 4, 1), density=100.0, young_modulus=E, poisson_ratio=nu,
                   damping=0.1)
    # each end face's load spread over its nodes by area (a uniform traction), equal and opposite
    tri = s.surface_triangles
    share = {}
    for end in (1, -1):
        on = tri[np.all(np.abs(v[tri, 1] - end * length / 2) < 1e-9, axis=1)]
        area = 0.5 * np.linalg.norm(np.cross(v[on[:, 1]] - v[on[:, 0]], v[on[:, 2]] - v[on[:, 0]]), axis=1)
        w_node = np.zeros(len(v))
        np.add.at(w_node, on.reshape(-1), np.repeat(area / 3, 3))
        share[end] = w_node / w_node.sum()
    for _ in range(1200):
        for end in (1, -1):
            for i in np.nonzero(share[end])[0]:
                s.apply_force((0, end * force * share[end][i], 0), [i])
        w.step(1 / 60)
    x = s.positions
    strain = force / (E * side * side)
    axial = (x[share[1] > 0, 1].mean() - x[share[-1] > 0, 1].mean() - length) / length
    # across: the distances between the nodes facing each other on the sides x = -side/2 and x = +side/2 (the
    # bar may have turned a little as a whole)
    left = np.nonzero(v[:, 0] < 0)[0]
    right = [np.nonzero(np.all(np.abs(v - v[i] - (side, 0, 0)) < 1e-9, axis=1))[0][0] for i in left]
    lateral = (np.linalg.norm(x[right] - x[left], axis=1).mean() - side) / side
    assert axial == pytest.approx(strain, rel=0.01)
    assert lateral == pytest.approx(-nu * strain, rel=0.02)


def test_a_fixed_free_bar_rings_at_its_quarter_wave_frequency():
    length, E, rho = 1.0, 1e4, 1000.0
    w, s, v = _bar((0.05, length / 2, 0.05), (1, 20, 1), density=rho, young_modulus=E, poisson_ratio=0.0)
    s.pin(np.where(v[:, 1] > length / 2 - 1e-9)[0])
    stretched = v.copy()
    stretched[:, 1] = length / 2 + (v[:, 1] - length / 2) * 1.01
    s.positions = stretched
    bottom = v[:, 1] < -length / 2 + 1e-9
    tip = []
    for _ in range(400):
        w.step(1 / 60)
        tip.append(s.positions[bottom, 1].mean() + length / 2)
    tip = np.array(tip)
    up = np.nonzero((tip[:-1] < 0) & (tip[1:] >= 0))[0]
    crossings = up + tip[up] / (tip[up] - tip[up + 1])
    frequency = (len(crossings) - 1) / ((crossings[-1] - crossings[0]) / 60)
    # f = c / (4 L), c = sqrt(E / rho); the step (a 76th of the period) lengthens it by (w h)^2 / 3 ~ 0.01%
    assert frequency == pytest.approx(math.sqrt(E / rho) / (4 * length), rel=0.01)


def test_a_cantilever_bends_towards_beam_theory_as_the_mesh_is_refined():
    length, depth, E, rho = 1.0, 0.1, 1e8, 1000.0
    beam = rho * G * depth * depth * length ** 4 / (8 * E * depth ** 4 / 12)      # q L^4 / (8 E I)
    deflections = []
    for cells in ((4, 1, 1), (8, 1, 1), (16, 2, 2)):
        w, s, v = _bar((length / 2, depth / 2, depth / 2), cells, gravity=(0, -G, 0), density=rho,
                       young_modulus=E, poisson_ratio=0.0, damping=0.002)
        s.pin(np.where(v[:, 0] < -length / 2 + 1e-9)[0])
        for _ in range(120):
            w.step(1 / 60)
        tip = v[:, 0] > length / 2 - 1e-9
        deflections.append(-(s.positions[tip, 1] - v[tip, 1]).mean())
    errors = [abs(d - beam) / beam for d in deflections]
    # linear tetrahedra are too stiff in bending (they lock): the deflection rises towards the beam's
    assert all(0 < d < beam for d in deflections)
    assert errors[0] > errors[1] > errors[2]


# --- contact --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("E", [1e4, 1e6, 1e8])
def test_a_soft_cube_dropped_on_the_ground_keeps_its_volume(E):
    # 10 cm of nu = 0.3: linear elasticity predicts a volume change under its own weight of
    # (1 - 2 nu) rho g a / (2 E) = 2% at E = 1e4 Pa
    vertices, tets = mb.tet_box((0.05, 0.05, 0.05), 4)
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane())
    s = w.add_soft_body(vertices, tets, young_modulus=E, poisson_ratio=0.3, position=(0, 0.3, 0),
                        orientation=(0.9, 0.3, 0.2, 0.1))
    for _ in range(240):
        w.step(1 / 60)
        assert np.all(np.isfinite(s.positions))
        assert s.positions[:, 1].min() > s.radius * (1 - 1e-6) - 1e-9
    assert s.volume == pytest.approx(s.rest_volume, rel=0.05)
    assert np.abs(s.velocities).max() < 0.1


def test_a_block_on_the_ground_settles_as_a_pinned_one():
    kw = dict(density=500.0, young_modulus=2e4, poisson_ratio=0.0, damping=0.01, position=(0, 0.125, 0))
    heights = []
    for support in ("pins", "ground"):
        vertices, tets = mb.tet_box((0.2, 0.1, 0.2), (4, 2, 4))
        w = mb.World(gravity=(0, -G, 0))
        w.add_static(mb.Plane())
        s = w.add_soft_body(vertices, tets, **kw)
        if support == "pins":
            s.pin(np.where(vertices[:, 1] < -0.1 + 1e-9)[0])
        for _ in range(300):
            w.step(1 / 60)
        top = s.positions[vertices[:, 1] > 0.1 - 1e-9, 1].mean()
        heights.append(top - s.positions[vertices[:, 1] < -0.1 + 1e-9, 1].mean())
    # rho g H^2 / (2 E) = 4.9 mm of its own weight, exact at the nodes for nu = 0
    assert 0.2 - heights[0] == pytest.approx(500 * G * 0.2 ** 2 / (2 * 2e4), rel=0.01)
    assert heights[1] == pytest.approx(heights[0], abs=1e-5)


def test_a_box_on_a_soft_block_sinks_by_its_weight_over_the_stiffness():
    # a 20 kg box over the whole top of a 0.4 x 0.2 x 0.4 m block, nu = 0: it sinks by M g H / (E A)
    expected = 20 * G * 0.2 / (2e4 * 0.16)
    errors = []
    for substeps in (16, 64):
        heights = []
        for mass in (0.0, 20.0):
            vertices, tets = mb.tet_box((0.2, 0.1, 0.2), (4, 2, 4))
            w = mb.World(gravity=(0, -G, 0))
            w.particle_substeps = substeps
            w.add_static(mb.Plane())
            s = w.add_soft_body(vertices, tets, density=500.0, young_modulus=2e4, poisson_ratio=0.0, damping=0.01,
                                position=(0, 0.1125, 0))
            if mass:
                box = w.add_body(mb.Box((0.25, 0.05, 0.25)), mass=mass, position=(0, 0.29, 0))
            for _ in range(300):
                w.step(1 / 60)
            top = s.positions[vertices[:, 1] > 0.1 - 1e-9, 1].mean()
            heights.append(top - s.positions[vertices[:, 1] < -0.1 + 1e-9, 1].mean())
        assert box.position[1] > 0.2                   # on the block
        errors.append((heights[0] - heights[1]) / expected - 1)
    # the contact with the box acts one sub-step late: an error in proportion to the sub-step
    assert 0 < errors[1] < 0.02 and errors[1] < errors[0] / 2.5


def test_a_box_pinned_to_a_soft_rope_hangs_where_its_stiffness_says():
    E, area, length, mass, rho = 1e5, 0.01, 0.5, 1.0, 100.0
    w, rope, v = _bar((0.05, length / 2, 0.05), (1, 5, 1), gravity=(0, -G, 0), density=rho, young_modulus=E,
                      poisson_ratio=0.0, damping=0.01)
    rope.pin(np.nonzero(v[:, 1] > length / 2 - 1e-9)[0])
    box = w.add_body(mb.Box((0.05, 0.05, 0.05)), mass=mass, position=(0, -length / 2 - 0.05, 0))
    rope.pin(np.nonzero(v[:, 1] < -length / 2 + 1e-9)[0], body=box)
    for _ in range(300):
        w.step(1 / 60)
    # the box's weight over the whole rope, the rope's own weight over half of it
    stretch = mass * G * length / (E * area) + rho * G * length ** 2 / (2 * E)
    assert box.position[1] == pytest.approx(-length / 2 - 0.05 - stretch, abs=0.001 * stretch)
    assert abs(box.velocity[1]) < 1e-4


def test_two_soft_bodies_stack_and_a_ray_finds_the_top_one():
    vertices, tets = mb.tet_box((0.1, 0.1, 0.1), 2)
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane())
    lower = w.add_soft_body(vertices, tets, young_modulus=1e5, position=(0, 0.15, 0))
    upper = w.add_soft_body(vertices, tets, young_modulus=1e5, position=(0.02, 0.45, 0))
    for _ in range(180):
        w.step(1 / 60)
    assert upper.positions[:, 1].min() > lower.positions[:, 1].max() + 1.5 * upper.radius
    hit = w.raycast((0.02, 2, 0.0), (0, -1, 0))
    assert hit is not None and hit.object is upper


def test_cloth_and_particles_come_to_rest_on_a_soft_block():
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane())
    vertices, tets = mb.tet_box((0.3, 0.15, 0.3), (4, 2, 4))
    block = w.add_soft_body(vertices, tets, young_modulus=5e4, position=(0, 0.16, 0))
    sheet = w.add_cloth(*mb.cloth_grid(0.8, 0.8, 20, 20), mass=0.2, position=(0, 0.6, 0))
    grains = w.add_particles([(0.1, 1.0, 0.05), (-0.1, 1.2, 0.0)], radius=0.03, collide_particles=True)
    # (the block under them rings down slowly: at 3 s the grains still rise and fall at up to 5 cm/s, at 4-5 s at
    # under 2 cm/s; every step of the fifth second is checked, not one instant of an oscillation)
    fastest = 0.0
    for step in range(300):
        w.step(1 / 60)
        if step >= 240:
            fastest = max(fastest, np.abs(grains.velocities).max())
    y = block.positions[:, 1]
    top = y[vertices[:, 1] > 0.15 - 1e-9]
    x = sheet.positions
    over = (np.abs(x[:, 0]) < 0.25) & (np.abs(x[:, 2]) < 0.25)
    # the sheet lies on the block's top face (its triangles keep the sheet's half thickness and the nodes'
    # radius away; a position pass per sub-step leaves it pressed in by less than that): above the top nodes'
    # spheres, nowhere through the block
    assert top.mean() + block.radius < x[over, 1].min() < top.max() + 0.5 * sheet.thickness + block.radius + 1e-3
    assert np.all(grains.positions[:, 1] > x[over, 1].min())
    assert fastest < 0.05


def test_soft_bodies_carry_rigid_bodies_and_are_pushed_by_them():
    vertices, tets = mb.tet_box((0.1, 0.1, 0.1), 2)
    w = mb.World(gravity=(0, 0, 0))
    s = w.add_soft_body(vertices, tets, young_modulus=1e5, density=100.0)
    ball = w.add_body(mb.Sphere(0.05), position=(-0.5, 0, 0), velocity=(3, 0, 0), mass=0.5)
    momentum = ball.velocity * 0.5
    for _ in range(60):
        w.step(1 / 60)
    total = ball.velocity * 0.5 + (s.velocities * s.mass[:, None]).sum(axis=0)
    assert ball.velocity[0] < 3.0 * 0.9 and s.velocities.mean(axis=0)[0] > 0.1
    assert total == pytest.approx(momentum, abs=1e-6 * np.linalg.norm(momentum) + 1e-9)


# --- the handle, snapshots, removal ------------------------------------------------------------------------
def test_snapshot_restore_repeats_a_soft_body_bit_for_bit():
    vertices, tets = mb.tet_box((0.1, 0.1, 0.1), 2)
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane())
    s = w.add_soft_body(vertices, tets, young_modulus=1e5, position=(0, 0.3, 0), orientation=(0.9, 0.1, 0.4, 0))
    for _ in range(20):
        w.step(1 / 60)
    snap = w.snapshot()
    for _ in range(20):
        w.step(1 / 60)
    end = w.state_hash()
    extra = w.add_soft_body(vertices, tets, position=(2, 1, 0))
    w.restore(snap)
    with pytest.raises(ValueError, match="removed"):
        extra.positions
    for _ in range(20):
        w.step(1 / 60)
    assert w.state_hash() == end
    w.remove(s)
    assert w.soft_bodies == [] and w._state.particles.nt == 0
    with pytest.raises(ValueError, match="removed"):
        s.volume
    with pytest.raises(ValueError, match="removed"):
        w.restore(snap)


def test_soft_body_handle_reads_and_writes():
    vertices, tets = mb.tet_box((0.1, 0.2, 0.3), (1, 2, 3))
    w = mb.World()
    s = w.add_soft_body(vertices, tets, density=800.0, position=(1, 0, 0))
    assert len(s) == len(vertices) and s.tetrahedra.shape == tets.shape
    assert s.mass.sum() == pytest.approx(800.0 * 0.2 * 0.4 * 0.6)
    assert s.volume == pytest.approx(0.2 * 0.4 * 0.6)
    assert np.allclose(s.positions, vertices + (1, 0, 0))
    s.pin([0])
    assert s.pinned[0] and not s.pinned[1:].any()
    s.unpin([0])
    assert not s.pinned.any()
    assert "SoftBody" in repr(s) and w.soft_bodies == [s]


def test_a_soft_body_refuses_flat_tetrahedra_and_impossible_materials():
    w = mb.World()
    vertices = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    with pytest.raises(ValueError, match="tetrahedra"):
        w.add_soft_body([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [(0, 1, 2, 3)])
    with pytest.raises(ValueError, match="poisson_ratio"):
        w.add_soft_body(vertices, [(0, 1, 2, 3)], poisson_ratio=0.5)
    with pytest.raises(ValueError, match="young_modulus"):
        w.add_soft_body(vertices, [(0, 1, 2, 3)], young_modulus=0.0)
    # a tetrahedron given clockwise is turned round, not refused
    s = w.add_soft_body(vertices, [(0, 2, 1, 3)])
    assert s.volume == pytest.approx(1 / 6)


@settings(max_examples=15, deadline=None)
@given(E=st.floats(1.0, 1e12), nu=st.floats(-0.9, 0.49), density=st.floats(1.0, 1e5), dt=st.floats(1e-4, 0.1),
       speed=st.floats(0, 100), damping=st.floats(0, 1))
def test_valid_soft_bodies_never_make_nan(E, nu, density, dt, speed, damping):
    vertices, tets = mb.tet_box((0.1, 0.1, 0.1), 1)
    w = mb.World(gravity=(0, -G, 0))
    w.add_static(mb.Plane())
    w.add_static(mb.Box((0.2, 0.2, 0.2)), position=(0.3, 0.2, 0))
    s = w.add_soft_body(vertices, tets, young_modulus=E, poisson_ratio=nu, density=density, damping=damping,
                        position=(0, 0.5, 0))
    s.velocities = np.tile([speed, -speed, 0.0], (len(s), 1))
    for _ in range(5):
        w.step(dt)
    assert np.all(np.isfinite(s.positions)) and np.all(np.isfinite(s.velocities))


def test_the_soft_bodies_example_comes_to_rest():
    """examples/soft_bodies.py after 3 s: the jelly on the floor with its volume kept, the plank bent down from
    its post, the ball caught on top of the block."""
    example = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "soft_bodies.py"))
    r = example["run"](3.0)
    assert r["jelly_volume"] == pytest.approx(1.0, abs=0.05)
    assert 0.0 < r["jelly_lowest"] < 0.02
    assert 0.05 < r["plank_tip"] < 1.2
    assert r["ball_height"] > 0.3 and r["ball_speed"] < 0.05 and r["block_dent"] > 0.0
