"""Figure for the lecture map: the cost of one sphere-mesh query with each mesh acceleration.

Reads the results of ``python bench/bench_mesh_query.py`` (``bench/results/*-mesh_query.json``, the newest)
and draws microseconds per query against the number of triangles, for the lecture's question "is the 2D
grid worth it?".  Writes ``docs/lecture/broad-phase/mesh-accel.png``.

Run from the repository's root:  python docs/scripts/plot_mesh_accel.py
"""
import glob
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "lecture", "broad-phase", "mesh-accel.png")
LABELS = {"grid2d": "grid2d (the lecture's 2D grid)", "bvh": "bvh", "brute": "brute (every triangle)"}


def main():
    path = sorted(glob.glob(os.path.join(ROOT, "bench", "results", "*-mesh_query.json")))[-1]
    with open(path) as f:
        rows = [r for r in json.load(f)["rows"] if r["engine"] == "marbellous"]
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=100)
    for accel, style in (("grid2d", "o-"), ("bvh", "s-"), ("brute", "^-")):
        mine = sorted((r for r in rows if r["accel"] == accel), key=lambda r: r["triangles"])
        ax.loglog([r["triangles"] for r in mine], [r["path_kernel_us"] for r in mine], style, label=LABELS[accel])
    ax.set_xlabel("triangles in the level mesh")
    ax.set_ylabel("us per sphere-mesh query")
    ax.set_title("A marble rolling over a terrain: one contact query", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT)
    print(OUT, "from", os.path.relpath(path, ROOT))


if __name__ == "__main__":
    main()
