"""Cost of the time-stepping modes on the standard scenes, against ``"fixed"``.

For each scene (sphere pile 1k, box pyramid base 20, marble on the 131k-triangle mesh, one body) and
each mode (``"fixed"`` with ``ccd=True``, the default; ``"fixed"`` with ``ccd=False``; ``"retroactive"``;
``"conservative"``) the scene is built afresh, stepped at 60 Hz through a warm-up, then timed over the
``step()`` calls only.  Modes run in turn, ``--repeats`` rounds, best round kept (the machine is shared).
Also reports the mean intervals per step (``World.last_step.steps``) and time-of-impact events.

    python bench/bench_time.py                  the table (about 10 minutes on 2 cores)
    python bench/bench_time.py --quick          small scenes, few steps: a check of the script
    python bench/bench_time.py --modes fixed    only the default mode (before/after comparisons)
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.scenes import DT, build_scene  # noqa: E402

#: (label, World settings) of each mode
MODES = {
    "fixed": {"time_stepping": "fixed", "ccd": True},
    "fixed_noccd": {"time_stepping": "fixed", "ccd": False},
    "retroactive": {"time_stepping": "retroactive", "ccd": True},
    "conservative": {"time_stepping": "conservative", "ccd": True},
}
#: (scene name, warm-up steps, timed steps; quick: the same /10); the pyramid is timed while it settles
#: (asleep after ~3 s, when every mode costs the same few microseconds)
SCENES = (("pile_1k", 200, 200), ("pyramid_20", 5, 100), ("marble_terrain", 100, 2000), ("one_body", 100, 20000))


def run(scene, mode, warm, steps, quick):
    """(ms per step, mean intervals per step, toi events per step) of ``scene`` in ``mode``."""
    world, _ = build_scene(scene, quick)
    for key, value in MODES[mode].items():
        if key == "time_stepping" and not hasattr(world, "time_stepping"):
            if value != "fixed":
                return None
            continue
        setattr(world, key, value)
    for _ in range(warm):
        world.step(DT)
    clock = time.perf_counter
    intervals = events = 0
    report = hasattr(world, "last_step")
    seconds = 0.0
    for _ in range(steps):
        t = clock()
        world.step(DT)
        seconds += clock() - t
        if report:
            r = world.last_step
            intervals += r.steps
            events += r.toi_events
    return 1e3 * seconds / steps, intervals / steps if report else 1.0, events / steps if report else 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--modes", nargs="+", default=list(MODES), choices=list(MODES))
    parser.add_argument("--scenes", nargs="+", default=[s[0] for s in SCENES])
    parser.add_argument("--json", help="write the results to this file")
    args = parser.parse_args()
    results = {}
    for scene, warm, steps in SCENES:
        if scene not in args.scenes:
            continue
        if args.quick:
            warm, steps = max(1, warm // 10), max(1, steps // 10)
        for _ in range(args.repeats):
            for mode in args.modes:
                r = run(scene, mode, warm, steps, args.quick)
                if r is None:
                    continue
                best = results.get((scene, mode))
                if best is None or r[0] < best[0]:
                    results[(scene, mode)] = r
    print(f"{'scene':16s} {'mode':14s} {'ms/step':>10s} {'x fixed':>8s} {'intervals':>10s} {'toi/step':>9s}")
    for scene, _, _ in SCENES:
        base = results.get((scene, "fixed"))
        for mode in args.modes:
            r = results.get((scene, mode))
            if r is None:
                continue
            ratio = r[0] / base[0] if base else float("nan")
            print(f"{scene:16s} {mode:14s} {r[0]:10.4f} {ratio:8.2f} {r[1]:10.2f} {r[2]:9.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({f"{s}/{m}": v for (s, m), v in results.items()}, f, indent=1)


if __name__ == "__main__":
    main()
