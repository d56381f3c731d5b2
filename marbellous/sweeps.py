"""Parameter sweeps: a function run once per set of parameters, on this process, on a pool of local
processes, or on a Ray cluster, with the results gathered into one table in the order of the sets.

    from marbellous.game.trial import autopilot_trial
    rows = mb.sweep(autopilot_trial, mb.grid(level=["course", "hills"], friction=[0.2, 0.5, 0.8]),
                    backend="processes")
    mb.write_table(rows, "sweep.csv")

The function is called with each set's parameters as keyword arguments and returns a dict of results (numbers,
strings, booleans); a row of the table is the parameters followed by the results.  For the ``"processes"``
and ``"ray"`` backends the function must be importable by the workers (defined at the top level of a module,
not in ``__main__`` for processes).  A function of its parameters alone gives the same table on every backend.

Ray (``pip install "marbellous[cluster]"``) is the engine for more than one machine: with ``address=None``
a local Ray is started for the sweep (with ``workers`` CPUs) and stopped after it; with ``address="auto"`` or
``"ray://host:10001"`` the sweep joins that cluster; a Ray the caller already started is used as it is.
"""
from __future__ import annotations

import csv
import itertools
import math
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

from ._validate import as_choice, as_int

#: where the runs are computed
BACKENDS = ("serial", "processes", "ray")
#: the most runs in one sweep, and the most workers asked for
MAX_RUNS = 10 ** 7
MAX_WORKERS = 4096


def grid(**axes: Sequence) -> list[dict]:
    """Every combination of the values of ``axes`` (name = a non-empty sequence of values), as a list of
    parameter dicts; the last axis varies fastest: ``grid(a=[1, 2], b=["x", "y"])`` is
    ``[{a: 1, b: "x"}, {a: 1, b: "y"}, {a: 2, b: "x"}, {a: 2, b: "y"}]``."""
    values = []
    for name, axis in axes.items():
        if isinstance(axis, (str, bytes, Mapping)) or not isinstance(axis, (Sequence, range)):
            raise TypeError(f"{name} must be a sequence of values (a list, tuple or range), got {axis!r}")
        if len(axis) == 0:
            raise ValueError(f"{name} must hold at least one value")
        values.append(list(axis))
    if math.prod(len(v) for v in values) > MAX_RUNS:
        raise ValueError(f"the grid holds more than {MAX_RUNS} runs")
    return [dict(zip(axes, combination)) for combination in itertools.product(*values)]


def sweep(run: Callable[..., Mapping], runs: Sequence[Mapping], *, backend: str = "serial",
          workers: int | None = None, address: str | None = None) -> list[dict]:
    """``run(**parameters)`` for each parameter dict of ``runs`` (see :func:`grid`), computed by ``backend``
    (``"serial"``: here, one after another; ``"processes"``: a pool of ``workers`` local processes, default
    one per core; ``"ray"``: Ray tasks, on a local Ray of ``workers`` CPUs or on the cluster at ``address``).
    Returns one row per run, in the order of ``runs``: the parameters, then the results ``run`` returned (a
    dict whose keys are not parameter names).  Bad arguments raise before any run; an exception in a run is
    raised here."""
    if not callable(run):
        raise TypeError(f"run must be a function, got {run!r}")
    if isinstance(runs, (str, bytes, Mapping)) or not isinstance(runs, Sequence):
        raise TypeError(f"runs must be a sequence of parameter dicts (see grid), got {type(runs).__name__}")
    if len(runs) > MAX_RUNS:
        raise ValueError(f"runs must hold at most {MAX_RUNS} parameter dicts, got {len(runs)}")
    for k, parameters in enumerate(runs):
        if not isinstance(parameters, Mapping) or not all(isinstance(name, str) for name in parameters):
            raise TypeError(f"runs[{k}] must be a dict of parameters by name, got {parameters!r}")
    backend = as_choice("backend", backend, BACKENDS)
    if workers is not None:
        workers = as_int("workers", workers, lo=1, hi=MAX_WORKERS)
    if address is not None and (not isinstance(address, str) or backend != "ray"):
        raise ValueError(f"address is a Ray cluster's address (a str, backend 'ray'), got {address!r}")
    runs = [dict(parameters) for parameters in runs]
    if backend == "serial" or not runs:
        results = [run(**parameters) for parameters in runs]
    elif backend == "processes":
        results = _in_processes(run, runs, workers)
    else:
        results = _on_ray(run, runs, workers, address)
    return [_row(k, parameters, result) for k, (parameters, result) in enumerate(zip(runs, results))]


def _call(run, parameters):
    """``run(**parameters)``: what a worker computes."""
    return run(**parameters)


def _in_processes(run, runs, workers):
    """The results of ``runs`` on a pool of ``workers`` fresh processes ("spawn": no state of this one's
    threads is copied into them)."""
    workers = min(workers or os.cpu_count() or 1, len(runs))
    with ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn")) as pool:
        return list(pool.map(_call, [run] * len(runs), runs, chunksize=max(1, len(runs) // (4 * workers))))


def _on_ray(run, runs, workers, address):
    """The results of ``runs`` as Ray tasks, one per run."""
    try:
        import ray
    except ImportError:
        raise ImportError('the "ray" backend needs Ray: pip install "marbellous[cluster]"') from None
    started = not ray.is_initialized()
    if started:
        ray.init(address=address, num_cpus=workers if address is None else None, include_dashboard=False,
                 log_to_driver=False, configure_logging=False)
    try:
        task = ray.remote(_call)
        return ray.get([task.remote(run, parameters) for parameters in runs])
    finally:
        if started:
            ray.shutdown()


def _row(k, parameters, result):
    """The table's row of run ``k``: its parameters, then its results."""
    if not isinstance(result, Mapping):
        raise TypeError(f"run {k} returned {type(result).__name__}, not a dict of results")
    clash = sorted(set(parameters) & set(result))
    if clash:
        raise ValueError(f"run {k} returned results named as its parameters: {clash}")
    return {**parameters, **result}


def write_table(rows: Sequence[Mapping], path: str | os.PathLike) -> None:
    """Write ``rows`` (a sweep's table) to ``path`` as CSV: one column per key, in the order the keys first
    appear; a row without a key leaves its cell empty."""
    columns = list(dict.fromkeys(name for row in rows for name in row))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
