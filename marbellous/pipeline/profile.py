"""``World.profile``: where the steps' time went, stage by stage, measured inside the compiled step.

With ``world.profiling = True`` every step adds the processor cycles of each of its stages (see
``pipeline/stages.py``) to running totals; :func:`step_profile` turns them into seconds.  Reading the
cycle counter costs about 20 ns per stage, and nothing at all while profiling is off.
"""
from typing import NamedTuple

from .._numba.clock import cycles_per_second
from ..state.layout import STAT_CYCLES, STAT_PROFILED_STEPS, STAT_SUM_CONTACTS, STAT_SUM_ITERATIONS, STAT_SUM_PAIRS
from .stages import STAGE_NAMES


class StepProfile(NamedTuple):
    """Totals over the profiled steps.

    ``steps``: steps profiled; ``seconds``: dict stage name -> total seconds in that stage, in step
    order (stages inside the sub-step loop summed over sub-steps; a step rerun because a buffer grew
    counts its collide stages twice); ``pairs``, ``contacts``, ``iterations``: mean candidate pairs,
    contact points and velocity iterations (all sub-steps) per step.
    """
    steps: int
    seconds: dict
    pairs: float
    contacts: float
    iterations: float

    @property
    def total(self):
        """Seconds in all stages together."""
        return sum(self.seconds.values())

    def per_step(self):
        """dict stage name -> mean seconds per step."""
        return {k: v / self.steps if self.steps else 0.0 for k, v in self.seconds.items()}

    def __str__(self):
        if not self.steps:
            return "StepProfile: no steps profiled (set world.profiling = True, then step)"
        rows = [f"{'stage':24s} {'us/step':>10s} {'share':>7s}"]
        total = self.total
        for name, sec in self.seconds.items():
            rows.append(f"{name:24s} {1e6 * sec / self.steps:10.2f} {sec / total if total else 0.0:7.1%}")
        rows.append(f"{'total':24s} {1e6 * total / self.steps:10.2f}")
        rows.append(f"{self.steps} steps; per step {self.pairs:.1f} pairs, {self.contacts:.1f} contacts, "
                    f"{self.iterations:.1f} iterations")
        return "\n".join(rows)


def step_profile(stats):
    """The :class:`StepProfile` of a world's ``stats`` array (the step kernel's running totals)."""
    steps = int(stats[STAT_PROFILED_STEPS])
    rate = cycles_per_second()
    if rate <= 0.0:
        raise RuntimeError("World.profile: this processor has no cycle counter the step can read")
    seconds = {name: float(stats[STAT_CYCLES + k]) / rate for k, name in enumerate(STAGE_NAMES)}
    per = 1.0 / steps if steps else 0.0
    return StepProfile(steps, seconds, float(stats[STAT_SUM_PAIRS]) * per, float(stats[STAT_SUM_CONTACTS]) * per,
                       float(stats[STAT_SUM_ITERATIONS]) * per)
