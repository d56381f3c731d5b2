"""A kernel compiled once among processes that need it at the same time.

Several processes of one installation often start cold together: a vector of environments in subprocesses, a
test run on every core, a batch of simulations launched at once.  Each would miss the kernel cache
(``cache.py``), compile the same kernel (the narrow phase with every pair test: two minutes of a core) and
save the same file.  Here a process that misses the cache first takes the kernel's lock, a file next to its
cache entry that one process at a time can lock (``flock``); a process that finds it locked waits, then
looks in the cache again and loads what the other compiled.  The holder lets go once the compile is saved,
or failed, or its process ended (the system releases the lock of a process that dies).

A kernel that calls others takes their locks while it holds its own; calls never go round in a circle, so
two processes never wait for each other, as long as a process that holds a lock never waits for another
process to compile that kernel (while this process compiles the step's entry, it never waits for the step's
helpers, ``pipeline/precompile.py``, to compile that entry).  A kernel that calls itself compiles on in the
process that holds its lock.  Where files cannot be locked (Windows, a file system without locks) or the wait passes
:data:`WAIT_SECONDS`, a process compiles as it would alone.
"""
import hashlib
import os
import time

from numba.core import caching, event, sigutils

from .cache import PackageCacheLocator
from .progress import PROGRESS, kernel_name

try:
    import fcntl
except ImportError:          # (Windows: no locks, every process compiles for itself)
    fcntl = None

#: the longest wait (s) for another process's compile: the dearest kernel takes about two minutes of a core, so a
#: holder past this is stopped or swapping, and this process compiles the kernel itself
WAIT_SECONDS = 900.0

#: the longest pause (s) between two looks at a lock
POLL = 0.2

#: the locks this process holds: (cache, argument types) -> file descriptor
_HELD = {}


def _try_lock(path):
    """An open descriptor of the file at ``path`` locked by this process, ``False`` if another process holds it,
    None if it cannot be locked at all."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return fd
    except BlockingIOError:
        os.close(fd)
        return False
    except OSError:
        os.close(fd)
        return None


def _lock(path):
    """The file at ``path`` locked, waiting while another process holds it (up to :data:`WAIT_SECONDS`):
    ``(descriptor or None, whether this process waited)``."""
    deadline = time.monotonic() + WAIT_SECONDS
    pause, waited = 0.01, False
    while True:
        fd = _try_lock(path)
        if fd is not False:
            return fd, waited
        if time.monotonic() > deadline:
            return None, waited
        waited = True
        time.sleep(pause)
        pause = min(2.0 * pause, POLL)


def _unlock(key):
    """Let go of the lock this process holds for ``key``, if it holds one."""
    fd = _HELD.pop(key, None)
    if fd is not None:
        os.close(fd)             # (closing the descriptor releases its lock)


class SharedCompileCache(caching.FunctionCache):
    """Numba's cache of one kernel, with a lock per signature so that processes missing the cache at the same
    time compile it once (see the module docstring).  ``kernel_name``: the kernel's name on the progress line."""

    def _key(self, sig):
        return id(self), tuple(sigutils.normalize_signature(sig)[0])

    def _lock_path(self, sig, target_context):
        """The lock file of ``sig``: beside the kernel's index, named by the digest of its index key (the
        argument types, the machine's target and the kernel's byte code)."""
        digest = hashlib.sha256(repr(self._index_key(sig, target_context.codegen())).encode()).hexdigest()[:16]
        return f"{self._cache_file._index_path[:-4]}.{digest}.lock"

    def load_overload(self, sig, target_context):
        """The cached compile of ``sig``; on a miss, this process holds the lock until it has saved its own
        compile (:meth:`save_overload`), after waiting for a process that was compiling it."""
        data = super().load_overload(sig, target_context)
        key = self._key(sig)
        if data is not None or fcntl is None or not self._enabled or key in _HELD:
            return data
        fd, waited = _lock(self._lock_path(sig, target_context))
        if fd is None:
            return None
        data = super().load_overload(sig, target_context) if waited else None
        if data is not None:
            os.close(fd)
            PROGRESS.compiled_elsewhere(self.kernel_name)
            return data
        _HELD[key] = fd
        return None

    def save_overload(self, sig, data):
        """Save the compile of ``sig``, then let the processes waiting for it load it."""
        try:
            super().save_overload(sig, data)
        finally:
            _unlock(self._key(sig))


class _FailedCompiles(event.Listener):
    """Lets go of the lock of a compile that raised (a typing error; Numba asking for literal arguments, after
    which it compiles another signature)."""

    def on_start(self, ev):
        pass

    def on_end(self, ev):
        # (``Event.is_failed`` answers the opposite in Numba 0.68; an event without the exception's details
        # counts as failed: the lock is let go early, and a waiting process compiles the kernel too)
        if getattr(ev, "_exc_details", True) is not None:
            dispatcher = ev.data["dispatcher"]
            _unlock((id(dispatcher._cache), tuple(ev.data["args"])))


event.register("numba:compile", _FailedCompiles())


def share(dispatcher):
    """Make the package kernel ``dispatcher`` compile once among processes (nothing for a kernel that is not
    cached in the package's cache); returns it."""
    cache = getattr(dispatcher, "_cache", None)          # (None: a plain function, ``NUMBA_DISABLE_JIT=1``)
    if type(cache) is caching.FunctionCache and isinstance(cache._impl.locator, PackageCacheLocator):
        cache.__class__ = SharedCompileCache      # (the same state; only the loading and saving differ)
        cache.kernel_name = kernel_name(dispatcher)
    return dispatcher
