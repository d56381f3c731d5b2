"""A world's step after many add/remove cycles against a fresh world's: the cost of what is alive, not of
what was ever made.

A game that spawns and removes projectiles keeps a few bodies alive; here 2 live bodies (a ground plane
and a resting ball, awake) and a projectile added and removed ``cycles`` times (stepping every third
cycle), then the step time of the churned world against a fresh world built the same way.  The same for
100 live spheres in a pile.

Run:  python bench/bench_churn.py [--cycles 20000]      (prints the table; the ratio should be ~1)
"""
import argparse
import pickle
import time

import marbellous as mb


def world(live_spheres):
    """A plane and ``live_spheres`` spheres at rest on it, kept awake (sleeping would hide the cost)."""
    w = mb.World(sleeping=False)
    w.add_static(mb.Plane())
    for k in range(live_spheres):
        w.add_body(mb.Sphere(0.25), position=(0.6 * (k % 10), 0.25, 0.6 * (k // 10)))
    return w


def churn(w, cycles):
    """Add and remove a projectile ``cycles`` times, stepping every third cycle."""
    for k in range(cycles):
        b = w.add_body(mb.Sphere(0.05), position=(-5.0, 1.0, 0.0), velocity=(20.0, 0.0, 0.0))
        if k % 3 == 0:
            w.step(1 / 60)
        w.remove(b)


def step_us(w, steps=2000, repeats=5):
    """Best mean step time (us) over ``repeats`` runs of ``steps`` steps."""
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(steps):
            w.step(1 / 60)
        best = min(best, (time.perf_counter() - t) / steps)
    return 1e6 * best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=20000)
    args = parser.parse_args()
    print(f"{'live bodies':>12s} {'fresh us':>10s} {'churned us':>11s} {'ratio':>7s} {'snapshot KB':>12s} "
          f"{'body rows':>10s}")
    for live in (1, 100):
        fresh, churned = world(live), world(live)
        churn(churned, args.cycles)
        fresh.step(1 / 60)
        churned.step(1 / 60)
        rounds = [(step_us(fresh), step_us(churned)) for _ in range(3)]    # alternated
        f, c = min(r[0] for r in rounds), min(r[1] for r in rounds)
        size = len(pickle.dumps(churned.snapshot())) / 1024
        print(f"{live + 1:12d} {f:10.3f} {c:11.3f} {c / f:7.3f} {size:12.1f} {churned._state.bodies.end:10d}")


if __name__ == "__main__":
    main()
