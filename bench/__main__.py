"""``python -m bench``: Marbellous side by side with PyBullet, MuJoCo, Jolt and Rapier on the standard scenes.

Every scene is built once in Marbellous (``marbellous.scenes``; the ball-jointed chains, ``bench/chains.py``)
and translated body by body and joint by joint into each peer (``bench/peers``), stepped at 60 Hz, timed
over the ``step()`` calls only (best of the scene's repeats, which go round the engines in turn), and checked
by a sanity measure (``bench/scenes.py``).
``jolt-wasm`` and ``rapier-wasm`` are Jolt Physics and Rapier compiled to WebAssembly, run by node (their
npm packages are installed on first use into a cache outside the checkout, ``bench/peers/npm_cache.py``)
and timed inside node around each engine step.  ``jolt-native`` and ``jolt-native-2t`` (two threads) are Jolt
Physics compiled from its C++ source, a checkout the user names (``--jolt-source PATH`` or
``$MARBELLOUS_JOLT_SOURCE``), built with CMake on first use into the same cache (``bench/peers/jolt_build.py``)
and timed inside the program around each step, at the settings of ``jolt-wasm``.  A peer that is not installed
is reported and skipped.
Prints a table and writes ``bench/results/<date>-<host>.json`` with its bar plot beside it (``.png``);
``--write-docs`` also publishes the table and the plot as ``docs/bench/latest.md`` and ``latest.png``.
Runs from any directory: ``python -m bench`` with the checkout on the path, or ``python path/to/bench``.

    python -m bench                         all scenes, all engines (about 10-15 minutes on 2 cores)
    python -m bench --quick                 small scenes, few steps: a check of the harness
    python -m bench --scenes tower_20 pile_1k --engines marbellous pybullet
    python -m bench --engines marbellous jolt-wasm rapier-wasm
    python -m bench --engines marbellous jolt-native jolt-native-2t --jolt-source ~/src/JoltPhysics
    python -m bench --profile               add the per-stage profile of Marbellous' step per scene
    python -m bench --write-docs            a full run that updates docs/bench/latest.md and latest.png
"""
import argparse
import json
import math
import os
import sys
import time
import traceback

if not __package__:         # run as ``python path/to/bench``: the checkout's bench and marbellous packages
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "bench"   # noqa: A001 (makes the relative imports below resolve)

from .machine import describe  # noqa: E402
from .peers import Unsupported, jolt_build, make_peer, version  # noqa: E402
from .runs import MarbellousRun, timed_run  # noqa: E402
from .scenes import DT, SCENES  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
#: "marbellous-2t": Marbellous with ``World.threads = 2`` (parallel contact passes; the default is serial);
#: "jolt-native", "jolt-native-2t": Jolt Physics built from its C++ source, with one and two threads;
#: "jolt-wasm", "rapier-wasm": Jolt Physics and Rapier in WebAssembly, run by node
ENGINES = ("marbellous", "marbellous-2t", "pybullet", "mujoco", "jolt-native", "jolt-native-2t", "jolt-wasm",
           "rapier-wasm")


def warm_up(names=(), quick=False, thread_counts=(1,)):
    """Compile or load the step kernels the timed runs will take, so that no run times them: a few steps of a
    small world, then one step of each world scene of ``names`` with each of ``thread_counts`` (a scene's step
    is compiled for its kinds of shape and its size, and its first step would load that variant: 0.13 s of the
    1k pile's 600 steps).  Returns the seconds it took."""
    import marbellous as mb
    from marbellous.scenes.terrain import terrain_mesh

    t = time.perf_counter()
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_static(terrain_mesh(4))
    w.add_static(mb.Box((1.0, 1.0, 1.0)), position=(5.0, 0.0, 0.0))
    w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5, 0.0))
    w.add_body(mb.Sphere(0.5), position=(0.0, 1.5, 0.0))
    for _ in range(3):
        w.step(DT)
    for name in names:
        if not SCENES[name].world:
            continue
        for threads in thread_counts:
            world, _ = SCENES[name].build(quick)
            world.threads = threads
            world.step(DT)
    return time.perf_counter() - t


