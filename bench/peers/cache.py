"""Where the peers keep what they install or build outside the checkout, and the lock that lets one process at a
time fill it.

Everything lives under ``$XDG_CACHE_HOME/marbellous-bench`` (``~/.cache/marbellous-bench`` when that is unset):
the WebAssembly peers' npm packages (``npm_cache.py``) and the native Jolt builds (``jolt_build.py``).
"""
import contextlib
import fcntl
import os


def cache_dir(*parts):
    """The benchmark's cache directory, or the path ``parts`` under it (neither created)."""
    user_cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(user_cache, "marbellous-bench", *parts)


@contextlib.contextmanager
def exclusive(path):
    """Hold an exclusive lock on the file ``path`` (created with its directory if missing) for the ``with`` block:
    processes started together (test workers, benchmark runs) install or build once, the others waiting for it
    and then finding it done.  Raises OSError when the file cannot be made."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield
