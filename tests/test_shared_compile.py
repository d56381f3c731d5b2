"""Processes that miss the kernel cache at the same time compile a kernel once: one holds the kernel's lock while
it compiles, the others wait and load what it saved; a compile that fails lets go of its lock."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from numba.core.errors import TypingError

from marbellous._numba import shared_compile

#: a process that waits for the file ``argv[1]``, then rasterises one triangle into a grid (a kernel of ~2 s to
#: compile) and prints how many times it compiled that kernel itself
CHILD = textwrap.dedent("""
    import os, sys, time
    import numpy as np
    from numba.core import event
    from marbellous.collision.mesh.grid2d import build_grid

    compiled = []

    class Count(event.Listener):
        def on_start(self, ev):
            pass

        def on_end(self, ev):
            compiled.append(ev.data["dispatcher"].py_func.__name__)

    event.register("numba:compile", Count())
    while not os.path.exists(sys.argv[1]):
        time.sleep(0.005)
    start, tris = build_grid(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
                             np.array([[0, 1, 2]]), np.zeros(1, np.bool_), 0.0, 0.0, 0.5, 2, 2, 0.0)
    assert len(tris) >= 3 and set(tris.tolist()) == {0}, tris
    print(compiled.count("build_grid"))
""")


@pytest.mark.skipif(shared_compile.fcntl is None, reason="no file locks on this system")
def test_processes_starting_cold_together_compile_a_kernel_once(tmp_path):
    go = tmp_path / "go"
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path / "cache"), MARBELLOUS_PROGRESS="0")
    children = [subprocess.Popen([sys.executable, "-c", CHILD, str(go)], env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True) for _ in range(3)]
    go.touch()                   # (all three miss the cache within milliseconds of each other)
    counts = []
    for child in children:
        out, err = child.communicate(timeout=600)
        assert child.returncode == 0, err
        counts.append(int(out.split()[-1]))
    assert sorted(counts) == [0, 0, 1]


def test_a_compile_that_fails_lets_go_of_its_lock():
    from marbellous.collision.mesh.grid2d import build_grid
    with pytest.raises(TypingError):
        build_grid(np.zeros((3, 3)), "not triangles", np.zeros(1, np.bool_), 0.0, 0.0, 0.5, 2, 2, 0.0)
    assert shared_compile._HELD == {}