def run_world_scene(name, engine, quick, cap, steps=None):
    """One timed run of one engine on one stepped scene (``steps``: None for the scene's own)."""
    spec = SCENES[name]
    steps = spec.n_steps(quick) if steps is None else steps
    world, meta = spec.build(quick)
    if engine == "marbellous-2t":
        world.threads = 2
    run = MarbellousRun(world, DT) if engine.startswith("marbellous") else make_peer(engine, world, DT)
    try:
        res = timed_run(run, steps, samples=spec.samples, time_cap=cap, orientations=spec.poses)
    finally:
        run.close()
    out = {"status": "ok" if res["steps"] == steps else f"partial: stopped after {res['steps']} of {steps} steps "
           f"(time cap {cap:.0f} s)", "steps": res["steps"], "seconds": res["seconds"],
           "ms_per_step": 1e3 * res["seconds"] / res["steps"], "steps_per_s": res["steps"] / res["seconds"],
           "sanity": spec.sanity(res["positions"], meta, res["max_penetration"])}
    if quick and not spec.judged_when_quick:
        out["sanity"]["ok"] = None      # too few steps for the verdict (a pile has not settled): not judged
    if engine.startswith("marbellous"):
        from marbellous.state import layout as L
        out["contacts_last_step"] = int(world._state.stats[L.STAT_CONTACTS])
        out["iterations_last_step"] = int(world._state.stats[L.STAT_ITERATIONS])
    return out


def run_query_scene(engine, quick):
    """Sphere-vs-mesh queries (``bench/bench_mesh_query.py``) on the terrain mesh: microseconds per query
    called from Python (Marbellous' kernel in a compiled loop is reported in the sanity column)."""
    from marbellous.scenes.terrain import terrain_arrays

    from . import bench_mesh_query as q
    from .scenes import _terrain

    _, meta = SCENES["mesh_queries"].build(quick)
    mesh = _terrain(meta["cells"])
    centres = q.marble_positions(mesh, meta["queries"])
    if engine == "marbellous":
        kernel_us, per = q.time_kernel(mesh, centres)
        us = q.time_python(mesh, centres)
        sanity = {"kernel_us_per_query": kernel_us, "contacts_per_query": per, "ok": per >= 1.0}
    elif engine == "pybullet":
        v, t = terrain_arrays(meta["cells"])
        r = q.time_pybullet(v, t, {"random": centres})
        if r is None:
            raise ImportError("pybullet")
        us = r["random_us"]
        sanity = {"contacts_per_query": r["random_contacts"], "ok": r["random_contacts"] >= 1.0}
    elif engine == "mujoco":
        raise Unsupported("MuJoCo collides meshes as convex hulls")
    else:
        raise Unsupported("a query per request to its process would time the pipe, not the engine")
    return {"status": "ok", "steps": meta["queries"], "seconds": us * 1e-6 * meta["queries"], "ms_per_step": us * 1e-3,
            "steps_per_s": 1e6 / us, "sanity": sanity, "unit": "query (from Python)"}


def run_one(name, engine, quick, cap, steps=None):
    """One run's result dict; a missing or unsupported peer, or a failure, becomes a status, never a crash."""
    try:
        if not engine.startswith("marbellous") and version(engine) is None:
            return {"status": "not installed"}
        if engine == "marbellous-2t" and not SCENES[name].world:
            raise Unsupported("queries do not use the solver's threads (same as marbellous)")
        if SCENES[name].world:
            return run_world_scene(name, engine, quick, cap, steps)
        return run_query_scene(engine, quick)
    except Unsupported as e:
        return {"status": f"unsupported: {e}"}
    except Exception as e:        # a peer's failure is reported in the table, the run goes on
        traceback.print_exc()
        return {"status": f"error: {type(e).__name__}: {e}"}


def run_scene(name, engines, quick, cap):
    """Every engine on one scene: ``{engine: result}``, each engine's fastest run.  The scene's repeats go
    round the engines in turn (one run of each engine per round), so that a burst of load on a shared
    host slows the runs of every engine alike rather than all of one engine's."""
    results = {}
    steps = None        # once an engine hits the time cap, the others run as many steps as it did
    for _ in range(SCENES[name].repeats if SCENES[name].world else 1):
        for engine in engines:
            best = results.get(engine)
            if best is not None and "ms_per_step" not in best:
                continue    # not installed, unsupported or failed: not run again
            t = time.perf_counter()
            r = run_one(name, engine, quick, cap, steps)
            if r["status"].startswith("partial"):
                steps = r["steps"]
            if best is None or r.get("ms_per_step", math.inf) < best["ms_per_step"]:
                results[engine] = r
            print(f"  {name:16s} {engine:14s} {r.get('ms_per_step', math.nan):10.4f} ms/step  {r['status']}  "
                  f"({time.perf_counter() - t:.0f} s)", flush=True)
    return results


