"""Figure for the lecture map: the three collision-handling schemes on one stack of boxes.

A tower of eight boxes (0.5 m cubes, 125 kg each) on the ground, stepped at 60 Hz for 4 s with each
``World(solver=...)``, sleeping off so that every scheme works for the whole run.  Plotted: how far
the top box has moved from where it was placed (mm), and the mean wall-clock time of a step.  Writes
``docs/lecture/collision-handling/stack.png`` and prints the numbers.

Run from the repository's root:  python docs/scripts/plot_collision_schemes.py
"""
import os
import time

import matplotlib
import numpy as np

import marbellous as mb

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "collision-handling", "stack.png")
SOLVERS = ("sequential_impulse", "penalty", "lcp")
BOXES, HALF, DT, SECONDS = 8, 0.25, 1.0 / 60.0, 4.0


def run(solver):
    """Times (s), the top box's displacement (m) and the mean seconds per step under ``solver``."""
    w = mb.World(solver=solver, sleeping=False)
    w.add_static(mb.Plane())
    boxes = [w.add_body(mb.Box((HALF, HALF, HALF)), position=(0.0, HALF + 2 * HALF * k, 0.0))
             for k in range(BOXES)]
    w.step(DT)                          # the first step may compile the scheme's kernels: not timed
    top0 = np.array([0.0, HALF + 2 * HALF * (BOXES - 1), 0.0])
    times, moved, spent = [w.time], [np.linalg.norm(boxes[-1].position - top0)], 0.0
    for _ in range(round(SECONDS / DT) - 1):
        start = time.perf_counter()
        w.step(DT)
        spent += time.perf_counter() - start
        times.append(w.time)
        moved.append(np.linalg.norm(boxes[-1].position - top0))
    return np.array(times), np.array(moved), spent / (len(times) - 1)


def main():
    results = {s: run(s) for s in SOLVERS}
    fig, (left, right) = plt.subplots(1, 2, figsize=(9.6, 3.6), dpi=100, gridspec_kw={"width_ratios": [2, 1]})
    for s, (t, moved, per_step) in results.items():
        left.plot(t, 1e3 * moved, label=s)
        print(f"{s:20s} top box moved {1e3 * moved[-1]:.3f} mm after {t[-1]:.2f} s, "
              f"{1e6 * per_step:.1f} us per step")
    left.set_xlabel("time (s)")
    left.set_ylabel("top box displacement (mm)")
    left.set_title(f"A tower of {BOXES} boxes, 60 Hz, 4 sub-steps", fontsize=10)
    left.grid(True, alpha=0.3)
    left.legend(fontsize=8)
    right.bar(range(len(SOLVERS)), [1e6 * results[s][2] for s in SOLVERS], color=["C0", "C1", "C2"])
    right.set_xticks(range(len(SOLVERS)), ["sequential\nimpulse", "penalty", "lcp"], fontsize=8)
    right.set_ylabel("us per step (this machine)")
    right.set_title("cost", fontsize=10)
    right.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    fig.savefig(OUT)
    print(OUT)


if __name__ == "__main__":
    main()
