"""A description of the machine and software a benchmark ran on, for the results file."""
import datetime
import json
import os
import platform
import socket
import subprocess


def cpu_model():
    """The CPU's model name from /proc/cpuinfo (or the platform's processor string elsewhere)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def git_commit(root):
    """``(commit, dirty)`` of the checkout at ``root``, or ``(None, None)`` outside git."""
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True,
                                check=True).stdout.strip()
        dirty = bool(subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                                    capture_output=True, text=True, check=True).stdout.strip())
        return commit, dirty
    except (OSError, subprocess.CalledProcessError):
        return None, None


def describe(root, peer_versions):
    """Date, host, CPU model, cores, OS, Python, NumPy, Numba, Marbellous, peers and git state."""
    import numba
    import numpy

    import marbellous

    commit, dirty = git_commit(root)
    return {"date": datetime.date.today().isoformat(),
            "time_utc": datetime.datetime.utcnow().isoformat(timespec="seconds"),
            "hostname": socket.gethostname(), "cpu": cpu_model(), "cores": os.cpu_count(),
            "os": platform.platform(), "python": platform.python_version(), "numpy": numpy.__version__,
            "numba": numba.__version__, "marbellous": marbellous.__version__, "peers": peer_versions,
            "git_commit": commit, "git_dirty": dirty}


def write_results(directory, name, record, path=None):
    """Write ``record`` (with its ``"machine"`` from :func:`describe`) to ``path``, or when it is None or empty
    as ``directory/<date>-<host>-<name>.json``; returns the path."""
    machine = record["machine"]
    if not path:
        os.makedirs(directory, exist_ok=True)
        path = os.path.join(directory, f"{machine['date']}-{machine['hostname']}-{name}.json")
    with open(path, "w") as f:
        json.dump(record, f, indent=1)
    return path