def _verdict(sanity):
    """The table's "ok" column: yes, NO, or n/a (quick) for a measure a quick run cannot judge."""
    if sanity.get("ok") is None:
        return "n/a (quick)"
    return "yes" if sanity["ok"] else "NO"


def _sanity_text(s):
    keys = [k for k in s if k != "ok"]
    return ", ".join(f"{k}={s[k]:.3g}" if isinstance(s[k], float) else f"{k}={s[k]}" for k in keys)


def table(results, engines):
    """The results as a text table: ms/step, steps/s, ratio to PyBullet's steps/s, sanity."""
    lines = [f"{'scene':24s} {'engine':14s} {'steps':>6s} {'ms/step':>10s} {'steps/s':>10s} {'vs PyBullet':>11s}"
             f"  ok    sanity"]
    for name, per in results.items():
        ref = per.get("pybullet", {}).get("steps_per_s")
        for engine in engines:
            r = per.get(engine)
            if r is None:
                continue
            if "steps_per_s" not in r:
                lines.append(f"{SCENES[name].label:24s} {engine:14s} {r['status']}")
                continue
            ratio = f"{r['steps_per_s'] / ref:.2f}x" if ref else "-"
            ok = _verdict(r["sanity"])
            note = "" if r["status"] == "ok" else f"  [{r['status']}]"
            lines.append(f"{SCENES[name].label:24s} {engine:14s} {r['steps']:6d} {r['ms_per_step']:10.4f} "
                         f"{r['steps_per_s']:10.1f} "
                         f"{ratio:>11s}  {ok:5s} {_sanity_text(r['sanity'])}{note}")
    return "\n".join(lines)


