"""Cloth in the viewer's pictures (EGL, headless): each cloth is a surface of its triangles as they are now, in
the cloth colour where the camera puts its vertices, with gaps where it tore and nothing once removed; smooth
normals recomputed from the positions; both faces lit (the sun shows through to the underside, and a shadow
on the sheet shows from below too); a world of cloth alone is framed; the stats line counts it; ``mb.record``
writes it to an MP4.  Its vertices are not drawn as particles, nor its edges as springs."""
import math

import numpy as np
import pytest
from PIL import Image, ImageDraw
from scipy import ndimage

import marbellous as mb
from marbellous.app.stats import stats_line
from marbellous.render import palette
from marbellous.render.bounds import world_points
from marbellous.render.cloth_drawing import cloth_surfaces, vertex_normals
from marbellous.render.draw_lists import SHEET, Surface, WorldFrame
from marbellous.render.orbit_camera import OrbitCamera
from marbellous.render.particle_drawing import network_lines, particle_spheres
from marbellous.render.transforms import look_at, perspective
from marbellous.render.video import read_frames
from marbellous.render.world_renderer import SUN, WorldRenderer

SIZE = (480, 270)
#: The camera of most pictures here: (eye, target) (m), above and in front of a sheet 1 m up.
CAMERA = (np.array([1.2, 2.6, 2.2]), np.array([0.0, 1.0, 0.0]))
VIEW = OrbitCamera.looking(*CAMERA).view()
#: The sheet of most pictures: N x N vertices, SIDE metres across, HEIGHT up.
N, SIDE, HEIGHT = 13, 1.2, 1.0


@pytest.fixture(scope="module")
def renderer():
    from marbellous.render.context import headless_context

    ctx = headless_context()
    yield WorldRenderer(ctx, SIZE)
    ctx.release()


def sheet(w, n=N, side=SIDE, height=HEIGHT, **kw):
    """A flat ``n`` x ``n`` sheet ``side`` metres across, ``height`` up, in ``w``; returns the cloth."""
    v, t = mb.cloth_grid(side, side, n, n)
    return w.add_cloth(v, t, mass=0.2, position=(0.0, height, 0.0), **kw)


def inner(n=N):
    """Indices of the vertices of an ``n`` x ``n`` grid that are not on its border."""
    i, j = np.meshgrid(np.arange(1, n - 1), np.arange(1, n - 1), indexing="ij")
    return (i * n + j).reshape(-1)


