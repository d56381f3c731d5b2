"""Running one scene in one engine: the Marbellous adapter and the timed loop shared by every engine.

An engine run offers ``step()``, ``positions()`` (dynamic bodies, Marbellous axes, (n, 3) m),
``max_penetration()`` (m) and ``close()``.  ``timed_run`` times the ``step()`` calls only; between
chunks of steps it samples positions and penetration (outside the clock) for the sanity measures.
"""
import time

import numpy as np


class MarbellousRun:
    """A Marbellous world stepped ``dt`` s at a time."""

    def __init__(self, world, dt):
        self.world = world
        self.dt = dt
        self.dynamic = [b for b in world.bodies if not b.is_static]

    def step(self):
        self.world.step(self.dt)

    def positions(self):
        return np.array([b.position for b in self.dynamic]).reshape(-1, 3)

    def max_penetration(self):
        return max([0.0] + [c.depth for c in self.world.contacts()])

    def close(self):
        pass


def timed_run(run, steps, samples=10, time_cap=None):
    """Step ``run`` ``steps`` times; returns a dict with ``steps`` done, ``seconds`` spent in ``step()``,
    ``positions`` (list of (step, (n, 3) array) samples, the first at step 0, the last two at the final
    step and the one before), and ``max_penetration`` (m, the deepest over the samples).
    With ``time_cap`` (s) the run stops early once the steps alone have taken that long."""
    chunk = max(1, steps // samples)
    seconds = 0.0
    trace = [(0, run.positions())]
    pen = run.max_penetration()
    clock = time.perf_counter
    done = 0
    capped = False
    while done < steps - 1 and not capped:
        for _ in range(min(chunk, steps - 1 - done)):
            t = clock()
            run.step()
            seconds += clock() - t
            done += 1
            capped = time_cap is not None and seconds > time_cap
            if capped:
                break
        trace.append((done, run.positions()))
        pen = max(pen, run.max_penetration())
    # the final step, one step after the last sample (speeds at the end)
    t = clock()
    run.step()
    seconds += clock() - t
    done += 1
    trace.append((done, run.positions()))
    pen = max(pen, run.max_penetration())
    return {"steps": done, "seconds": seconds, "positions": trace, "max_penetration": pen}
