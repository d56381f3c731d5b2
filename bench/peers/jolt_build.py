"""Jolt Physics built natively from its C++ source, on first use, for the native Jolt peers
(``jolt_native_world.py``).

The benchmark is pointed at a Jolt checkout, a directory holding ``Jolt/`` and ``Build/`` (a clone of
https://github.com/jrouwe/JoltPhysics, or those two directories of it): ``python -m bench --jolt-source PATH``, or
``MARBELLOUS_JOLT_SOURCE=PATH``.  Without one the native peers are "not installed".  The first run configures
and builds Jolt with the driver (``bench/peers/jolt_native/``: ``driver.cpp`` and its ``CMakeLists.txt``) with
CMake, and keeps the program in ``~/.cache/marbellous-bench/jolt-native/<key>/`` (``cache.cache_dir``), one
build at a time under a lock; later runs find it there.  The key hashes the source (its path, its git commit when
it is a git checkout, and the size and modification time of each of its files), the driver's two files, the
compiler and the build options: a change to any of them builds anew.  The build needs CMake 3.20 or later and a
C++17 compiler (``$CXX``, else CMake's choice), and takes about a minute and a half on 2 cores.

The build: Jolt's ``Distribution`` configuration (``-O3``; no asserts, profiler or debug renderer),
``-march=native``, link-time optimisation where CMake finds it supported, single precision, and Jolt's
instruction-set options (``USE_AVX2``, ``USE_AVX512``, ...) as this CPU reports them in ``/proc/cpuinfo``
(where there is no such file, Jolt's defaults: AVX2 and below).  ``CMakeLists.txt`` lists the rest.
"""
import functools
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys

from .cache import cache_dir, exclusive

#: the environment variable naming the Jolt checkout (``python -m bench --jolt-source`` sets it)
ENV = "MARBELLOUS_JOLT_SOURCE"
#: the directory of the driver's sources, and their names
DRIVER_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "jolt_native")
DRIVER_FILES = ("driver.cpp", "CMakeLists.txt")
#: the driver's CMake target and program
PROGRAM = "jolt_driver"
#: seconds the build may take
BUILD_TIMEOUT = 1800.0
#: Jolt's instruction-set options and the flags of ``/proc/cpuinfo`` each needs (Jolt compiles with
#: ``-mavx2 -mbmi -mpopcnt -mlzcnt -mf16c`` under ``USE_AVX2``, ``-mavx512f -mavx512vl -mavx512dq`` under
#: ``USE_AVX512``; ``abm`` is the CPU's name for lzcnt)
INSTRUCTION_SETS = {
    "USE_SSE4_1": ("sse4_1",),
    "USE_SSE4_2": ("sse4_2", "popcnt"),
    "USE_AVX": ("avx",),
    "USE_AVX2": ("avx2", "bmi1", "popcnt", "abm", "f16c"),
    "USE_AVX512": ("avx512f", "avx512vl", "avx512dq"),
    "USE_LZCNT": ("abm",),
    "USE_TZCNT": ("bmi1",),
    "USE_F16C": ("f16c",),
    "USE_FMADD": ("fma",),
}


def source():
    """The Jolt checkout the user named (``$MARBELLOUS_JOLT_SOURCE``) as an absolute path, or None."""
    path = os.environ.get(ENV)
    return os.path.abspath(os.path.expanduser(path)) if path else None


def checkout_problem(path):
    """Why ``path`` is not a Jolt checkout, or None when it is one."""
    if not (os.path.isfile(os.path.join(path, "Jolt", "Jolt.h"))
            and os.path.isfile(os.path.join(path, "Build", "CMakeLists.txt"))):
        return f"{path} is not a Jolt Physics checkout (no Jolt/Jolt.h and Build/CMakeLists.txt)"
    return None


def cpu_flags():
    """The CPU's flags as ``/proc/cpuinfo`` lists them (a set), or None where there is no such file."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return None


def instruction_sets(flags):
    """Jolt's instruction-set options (``{"USE_AVX2": "ON", ...}``) for a CPU with ``flags`` (``cpu_flags()``;
    None, unknown: no options, Jolt's defaults)."""
    if flags is None:
        return {}
    return {option: "ON" if all(f in flags for f in needs) else "OFF" for option, needs in INSTRUCTION_SETS.items()}


