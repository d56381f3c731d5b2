"""Particles and particle networks in the viewer's pictures (EGL, headless): each particle is a sphere of its
radius where the camera puts it, teal or, pinned, raspberry; a network's edges are lines coloured by kind
(rods white, springs magenta, cables brown), hidden behind what is in front of them and gone once broken;
a world of particles alone is framed; the stats line counts them; ``mb.record`` writes them to an MP4."""
import math

import numpy as np
import pytest

import marbellous as mb
from marbellous.app.stats import stats_line
from marbellous.render import palette
from marbellous.render.bounds import world_points
from marbellous.render.draw_lists import Spheres, WorldFrame
from marbellous.render.orbit_camera import OrbitCamera
from marbellous.render.particle_drawing import particle_spheres
from marbellous.render.transforms import look_at, perspective
from marbellous.render.video import read_frames
from marbellous.render.world_renderer import WorldRenderer

SIZE = (480, 270)
#: The camera of most pictures here: (eye, target) (m).
CAMERA = (np.array([2.0, 3.0, 6.0]), np.array([0.0, 0.7, 0.0]))
VIEW = OrbitCamera.looking(*CAMERA).view()
#: The rope hangs between these two pins (m); its particles are ROPE_RADIUS, its pinned ends PIN_RADIUS.
ROPE_FROM, ROPE_TO, ROPE_LINKS = np.array([-0.4, 1.9, -0.5]), np.array([2.0, 1.9, -0.5]), 6
ROPE_RADIUS, PIN_RADIUS = 0.03, 0.09


@pytest.fixture(scope="module")
def renderer():
    from marbellous.render.context import headless_context

    ctx = headless_context()
    yield WorldRenderer(ctx, SIZE)
    ctx.release()


def heap_and_rope(kind="rod", breaking_force=None, floor=True):
    """``(world, heap, rope, network)``: a 4 x 4 x 4 block of 10 cm particles on the ground at x = -1.2,
    and a rope of ``ROPE_LINKS`` edges of ``kind`` pinned at both ends, straight (taut) between them."""
    w = mb.World()
    if floor:
        w.add_static(mb.Plane())
    grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    heap = w.add_particles(grid * 0.2 + (-1.5, 0.1, -0.3), radius=0.1, collide_particles=True)
    t = np.linspace(0.0, 1.0, ROPE_LINKS + 1)[:, None]
    radii = np.full(ROPE_LINKS + 1, ROPE_RADIUS)
    radii[[0, -1]] = PIN_RADIUS
    rope = w.add_particles(ROPE_FROM + t * (ROPE_TO - ROPE_FROM), radius=radii, mass=0.05)
    rope.pin([0, ROPE_LINKS])
    edges = np.column_stack([np.arange(ROPE_LINKS), np.arange(1, ROPE_LINKS + 1)])
    stiffness = 200.0 if kind == "spring" else None
    net = w.add_network(rope, edges, kind=kind, stiffness=stiffness, breaking_force=breaking_force)
    return w, heap, rope, net


def project(point, view=VIEW, size=SIZE):
    """Pixel (column, row from the top) of a world point (m) with the renderer's camera matrices."""
    c = perspective(view.fov, size[0] / size[1], 0.05, 400.0) @ look_at(view.eye, view.target) @ np.append(point, 1)
    return int(round((c[0] / c[3] + 1) / 2 * size[0])), int(round((1 - c[1] / c[3]) / 2 * size[1]))


def patch(img, point, r=1, view=VIEW):
    """Pixels (K, 3) int of the (2 r + 1)^2 square around the projection of ``point``."""
    x, y = project(point, view, (img.shape[1], img.shape[0]))
    return img[y - r:y + r + 1, x - r:x + r + 1].reshape(-1, 3).astype(int)


def teal(px):
    """The particles' teal, lit or in shade: green and blue over twice the red (no body's colour, nor the
    background's or the floor's)."""
    return (px[:, 1] > 2 * px[:, 0] + 20) & (px[:, 2] > 2 * px[:, 0] + 20)


def drawn(img):
    """Pixels (mask) that differ from the background."""
    return np.abs(img.astype(int) - 255 * np.asarray(palette.BACKGROUND)).max(axis=-1) > 12


def raspberry(px):
    """Pinned particles, lit or in shade: red well over green and blue (not the springs' magenta), blue over
    green (not a dynamic body's warm hues)."""
    return (px[:, 0] > 2 * px[:, 1] + 30) & (px[:, 0] > 1.5 * px[:, 2] + 10) & (px[:, 2] > px[:, 1] + 8)


def near(px, color, tol=45):
    return np.all(np.abs(px - 255 * np.asarray(color)) < tol, axis=1)


