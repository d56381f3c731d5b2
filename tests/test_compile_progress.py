"""The first run's progress line and notice while kernels compile (``_numba/progress.py``)."""
import io
import os
import subprocess
import sys
from types import SimpleNamespace

import pytest

from marbellous import math3d
from marbellous._numba import progress


class _Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def _event(dispatcher):
    return SimpleNamespace(data={"dispatcher": dispatcher})


def _compile(listener, clock, dispatcher, seconds):
    listener.on_start(_event(dispatcher))
    clock.now += seconds
    listener.on_end(_event(dispatcher))


@pytest.fixture(autouse=True)
def _default_setting(monkeypatch):
    monkeypatch.delenv("MARBELLOUS_PROGRESS", raising=False)


def test_a_short_compile_says_nothing():
    out, clock = io.StringIO(), _Clock()
    listener = progress.CompileProgress(out, clock)
    for _ in range(3):
        _compile(listener, clock, math3d.dot3, 0.5)
    listener.finish()
    assert out.getvalue() == ""


def test_a_long_compile_shows_what_how_far_and_how_long_then_the_notice():
    out, clock = io.StringIO(), _Clock()
    listener = progress.CompileProgress(out, clock)
    for _ in range(10):
        _compile(listener, clock, math3d.dot3, 1.0)
    lines = out.getvalue().splitlines()
    # not a terminal: the first line once compiling has lasted QUIET_SECONDS, then one per PLAIN_INTERVAL
    assert len(lines) == 1
    first = lines[0]
    assert first.startswith("marbellous: compiling kernels (first run only) ")
    assert f"/~{progress.FIRST_WORLD_KERNELS} math3d.dot3" in first
    assert "left" in first
    listener.finish()
    notice = out.getvalue().splitlines()[-1]
    assert notice.startswith("marbellous: compiled 10 kernels in 10 s; ")
    # and counting starts afresh
    assert listener.compiled == 0 and listener.started is None


def test_the_time_left_is_the_rate_so_far_over_the_kernels_still_to_come():
    out, clock = _Terminal(), _Clock()
    listener = progress.CompileProgress(out, clock)
    done = 30
    for _ in range(done):
        _compile(listener, clock, math3d.dot3, 1.0)     # 30 s for 30 kernels
    listener.on_start(_event(math3d.dot3))
    left = 30.0 * (progress.FIRST_WORLD_KERNELS - done) / done
    expected = f"{done}/~{progress.FIRST_WORLD_KERNELS} math3d.dot3, 30 s, ~{progress._duration(left)} left"
    assert out.getvalue().split("\r")[-1].rstrip() == "marbellous: compiling kernels (first run only) " + expected


def test_on_a_terminal_the_line_is_rewritten_in_place():
    out, clock = _Terminal(), _Clock()
    listener = progress.CompileProgress(out, clock)
    for _ in range(10):
        _compile(listener, clock, math3d.dot3, 1.0)
    text = out.getvalue()
    assert "\n" not in text and text.count("\r") >= 8
    listener.finish()
    assert out.getvalue().endswith("\n") and "compiled 10 kernels" in out.getvalue()


def test_kernels_of_other_packages_are_not_counted():
    out, clock = io.StringIO(), _Clock()
    listener = progress.CompileProgress(out, clock)
    other = SimpleNamespace(py_func=len)         # a builtin: not a marbellous kernel
    for _ in range(10):
        _compile(listener, clock, other, 1.0)
    listener.finish()
    assert listener.compiled == 0 and out.getvalue() == ""


def test_the_environment_can_silence_it(monkeypatch):
    monkeypatch.setenv("MARBELLOUS_PROGRESS", "0")
    out, clock = io.StringIO(), _Clock()
    listener = progress.CompileProgress(out, clock)
    for _ in range(10):
        _compile(listener, clock, math3d.dot3, 1.0)
    listener.finish()
    assert out.getvalue() == ""


def test_a_real_cold_compile_prints_the_line_and_the_notice(tmp_path):
    # a fresh cache directory: the kernel really compiles; MARBELLOUS_PROGRESS=1 reports even a short compile
    code = ("from marbellous._numba import progress; progress.install()\n"
            "from marbellous.math3d import dot3\n"
            "with progress.compiling():\n"
            "    print(dot3((1.0, 2.0, 3.0), (4.0, 5.0, 6.0)))\n")
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path), MARBELLOUS_PROGRESS="1")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "32.0"
    err = run.stderr.splitlines()
    assert err[0].startswith("marbellous: compiling kernels (first run only) 0/~")
    assert "math3d.dot3" in err[0]
    assert err[-1].startswith("marbellous: compiled ")
    assert f"cached in {tmp_path}" in err[-1]
    # the second run loads it from the cache: nothing compiles, nothing is said
    again = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert again.returncode == 0 and again.stderr == ""
