"""``mb.show`` in a real window under Xvfb: the world is drawn where its camera puts it, and xdotool's
keys pause, step, toggle overlays, reset and close."""
import os
import pathlib
import queue
import re
import subprocess
import sys
import threading

import numpy as np
import viewer_scene

from marbellous.render.bounds import world_points
from marbellous.render.orbit_camera import OrbitCamera
from marbellous.render.transforms import look_at, perspective

SIZE = (480, 270)
LINE = re.compile(r"viewer (\S+) t=([\d.]+) steps=(\d+) paused=([01]) layers=(\S+) first=(\S+)")
SCRIPT = f"""
import marbellous as mb
import viewer_scene
world, _ = viewer_scene.build()
mb.show(world, size={SIZE}, print_state=True)
"""


class Viewer:
    """The viewer in a subprocess, its state lines read as they come."""

    def __init__(self, display):
        tests = str(pathlib.Path(__file__).parent)
        env = {**os.environ, "DISPLAY": display,
               "PYTHONPATH": os.pathsep.join(p for p in (tests, os.environ.get("PYTHONPATH")) if p)}
        self.display = display
        self.proc = subprocess.Popen([sys.executable, "-c", SCRIPT], env=env, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)
        self.lines = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            m = LINE.search(line)
            if m:
                self.lines.put(dict(event=m[1], t=float(m[2]), steps=int(m[3]), paused=m[4] == "1",
                                    layers=m[5].split("+"), first=np.array([float(v) for v in m[6].split(",")])))

    def wait(self, event, timeout=60):
        """The next state line of ``event`` (e.g. ``"ready"``, ``"key=SPACE"``, ``"tick"``)."""
        while True:
            try:
                state = self.lines.get(timeout=timeout)
            except queue.Empty:
                raise AssertionError(f"the viewer printed no {event!r} line in time; stderr: "
                                     f"{self.proc.stderr.read() if self.proc.poll() is not None else ''}") from None
            if state["event"] == event:
                return state

    def xdotool(self, *args):
        return subprocess.run(["xdotool", *args], env={**os.environ, "DISPLAY": self.display},
                              capture_output=True, text=True, timeout=30)

    def key(self, name):
        assert self.xdotool("key", name).returncode == 0

    def close(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()


def screen_position(point):
    """Where the viewer's starting camera (framing every body) puts a world point: (column, row) in the
    window."""
    w, _ = viewer_scene.build()
    v = OrbitCamera.framing(world_points(w), SIZE[0] / SIZE[1]).view()
    c = perspective(v.fov, SIZE[0] / SIZE[1], 0.05, 400.0) @ look_at(v.eye, v.target) @ np.append(point, 1.0)
    return int(round((c[0] / c[3] + 1) / 2 * SIZE[0])), int(round((1 - c[1] / c[3]) / 2 * SIZE[1]))


def test_show_draws_the_world_and_answers_the_keys(xvfb):
    viewer = Viewer(xvfb)
    try:
        ready = viewer.wait("ready", timeout=400)        # the first start may load compiled kernels
        assert not ready["paused"] and ready["layers"] == ["bodies", "particles", "cloth", "soft", "fluids", "flow",
                                                           "constraints"]
        found = viewer.xdotool("search", "--sync", "--name", "Marbellous viewer")
        assert found.returncode == 0, found.stderr
        wid = found.stdout.split()[0]
        viewer.xdotool("windowfocus", "--sync", wid)
        geometry = dict(line.split("=") for line in viewer.xdotool("getwindowgeometry", "--shell", wid).stdout.split())
        x0, y0 = int(geometry["X"]), int(geometry["Y"])
        viewer.wait("tick")                              # (a few frames drawn since)

        from PIL import ImageGrab

        shot = np.asarray(ImageGrab.grab(xdisplay=xvfb).convert("RGB")).astype(int)
        _, parts = viewer_scene.build()

        def around(point, r=2):
            cx, cy = screen_position(point)
            return shot[y0 + cy - r:y0 + cy + r + 1, x0 + cx - r:x0 + cx + r + 1].reshape(-1, 3)

        for box in parts["stack"]:                       # dynamic boxes, resting where they started: warm while
            px = around(box.position)                    # awake, blue once asleep (the stack sleeps after 0.68 s)
            awake = (px[:, 0] >= px[:, 1]) & (px[:, 0] > 2 * px[:, 2] + 15)
            asleep = (px[:, 2] > px[:, 0] + 15) & (px[:, 2] > px[:, 1] + 10)
            assert np.all(awake) or np.all(asleep)
        floor = around((0.5, 0.0, 3.5))                  # the grey mesh floor
        assert np.all((np.ptp(floor, axis=1) < 30) & (floor.mean(axis=1) > 65))
        rod = [around(viewer_scene.ROD_ANCHOR - (0.0, t, 0.0), 2) for t in (0.4, 0.7, 1.0)]
        assert all((p.min(axis=1) > 200).any() for p in rod)            # the rod: a white line

        # space pauses: the time stands still
        viewer.key("space")
        paused = viewer.wait("key=SPACE")
        assert paused["paused"]
        assert viewer.wait("tick")["t"] == paused["t"]
        # N takes exactly one step (t is printed to 1 us)
        viewer.key("n")
        stepped = viewer.wait("key=N")
        assert stepped["steps"] == paused["steps"] + 1 and abs(stepped["t"] - paused["t"] - 1 / 60) < 2e-6
        # C and B toggle the overlays
        viewer.key("c")
        assert "contacts" in viewer.wait("key=C")["layers"]
        viewer.key("b")
        assert "boxes" in viewer.wait("key=B")["layers"]
        viewer.key("p")
        assert "particles" not in viewer.wait("key=P")["layers"]
        # space again runs on; R returns to the start
        viewer.key("space")
        assert not viewer.wait("key=SPACE")["paused"]
        later = viewer.wait("tick")
        assert later["t"] > stepped["t"]
        viewer.key("r")
        reset = viewer.wait("key=R")
        assert reset["t"] == 0.0 and reset["steps"] == 0
        assert np.allclose(reset["first"], parts["stack"][0].position, atol=1e-4)
        # Esc closes the window and show returns
        viewer.key("Escape")
        viewer.wait("closed")
        assert viewer.proc.wait(30) == 0
    finally:
        viewer.close()
