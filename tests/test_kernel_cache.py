"""The kernel cache: each kernel keyed by its file and everything that file imports, and a place to live
even when the package and the home directory cannot be written."""
import os
import shutil
import subprocess
import sys

from marbellous._numba import cache

PKG = cache.PACKAGE_DIR


def _closure(rel):
    out, todo = set(), [os.path.join(PKG, rel)]
    while todo:
        p = todo.pop()
        if p not in out:
            out.add(p)
            todo.extend(cache._imported_files(p))
    return {os.path.relpath(p, PKG) for p in out}


def test_a_kernel_is_keyed_by_everything_it_can_reach():
    step = _closure(os.path.join("pipeline", "step.py"))
    # the step inlines the narrow phase, which calls the pair tests, and the solvers
    assert {os.path.join("dynamics", "contact_solver.py"), os.path.join("collision", "pairs", "sphere_sphere.py"),
            os.path.join("collision", "mesh", "mesh_collide.py"), os.path.join("_numba", "record.py"),
            os.path.join("state", "layout.py")} <= step
    # but not by the facade, the game or the renderer, whose edits cannot change a kernel
    assert not {f for f in step if f.startswith(("world.py", "body.py", "game", "render", "app"))}
    # a leaf kernel file depends on little
    assert _closure("math3d.py") <= {"math3d.py"} | {os.path.join("_numba", f) for f in
                                                     ("jit.py", "cache.py", "shared_compile.py", "progress.py",
                                                      "__init__.py")}


def test_the_fingerprint_follows_the_content_of_every_file_reached(monkeypatch):
    step = os.path.join(PKG, "pipeline", "step.py")
    leaf = os.path.join(PKG, "math3d.py")
    solver = os.path.join(PKG, "dynamics", "contact_solver.py")
    before_step, before_leaf = cache.source_fingerprint(step), cache.source_fingerprint(leaf)
    real = cache._read

    def edited(path):          # the solver's file as if it had been edited
        digest, text = real(path)
        return (b"edited" + digest, text) if path == solver else (digest, text)
    monkeypatch.setattr(cache, "_read", edited)
    cache.source_fingerprint.cache_clear()
    cache._stamp.cache_clear()
    try:
        assert cache.source_fingerprint(step) != before_step
        assert cache.source_fingerprint(leaf) == before_leaf
    finally:
        cache.source_fingerprint.cache_clear()
        cache._stamp.cache_clear()


def test_the_fingerprint_is_the_hash_of_each_reached_file_path_and_content_in_path_order():
    """A kernel's key is the SHA-256 over the files it reaches, in sorted order, of each file's path in the
    package then its own SHA-256: a pure function of the tree, so a fresh clone of it reuses a cache."""
    import hashlib
    step = os.path.join(PKG, "pipeline", "step.py")
    h = hashlib.sha256()
    for rel in sorted(_closure(os.path.join("pipeline", "step.py")), key=lambda r: os.path.join(PKG, r)):
        with open(os.path.join(PKG, rel), "rb") as f:
            h.update(rel.encode())
            h.update(hashlib.sha256(f.read()).digest())
    assert cache.source_fingerprint(step) == h.hexdigest()


def test_the_garbage_collector_is_frozen_at_exit_once_kernels_are_loaded():
    """Numba's compiler objects are not walked and disposed of one by one as the interpreter ends: the
    package's exit handler freezes the collector, after the handlers a program registers itself."""
    code = """
import atexit, gc
import marbellous as mb
w = mb.World()
w.add_body(mb.Sphere(0.1))
w.step(1 / 60)
atexit.register(lambda: print("user handler", gc.get_freeze_count() == 0))
atexit._run_exitfuncs()
print("frozen", gc.get_freeze_count() > 0)
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split("\n")[:2] == ["user handler True", "frozen True"]


def test_no_writable_place_means_kernels_compile_in_memory():
    """With every candidate directory unwritable (simulated: the write test fails), importing works and
    kernels still run, compiled without a cache."""
    code = """
import tempfile
def refuse(*a, **k):
    raise OSError("read-only")
tempfile.TemporaryFile = refuse
import marbellous as mb
from marbellous._numba import cache, jit
from marbellous.math3d import dot3
import numpy as np
print(cache.CACHE_DIR, jit.CACHING, dot3(np.ones(3), np.ones(3)))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["None", "False", "3.0"]


def test_the_cache_directory_can_be_chosen(tmp_path):
    code = "from marbellous._numba import cache; print(cache.CACHE_DIR)"
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path / "kernels"))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert r.stdout.strip() == env["MARBELLOUS_CACHE_DIR"]


STEP_ONCE = """
import marbellous as mb
w = mb.World(threads=2)
w.add_static(mb.Plane())
for k in range(80):
    w.add_body(mb.Sphere(0.25), position=(0.51 * (k % 9), 0.25 + 0.51 * (k // 81), 0.51 * (k // 9)))
for _ in range(3):
    w.step(1 / 60)
print(len(w.contacts()))
"""


def test_a_step_recompiled_against_cached_kernels_loads_in_the_next_process(tmp_path):
    """The step compiled in a process that loaded every other kernel from the cache (what an edit of the
    step's file leads to) is saved whole: the next process loads and runs it."""
    import marbellous as mb

    w = mb.World()                           # the step and its kernels in this process's cache
    w.add_body(mb.Sphere(0.5))
    w.step(1 / 60)
    shutil.copytree(cache.CACHE_DIR, tmp_path / "kernels", ignore=shutil.ignore_patterns("*.tmp.*"))  # not half-written
    for f in (tmp_path / "kernels" / "pipeline").glob("step.*"):
        f.unlink()
    env = dict(os.environ, MARBELLOUS_CACHE_DIR=str(tmp_path / "kernels"))
    runs = [subprocess.run([sys.executable, "-c", STEP_ONCE], capture_output=True, text=True, env=env,
                           timeout=1200) for _ in range(2)]          # compiles the step, then loads it
    for r in runs:
        assert r.returncode == 0, r.stderr[-2000:]
    assert runs[0].stdout == runs[1].stdout and int(runs[0].stdout) > 64
