"""Timing the peer engines side by side: the best of several runs, and MuJoCo's step loop with its
instability check."""
import time


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
