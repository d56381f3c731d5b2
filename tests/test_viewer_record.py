"""``mb.record`` and ``mb.render_image``: headless videos and pictures of any World, and their argument
checks; ``import marbellous`` loads no rendering package."""
import subprocess
import sys

import numpy as np
import pytest
import viewer_scene
from PIL import Image

import marbellous as mb
from marbellous.render import palette
from marbellous.render.video import read_frames


def test_record_writes_a_playable_mp4(tmp_path):
    w, parts = viewer_scene.build()
    top = parts["stack"][-1]
    top.velocity = (0.0, 0.0, 3.0)            # something moves: the top box slides off
    out = mb.record(w, tmp_path / "stack.mp4", seconds=1.0, fps=24, size=(320, 180), contacts=True, stats=True)
    assert out == tmp_path / "stack.mp4" and out.stat().st_size > 0
    frames = read_frames(out)
    assert len(frames) == 24
    assert w.time == pytest.approx(1.0, abs=1e-9)
    background = np.asarray(palette.BACKGROUND) * 255
    for f in frames:
        assert f.shape == (180, 320, 3)
        assert (np.abs(f - background).max(axis=-1) > 40).mean() > 0.1      # not blank
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 60  # and not still


def test_record_writes_a_gif_of_the_right_length(tmp_path):
    w, _ = viewer_scene.build()
    out = mb.record(w, str(tmp_path / "stack.gif"), seconds=0.5, fps=10, size=(160, 90))
    frames = read_frames(out)
    assert 1 <= len(frames) <= 5 and frames[0].shape == (90, 160, 3)
    with Image.open(out) as gif:   # (identical frames are merged, their durations added)
        total = 0
        for k in range(gif.n_frames):
            gif.seek(k)
            total += gif.info["duration"]
    assert total == 500


def test_render_image_returns_the_picture_and_saves_a_png(tmp_path):
    w, _ = viewer_scene.build()
    img = mb.render_image(w, tmp_path / "scene.png", size=(200, 120), camera=viewer_scene.CAMERA, boxes=True)
    assert img.shape == (120, 200, 3) and img.dtype == np.uint8
    with Image.open(tmp_path / "scene.png") as png:
        assert np.array_equal(np.asarray(png.convert("RGB")), img)
    # framing every body: all in view (the camera orbits their box's centre, so some margin is uneven)
    framed = mb.render_image(w, size=(200, 120))
    fg = np.abs(framed - np.asarray(palette.BACKGROUND) * 255).max(axis=-1) > 40
    rows, cols = np.nonzero(fg)
    assert 0 < cols.min() and cols.max() < 199 and 0 < rows.min() and rows.max() < 119
    assert np.ptp(cols) > 0.45 * 200 and np.ptp(rows) > 0.45 * 120


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(path="out.avi"), ValueError, "path must end in .mp4 or .gif"),
    (dict(path=3), TypeError, "path"),
    (dict(seconds=0.0), ValueError, "seconds must be > 0"),
    (dict(seconds=float("inf")), ValueError, "seconds must be finite"),
    (dict(seconds=float("nan")), ValueError, "seconds must be finite"),
    (dict(seconds="2"), TypeError, "seconds must be a real number"),
    (dict(fps=0), ValueError, "fps must be >= 1"),
    (dict(fps=29.97), TypeError, "fps must be an integer"),
    (dict(dt=-0.01), ValueError, "dt must be > 0"),
    (dict(size=(8, 100)), ValueError, "size must be 16 to 4096"),
    (dict(size=(640, 5000)), ValueError, "size must be 16 to 4096"),
    (dict(size=(640.0, 360)), TypeError, "size must be two integers"),
    (dict(size="640x360"), TypeError, "size must be two integers"),
    (dict(camera=((0, 1, 2),)), TypeError, "camera must be None or a pair"),
    (dict(camera=((0, 1, 2), (0, 1, 2))), ValueError, "camera eye and target must differ"),
    (dict(camera=((0, 1), (0, 1, 2))), ValueError, "camera eye"),
    (dict(contacts=1), TypeError, "contacts must be True or False"),
    (dict(world="world"), TypeError, "world must be a marbellous.World"),
])
def test_record_names_the_bad_argument(tmp_path, kwargs, error, message):
    args = dict(world=mb.World(), path=tmp_path / "out.mp4", seconds=1.0)
    args.update(kwargs)
    with pytest.raises(error, match=message):
        mb.record(args.pop("world"), args.pop("path"), **args)
    assert not (tmp_path / "out.mp4").exists()


def test_render_image_and_show_name_the_bad_argument(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match="path must end in .png"):
        mb.render_image(mb.World(), tmp_path / "x.jpg")
    with pytest.raises(ValueError, match="size"):
        mb.show(mb.World(), size=(10, 10))
    with pytest.raises(ValueError, match="dt must be > 0"):
        mb.show(mb.World(), dt=0.0)
    with pytest.raises(ValueError, match="max_steps_per_frame must be >= 1"):
        mb.show(mb.World(), max_steps_per_frame=0)
    with pytest.raises(TypeError, match="paused must be True or False"):
        mb.show(mb.World(), paused="yes")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if sys.platform.startswith("linux"):
        with pytest.raises(OSError, match="DISPLAY"):
            mb.show(mb.World())


def test_import_loads_no_rendering_package():
    code = ("import sys, marbellous as mb; assert callable(mb.show) and callable(mb.record); "
            "print(sorted(m for m in ('moderngl', 'pyglet', 'PIL', 'imageio') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
