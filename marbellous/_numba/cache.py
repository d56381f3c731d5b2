"""Where compiled kernels are cached, and when a cached kernel is stale.

Numba keys a cached kernel by its own source file only, so when a kernel calls or inlines a kernel of
another file and that file changes, the cached caller is stale: it may compute with the old callee or
crash.  Here a kernel is keyed by the fingerprint of its file together with every file of the package
that it imports, directly or through others (the SHA-256 of their paths and contents): a kernel can
only reach code it imports, so editing a file recompiles exactly the kernels that may depend on it,
and an unchanged tree (a fresh clone, another checkout of the same commit) reuses its cache.

The cache directory is the first writable one of: ``$MARBELLOUS_CACHE_DIR``; ``__pycache__/kernels``
inside the package (a clone or a user install); ``$XDG_CACHE_HOME/marbellous`` or ``~/.cache/marbellous``;
the system's temporary directory.  With none writable, kernels are compiled in memory on every start
(``CACHE_DIR`` is None) rather than failing.  An administrator can share one warmed cache between users
by pointing ``MARBELLOUS_CACHE_DIR`` at a directory they can read (and the first run can write).
"""
import functools
import hashlib
import os
import re
import tempfile

import numba
from numba.core import caching

#: the package's directory
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@functools.cache
def _module_file(module):
    """The file of package module ``module`` (dotted), or None if it is not a file of the package."""
    rel = module.split(".")[1:]
    base = os.path.join(PACKAGE_DIR, *rel)
    for path in (base + ".py", os.path.join(base, "__init__.py")):
        if os.path.isfile(path):
            return path
    return None


#: an import statement: (leading dots, module, imported names) of ``from ... import ...``, or the module of
#: ``import ...``
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)"
                     r"|import[ \t]+([\w.]+))", re.M)


@functools.cache
def _read(path):
    """``(digest, text)`` of the file at ``path``."""
    with open(path, "rb") as f:
        data = f.read()
    return hashlib.sha256(data).digest(), data.decode("utf-8")


@functools.cache
def _imported_files(path):
    """The package files that the file at ``path`` imports (at any depth of its code)."""
    rel = os.path.relpath(path, PACKAGE_DIR)[:-3].split(os.sep)
    package = ["marbellous"] + rel[:-1]
    found = set()
    for dots, module, names, plain in _IMPORT.findall(_read(path)[1]):
        if plain:
            candidates = [plain]
        else:
            base = package[:len(package) - len(dots) + 1] if dots else []
            module = ".".join(base + ([module] if module else []))
            candidates = [module] + [f"{module}.{n.split(' as ')[0].strip()}"
                                     for n in names.strip("()").replace("\n", " ").split(",") if n.strip()]
        for name in candidates:
            target = _module_file(name) if name.startswith("marbellous") else None
            if target is not None and target != path:
                found.add(target)
    return frozenset(found)


@functools.cache
def source_fingerprint(path):
    """SHA-256 (hex) of the file at ``path`` and of every package file it imports, transitively."""
    closure, todo = set(), [os.path.abspath(path)]
    while todo:
        p = todo.pop()
        if p not in closure:
            closure.add(p)
            todo.extend(_imported_files(p))
    h = hashlib.sha256()
    for p in sorted(closure):
        h.update(_stamp(p))
    return h.hexdigest()


@functools.cache
def _stamp(path):
    """What the file at ``path`` adds to a fingerprint: its path in the package, then its SHA-256."""
    return os.path.relpath(path, PACKAGE_DIR).encode() + _read(path)[0]


@functools.cache
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
    :func:`source_fingerprint` of the kernel's file."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(CACHE_DIR, os.path.relpath(os.path.dirname(py_file), PACKAGE_DIR))

    def get_cache_path(self):
        return self._cache_path

    def ensure_cache_path(self):
        """Make the cache directory, and check that it is writable once per directory (Numba's own check
        writes a temporary file for every kernel: ~60 us each, 0.04 s of a start of 700 kernels)."""
        if not _writable(self._cache_path):
            raise OSError(f"cannot write kernels to {self._cache_path}")

    def get_source_stamp(self):
        return source_fingerprint(self._py_file)

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
