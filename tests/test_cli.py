"""The `marbellous` command: demo headless to a video, levels, and clear errors."""
import subprocess
import sys

import numpy as np

from marbellous.render.video import read_frames


def run(*args, tmp_path, module="marbellous.cli"):
    import os

    # every place the user's data could go is inside tmp_path (the demo must write none of it)
    env = {**os.environ, "MARBELLOUS_DATA_DIR": str(tmp_path / "data"), "HOME": str(tmp_path / "home"),
           "XDG_DATA_HOME": str(tmp_path / "xdg-data")}
    env.pop("DISPLAY", None)            # the demo needs no display
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=600)


def written_files(tmp_path, *dirs):
    """Files under the given subdirectories of ``tmp_path``."""
    return [p for d in dirs for p in (tmp_path / d).rglob("*") if p.is_file()]


def marble_pixels(img):
    rgb = img.astype(float) + 1.0
    red = (rgb[..., 0] > 2.5 * rgb[..., 1]) & (rgb[..., 0] > 2.5 * rgb[..., 2])
    blue = (rgb[..., 2] > 2.5 * rgb[..., 0]) & (rgb[..., 2] > 1.8 * rgb[..., 1])
    return int(red.sum()), int(blue.sum())


def test_demo_reaches_the_goal_headless_and_writes_a_video_showing_the_marble(tmp_path):
    out = tmp_path / "demo.mp4"
    r = run("demo", "--out", str(out), "--size", "320x180", "--fps", "10", tmp_path=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Traceback" not in r.stderr and "sparse" not in r.stderr, r.stderr   # no optional package missed
    last = r.stdout.strip().splitlines()[-1]
    assert last.startswith("goal reached in "), r.stdout
    seconds = float(last.split("(")[1].split(" s)")[0])
    assert 5.0 < seconds < 60.0
    assert "physics:" in r.stdout and "render:" in r.stdout
    assert out.stat().st_size > 10_000
    frames = read_frames(out)
    assert len(frames) >= 10 * seconds
    assert frames[0].shape == (180, 320, 3)
    # the marble (saturated red and blue octants) is on screen, near the middle, in almost every frame
    seen = 0
    for f in frames[::5]:
        red, blue = marble_pixels(f[30:150, 60:260])
        seen += red + blue > 20
    assert seen >= 0.9 * len(frames[::5])
    # the autopilot's time is not the player's: no best time (nor anything else) in the user's data
    assert written_files(tmp_path, "data", "home", "xdg-data") == []


def test_levels_lists_the_shipped_levels(tmp_path):
    r = run("levels", tmp_path=tmp_path)
    assert r.returncode == 0
    names = [line.split()[0] for line in r.stdout.splitlines()]
    assert {"course", "hills", "blocks"} <= set(names)


def test_levels_lists_without_starting_the_engine(tmp_path):
    code = ("import sys; from marbellous.cli import main; main(['levels']); "
            "print('engine loaded:', 'numba' in sys.modules or 'marbellous.world' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "course" in r.stdout and r.stdout.strip().splitlines()[-1] == "engine loaded: False"


def test_python_dash_m_marbellous_is_the_command(tmp_path):
    r = run("levels", tmp_path=tmp_path, module="marbellous")
    assert r.returncode == 0, r.stderr
    assert r.stdout == run("levels", tmp_path=tmp_path).stdout
    r = run("--version", tmp_path=tmp_path, module="marbellous")
    assert r.returncode == 0 and r.stdout.startswith("marbellous ")
    r = run("frobnicate", tmp_path=tmp_path, module="marbellous")
    assert r.returncode == 2 and "invalid choice" in r.stderr


def test_bad_arguments_give_clear_errors(tmp_path):
    r = run("demo", "--out", "x.avi", tmp_path=tmp_path)
    assert r.returncode == 2 and "--out must end in .mp4 or .gif" in r.stderr
    r = run("demo", "--level", "nowhere", tmp_path=tmp_path)
    assert r.returncode == 2 and "neither a shipped level" in r.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 3\n")
    r = run("demo", "--level", str(bad), tmp_path=tmp_path)
    assert r.returncode == 2 and "bad.toml" in r.stderr
    r = run("demo", "--seconds", "-1", tmp_path=tmp_path)
    assert r.returncode == 2 and "--seconds" in r.stderr
    r = run("play", tmp_path=tmp_path)
    assert r.returncode == 2 and "needs a display" in r.stderr
    r = run("frobnicate", tmp_path=tmp_path)
    assert r.returncode == 2


def test_short_gif_demo_reports_not_reached(tmp_path):
    out = tmp_path / "d.gif"
    r = run("demo", "--level", "blocks", "--out", str(out), "--seconds", "0.5", "--size", "96x64",
            "--fps", "10", tmp_path=tmp_path)
    assert r.returncode == 1
    assert r.stdout.strip().splitlines()[-1].startswith("goal not reached within 0.5")
    frames = read_frames(out)
    assert len(frames) == 5 and np.asarray(frames[0]).shape == (64, 96, 3)
