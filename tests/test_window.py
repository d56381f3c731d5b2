"""`marbellous play` in a real window under Xvfb: xdotool presses keys and the marble moves."""
import os
import queue
import re
import subprocess
import sys
import threading
import time

import numpy as np

LINE = re.compile(r"t=([\d.]+) position=([-\d.]+),([-\d.]+),([-\d.]+)")


def reader(stream, q):
    for line in stream:
        q.put(line)


def wait_for(q, pred, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            line = q.get(timeout=max(0.01, end - time.monotonic()))
        except queue.Empty:
            break
        m = LINE.search(line)
        if m and pred(float(m.group(1))):
            return np.array([float(m.group(k)) for k in (2, 3, 4)]), float(m.group(1))
    raise AssertionError("the game printed no state in time")


def xdotool(display, *args):
    return subprocess.run(["xdotool", *args], env={**os.environ, "DISPLAY": display},
                          capture_output=True, text=True, timeout=30)


def test_arrow_key_rolls_the_marble_forward(xvfb, tmp_path):
    env = {**os.environ, "DISPLAY": xvfb, "MARBELLOUS_DATA_DIR": str(tmp_path)}
    game = subprocess.Popen([sys.executable, "-m", "marbellous.cli", "play", "--level", "blocks",
                             "--size", "480x270", "--print-state"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    q = queue.Queue()
    threading.Thread(target=reader, args=(game.stdout, q), daemon=True).start()
    try:
        found = xdotool(xvfb, "search", "--sync", "--name", "Marbellous")
        assert found.returncode == 0, found.stderr
        wid = found.stdout.split()[0]
        # let the marble settle on the ground
        before, t0 = wait_for(q, lambda t: t >= 1.0, 400)   # the first start may compile kernels
        xdotool(xvfb, "windowfocus", "--sync", wid)
        assert xdotool(xvfb, "keydown", "Up").returncode == 0
        # (one second: after two the marble is on the ramp, and rolls on into the brook's water, which
        # tints it, before the screenshot below is taken)
        after, _ = wait_for(q, lambda t: t >= t0 + 1.0, 120)
        xdotool(xvfb, "keyup", "Up")
        # the blocks level starts looking along +x: Up pushes the marble that way
        assert after[0] - before[0] > 0.5
        assert abs(after[2] - before[2]) < 0.3
        from PIL import ImageGrab

        shot = np.asarray(ImageGrab.grab(xdisplay=xvfb).convert("RGB")).astype(float) + 1.0
        red = (shot[..., 0] > 2.5 * shot[..., 1]) & (shot[..., 0] > 2.5 * shot[..., 2])
        assert red.sum() > 20          # the marble is on screen
    finally:
        game.terminate()
        try:
            game.wait(10)
        except subprocess.TimeoutExpired:
            game.kill()
    assert game.returncode is not None
