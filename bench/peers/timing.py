"""Timing the peer engines side by side: the benches' command line, the best of several runs (and, for the
deformable benches, of runs that may blow up or be capped), and MuJoCo's step loop with its instability check."""
import argparse
import time


def bench_arguments(doc, engines=None):
    """The command line every side-by-side bench takes (``--quick``, ``--repeats``, ``--json FILE``), described
    by the first line of its docstring ``doc``: the parsed arguments.  Given ``engines`` (the bench's engine
    names), also ``--engines A,B``: the ones to run (``args.engines``, a list; all of them by default)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a smaller scene and fewer steps")
    parser.add_argument("--repeats", type=int, default=3, help="runs per engine, the fastest kept")
    parser.add_argument("--json", help="write the results to this file")
    if engines is not None:
        parser.add_argument("--engines", default=",".join(engines),
                            help=f"comma-separated engines to run, of {', '.join(engines)} (default: all)")
    args = parser.parse_args()
    if engines is not None:
        args.engines = [e.strip() for e in args.engines.split(",") if e.strip()]
        unknown = [e for e in args.engines if e not in engines]
        if unknown or not args.engines:
            parser.error(f"unknown engines {', '.join(unknown)}; choose from {', '.join(engines)}" if unknown
                         else "no engine given")
    return args


def best_results(runs, repeats, *scene):
    """Run each engine of ``runs`` (name -> ``run(*scene)`` returning ``(ms per step, measures...)``)
    ``repeats`` times and keep its fastest run: name -> that tuple, or ``{"failed": message}`` for an engine
    whose run raised RuntimeError; engines that are not installed (ImportError) are left out."""
    results = {}
    for name, run in runs.items():
        try:
            results[name] = min((run(*scene) for _ in range(repeats)), key=lambda r: r[0])
        except ImportError:
            continue
        except RuntimeError as e:
            results[name] = {"failed": str(e)}
    return results


class Capped(RuntimeError):
    """A run too slow to finish: stopped, and its engine not run at larger sizes."""


class BlewUp(RuntimeError):
    """A run whose points went non-finite or too fast, or that the engine flagged unstable: stopped, and its
    engine not run at larger sizes."""


class NotAvailable(Exception):
    """The engine cannot run this scene in the installed version."""


def best_of(run, repeats, n, long_run_s):
    """The fastest (``ms_per_step``) of up to ``repeats`` runs of ``run(n)`` (a results dict) with ``runs``, the
    number of runs (fewer after a run over ``long_run_s`` seconds), or ``{"failed": ...}``, ``{"blew_up": ...}``,
    ``{"capped": ...}``, ``{"skipped": ...}``; ImportError (a peer not installed) passes through."""
    best, runs = None, 0
    for _ in range(repeats):
        start = time.perf_counter()
        try:
            r = run(n)
        except NotAvailable as e:
            return {"skipped": str(e)}
        except Capped as e:
            return {"capped": str(e)}
        except BlewUp as e:
            return {"blew_up": str(e)}
        except RuntimeError as e:
            return {"failed": str(e)}
        except MemoryError as e:
            return {"failed": f"out of memory: {' '.join(str(e).split())}"}
        runs += 1
        if best is None or r["ms_per_step"] < best["ms_per_step"]:
            best = r
        if time.perf_counter() - start > long_run_s:
            break
    return {**best, "runs": runs}


def time_pybullet(p, kw, steps):
    """Milliseconds per ``stepSimulation`` of the PyBullet client ``kw`` over ``steps`` steps after a first one."""
    p.stepSimulation(**kw)
    seconds = 0.0
    for _ in range(steps):
        t = time.perf_counter()
        p.stepSimulation(**kw)
        seconds += time.perf_counter() - t
    return 1e3 * seconds / steps


def time_mujoco(model, data, steps, what):
    """Milliseconds per ``mj_step`` over ``steps`` steps after a first one; raises RuntimeError naming
    ``what`` if MuJoCo flagged the run unstable (NaN or huge accelerations, after which it resets it)."""
    import mujoco
    mujoco.mj_step(model, data)
    seconds = 0.0
    for _ in range(steps):
        t = time.perf_counter()
        mujoco.mj_step(model, data)
        seconds += time.perf_counter() - t
    if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
        raise RuntimeError(f"MuJoCo flagged {what} unstable (NaN or huge accelerations) and reset them")
    return 1e3 * seconds / steps
