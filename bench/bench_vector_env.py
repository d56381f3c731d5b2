"""Env steps per second of ``"Marbellous-v0"`` vectorised: the native vector environment against gymnasium's sync
and async wrappers around the single environment, and around the same task with PyBullet as the physics
(``bench/peers/marble_env.py``; MuJoCo collides a mesh as its convex hull, so it has no peer on the concave
course), at N = 1, 16, 256, 1024 envs on the course level.

Each run makes the vector environment, resets it (seed 0), takes ``--warm`` steps of random actions, then
times ``--steps`` steps (best of ``--repeats`` rounds; the machine is shared).  Env steps per second is
``N * steps / seconds``.  gymnasium's async wrapper runs one process per env, each with its own interpreter,
Numba and kernels (~0.2 GB), so it is run only up to ``--max-async`` envs.

    python bench/bench_vector_env.py                    the table (a few minutes on 2 cores)
    python bench/bench_vector_env.py --quick            N = 1 and 16, few steps: a check of the script
    python bench/bench_vector_env.py --json bench/results/DATE-vm-vector-env.json
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.machine import describe  # noqa: E402
from bench.peers import version  # noqa: E402

#: the vectorisations compared: (label, how to make N of them)
KINDS = (("native", lambda n: _make_vec(n, vectorization_mode="vector_entry_point")),
         ("native_2_threads", lambda n: _make_vec(n, vectorization_mode="vector_entry_point", threads=2)),
         ("gymnasium_sync", lambda n: _make_vec(n, vectorization_mode="sync")),
         ("gymnasium_async", lambda n: _make_vec(n, vectorization_mode="async")),
         ("pybullet_sync", lambda n: _pybullet(n, asynchronous=False)),
         ("pybullet_async", lambda n: _pybullet(n, asynchronous=True)))
#: the kinds that start a process per env
ASYNC = ("gymnasium_async", "pybullet_async")


def _make_vec(n, **kwargs):
    import gymnasium as gym

    import marbellous  # noqa: F401  (registers the environment)

    return gym.make_vec("Marbellous-v0", num_envs=n, **kwargs)


def _pybullet(n, asynchronous):
    import gymnasium as gym

    from bench.peers.marble_env import PyBulletMarbleEnv

    return (gym.vector.AsyncVectorEnv if asynchronous else gym.vector.SyncVectorEnv)([PyBulletMarbleEnv] * n)


def env_steps_per_second(n, kind, warm, steps, repeats):
    """Env steps per second of ``n`` envs vectorised as ``kind`` (a label of :data:`KINDS`)."""
    import numpy as np

    envs = dict(KINDS)[kind](n)
    try:
        rng = np.random.default_rng(0)
        envs.reset(seed=0)
        for _ in range(warm):
            envs.step(rng.uniform(-1, 1, size=(n, 2)).astype(np.float32))
        best = float("inf")
        for _ in range(repeats):
            actions = rng.uniform(-1, 1, size=(steps, n, 2)).astype(np.float32)
            t = time.perf_counter()
            for a in actions:
                envs.step(a)
            best = min(best, time.perf_counter() - t)
        return n * steps / best
    finally:
        envs.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 16, 256, 1024])
    parser.add_argument("--steps", type=int, default=50)
    parser.add_argument("--warm", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--max-async", type=int, default=16)
    parser.add_argument("--max-pybullet", type=int, default=256,
                        help="most PyBullet envs (each client holds its own copy of the level's triangle BVH: "
                             "1,024 of them ran out of 24 GiB)")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--kinds", nargs="+", choices=[k for k, _ in KINDS], default=[k for k, _ in KINDS])
    parser.add_argument("--json", help="write the results to this file")
    args = parser.parse_args()
    if args.quick:
        args.sizes, args.steps, args.warm, args.repeats = [1, 16], 5, 1, 1
    results = {}
    for n in args.sizes:
        for kind in args.kinds:
            if kind in ASYNC and n > args.max_async or kind.startswith("pybullet") and n > args.max_pybullet:
                continue
            steps = max(2, args.steps * 16 // max(n, 16)) if n > 16 else args.steps
            rate = env_steps_per_second(n, kind, args.warm, steps, args.repeats)
            results[f"{n}/{kind}"] = rate
            print(f"N = {n:5d}  {kind:18s} {rate:10.0f} env steps/s", flush=True)
    single = results.get("1/native")
    if single:
        print("\nagainst the single environment's rate (N = 1, native):")
        for key, rate in results.items():
            print(f"  {key:28s} {rate / single:6.1f}x")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": describe(os.path.dirname(HERE), {"pybullet": version("pybullet")}),
                       "env_steps_per_second": results, "steps": args.steps, "repeats": args.repeats}, f, indent=1)


if __name__ == "__main__":
    main()
