"""Fixed cost of a step: one body, and 10,000 free bodies; cold (compiling) and warm (cached) start.

Run:  python bench/bench_step.py            (prints a table, writes bench/results/<date>-<host>-step.json)
"""
import datetime
import json
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
START_SNIPPET = ("import time; t = time.perf_counter(); import marbellous as mb; w = mb.World(); "
                 "w.add_body(mb.Sphere(0.5)); w.step(1/60); print(time.perf_counter() - t)")


def start_time(cache_dir=None):
    """Seconds for ``import marbellous`` + one step in a fresh interpreter; with ``cache_dir`` (an empty
    directory) the kernels are compiled there from nothing (a cold start), else loaded from the cache."""
    env = dict(os.environ)
    if cache_dir is not None:
        env["MARBELLOUS_CACHE_DIR"] = cache_dir
    out = subprocess.run([sys.executable, "-c", START_SNIPPET], capture_output=True, text=True, check=True,
                         env=env)
    return float(out.stdout.strip())


def steps_per_second(n_bodies, steps):
    import marbellous as mb

    w = mb.World(gravity=(0.0, -9.81, 0.0))
    for i in range(n_bodies):
        w.add_body(mb.Sphere(0.5), position=(2.0 * (i % 100), 1000.0, 2.0 * (i // 100)))  # 1 m apart
    w.step(1 / 60)
    t = time.perf_counter()
    for _ in range(steps):
        w.step(1 / 60)
    return steps / (time.perf_counter() - t)


def pybullet_one_body(steps):
    try:
        import pybullet as p
    except ImportError:
        return None
    cid = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81, physicsClientId=cid)
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.5, physicsClientId=cid)
    p.createMultiBody(1.0, shape, basePosition=(0, 0, 1000), physicsClientId=cid)
    p.setTimeStep(1 / 60, physicsClientId=cid)
    p.stepSimulation(physicsClientId=cid)
    t = time.perf_counter()
    for _ in range(steps):
        p.stepSimulation(physicsClientId=cid)
    rate = steps / (time.perf_counter() - t)
    p.disconnect(cid)
    return rate


def extra_stage_call_ns(calls=200_000):
    """Nanoseconds per call of a compiled entry that takes a world's step context by address and returns at
    once: what a subsystem stage (particles, cloth, fluids, ...) called besides the rigid-body step costs."""
    import marbellous as mb
    from marbellous._numba.jit import njit
    from marbellous._numba.record import compiled_entry
    from marbellous.pipeline.context import context_at, view

    @njit
    def empty_stage_at(address):
        return view(context_at(address)).nb

    w = mb.World()
    w.add_body(mb.Sphere(0.5))
    w.step(1 / 60)
    address = w._state.addresses[0]
    entry = compiled_entry(empty_stage_at, address)
    best = float("inf")
    for _ in range(5):
        t = time.perf_counter()
        for _ in range(calls):
            entry(address)
        best = min(best, (time.perf_counter() - t) / calls)
    return 1e9 * best


def main():
    results = {
        "cold_start_s": start_time(tempfile.mkdtemp(prefix="marbellous-cold-")),
        "warm_start_s": start_time(),
        "one_body_steps_per_s": steps_per_second(1, 50000),
        "free_10k_steps_per_s": steps_per_second(10000, 200),
        "pybullet_one_body_steps_per_s": pybullet_one_body(50000),
        "extra_stage_call_ns": extra_stage_call_ns(),
    }
    results["one_body_us_per_step"] = 1e6 / results["one_body_steps_per_s"]
    results["free_10k_ms_per_step"] = 1e3 / results["free_10k_steps_per_s"]
    for k, v in results.items():
        print(f"{k:32s} {v if v is None else round(v, 4)}")
    record = {"date": datetime.date.today().isoformat(), "machine": platform.platform(),
              "processor": platform.processor(), "cpus": os.cpu_count(), "python": platform.python_version(),
              "results": results}
    path = os.path.join(HERE, "results", f"{record['date']}-{socket.gethostname()}-step.json")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(record, f, indent=2)
    print("written", path)


if __name__ == "__main__":
    main()
