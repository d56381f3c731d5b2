"""What the first run says while kernels compile: a progress line, then a one-line notice.

Kernels compile on first use and are cached (``cache.py``), so only a first run (a fresh install, or
after an upgrade) compiles; that takes minutes, and a silent terminal for minutes looks like a hang.
A Numba compile listener counts the package's kernels as they compile (here, and in the helper processes that
compile a step for this one, ``pipeline/precompile.py``) and, once compiling has gone on for
:data:`QUIET_SECONDS`, keeps one line on standard error up to date:

    marbellous: compiling kernels (first run only) 95/~190 dynamics.rigid.inverse_inertia_world, 20 s, ~20 s left

(on a terminal the line is rewritten in place; otherwise a line is printed every
:data:`PLAIN_INTERVAL` seconds).  When the operation that compiled finishes (:func:`compiling`), one
line says what was compiled and where it is cached, so that the next run starts fast.

The estimate of how many kernels a first world compiles (:data:`FIRST_WORLD_KERNELS`) is measured (the
notice's count); a run that compiles more simply counts on without a total.
``MARBELLOUS_PROGRESS=0`` in the environment silences both lines, ``=1`` prints them even for short
compiles.
"""
import atexit
import contextlib
import os
import sys
import time

from numba.core import event

from . import cache

#: kernels of the package that the first step of a first world compiles, in this process and the helper
#: processes that compile its lean step (``pipeline/precompile.py``), a sphere on a plane: 190 on 2026-12-05,
#: the notice's count with an empty ``MARBELLOUS_CACHE_DIR`` on two cores (a kernel two helpers both need
#: while neither has cached it counts twice); a run that compiles more counts on past it
FIRST_WORLD_KERNELS = 190

#: compiling shorter than this (s) says nothing (a kernel or two after an edit, a new variant)
QUIET_SECONDS = 2.0

#: seconds between lines when standard error is not a terminal (a log, CI)
PLAIN_INTERVAL = 15.0

#: seconds between rewrites of the line on a terminal
TERMINAL_INTERVAL = 0.25


def _setting():
    """``MARBELLOUS_PROGRESS``: "0" silent, "1" always, anything else (or unset) the default."""
    return os.environ.get("MARBELLOUS_PROGRESS", "")


def kernel_name(dispatcher):
    """``module.function`` of a package kernel without the ``marbellous.`` prefix, or None for a kernel of
    another package (Numba's own helpers compile too)."""
    func = getattr(dispatcher, "py_func", None)
    module = getattr(func, "__module__", "") or ""
    if not module.startswith("marbellous."):
        return None
    return f"{module[len('marbellous.'):]}.{func.__qualname__.replace('.<locals>.', '.')}"


def _duration(seconds):
    """``seconds`` as "38 s" or "2 min 5 s"."""
    seconds = int(round(seconds))
    return f"{seconds} s" if seconds < 60 else f"{seconds // 60} min {seconds % 60} s"


class CompileProgress(event.Listener):
    """Counts the package's kernels as Numba compiles them and reports on ``stream`` (see the module
    docstring).  ``clock`` is a function returning seconds (``time.monotonic``)."""

    def __init__(self, stream=None, clock=time.monotonic):
        self.stream = stream
        self.clock = clock
        self.compiled = 0            # kernels compiled since the last report of :func:`compiling`
        self.started = None          # when the first of them began
        self.shown = False           # whether a progress line has been written since then
        self.last_write = -1e9
        self.line_open = False       # a terminal line written without its newline

    # --- the listener ---------------------------------------------------------------------------------
    def on_start(self, ev):
        name = kernel_name(ev.data.get("dispatcher"))
        if name is None:
            return
        now = self.clock()
        if self.started is None:
            self.started = now
        self._report(name, now)

    def on_end(self, ev):
        if kernel_name(ev.data.get("dispatcher")) is not None:
            self.compiled += 1

    def compiled_elsewhere(self, name):
        """Count kernel ``name`` (``module.function``), which a helper process compiled for this one
        (``pipeline/precompile.py``)."""
        now = self.clock()
        if self.started is None:
            self.started = now
        self.compiled += 1
        self._report(name, now)

    # --- output -----------------------------------------------------------------------------------------
    def _out(self):
        return self.stream if self.stream is not None else sys.stderr

    def _terminal(self):
        out = self._out()
        return hasattr(out, "isatty") and out.isatty()

    def _report(self, name, now):
        setting = _setting()
        if setting == "0":
            return
        elapsed = now - self.started
        if elapsed < QUIET_SECONDS and setting != "1":
            return
        terminal = self._terminal()
        if now - self.last_write < (TERMINAL_INTERVAL if terminal else PLAIN_INTERVAL) and self.shown:
            return
        done = self.compiled
        if done == 0:
            how_far = f"0/~{FIRST_WORLD_KERNELS} {name}, {_duration(elapsed)}"
        elif done < FIRST_WORLD_KERNELS:
            left = elapsed * (FIRST_WORLD_KERNELS - done) / done
            how_far = f"{done}/~{FIRST_WORLD_KERNELS} {name}, {_duration(elapsed)}, ~{_duration(left)} left"
        else:
            how_far = f"{done} {name}, {_duration(elapsed)}"
        line = f"marbellous: compiling kernels (first run only) {how_far}"
        out = self._out()
        if terminal:
            out.write("\r" + line[:150].ljust(150))
            self.line_open = True
        else:
            out.write(line + "\n")
        out.flush()
        self.shown = True
        self.last_write = now

    def finish(self):
        """After an operation that may have compiled: if a progress line was shown, one line saying what was
        compiled and that later runs load it from the cache; then start counting afresh."""
        if self.shown and _setting() != "0":
            where = cache.CACHE_DIR
            later = (f"cached in {where}: later runs start in about a second" if where is not None else
                     "no cache directory is writable, so every run compiles again (set MARBELLOUS_CACHE_DIR)")
            out = self._out()
            if self.line_open:
                out.write("\r" + " " * 150 + "\r")
            out.write(f"marbellous: compiled {self.compiled} kernels in {_duration(self.clock() - self.started)}; "
                      f"{later}\n")
            out.flush()
        self.compiled = 0
        self.started = None
        self.shown = False
        self.line_open = False
        self.last_write = -1e9


#: the package's listener (installed once, by :func:`install`)
PROGRESS = CompileProgress()


def install():
    """Register :data:`PROGRESS` for Numba's compile events (once per process)."""
    if not getattr(install, "done", False):
        event.register("numba:compile", PROGRESS)
        atexit.register(PROGRESS.finish)
        install.done = True


@contextlib.contextmanager
def compiling():
    """Around an operation that may compile kernels (a world's first step): the notice when it is done."""
    try:
        yield
    finally:
        PROGRESS.finish()
