"""Headless rendering through EGL: levels, the patterned marble, the flag, HUD, debug overlay, video."""
import numpy as np
import pytest

from marbellous.game.level import load_level
from marbellous.render.antialiasing import ANTIALIASING
from marbellous.render.renderer import DebugOverlay, Renderer
from marbellous.render.transforms import look_at, perspective
from marbellous.render.video import VideoWriter, read_frames
from marbellous.render.view import CameraView

SIZE = (320, 180)


@pytest.fixture(scope="module")
def ctx():
    from marbellous.render.context import headless_context

    c = headless_context()
    yield c
    c.release()


def marble_mask(img):
    """Pixels of the marble's saturated red and blue octants (no level material is that saturated)."""
    rgb = img.astype(float) + 1.0
    red = (rgb[..., 0] > 2.5 * rgb[..., 1]) & (rgb[..., 0] > 2.5 * rgb[..., 2])
    blue = (rgb[..., 2] > 2.5 * rgb[..., 0]) & (rgb[..., 2] > 1.8 * rgb[..., 1])
    return red, blue


def project(view, point, size=SIZE):
    """Pixel (column, row from the top) of a world point."""
    c = perspective(view.fov, size[0] / size[1], 0.05, 400.0) @ look_at(view.eye, view.target) @ np.append(point, 1)
    ndc = c[:3] / c[3]
    return (ndc[0] + 1) / 2 * size[0], (1 - ndc[1]) / 2 * size[1]


def behind(level, back=5.0, up=2.5):
    p = level.start_position
    d = np.array([np.cos(level.start_heading), 0.0, np.sin(level.start_heading)])
    return CameraView(eye=p - back * d + [0.0, up, 0.0], target=p.copy())


