"""Two checkouts of Marbellous side by side on the standard scenes, in one run.

A change that must not cost speed (a refactor, a new stage that is off by default) is measured against the
commit before it: check both out (``git worktree add /tmp/before <commit>``), then

    python bench/compare_trees.py /tmp/before . --scenes one_body pile_1k --rounds 5

Each round runs every scene once per tree in a fresh process, alternating which tree goes first; the steps are
timed in the CPU time of the stepping thread, which a busy shared machine disturbs far less than wall time
(the sphere-mesh queries keep the bench's own wall-clock timing). Kernels are compiled once per tree before
the first round (warm caches). The table gives
each tree's median ms per step over the rounds and the ratio after / before with its spread (the ratio of
the rounds' extremes), which is the noise the comparison can resolve.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path


#: run in each tree: build each scene with that tree's own bench scenes, step it, and time the steps in
#: CPU time of the stepping thread (on a shared machine wall time mostly measures the neighbours)
_PROBE = """
import json, sys, time
from bench.scenes import SCENES
from bench.__main__ import DT, run_query_scene
out = {}
for name in sys.argv[2:]:
    if not SCENES[name].world:
        out[name] = run_query_scene("marbellous", False)["ms_per_step"]
        continue
    world, _ = SCENES[name].build(False)
    steps = min(SCENES[name].n_steps(False), int(sys.argv[1]))
    world.step(DT)  # untimed: loads the cached kernels
    t = time.thread_time()
    for _ in range(steps):
        world.step(DT)
    out[name] = 1e3 * (time.thread_time() - t) / steps
print(json.dumps(out))
"""


def run_bench(tree, scenes, max_steps):
    """Each of ``scenes`` stepped (at most ``max_steps`` steps) in checkout ``tree``; returns {scene: ms per
    step} (sphere-mesh queries: ms per query, timed by the bench itself in wall time)."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    done = subprocess.run([sys.executable, "-c", _PROBE, str(max_steps), *scenes], cwd=tree, env=env,
                          check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def compare(before, after, scenes, rounds, max_steps):
    """Alternating runs of the two trees; returns {scene: ([before ms], [after ms])}."""
    times = {s: ([], []) for s in scenes}
    for tree in (before, after):  # compile and cache every kernel once, outside the rounds
        run_bench(tree, scenes, 2)
    for r in range(rounds):
        order = ((0, before), (1, after)) if r % 2 == 0 else ((1, after), (0, before))
        for k, tree in order:
            for s, ms in run_bench(tree, scenes, max_steps).items():
                times[s][k].append(ms)
        print(f"round {r + 1}/{rounds} done", file=sys.stderr)
    return times


def table(times):
    """Markdown rows: scene, median ms before and after, median ratio, and the spread of the ratio."""
    rows = ["| scene | before ms | after ms | after / before | range over rounds |", "|---|---|---|---|---|"]
    for s, (b, a) in times.items():
        if not b or not a:
            rows.append(f"| {s} | - | - | - | - |")
            continue
        ratios = [x / y for x, y in zip(a, b)]
        rows.append(f"| {s} | {statistics.median(b):.4f} | {statistics.median(a):.4f} | "
                    f"{statistics.median(ratios):.3f} | {min(ratios):.3f} - {max(ratios):.3f} |")
    return "\n".join(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("before", type=Path, help="checkout measured first (the reference)")
    parser.add_argument("after", type=Path, help="checkout compared with it")
    parser.add_argument("--scenes", nargs="+", default=["one_body", "marble_terrain", "pile_1k", "pyramid_20"])
    parser.add_argument("--rounds", type=int, default=5, help="alternating runs per tree")
    parser.add_argument("--max-steps", type=int, default=20000,
                        help="most steps per scene and run (the default keeps each scene's own count)")
    parser.add_argument("--out", type=Path, help="also write the raw times here (JSON)")
    args = parser.parse_args(argv)
    times = compare(args.before.resolve(), args.after.resolve(), args.scenes, args.rounds, args.max_steps)
    print(table(times))
    if args.out:
        args.out.write_text(json.dumps({"before": str(args.before), "after": str(args.after), "times": times},
                                       indent=1))


if __name__ == "__main__":
    main()
