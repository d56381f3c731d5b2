"""The npm packages of the WebAssembly peers, installed on first use into a cache outside the checkout.

The packages live in ``node_modules`` under an npm prefix: ``$MARBELLOUS_BENCH_NPM_DIR`` when set, else
``$XDG_CACHE_HOME/marbellous-bench/npm`` or ``~/.cache/marbellous-bench/npm``.  The first peer that needs them
runs ``npm install --prefix DIR`` with the exact versions of ``PACKAGES`` (a few seconds; it needs the npm
registry); later runs find them there.  Needs ``node`` (tested with 20) and, for that first install, ``npm`` on
the ``PATH``.
"""
import functools
import json
import os
import shutil
import subprocess
import sys

from .cache import cache_dir, exclusive

#: the npm packages and the exact versions the peers are run with
PACKAGES = {"jolt-physics": "1.1.0", "@dimforge/rapier3d-compat": "0.21.0"}
#: seconds the first install may take
INSTALL_TIMEOUT = 600.0


def prefix():
    """The npm prefix (a directory) the packages are installed under."""
    return os.environ.get("MARBELLOUS_BENCH_NPM_DIR") or cache_dir("npm")


def installed_version(directory, package):
    """The version of ``package`` installed under the npm prefix ``directory``, or None."""
    try:
        with open(os.path.join(directory, "node_modules", *package.split("/"), "package.json")) as f:
            return json.load(f).get("version")
    except (OSError, ValueError):
        return None


def _missing(directory):
    return [f"{name}@{v}" for name, v in PACKAGES.items() if installed_version(directory, name) != v]


@functools.cache
def _setup():
    """``(node, prefix, None)`` with every package in place, or ``(None, None, reason)``; tried once a process."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None:
        return None, None, "node is not on the PATH"
    directory = prefix()
    if not _missing(directory):
        return node, directory, None
    try:
        with exclusive(os.path.join(directory, "install.lock")):     # one install at a time
            return _install(node, npm, directory)
    except OSError as e:
        return None, None, f"npm install failed: {e}"


def _install(node, npm, directory):
    """:func:`_setup`'s install of the packages still missing under ``directory``."""
    wanted = _missing(directory)
    if not wanted:
        return node, directory, None
    if npm is None:
        return None, None, f"npm is not on the PATH (to install {' '.join(wanted)})"
    print(f"installing {' '.join(wanted)} into {directory} (first use)", file=sys.stderr, flush=True)
    try:
        r = subprocess.run([npm, "install", "--prefix", directory, "--no-audit", "--no-fund", "--save-exact",
                            *[f"{name}@{v}" for name, v in PACKAGES.items()]],
                           capture_output=True, text=True, timeout=INSTALL_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, None, f"npm install failed: {e}"
    still = _missing(directory)
    if r.returncode != 0 or still:
        tail = " ".join((r.stderr or r.stdout).split())[-400:]
        return None, None, f"npm install of {' '.join(still or wanted)} failed (exit {r.returncode}): {tail}"
    return node, directory, None


def node_and_prefix():
    """``(node executable, npm prefix)`` with every package of ``PACKAGES`` installed under the prefix,
    installing them there on first use; raises ImportError, saying why, when node or npm is missing or the
    install failed."""
    node, directory, reason = _setup()
    if reason is not None:
        raise ImportError(f"WebAssembly peers unavailable: {reason}")
    return node, directory
