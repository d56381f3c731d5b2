"""Shared fixtures: compile the kernels once per session so tests time physics, not compilation; a fresh
X server for the window tests."""
import os
import shutil
import subprocess

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("marbellous", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("marbellous")


def pytest_xdist_auto_num_workers(config):
    """``-n auto``: one worker more than this process may use cores, so that while a worker waits for a kernel
    that another is compiling (marbellous/_numba/shared_compile.py), the spare worker runs tests on its core."""
    return len(os.sched_getaffinity(0)) + 1 if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1) + 1


@pytest.fixture(scope="session", autouse=True)
def warm_kernels():
    """Take one step of a small world so the step kernel is compiled (or loaded from cache) once."""
    import marbellous as mb

    w = mb.World()
    w.add_body(mb.Sphere(0.5), position=(0.0, 1.0, 0.0))
    w.step(1.0 / 60.0)
    yield


@pytest.fixture
def xvfb():
    """A fresh X server (Xvfb picks a free display number and reports it); yields the display name."""
    for tool in ("Xvfb", "xdotool"):
        if shutil.which(tool) is None:
            pytest.fail(f"{tool} is needed: apt-get install xvfb xdotool")
    r, w = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                            pass_fds=(w,), stderr=subprocess.DEVNULL)
    os.close(w)
    with os.fdopen(r) as f:
        display = ":" + f.readline().strip()
    yield display
    proc.terminate()
    proc.wait(10)
