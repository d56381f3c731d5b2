"""Running one scene in one engine: the Marbellous adapter and the timed loop shared by every engine.

An engine run offers ``step()``, ``positions()`` (dynamic bodies, Marbellous axes, (n, 3) m),
``orientations()`` (the same bodies', (n, 4) w, x, y, z), ``max_penetration()`` (m) and ``close()``.
``timed_run`` times the ``step()`` calls only, or, for a run that times its own steps (``timed_steps(n,
budget)``: an engine in another process, whose requests cost more than its steps), the times it reports;
between chunks of steps it samples positions and penetration (outside the clock) for the sanity measures,
and orientations too for the measures that need them.
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
        """Positions (m) of the dynamic bodies, shape (n, 3)."""
        return np.array([b.position for b in self.dynamic]).reshape(-1, 3)

    def orientations(self):
        """Orientations (w, x, y, z) of the dynamic bodies, shape (n, 4)."""
        return np.array([b.orientation for b in self.dynamic]).reshape(-1, 4)

    def max_penetration(self):
        return max([0.0] + [c.depth for c in self.world.contacts()])

    def close(self):
        pass


def steps_timed(run, n, budget=None):
    """Step ``run`` up to ``n`` times, stopping once the steps have taken more than ``budget`` seconds (None:
    no limit): ``(steps done, seconds spent stepping)``.  The seconds are the run's own (``timed_steps``)
    where it has them, else the clock's around each ``step()`` call."""
    if hasattr(run, "timed_steps"):
        seconds = run.timed_steps(n, budget)
        return len(seconds), float(sum(seconds))
    clock = time.perf_counter
    done, spent = 0, 0.0
    while done < n and (budget is None or spent <= budget):
        t = clock()
        run.step()
        spent += clock() - t
        done += 1
    return done, spent


def timed_run(run, steps, samples=10, time_cap=None, orientations=False):
    """Step ``run`` ``steps`` times; returns a dict with ``steps`` done, ``seconds`` spent in ``step()``,
    ``positions`` (list of (step, (n, 3) array) samples, the first at step 0, the last two at the final
    step and the one before; with ``orientations``, (step, positions, (n, 4) orientations) samples), and
    ``max_penetration`` (m, the deepest over the samples).
    With ``time_cap`` (s) the run stops early once the steps alone have taken that long."""
    def sample(step):
        """One sample of the trace at ``step``: the positions (m), and the orientations when asked for."""
        return (step, run.positions(), run.orientations()) if orientations else (step, run.positions())

    chunk = max(1, steps // samples)
    seconds = 0.0
    trace = [sample(0)]
    pen = run.max_penetration()
    done = 0
    capped = False
    while done < steps - 1 and not capped:
        k, s = steps_timed(run, min(chunk, steps - 1 - done), None if time_cap is None else time_cap - seconds)
        done += k
        seconds += s
        capped = time_cap is not None and seconds > time_cap
        trace.append(sample(done))
        pen = max(pen, run.max_penetration())
    # the final step, one step after the last sample (speeds at the end)
    k, s = steps_timed(run, 1)
    done += k
    seconds += s
    trace.append(sample(done))
    pen = max(pen, run.max_penetration())
    return {"steps": done, "seconds": seconds, "positions": trace, "max_penetration": pen}