@pytest.mark.parametrize("name", ["course", "hills", "blocks"])
def test_level_and_marble_are_drawn(ctx, name):
    level = load_level(name)
    r = Renderer(ctx, level, 0.3, SIZE)
    view = behind(level)
    img = r.render_to_array(view, level.start_position, np.eye(3))
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    red, blue = marble_mask(img)
    assert red.sum() > 30 and blue.sum() > 30
    cx, cy = project(view, level.start_position)
    ys, xs = np.nonzero(red | blue)
    assert abs(xs.mean() - cx) < 8 and abs(ys.mean() - cy) < 8
    # the level is lit and shaded: not just sky, and more than a few distinct shades
    sky = np.all(np.abs(img.astype(int) - [178, 204, 234]) < 25, axis=-1)
    assert (~sky).mean() > 0.2
    assert len(np.unique(img.reshape(-1, 3) // 8, axis=0)) > 40


def test_marble_rotation_is_visible(ctx):
    level = load_level("blocks")
    r = Renderer(ctx, level, 0.3, SIZE)
    view = behind(level, back=1.5, up=0.6)
    a = r.render_to_array(view, level.start_position, np.eye(3))
    c, s = np.cos(0.6), np.sin(0.6)
    rolled = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    b = r.render_to_array(view, level.start_position, rolled)
    red_a, _ = marble_mask(a)
    red_b, _ = marble_mask(b)
    assert (red_a ^ red_b).sum() > 100


def test_goal_flag_billboard_faces_the_camera_from_any_side(ctx):
    level = load_level("blocks")
    r = Renderer(ctx, level, 0.3, SIZE)
    flag = r.flag_top + [0.0, -0.5, 0.0]
    for ang in np.linspace(0, 2 * np.pi, 5)[:-1]:
        eye = flag + 6.0 * np.array([np.cos(ang), 0.3, np.sin(ang)])
        img = r.render_to_array(CameraView(eye=eye, target=flag), (0.0, -50.0, 0.0), np.eye(3))
        cx, cy = project(CameraView(eye=eye, target=flag), flag)
        patch = img[int(cy) - 12:int(cy) + 12, int(cx) - 25:int(cx) + 25].astype(int)
        dark = (patch.max(axis=-1) < 60).sum()
        bright = (patch.min(axis=-1) > 200).sum()
        assert dark > 20 and bright > 20, ang


def test_every_antialiasing_draws_the_marble_and_fxaa_changes_only_edges(ctx):
    level = load_level("course")
    view = behind(level)
    imgs = {aa: Renderer(ctx, level, 0.3, SIZE, antialiasing=aa).render_to_array(view, level.start_position, np.eye(3))
            for aa in ANTIALIASING}
    for img in imgs.values():
        red, blue = marble_mask(img)
        assert red.sum() > 30 and blue.sum() > 30
    # FXAA leaves a pixel alone where it and its four diagonal neighbours span less than 1/16 of the luma range
    # (16 of 255); 10 keeps clear of rounding
    none, fxaa = imgs["none"].astype(float), imgs["fxaa"].astype(float)
    luma = none @ [0.299, 0.587, 0.114]
    pad = np.pad(luma, 1, mode="edge")
    around = np.stack([pad[1:-1, 1:-1], pad[:-2, :-2], pad[:-2, 2:], pad[2:, :-2], pad[2:, 2:]])
    flat = around.max(axis=0) - around.min(axis=0) < 10.0
    changed = np.any(none != fxaa, axis=-1)
    assert flat.mean() > 0.5 and not changed[flat].any()
    assert changed.sum() > 100                 # the edges are smoothed
    with pytest.raises(ValueError, match="antialiasing"):
        Renderer(ctx, level, 0.3, SIZE, antialiasing="ssaa")


def test_hud_and_debug_overlay(ctx):
    level = load_level("course")
    r = Renderer(ctx, level, 0.3, SIZE)
    view = behind(level)
    plain = r.render_to_array(view, level.start_position, np.eye(3))
    hud = r.render_to_array(view, level.start_position, np.eye(3), ["Course  time 0:12.3"])
    changed = np.any(plain != hud, axis=-1)
    ys, xs = np.nonzero(changed)
    assert changed.sum() > 200 and ys.max() < 60 and xs.min() < 30
    p = level.start_position - [0.0, 0.3, 0.0]
    dbg = r.render_to_array(view, level.start_position, np.eye(3),
                            debug=DebugOverlay(points=[p], normals=[[0.0, 1.0, 0.0]], grid=True))
    cyan = (dbg[..., 2] > 200) & (dbg[..., 1] > 180) & (dbg[..., 0] < 90)
    assert cyan.sum() > 100
    # the contact normal: a thin yellow line (anti-aliased, so blended with what lies behind it)
    only_contact = r.render_to_array(view, level.start_position, np.eye(3),
                                     debug=DebugOverlay(points=[p], normals=[[0.0, 1.0, 0.0]], grid=False))
    line = np.any(only_contact != plain, axis=-1)
    px = only_contact[line].astype(int)
    yellowish = (px[:, 0] - px[:, 2] > 60) & (px[:, 1] - px[:, 2] > 60)
    assert line.sum() > 10 and yellowish.mean() > 0.7


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_video_round_trip(tmp_path, suffix):
    frames = []
    for k in range(6):
        f = np.full((64, 96, 3), 30, np.uint8)
        f[20:44, 10 + 10 * k:34 + 10 * k] = (220, 40, 40)
        frames.append(f)
    out = tmp_path / f"v{suffix}"
    with VideoWriter(out, fps=10) as w:
        for f in frames:
            w.write(f)
    assert out.stat().st_size > 0
    back = read_frames(out)
    assert len(back) == len(frames)
    for k, f in enumerate(back):
        assert f.shape == (64, 96, 3)
        assert f[32, 22 + 10 * k, 0] > 150 and f[32, 22 + 10 * k, 1] < 100


def test_video_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match="out"):
        VideoWriter(tmp_path / "v.avi")
    with VideoWriter(tmp_path / "v.gif") as w:
        with pytest.raises(ValueError, match="frame"):
            w.write(np.zeros((4, 4), np.uint8))


def test_soft_blocks_are_drawn_in_their_colour(ctx):
    from marbellous.game.session import Game

    level = load_level("blocks")
    game = Game(level, flag=False)
    block = level.soft_blocks[0]
    r = Renderer(ctx, level, 0.3, SIZE, soft_bodies=game.soft_blocks)
    view = CameraView(eye=np.add(block.position, (0.0, 1.7, -4.5)), target=np.array(block.position))
    img = r.render_to_array(view, (0.0, -50.0, 0.0), np.eye(3))
    colour = np.array(block.material.color) * 255
    cx, cy = project(view, block.position)
    patch = img[int(cy) - 8:int(cy) + 8, int(cx) - 8:int(cx) + 8].astype(float)
    # lit or shaded, the block's pixels keep its hue: pink, red over green and blue
    assert np.all(patch[..., 0] > patch[..., 1] + 20) and np.all(patch[..., 0] > patch[..., 2] + 5)
    assert np.linalg.norm(patch.mean(axis=(0, 1)) / patch.mean() - colour / colour.mean()) < 0.35


def test_a_renderer_is_made_and_draws_on_its_context_after_another_came_and_went(ctx):
    """Making a context makes it current and releasing it leaves none current: a renderer on an earlier
    context still builds its shaders on that one and draws the same picture."""
    from marbellous.render.context import headless_context

    level = load_level("course")
    view = behind(level)
    expected = Renderer(ctx, level, 0.3, SIZE).render_to_array(view, level.start_position, np.eye(3))
    headless_context().release()
    r = Renderer(ctx, level, 0.3, SIZE)
    assert np.array_equal(r.render_to_array(view, level.start_position, np.eye(3)), expected)


def test_a_context_stays_usable_after_a_renderer_drew_on_it(ctx):
    """The renderer leaves its context current: what the caller does on it next (a program, a texture)
    works."""
    level = load_level("course")
    Renderer(ctx, level, 0.3, SIZE).render_to_array(behind(level), level.start_position, np.eye(3))
    ctx.program(vertex_shader="#version 330\nin vec3 p;\nvoid main() { gl_Position = vec4(p, 1.0); }",
                fragment_shader="#version 330\nout vec4 c;\nvoid main() { c = vec4(1.0); }")