def test_particles_are_spheres_where_the_camera_puts_them(renderer):
    w, heap, rope, _ = heap_and_rope()
    img = renderer.render_to_array(w, VIEW)
    # the heap: every particle on the faces turned to the camera (top, front, right) is teal at its centre's
    # projection pushed out by its radius towards the camera
    x = heap.positions
    eye = VIEW.eye
    front = x[(x[:, 1] > 0.65) | (x[:, 2] > 0.25) | (x[:, 0] > -0.95)]
    assert len(front) == 37
    for p in front:
        toward = p + 0.1 * (eye - p) / np.linalg.norm(eye - p)
        assert teal(patch(img, toward, 1)).all(), p
    # the rope's free particles teal too, its pinned ends raspberry
    rx = rope.positions
    assert all(teal(patch(img, p, 1)).any() for p in rx[1:-1])
    assert raspberry(patch(img, rx[0], 1)).all() and raspberry(patch(img, rx[-1], 1)).all()
    # nothing teal far from any particle, and the background above the scene
    assert not teal(patch(img, (0.5, 0.0, 1.5), 3)).any()
    assert near(img[:5, -5:].reshape(-1, 3).astype(int), palette.BACKGROUND, 3).all()
    # without the particles layer, the heap is gone (the rope's edges stay)
    bare = renderer.render_to_array(w, VIEW, layers=("bodies", "constraints"))
    assert not any(teal(patch(bare, p, 1)).any() for p in front)


def test_a_sphere_is_drawn_at_its_radius(renderer):
    """A 40 cm particle 5 m away covers the disc the perspective makes of it (within 2 %), like a body
    sphere of the same radius does."""
    view = OrbitCamera.looking((0.0, 0.0, 5.0), (0.0, 0.0, 0.0)).view()
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    w.add_particles([[0.0, 0.0, 0.0]], radius=0.4)
    img = renderer.render_to_array(w, view)
    f = 0.5 * SIZE[1] / math.tan(view.fov / 2.0)
    expected = math.pi * (f * 0.4 / math.sqrt(5.0 ** 2 - 0.4 ** 2)) ** 2
    area = drawn(img).sum()
    assert area == pytest.approx(expected, rel=0.02)
    assert teal(img[drawn(img)].astype(int)).mean() > 0.9
    ball = mb.World(gravity=(0.0, 0.0, 0.0))
    ball.add_body(mb.Sphere(0.4))
    assert drawn(renderer.render_to_array(ball, view)).sum() == pytest.approx(area, rel=0.05)   # (its edge: MSAA)


def test_a_tiny_far_particle_is_still_drawn(renderer):
    """A 1 mm particle 20 m away (a fifth of a pixel) is drawn a pixel or so wide, not lost."""
    view = OrbitCamera.looking((0.0, 0.0, 20.0), (0.0, 0.0, 0.0)).view()
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    w.add_particles([[0.0, 0.0, 0.0]], radius=0.001)
    img = renderer.render_to_array(w, view)
    assert 1 <= drawn(img).sum() <= 9
    assert teal(img[drawn(img)].astype(int)).all()


@pytest.mark.parametrize("kind, color", [("rod", palette.ROD), ("spring", palette.SPRING), ("cable", palette.CABLE)])
def test_a_network_is_lines_along_its_edges_in_the_colour_of_its_kind(renderer, kind, color):
    w, _, rope, net = heap_and_rope(kind)
    img = renderer.render_to_array(w, VIEW)
    x = rope.positions
    for a, b in net.edges:                        # a line of pixels between every two neighbours of the rope
        for t in (0.3, 0.5, 0.7):
            assert near(patch(img, x[a] + t * (x[b] - x[a]), 1), color).any(), (a, t)
    assert not near(patch(img, 0.5 * (x[0] + x[1]) + (0.0, 0.3, 0.0), 2), color).any()
    # the other kinds' colours are not on the rope
    others = [c for c in (palette.ROD, palette.SPRING, palette.CABLE) if c != color]
    mid = 0.5 * (x[2] + x[3])
    assert not any(near(patch(img, mid, 1), c).any() for c in others)
    # without the constraints layer the lines are gone (the particles stay)
    bare = renderer.render_to_array(w, VIEW, layers=("bodies", "particles"))
    assert not near(patch(bare, mid, 1), color).any()
    assert teal(patch(bare, x[3], 1)).any()


def test_broken_edges_are_not_drawn(renderer):
    w, _, rope, net = heap_and_rope("rod", breaking_force=1e-3)
    x = rope.positions
    mid = 0.5 * (x[2] + x[3])
    assert near(patch(renderer.render_to_array(w, VIEW), mid, 1), palette.ROD).any()
    w.step(1 / 60)                                # the rope's weight breaks every link
    assert net.broken.all()
    x = rope.positions
    img = renderer.render_to_array(w, VIEW)
    for a, b in net.edges:
        assert not near(patch(img, 0.5 * (x[a] + x[b]), 1), palette.ROD).any()


def test_particles_and_edges_hide_behind_a_body_and_in_front_of_it(renderer):
    """A box between the camera and part of the rope and heap hides them there; a particle in front of the
    box is drawn over it."""
    w, heap, rope, _ = heap_and_rope()
    x = rope.positions
    mid = 0.5 * (x[3] + x[4])
    toward = (VIEW.eye - mid) / np.linalg.norm(VIEW.eye - mid)
    box = w.add_static(mb.Box((0.3, 0.3, 0.05)), position=mid + 1.5 * toward)
    ball = w.add_particles([box.position + 0.6 * toward + (0.12, 0.12, 0.0)], radius=0.05)
    img = renderer.render_to_array(w, VIEW)
    for hidden in (x[3], mid, x[4]):
        px = patch(img, hidden, 1)
        assert not near(px, palette.ROD).any() and not teal(px).any()
    assert near(patch(img, 0.5 * (x[0] + x[1]), 1), palette.ROD).any()     # (elsewhere the rope shows)
    assert teal(patch(img, ball.positions[0], 1)).all()


def test_a_world_of_particles_alone_is_framed(renderer):
    """With no body at all, the camera frames the particles: all in view, filling a good part of it."""
    w, *_ = heap_and_rope(floor=False)
    assert not w.bodies
    img = mb.render_image(w, size=SIZE)
    fg = np.abs(img.astype(int) - 255 * np.asarray(palette.BACKGROUND)).max(axis=-1) > 40
    rows, cols = np.nonzero(fg)
    assert 0 < cols.min() and cols.max() < SIZE[0] - 1 and 0 < rows.min() and rows.max() < SIZE[1] - 1
    assert np.ptp(cols) > 0.5 * SIZE[0]
    assert teal(img[fg].astype(int)).mean() > 0.5
    # the framing points: every particle's box corners
    pts = world_points(w)
    assert len(pts) == 8 * (64 + ROPE_LINKS + 1)
    assert pts[:, 0].max() == pytest.approx(ROPE_TO[0] + PIN_RADIUS)


def test_one_draw_list_holds_every_particle():
    w, heap, rope, _ = heap_and_rope()
    (spheres,) = particle_spheres(WorldFrame(w, np.zeros(3), 5.0))
    assert isinstance(spheres, Spheres) and len(spheres.centers) == len(heap) + len(rope)
    assert np.allclose(spheres.radii[:64], 0.1) and spheres.radii[64] == PIN_RADIUS
    assert np.array_equal(spheres.colors[64], palette.PINNED_PARTICLE)
    w.remove(heap)
    w.remove(rope)
    assert particle_spheres(WorldFrame(w, np.zeros(3), 5.0)) == []


def test_the_stats_line_counts_particles_and_edges():
    w, heap, rope, net = heap_and_rope("rod", breaking_force=1e-3)
    assert stats_line(w, contacts=2) == ("bodies 1 (1 static, 0 asleep)  |  particles 71 (2 pinned, 6 edges, "
                                         "0 broken)  |  contacts 2  |  t 0.00 s")
    w.step(1 / 60)
    assert "particles 71 (2 pinned, 6 edges, 6 broken)" in stats_line(w, contacts=0)
    w.remove(net)
    assert "particles 71 (2 pinned)  |" in stats_line(w, contacts=0)
    w.remove(heap)
    w.remove(rope)
    assert "particles" not in stats_line(w, contacts=0)


def test_record_writes_a_playable_mp4_of_particles(tmp_path):
    w, heap, rope, _ = heap_and_rope()
    heap.velocities = np.tile((0.0, 4.0, 0.0), (len(heap), 1))     # the heap jumps and falls back
    out = mb.record(w, tmp_path / "particles.mp4", seconds=1.0, fps=12, size=(320, 180), camera=CAMERA,
                    stats=True)
    assert out.stat().st_size > 0
    frames = read_frames(out)
    assert len(frames) == 12 and w.time == pytest.approx(1.0, abs=1e-9)
    view = OrbitCamera.looking(*CAMERA).view()
    for f in frames:
        assert f.shape == (180, 320, 3)
        assert teal(f.reshape(-1, 3).astype(int)).sum() > 200                   # the particles, through H.264
    # the rope's middle in the first frame: a white line
    x = rope.positions
    assert near(patch(frames[0], 0.5 * (x[3] + x[4]), 1, view), palette.ROD, 60).any()
    assert np.abs(frames[0].astype(int) - frames[4].astype(int)).max() > 60   # the heap moved