def plot(results, engines, machine, path):
    """Grouped bars of steps per second (log scale) per scene and engine; hatched where the sanity
    measure failed (a stack that fell, a marble that sank)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(results)
    fig, ax = plt.subplots(figsize=(max(6.0, 1.6 * len(names)), 4.5))
    width = 0.8 / len(engines)
    colours = {"marbellous": "#c0392b", "marbellous-2t": "#e67e22", "pybullet": "#2c3e50", "mujoco": "#7f8c8d",
               "jolt-native": "#1a3c6e", "jolt-native-2t": "#8e44ad", "jolt-wasm": "#2980b9", "rapier-wasm": "#27ae60"}
    for k, engine in enumerate(engines):
        xs, ys, hatches = [], [], []
        for i, name in enumerate(names):
            r = results[name].get(engine, {})
            if "steps_per_s" in r:
                xs.append(i + (k - (len(engines) - 1) / 2) * width)
                ys.append(r["steps_per_s"])
                hatches.append("xx" if r["sanity"].get("ok") is False else "")
        bars = ax.bar(xs, ys, width, label=engine, color=colours.get(engine), edgecolor="white")
        for bar, hatch in zip(bars, hatches):
            bar.set_hatch(hatch)
    ax.set_yscale("log")
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels([SCENES[n].label for n in names], rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("steps/s (queries/s), log")
    ax.set_title(f"Marbellous vs peers, 60 Hz, {machine['cpu']} ({machine['cores']} cores), {machine['date']}; "
                 f"hatched: sanity failed (e.g. the stack fell)", fontsize=9)
    ax.legend()
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def output_paths(machine, out=None, quick=False, plot=True, write_docs=False):
    """Where a run writes, as absolute paths: ``results`` (the JSON: ``out``, else
    ``bench/results/<date>-<host>[-quick].json`` in the checkout), ``plot`` (beside it, ``.png``; None
    without ``plot``), and with ``write_docs`` the published table and plot, ``docs_table`` and
    ``docs_plot`` (``docs/bench/latest.md``, ``latest.png``; else None).  Independent of the working
    directory."""
    results = os.path.abspath(out) if out else os.path.join(
        HERE, "results", f"{machine['date']}-{machine['hostname']}{'-quick' if quick else ''}.json")
    docs = os.path.join(ROOT, "docs", "bench")
    return {"results": results, "plot": os.path.splitext(results)[0] + ".png" if plot else None,
            "docs_table": os.path.join(docs, "latest.md") if write_docs else None,
            "docs_plot": os.path.join(docs, "latest.png") if write_docs else None}


def _docs_table(machine, text):
    return (f"# Latest benchmark ({machine['date']})\n\n`python -m bench` on {machine['cpu']}, "
            f"{machine['cores']} cores, Python {machine['python']}, NumPy {machine['numpy']}, Numba "
            f"{machine['numba']}, peers {machine['peers']}, commit {machine['git_commit']}"
            f"{' (with local changes)' if machine['git_dirty'] else ''}.  60 Hz; ms per step of the "
            f"`step()` calls only, best of the scene's repeats (taken round the engines in turn); "
            f"sphere-mesh queries in ms per query from Python.\n\n```\n{text}\n```\n\n"
            f"![steps per second](latest.png)\n")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m bench", description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES), help="scenes to run")
    ap.add_argument("--engines", nargs="+", choices=ENGINES, default=list(ENGINES), help="engines to run")
    ap.add_argument("--quick", action="store_true", help="small scenes, few steps (a check, not numbers)")
    ap.add_argument("--cap", type=float, default=150.0, help="most seconds of stepping per engine and scene")
    ap.add_argument("--profile", action="store_true", help="add Marbellous' per-stage profile of each scene")
    ap.add_argument("--out", default=None, help="results file (default bench/results/<date>-<host>.json)")
    ap.add_argument("--no-plot", action="store_true", help="skip the plot beside the results file")
    ap.add_argument("--write-docs", action="store_true",
                    help="also publish the table and plot as docs/bench/latest.md and latest.png")
    ap.add_argument("--jolt-source", metavar="PATH", default=None,
                    help=f"a Jolt Physics checkout (holding Jolt/ and Build/) for jolt-native and jolt-native-2t, "
                    f"built on first use (default ${jolt_build.ENV})")
    args = ap.parse_args(argv)
    if args.write_docs and args.quick:
        ap.error("--write-docs publishes a full run's numbers, not a --quick check")
    if args.jolt_source is not None:
        source = os.path.abspath(os.path.expanduser(args.jolt_source))
        problem = jolt_build.checkout_problem(source)
        if problem:
            ap.error(f"--jolt-source: {problem}")
        os.environ[jolt_build.ENV] = source     # for the native Jolt peers, in this process and its children

    machine = describe(ROOT, {e: version(e) for e in args.engines if not e.startswith("marbellous")})
    paths = output_paths(machine, args.out, args.quick, not args.no_plot, args.write_docs)
    print(f"{machine['cpu']}, {machine['cores']} cores, Python {machine['python']}, NumPy {machine['numpy']}, "
          f"Numba {machine['numba']}, peers {machine['peers']}")
    marbellous_engines = [e for e in args.engines if e.startswith("marbellous")]
    compile_s = warm_up(args.scenes if marbellous_engines else (), args.quick,
                        sorted({2 if e == "marbellous-2t" else 1 for e in marbellous_engines}))
    print(f"warm-up (compile or load the step kernels): {compile_s:.1f} s")
    results = {}
    for name in args.scenes:
        results[name] = run_scene(name, args.engines, args.quick, args.cap)
    profiles = {}
    if args.profile:
        for name in args.scenes:
            if SCENES[name].world:
                spec = SCENES[name]
                world, _ = spec.build(args.quick)
                for _ in range(spec.warmup_steps(args.quick)):
                    world.step(DT)
                world.profiling = True
                for _ in range(spec.profile_steps(args.quick)):
                    world.step(DT)
                profiles[name] = {k: 1e3 * v for k, v in world.profile.per_step().items()}
    text = table(results, args.engines)
    print()
    print(text)
    for name, row in profiles.items():
        print(f"profile {name:16s} " + "  ".join(f"{k} {1e3 * v:.1f}" for k, v in row.items()) + "  (us/step)")
    record = {"machine": machine, "quick": args.quick, "dt": DT, "warm_up_s": compile_s, "results": results,
              "profile_ms_per_step": profiles}
    os.makedirs(os.path.dirname(paths["results"]), exist_ok=True)
    with open(paths["results"], "w") as f:
        json.dump(record, f, indent=1)
    print("written", paths["results"])
    for key in ("plot", "docs_plot"):
        if paths[key] is not None:
            plot(results, args.engines, machine, paths[key])
            print("written", paths[key])
    if paths["docs_table"] is not None:
        with open(paths["docs_table"], "w") as f:
            f.write(_docs_table(machine, text))
        print("written", paths["docs_table"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
