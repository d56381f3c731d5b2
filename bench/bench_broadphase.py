"""Benchmark of the seven broad phases on uniform, clustered and sparse scenes of moving boxes.

For every scene (100, 1k, 10k, 100k boxes) and method: one fresh build, then ``STEPS`` updates with
motion.  Prints the time per update, the part of it spent maintaining the structure (``update`` alone)
and pairs per second (pairs reported / time per update),
checks that every method reports the same pairs as the first one, writes
``bench/results/<date>-<host>-broadphase.json`` and one plot per scene in ``docs/broadphase/``.

Run:  python bench/bench_broadphase.py            (about 2 minutes on 2 cores)
      python bench/bench_broadphase.py --quick    (up to 10k boxes)
"""
import argparse
import datetime
import json
import os
import platform
import socket
import time

import numba
import numpy as np

from marbellous.collision.broadphase import ALIVE, METHODS, find_pairs, make_state, update

STEPS = 6
# Times are the minimum over the STEPS updates: on a shared machine, other processes only ever add
# time, so the minimum is the best estimate of the method's own cost (the motion is slow enough
# that the steps are alike).
#: the three scenes of the issue, then two extra ones probing the lecture's claims
SCENES = ["uniform", "clustered", "sparse", "mixed", "fast"]
#: brute force needs n^2 / 2 box tests per update: 5e9 at 100k, minutes per step
BRUTE_LIMIT = 10_000
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def make_scene(kind, n, seed=0):
    """Boxes (centres, half extents, motion per step).  Half extents U(0.2, 0.5) m unless stated.

    uniform:   a cube sized for a 10 % volume fraction (about half a neighbour per box);
    clustered: n / 500 Gaussian clusters (at least 4) scattered through a cube 20x wider, each dense
               (about 30 % volume fraction in its core): piles of touching boxes with empty space between;
    sparse:    the uniform boxes spread through a cube 20x wider (8000x emptier): almost no pairs;
    mixed:     (extra) the clustered scene with 5 % of the boxes 10x larger and spread through the whole
               cube: sizes and density both vary;
    fast:      (extra) the uniform scene moving 50 % of a box edge per step instead of 1 %.
    Velocities have random directions; each step moves every box by its velocity.
    """
    rng = np.random.default_rng(seed)
    half = rng.uniform(0.2, 0.5, (n, 3))
    mean_volume = float(np.mean(np.prod(2 * half, axis=1)))
    side = (n * mean_volume / 0.10) ** (1 / 3)
    speed = 0.5 if kind == "fast" else 0.01
    if kind in ("uniform", "fast"):
        centres = rng.uniform(0, side, (n, 3))
    elif kind == "sparse":
        centres = rng.uniform(0, 20 * side, (n, 3))
    elif kind in ("clustered", "mixed"):
        k = max(4, n // 500)
        hubs = rng.uniform(0, 20 * side, (k, 3))
        sigma = 0.5 * ((n / k) * mean_volume / 0.30) ** (1 / 3)
        centres = hubs[rng.integers(0, k, n)] + rng.normal(0, sigma, (n, 3))
        if kind == "mixed":
            big = rng.random(n) < 0.05
            half[big] *= 10.0
            centres[big] = rng.uniform(0, 20 * side, (int(big.sum()), 3))
    else:
        raise ValueError(kind)
    velocity = rng.normal(0, 1, (n, 3))
    velocity *= speed * 0.7 / np.linalg.norm(velocity, axis=1, keepdims=True)
    return centres, half, velocity


def aabbs_of(centres, half):
    return np.hstack([centres - half, centres + half])


def dense_grid_cells(aabbs):
    """Cells a dense (array) grid of the grid method's cell size would need: the lecture's regular grid."""
    edge = np.median(np.max(aabbs[:, 3:] - aabbs[:, :3], axis=1))
    span = aabbs[:, 3:].max(axis=0) - aabbs[:, :3].min(axis=0)
    return float(np.prod(np.ceil(span / (2.0 * edge))))


def run_method(code, centres, half, velocity, steps):
    """Fresh state, one build, then ``steps`` updates with motion.  Returns the first call's time,
    the shortest time of the later ``find_pairs`` calls, the shortest time of ``update`` alone (maintaining
    the structure without listing pairs, timed on a second fresh state over the same motion), the
    pair counts and the last pair list."""
    n = len(centres)
    flags = np.full(n, ALIVE, np.int64)
    bits = np.full(n, -1, np.int64)
    state_f, state_i = make_state(code, n)
    out = np.empty((4 * n, 2), np.int64)
    c = centres.copy()
    times = []
    counts = []
    last = None
    for _ in range(steps + 1):
        a = aabbs_of(c, half)
        t0 = time.perf_counter()
        count = find_pairs(code, a, flags, bits, bits, n, state_f, state_i, out)
        if count > len(out):
            out = np.empty((2 * count, 2), np.int64)
            count = find_pairs(code, a, flags, bits, bits, n, state_f, state_i, out)
        times.append(time.perf_counter() - t0)
        counts.append(count)
        last = out[:count].copy()
        c += velocity
    state_f, state_i = make_state(code, n)
    c = centres.copy()
    maintain = []
    for _ in range(steps + 1):
        a = aabbs_of(c, half)
        t0 = time.perf_counter()
        update(code, a, flags, n, state_f, state_i)
        maintain.append(time.perf_counter() - t0)
        c += velocity
    return times[0], float(np.min(times[1:])), float(np.min(maintain[1:])), counts, last


def compile_all():
    """Compile (or load from the cache) every method before timing."""
    c, h, v = make_scene("uniform", 64)
    for code in METHODS.values():
        run_method(code, c, h, v, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="up to 10k boxes")
    args = parser.parse_args()
    sizes = [100, 1_000, 10_000] if args.quick else [100, 1_000, 10_000, 100_000]
    t_start = time.perf_counter()
    compile_all()
    print(f"compiled/loaded kernels in {time.perf_counter() - t_start:.1f} s")
    rows = []
    for kind in SCENES:
        for n in sizes:
            centres, half, velocity = make_scene(kind, n, seed=n)
            cells = dense_grid_cells(aabbs_of(centres, half))
            reference = None
            for name, code in METHODS.items():
                if name == "brute" and n > BRUTE_LIMIT:
                    print(f"{kind:9s} {n:7d} {name:7s} skipped: O(n^2) = {n * (n - 1) // 2:.2e} "
                          f"box tests per update")
                    continue
                build, per_update, maintain, counts, last = run_method(code, centres, half,
                                                                       velocity, STEPS)
                if reference is None:
                    reference = (name, counts, last)
                elif counts != reference[1] or not np.array_equal(last, reference[2]):
                    raise AssertionError(f"{name} disagrees with {reference[0]} on {kind} {n}")
                pairs = float(np.median(counts[1:]))
                row = {"scene": kind, "n": n, "method": name, "build_ms": 1e3 * build,
                       "update_ms": 1e3 * per_update, "maintain_ms": 1e3 * maintain,
                       "pairs": pairs,
                       "pairs_per_s": pairs / per_update, "dense_grid_cells": cells}
                rows.append(row)
                print(f"{kind:9s} {n:7d} {name:7s} build {1e3 * build:9.3f} ms  "
                      f"update {1e3 * per_update:9.3f} ms  (structure {1e3 * maintain:9.3f} ms)  "
                      f"pairs {pairs:8.0f}  {pairs / per_update:10.3e} pairs/s")
            print(f"{kind:9s} {n:7d} a dense grid of the same cell size would need {cells:.2e} cells")
    elapsed = time.perf_counter() - t_start
    print(f"total {elapsed:.0f} s")
    report(rows, elapsed, args.quick)


def fastest_overall(rows):
    """The method with the smallest mean, over the issue's three scenes and all sizes, of its update
    time relative to the fastest method on that scene and size."""
    score = {}
    for (kind, n) in {(r["scene"], r["n"]) for r in rows if r["scene"] in SCENES[:3]}:
        group = [r for r in rows if r["scene"] == kind and r["n"] == n]
        best = min(r["update_ms"] for r in group)
        for r in group:
            score.setdefault(r["method"], []).append(r["update_ms"] / best)
    full = {m: float(np.mean(v)) for m, v in score.items() if len(v) == max(map(len, score.values()))}
    return min(full, key=full.get), full


def report(rows, elapsed, quick):
    winner, scores = fastest_overall(rows)
    print("mean update time relative to the fastest method (uniform, clustered, sparse; all sizes):")
    for m, s in sorted(scores.items(), key=lambda kv: kv[1]):
        print(f"  {m:7s} {s:6.2f}")
    print(f"fastest overall: {winner}")
    host = socket.gethostname()
    date = datetime.date.today().isoformat()
    machine = {"host": host, "platform": platform.platform(), "processor": platform.processor(),
               "cpus": os.cpu_count(), "python": platform.python_version(),
               "numpy": np.__version__, "numba": numba.__version__}
    result = {"benchmark": "broadphase", "date": date, "machine": machine, "steps": STEPS,
              "quick": quick, "seconds": elapsed, "rows": rows, "relative_update_time": scores,
              "fastest_overall": winner}
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    path = os.path.join(HERE, "results", f"{date}-{host}-broadphase.json")
    with open(path, "w") as fh:
        json.dump(result, fh, indent=1)
    print(f"wrote {path}")
    print(markdown_tables(rows))
    plot(rows)


def _ms(v):
    """Milliseconds with three significant digits or so."""
    return f"{v:.3f}" if v < 1 else f"{v:.2f}" if v < 10 else f"{v:.1f}" if v < 100 else f"{v:.0f}"


def markdown_tables(rows):
    """One Markdown table per scene: ms per update (structure upkeep in parentheses), the fastest
    in bold, then pairs per update, pairs per second of the fastest and the dense grid's cells."""
    lines = []
    for kind in SCENES:
        group = [r for r in rows if r["scene"] == kind]
        sizes = sorted({r["n"] for r in group})
        lines += ["", f"**{kind}**: ms per update (structure upkeep alone)", "",
                  "| method | " + " | ".join(f"{n:,}" for n in sizes) + " |",
                  "|---|" + "---:|" * len(sizes)]
        for name in METHODS:
            cells = []
            for n in sizes:
                hit = [r for r in group if r["n"] == n and r["method"] == name]
                if not hit:
                    cells.append("skipped")
                    continue
                r = hit[0]
                cell = _ms(r["update_ms"])
                if name not in ("brute", "grid"):
                    cell += f" ({_ms(r['maintain_ms'])})"
                if r["update_ms"] == min(q["update_ms"] for q in group if q["n"] == n):
                    cell = f"**{cell}**"
                cells.append(cell)
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        first = {n: next(r for r in group if r["n"] == n) for n in sizes}
        best = {n: max(r["pairs_per_s"] for r in group if r["n"] == n) for n in sizes}
        lines.append("| pairs per update | " + " | ".join(f"{first[n]['pairs']:.0f}" for n in sizes)
                     + " |")
        lines.append("| pairs/s, fastest | " + " | ".join(f"{best[n]:.2e}" for n in sizes) + " |")
        lines.append("| dense grid cells | "
                     + " | ".join(f"{first[n]['dense_grid_cells']:.1e}" for n in sizes) + " |")
    return "\n".join(lines)


def plot(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = os.path.join(ROOT, "docs", "broadphase")
    os.makedirs(out_dir, exist_ok=True)
    for kind in SCENES:
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        for name in METHODS:
            pts = sorted((r["n"], r["update_ms"]) for r in rows
                         if r["scene"] == kind and r["method"] == name)
            if pts:
                ax.plot(*zip(*pts), marker="o", label=name)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("moving boxes")
        ax.set_ylabel("time per update (ms)")
        ax.set_title(f"Broad phase, {kind} scene (best of {STEPS} updates)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        path = os.path.join(out_dir, f"{kind}.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
