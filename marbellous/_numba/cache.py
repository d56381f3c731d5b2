"""Where compiled kernels are cached, and when a cached kernel is stale.

Numba keys a cached kernel by its own source file only, so when a kernel calls or inlines a kernel of
another file and that file changes, the cached caller is stale: it may compute with the old callee or
crash.  Here every kernel of the package is keyed by a fingerprint of the whole package's source (the
SHA-256 of every ``.py`` file's path and content): any edit anywhere recompiles what is used, and an
unchanged tree (a fresh clone, another checkout of the same commit) reuses its cache.

The cache directory is the first writable one of: ``$MARBELLOUS_CACHE_DIR``; ``__pycache__/kernels``
inside the package (a clone or a user install); ``$XDG_CACHE_HOME/marbellous`` or ``~/.cache/marbellous``;
the system's temporary directory.  With none writable, kernels are compiled in memory on every start
(``CACHE_DIR`` is None) rather than failing.  An administrator can share one warmed cache between users
by pointing ``MARBELLOUS_CACHE_DIR`` at a directory they can read (and the first run can write).
"""
import functools
import hashlib
import os
import tempfile

import numba
from numba.core import caching

#: the package's directory
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@functools.lru_cache(maxsize=None)
def source_fingerprint():
    """SHA-256 (hex) of the path and content of every ``.py`` file of the package."""
    h = hashlib.sha256()
    for root, dirs, files in os.walk(PACKAGE_DIR):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(root, name)
                h.update(os.path.relpath(path, PACKAGE_DIR).encode())
                with open(path, "rb") as f:
                    h.update(f.read())
    return h.hexdigest()


def _writable(path):
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
        return True
    except OSError:
        return False


def _choose_cache_dir():
    tag = hashlib.sha1(PACKAGE_DIR.encode()).hexdigest()[:12]
    user_cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidates = [os.environ.get("MARBELLOUS_CACHE_DIR"),
                  os.path.join(PACKAGE_DIR, "__pycache__", "kernels"),
                  os.path.join(user_cache, "marbellous", tag),
                  os.path.join(tempfile.gettempdir(), f"marbellous-{os.getuid() if hasattr(os, 'getuid') else 0}",
                               tag)]
    for path in candidates:
        if path and _writable(path):
            return path
    return None


#: the directory of the kernel cache, or None when nothing is writable (kernels compiled in memory)
CACHE_DIR = _choose_cache_dir()


class PackageCacheLocator(caching._CacheLocator):
    """Numba cache locator for the package's kernels: files under :data:`CACHE_DIR`, freshness by
    :func:`source_fingerprint`."""

    def __init__(self, py_func, py_file):
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(CACHE_DIR, os.path.relpath(os.path.dirname(py_file), PACKAGE_DIR))

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return source_fingerprint()

    def get_disambiguator(self):
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        path = os.path.abspath(py_file)
        if CACHE_DIR is None or not path.startswith(PACKAGE_DIR + os.sep):
            return None
        locator = cls(py_func, path)
        try:
            locator.ensure_cache_path()
        except OSError:
            return None
        return locator


def install():
    """Put :class:`PackageCacheLocator` first among Numba's cache locators (once); returns whether kernels
    can be cached at all."""
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    if PackageCacheLocator not in impl._locator_classes:
        impl._locator_classes.insert(0, PackageCacheLocator)
    return CACHE_DIR is not None and not numba.config.DISABLE_JIT