def screen(points, view=VIEW, size=SIZE):
    """Where the renderer's camera puts world points (K, 3) (m): (K, 2) (column, row from the top), in pixels
    (a pixel's centre at + 0.5)."""
    p = np.column_stack([np.reshape(points, (-1, 3)), np.ones(np.size(points) // 3)])
    c = p @ (perspective(view.fov, size[0] / size[1], 0.05, 400.0) @ look_at(view.eye, view.target)).T
    return np.column_stack([(c[:, 0] / c[:, 3] + 1) / 2 * size[0], (1 - c[:, 1] / c[:, 3]) / 2 * size[1]])


def patch(img, point, r=1, view=VIEW):
    """Pixels (K, 3) int of the (2 r + 1)^2 square around the projection of ``point``."""
    x, y = np.floor(screen(point, view, (img.shape[1], img.shape[0]))[0]).astype(int)
    return img[y - r:y + r + 1, x - r:x + r + 1].reshape(-1, 3).astype(int)


def chartreuse(px):
    """The cloth colour, lit, in shade or seen from below: green over red well over blue (no body's colour,
    the particles', the overlays', the background's or the floor's)."""
    return (px[:, 1] > px[:, 0] + 8) & (px[:, 0] > px[:, 2] + 25)


def teal(px):
    return (px[:, 1] > 2 * px[:, 0] + 20) & (px[:, 2] > 2 * px[:, 0] + 20)


def near(px, color, tol=45):
    return np.all(np.abs(px - 255 * np.asarray(color)) < tol, axis=1)


def covered(points, triangles, view, size=SIZE):
    """The pixels (height, width) bool that the triangles (T, 3) of ``points`` (m) cover, by the camera of
    ``view``: the picture a renderer of exactly those triangles would draw, rasterised by PIL."""
    uv = screen(points, view, size) - 0.5
    mask = Image.new("L", size, 0)
    draw = ImageDraw.Draw(mask)
    for tri in np.asarray(triangles):
        draw.polygon([tuple(uv[k]) for k in tri], fill=1)
    return np.asarray(mask, bool)


def test_a_sheet_is_drawn_in_the_cloth_colour_where_the_camera_puts_its_vertices(renderer):
    w = mb.World()
    w.add_static(mb.Plane())
    c = sheet(w)
    img = renderer.render_to_array(w, VIEW)
    x = c.positions
    for p in x[inner()]:
        assert chartreuse(patch(img, p, 1)).all(), p
    # each border vertex is on the sheet's outline: cloth on one side of it
    assert all(chartreuse(patch(img, p, 1)).any() for p in x[np.setdiff1d(np.arange(N * N), inner())])
    # not beyond the sheet's edge (the floor there), and the cloth is drawn once, as a surface: no particle
    # spheres at its vertices, no spring lines along its edges
    assert not chartreuse(patch(img, (0.0, HEIGHT, 0.5 * SIDE + 0.25), 2)).any()
    flat = img.reshape(-1, 3).astype(int)
    assert not teal(flat).any() and not near(flat, palette.PINNED_PARTICLE, 30).any()
    assert not near(flat, palette.SPRING, 40).any()
    # moved, it is drawn where it is now (and no longer where it was)
    c.positions = x + (0.0, 0.0, -1.0)
    moved = renderer.render_to_array(w, VIEW)
    assert chartreuse(patch(moved, x[N * N // 2] + (0.0, 0.0, -1.0), 2)).all()
    assert not chartreuse(patch(moved, x[N * N // 2] + (0.0, 0.0, 0.4), 2)).any()
    # without the cloth layer it is gone
    bare = renderer.render_to_array(w, VIEW, layers=("bodies", "particles", "constraints"))
    assert not chartreuse(bare.reshape(-1, 3).astype(int)).any()


def test_the_cloth_is_its_triangles_as_they_are_now_with_gaps_where_it_tore(renderer):
    """A 5 kg ball dropped onto a 20 x 20 sheet pinned along its border tears a hole through it (hung by its
    corners alone, the sheet tears off them, where its strain is highest, and falls).  The picture shows the
    cloth exactly where its present triangles lie (the reference rasteriser's cover), the background elsewhere;
    in the hole, which the triangles it had before tearing (between its original vertices, where they are now)
    would cover, there is only background."""
    w = mb.World()
    v, t = mb.cloth_grid(1.0, 1.0, 20, 20)
    c = w.add_cloth(v, t, mass=0.2, tear_strain=0.1, position=(0.0, 1.0, 0.0))
    index = np.arange(400).reshape(20, 20)
    c.pin(np.unique(np.concatenate([index[0], index[-1], index[:, 0], index[:, -1]])))
    w.add_body(mb.Sphere(0.1), position=(0.05, 1.5, 0.05), mass=5.0)
    for _ in range(60):
        w.step(1.0 / 60.0)
    assert c.torn > 0 and len(c) > 400 and not np.array_equal(c.triangles, t)
    view = OrbitCamera.looking((0.3, 2.4, 0.9), (0.0, 0.9, 0.0)).view()
    img = renderer.render_to_array(w, view, layers=("cloth",))
    x = c.positions
    now = covered(x, c.triangles, view)
    whole = covered(x[:400], t, view)                      # the untorn triangles, stretched over the gaps
    inside = ndimage.binary_erosion(now, iterations=2)     # (two pixels off every outline: antialiasing)
    outside = ~ndimage.binary_dilation(now, iterations=2)
    assert inside.sum() > 3000
    assert chartreuse(img[inside].astype(int)).mean() > 0.99
    assert near(img[outside].astype(int), palette.BACKGROUND, 3).all()
    hole = outside & whole
    assert hole.sum() > 100 and near(img[hole].astype(int), palette.BACKGROUND, 3).all()


def test_a_world_of_cloth_alone_is_framed(renderer):
    """With no body at all, the camera frames the cloth: all of it in view, filling a good part of it; the
    framing points are its vertices' boxes."""
    w = mb.World()
    c = sheet(w)
    assert not w.bodies and not w.particles
    img = mb.render_image(w, size=SIZE)
    fg = np.abs(img.astype(int) - 255 * np.asarray(palette.BACKGROUND)).max(axis=-1) > 40
    rows, cols = np.nonzero(fg)
    assert 0 < cols.min() and cols.max() < SIZE[0] - 1 and 0 < rows.min() and rows.max() < SIZE[1] - 1
    assert np.ptp(cols) > 0.5 * SIZE[0]
    assert chartreuse(img[fg].astype(int)).mean() > 0.95
    pts = world_points(w)
    assert len(pts) == 8 * N * N
    assert pts[:, 0].max() == pytest.approx(0.5 * SIDE + 0.5 * c.thickness)
    assert pts[:, 1].min() == pytest.approx(HEIGHT - 0.5 * c.thickness)


def test_both_faces_are_lit_and_the_sun_shows_through_to_the_underside(renderer):
    """Seen from below (the sun above), the sheet is the cloth colour and well lit, not black: a third of
    its top's brightness or more.  That light is the sun's, through the cloth: where a box above shades the
    sheet, its underside is darker too."""
    w = mb.World()
    c = sheet(w)
    lit, shaded = np.array([0.35, HEIGHT, 0.3]), np.array([-0.3, HEIGHT, -0.1])
    shade_box = w.add_static(mb.Box((0.15, 0.02, 0.15)), position=shaded + 0.5 * SUN)
    top = renderer.render_to_array(w, VIEW)
    below = OrbitCamera.looking((1.2, -0.4, 2.2), (0.0, 1.0, 0.0)).view()
    bottom = renderer.render_to_array(w, below)
    x = c.positions[inner()]
    x = x[np.linalg.norm(x - shaded, axis=1) > 0.35]        # (away from the box's shade)
    up = np.concatenate([patch(top, p, 1) for p in x])
    down = np.concatenate([patch(bottom, p, 1, below) for p in x])
    assert chartreuse(down).all()
    assert np.median(down[:, 1]) > 60
    assert np.median(down[:, 1]) > np.median(up[:, 1]) / 3
    # the shade of the box, seen from below through the sheet (the box itself is hidden behind it): darker,
    # lit by the sky alone, still green over red over blue
    dark = patch(bottom, shaded, 2, below)
    assert np.all((dark[:, 1] > dark[:, 0] + 4) & (dark[:, 0] > dark[:, 2] + 10))
    assert dark[:, 1].mean() < 0.6 * patch(bottom, lit, 2, below)[:, 1].mean()
    # and from above, the shade on the sheet's top
    assert patch(top, shaded, 2)[:, 1].mean() < 0.6 * patch(top, lit, 2)[:, 1].mean()
    w.remove(shade_box)
    bottom = renderer.render_to_array(w, below)
    assert patch(bottom, shaded, 2, below)[:, 1].mean() == pytest.approx(patch(bottom, lit, 2, below)[:, 1].mean(),
                                                                         abs=6)


def test_normals_are_smooth_and_follow_the_positions(renderer):
    """A sheet of 9 rows bent into a half cylinder (22.5 degrees between neighbouring facets), seen from above,
    is shaded without steps across its facets; turned edge-on to the sun, a flat sheet is darker than facing
    it."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    v, t = mb.cloth_grid(1.0, math.pi * 0.5, 5, 9)
    angle = v[:, 2] / 0.5                                    # arc length over the radius: -pi/2 .. pi/2
    bent = np.column_stack([v[:, 0], 0.5 * np.cos(angle), 0.5 * np.sin(angle)])
    w.add_cloth(bent, t, mass=0.1, position=(0.0, HEIGHT, 0.0))
    view = OrbitCamera.looking((0.0, HEIGHT + 3.0, 0.3), (0.0, HEIGHT, 0.0)).view()
    img = renderer.render_to_array(w, view, layers=("cloth",))
    # over the arch, 40 degrees either side of its top (across four facets), a fifth of a degree apart
    a = np.radians(np.linspace(-40.0, 40.0, 400))
    uv = np.floor(screen(np.column_stack([np.zeros(400), HEIGHT + 0.5 * np.cos(a), 0.5 * np.sin(a)]), view))
    px = img[uv[:, 1].astype(int), uv[:, 0].astype(int)].astype(int)
    assert chartreuse(px).all()
    green = px[:, 1]
    # the shading turns with the surface in many small steps (one shade per facet if the normals were the
    # facets'; their neighbours differ by 11 to 50 shades of green here)
    assert np.ptp(green) > 40 and len(np.unique(green)) > 30
    assert np.abs(np.diff(green)).max() <= 5
    # the normals come from the positions now: the flat sheet facing the sun, then turned edge-on to it
    w2 = mb.World(gravity=(0.0, 0.0, 0.0))
    flat = sheet(w2)
    centre = flat.positions.mean(axis=0)
    eye = centre + 2.5 * np.array([0.3, 0.9, 0.3]) / np.linalg.norm([0.3, 0.9, 0.3])
    view = OrbitCamera.looking(eye, centre).view()

    def facing(normal):
        """The sheet's vertices turned about its centre so that its normal (+y at rest) is ``normal``."""
        n = np.asarray(normal) / np.linalg.norm(normal)
        a = np.cross((0.0, 1.0, 0.0), n)
        s, cos = np.linalg.norm(a), n[1]
        k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]) / max(s, 1e-12)
        rot = np.eye(3) + s * k + (1 - cos) * k @ k
        return (flat.positions - centre) @ rot.T + centre

    p0 = flat.positions.copy()
    flat.positions = facing(SUN)
    towards = renderer.render_to_array(w2, view, layers=("cloth",))
    edge_on = np.cross(SUN, (0.0, 0.0, 1.0))
    flat.positions = facing(edge_on + 0.2 * np.asarray(view.eye - centre))
    grazing = renderer.render_to_array(w2, view, layers=("cloth",))
    flat.positions = p0
    a, b = patch(towards, centre, 3, view), patch(grazing, centre, 3, view)
    assert chartreuse(a).all() and chartreuse(b).all()
    assert b[:, 1].mean() < 0.75 * a[:, 1].mean()


def test_vertex_normals():
    v, t = mb.cloth_grid(1.0, 2.0, 4, 5)
    assert np.allclose(vertex_normals(v, t), (0.0, 1.0, 0.0))
    assert np.allclose(vertex_normals(v, t[:, ::-1]), (0.0, -1.0, 0.0))          # the other face
    # a tent: two equal triangles folded 90 degrees along their shared edge (0, 1): the edge's vertices take
    # the mean of the two faces' normals, the far corners their own face's; a vertex of no triangle, +y
    tent = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [5.0, 5.0, 5.0]])
    n = vertex_normals(tent, [[0, 1, 3], [0, 2, 1]])
    assert np.allclose(n[[0, 1]], (0.0, 1.0, 0.0))
    assert np.allclose(n[2], np.array([-1.0, 1.0, 0.0]) / math.sqrt(2.0))
    assert np.allclose(n[3], np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0))
    assert np.allclose(n[4], (0.0, 1.0, 0.0))
    # a fine sphere: each normal points out from the centre (within a degree)
    import trimesh
    ball = trimesh.creation.icosphere(subdivisions=4, radius=2.0)
    n = vertex_normals(ball.vertices + 7.0, ball.faces)
    assert np.all(np.einsum("ij,ij->i", n, ball.vertices / 2.0) > math.cos(math.radians(1.0)))


def test_one_surface_per_cloth_and_no_particles_nor_springs_for_it():
    w = mb.World()
    a = sheet(w)
    b = sheet(w, n=5, height=3.0)
    grain = w.add_particles([[0.0, 5.0, 0.0], [0.3, 5.0, 0.0]], radius=0.05)
    frame = WorldFrame(w, np.zeros(3), 5.0)
    surfaces = cloth_surfaces(frame)
    assert [type(s) for s in surfaces] == [Surface, Surface]
    assert np.array_equal(surfaces[0].positions, a.positions) and np.array_equal(surfaces[1].triangles, b.triangles)
    assert np.array_equal(surfaces[0].color, palette.CLOTH) and surfaces[0].pattern == SHEET
    assert np.allclose(surfaces[1].normals, (0.0, 1.0, 0.0))
    # the particles layer draws the particles only, the constraints layer no edge of a cloth
    (spheres,) = particle_spheres(frame)
    assert np.array_equal(spheres.centers, grain.positions)
    assert network_lines(frame) == []
    w.remove(grain)
    assert particle_spheres(frame) == []
    # a removed cloth is drawn no more
    w.remove(a)
    assert [s.positions.shape for s in cloth_surfaces(frame)] == [(25, 3)]
    w.remove(b)
    assert cloth_surfaces(frame) == []


def test_a_removed_cloth_leaves_nothing_and_the_floor_shows_its_shadow(renderer):
    w = mb.World()
    w.add_static(mb.Plane())
    c = sheet(w)
    img = renderer.render_to_array(w, VIEW)
    centre = c.positions.mean(axis=0)
    shadow = centre - SUN * centre[1] / SUN[1]                 # the sheet's centre, cast on the floor
    beside = shadow + (0.0, 0.0, 1.5)
    assert patch(img, shadow, 2).mean() < 0.7 * patch(img, beside, 2).mean()
    w.remove(c)
    img = renderer.render_to_array(w, VIEW)
    assert not chartreuse(img.reshape(-1, 3).astype(int)).any()
    assert patch(img, shadow, 2).mean() == pytest.approx(patch(img, beside, 2).mean(), rel=0.1)


def test_the_stats_line_counts_cloths():
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    assert "cloths" not in stats_line(w, contacts=0)
    c = sheet(w, n=10, side=0.5, tear_strain=0.2)
    assert stats_line(w, contacts=3) == ("bodies 0 (0 static, 0 asleep)  |  cloths 1 (100 vertices, 162 triangles, "
                                         "0 torn)  |  contacts 3  |  t 0.00 s")
    for _ in range(30):
        c.apply_force((-200.0, 0.0, 0.0), np.arange(10))
        c.apply_force((200.0, 0.0, 0.0), np.arange(90, 100))
        w.step(1.0 / 60.0)
    assert c.torn > 0
    assert f"cloths 1 ({len(c)} vertices, {len(c.triangles)} triangles, {c.torn} torn)" in stats_line(w, contacts=0)
    sheet(w, n=4)
    assert f"cloths 2 ({len(c) + 16} vertices, {len(c.triangles) + 18} triangles, {c.torn} torn)" \
        in stats_line(w, contacts=0)
    assert "particles" not in stats_line(w, contacts=0)       # (a cloth's vertices are not counted as particles)
    for cloth in w.cloths:
        w.remove(cloth)
    assert "cloths" not in stats_line(w, contacts=0)


def test_record_writes_a_playable_mp4_of_cloth(tmp_path):
    """A sheet falls onto a sphere: every frame shows it, lower each time until it drapes."""
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_static(mb.Sphere(0.3), position=(0.0, 0.3, 0.0))
    sheet(w, n=20, height=1.2)
    out = mb.record(w, tmp_path / "cloth.mp4", seconds=1.0, fps=12, size=(320, 180), camera=CAMERA, stats=True)
    assert out.stat().st_size > 0
    frames = read_frames(out)
    assert len(frames) == 12 and w.time == pytest.approx(1.0, abs=1e-9)
    rows = []
    for f in frames:
        assert f.shape == (180, 320, 3)
        mask = chartreuse(f.reshape(-1, 3).astype(int)).reshape(f.shape[:2])
        assert mask.sum() > 1000                                               # the sheet, through H.264
        rows.append(np.nonzero(mask)[0].mean())
    assert rows[6] > rows[0] + 5                                               # it fell (down the picture)