def _git_commit(path):
    """The commit checked out at ``path`` when ``path`` is the top of a git checkout, else None."""
    try:
        r = subprocess.run(["git", "-C", path, "rev-parse", "--show-toplevel", "HEAD"], capture_output=True,
                           text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = r.stdout.split()
    if r.returncode != 0 or len(lines) != 2 or os.path.realpath(lines[0]) != os.path.realpath(path):
        return None
    return lines[1]


def jolt_version(path):
    """Jolt's version at ``path`` (from ``Build/CMakeLists.txt``) with its commit when known: ``5.5.1@3b47ec390c``."""
    with open(os.path.join(path, "Build", "CMakeLists.txt")) as f:
        m = re.search(r"project\s*\(\s*JoltPhysics\s+VERSION\s+([0-9.]+)", f.read())
    version = m.group(1) if m else "unknown"
    commit = _git_commit(path)
    return f"{version}@{commit[:10]}" if commit else version


def _files(directory):
    """``(path relative to directory, size, modification time)`` of every file under ``directory``, sorted."""
    out = []
    for root, dirs, files in os.walk(directory):
        dirs[:] = sorted(d for d in dirs if d != ".git")
        for name in files:
            st = os.stat(os.path.join(root, name))
            out.append((os.path.relpath(os.path.join(root, name), directory), st.st_size, st.st_mtime_ns))
    return sorted(out)


def _compiler():
    """``(command, first line of its --version)`` of the C++ compiler CMake will pick, or None."""
    cxx = os.environ.get("CXX") or shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")
    if not cxx:
        return None
    try:
        r = subprocess.run([cxx, "--version"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return (cxx, (r.stdout.splitlines() or [""])[0]) if r.returncode == 0 else None


def build_key(path, options, compiler):
    """The cache key of a build of the checkout ``path`` with CMake ``options`` by ``compiler``."""
    digest = hashlib.sha256()
    for name in DRIVER_FILES:
        with open(os.path.join(DRIVER_DIR, name), "rb") as f:
            digest.update(f.read())
    digest.update(json.dumps([path, _git_commit(path), _files(os.path.join(path, "Jolt")),
                              _files(os.path.join(path, "Build")), compiler, options]).encode())
    return digest.hexdigest()[:16]


@functools.cache
def _setup(path):
    """``(program, version, None)`` with the driver built from the checkout ``path``, or ``(None, None, reason)``;
    tried once a process for each path."""
    problem = checkout_problem(path)
    if problem:
        return None, None, problem
    cmake, compiler = shutil.which("cmake"), _compiler()
    if cmake is None or compiler is None:
        return None, None, "cmake is not on the PATH" if cmake is None else "no C++ compiler found (set $CXX)"
    version = jolt_version(path)
    options = {"JOLT_SOURCE": path, "JOLT_NATIVE_VERSION": version, **instruction_sets(cpu_flags())}
    directory = cache_dir("jolt-native", build_key(path, options, compiler))
    program = os.path.join(directory, PROGRAM)
    if not os.path.isfile(program):
        try:
            with exclusive(directory + ".lock"):        # one build at a time; the others then find it done
                reason = None if os.path.isfile(program) else _build(cmake, directory, options, version)
        except OSError as e:
            reason = f"build failed: {e}"
        if reason:
            print(f"native Jolt: {reason}", file=sys.stderr, flush=True)
            return None, None, reason
    return program, version, None


def _build(cmake, directory, options, version):
    """Configure and build the driver with CMake into ``directory``; the reason it failed, or None.  The program
    is moved to ``directory`` and the build tree removed (about 110 MB); the build's output stays, ``build.log``."""
    print(f"building Jolt Physics {version} from {options['JOLT_SOURCE']} into {directory} (first use, a minute or "
          "two)", file=sys.stderr, flush=True)
    tree, log = os.path.join(directory, "build"), os.path.join(directory, "build.log")
    shutil.rmtree(tree, ignore_errors=True)     # a build that was stopped
    os.makedirs(directory, exist_ok=True)
    generator = ["-G", "Ninja"] if shutil.which("ninja") else []
    commands = [[cmake, "-S", DRIVER_DIR, "-B", tree, *generator, *[f"-D{k}={v}" for k, v in options.items()]],
                [cmake, "--build", tree, "--target", PROGRAM, "--parallel", str(os.cpu_count() or 1)]]
    with open(log, "w") as f:
        for command in commands:
            f.write("$ " + " ".join(command) + "\n")
            f.flush()
            try:
                r = subprocess.run(command, stdout=f, stderr=subprocess.STDOUT, timeout=BUILD_TIMEOUT)
            except (OSError, subprocess.TimeoutExpired) as e:
                return f"build failed: {e} (see {log})"
            if r.returncode != 0:
                with open(log) as g:
                    tail = " ".join(g.read().split())[-400:]
                return f"build failed (exit {r.returncode}, see {log}): {tail}"
    os.replace(os.path.join(tree, PROGRAM), os.path.join(directory, PROGRAM))
    shutil.rmtree(tree, ignore_errors=True)
    return None


def driver_and_version():
    """``(driver program, Jolt's version)``, building the driver on first use; raises ImportError, saying why, when
    no Jolt checkout is named, CMake or a compiler is missing, or the build failed."""
    path = source()
    if path is None:
        raise ImportError(f"native Jolt unavailable: no Jolt source (python -m bench --jolt-source PATH, or ${ENV})")
    program, version, reason = _setup(path)
    if reason is not None:
        raise ImportError(f"native Jolt unavailable: {reason}")
    return program, version
