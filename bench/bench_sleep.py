"""How soon a pile at rest falls asleep, and what it costs then, side by side with PyBullet.

The scene: 1,000 spheres of radius 0.5 m poured into a walled box (``marbellous.scenes.sphere_pile``, the
benchmark's pile), friction 0.5, once with the defaults (no rolling or torsional friction) and once with a
lever arm of 1 cm of each (2 % of the radius, a rubber ball's rolling resistance), 40 s at 60 Hz.
- Marbellous: its defaults (sleeping on: an island sleeps after 0.5 s below its rest tolerances);
- PyBullet: the same world (``bench/peers/pybullet_world.py``: rolling and spinning friction as lever arms,
  Bullet's default deactivation).
Reported per engine and friction: when the pile settled (the end of the last 0.1 s in which a sphere moved
faster than 0.5 m/s on average: the benchmark's "settled"), for Marbellous when every sphere was asleep, and
the ms per step (the ``step()`` calls only) over the last 10 s, when the pile lies still.

    python bench/bench_sleep.py [--quick] [--json FILE]
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402

DT = 1.0 / 60.0
#: steps between samples of the positions (0.1 s), and the speed (m/s) below which a sphere is at rest
SAMPLE, SETTLED_SPEED = 6, 0.5


def pile(count, lever):
    from marbellous.scenes import sphere_pile

    return sphere_pile(count=count, rolling_friction=lever, torsional_friction=lever)


def run(engine, count, lever, seconds):
    """``{"settled_s", "asleep_s", "ms_per_step_end"}`` of one run (``asleep_s`` None when not all asleep, or
    for PyBullet, which does not report it)."""
    world, spheres = pile(count, lever)
    if engine == "pybullet":
        from bench.peers.pybullet_world import PyBulletRun

        peer = PyBulletRun(world, DT)
        step, positions, asleep, close = peer.step, peer.positions, None, peer.close
    else:
        def positions():
            return np.array([b.position for b in spheres])

        def asleep():
            return all(b.is_sleeping for b in spheres)

        def step():
            world.step(DT)

        def close():
            pass
    steps = int(round(seconds / DT))
    tail = steps - int(round(10.0 / DT))
    last_fast, asleep_at, tail_seconds = 0.0, None, 0.0
    before = positions()
    for k in range(1, steps + 1):
        t = time.perf_counter()
        step()
        if k > tail:
            tail_seconds += time.perf_counter() - t
        if k % SAMPLE == 0:
            now = positions()
            speed = np.linalg.norm(now - before, axis=1).max() / (SAMPLE * DT)
            before = now
            if speed >= SETTLED_SPEED:
                last_fast = k * DT
            if asleep is not None and asleep_at is None and asleep():
                asleep_at = k * DT
    close()
    return {"settled_s": last_fast, "asleep_s": asleep_at, "ms_per_step_end": 1e3 * tail_seconds / (steps - tail)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="200 spheres, 15 s (a check of the script)")
    parser.add_argument("--json", help="write the results to this file")
    args = parser.parse_args()
    count, seconds = (200, 15.0) if args.quick else (1000, 40.0)
    engines = ["marbellous"] + (["pybullet"] if version("pybullet") else [])
    results = {}
    for lever in (0.0, 0.01):
        for engine in engines:
            r = run(engine, count, lever, seconds)
            results[f"{engine}/lever_{lever}"] = r
            asleep = "-" if r["asleep_s"] is None else f"{r['asleep_s']:.1f} s"
            print(f"{engine:11s} rolling/torsional {lever:4.2f} m: settled at {r['settled_s']:5.1f} s, all asleep "
                  f"at {asleep:>7s}, {r['ms_per_step_end']:.3f} ms per step over the last 10 s", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": describe(os.path.dirname(HERE), {"pybullet": version("pybullet")}),
                       "count": count, "seconds": seconds, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
