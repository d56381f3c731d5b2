"""One headless run of a level by the autopilot, as a function of its parameters: the unit of a sweep.

``autopilot_trial(level="course", friction=0.5, push=9.0, start_offset=0.0, seconds=60.0)`` plays the level
with the autopilot (no rendering, no camera) until the marble reaches the goal or ``seconds`` of simulated
time have passed, and reports what happened as a dict of plain numbers.  It depends on nothing but its
arguments, so the same parameters give the same answer bit for bit, on any worker of a sweep
(``marbellous/sweeps.py``).
"""
import functools
import math

from .._validate import as_float
from .autopilot import Autopilot
from .goal import BestTimes
from .level import load_level
from .marble import MarbleSpec
from .session import Game

#: the longest trial (simulated seconds)
MAX_TRIAL_SECONDS = 3600.0


@functools.lru_cache(maxsize=8)
def _level(name):
    """The shipped level or level file ``name``, loaded once per process."""
    return load_level(name)


def trial_numbers(level="course", *, friction=0.5, push=9.0, start_offset=0.0, seconds=60.0, flag=False):
    """The arguments of :func:`autopilot_trial` checked without playing (a TypeError or ValueError naming the
    first bad one; the level file itself is read by the trial): ``(friction, push, start_offset, seconds)``
    as floats.  For checking every run of a sweep before any starts."""
    if not isinstance(level, str):
        raise TypeError(f"level must be a level name or a path (a str), got {level!r}")
    if not isinstance(flag, bool):
        raise TypeError(f"flag must be True or False, got {flag!r}")
    return (as_float("friction", friction, lo=0.0, hi=10.0), as_float("push", push, lo=0.0, hi=1000.0, unit="m/s^2"),
            as_float("start_offset", start_offset, lo=-100.0, hi=100.0, unit="m"),
            as_float("seconds", seconds, lo=0.0, hi=MAX_TRIAL_SECONDS, unit="s"))


def autopilot_trial(level="course", *, friction=0.5, push=9.0, start_offset=0.0, seconds=60.0, flag=False):
    """Play ``level`` (a shipped level's name or a level file's path) with the autopilot for at most
    ``seconds`` (s, 0 .. 3600) of simulated time, the marble's Coulomb ``friction`` coefficient (0 .. 10; its
    static friction is 1.4 times that, as the default marble's) and control acceleration ``push`` (m/s^2,
    0 .. 1000) as given, starting ``start_offset`` metres (-100 .. 100) to the side of the level's start;
    ``flag``: whether the goal's cloth flag waves (scenery; off by default).

    Returns ``{"reached": bool, "time": s to the goal (nan if not reached), "progress": m along the course
    at the end, "falls": int, "steps": physics steps taken}``."""
    friction, push, start_offset, seconds = trial_numbers(level, friction=friction, push=push,
                                                         start_offset=start_offset, seconds=seconds, flag=flag)
    lvl = _level(level)
    if lvl.path is None:
        raise ValueError(f"level {lvl.name!r} has no [course] path for the autopilot")
    spec = MarbleSpec(friction=friction, static_friction=1.4 * friction, push=push)
    game = Game(lvl, marble=spec, best_times=BestTimes(persistent=False), flag=flag)
    game.marble.position = lvl.start_position + start_offset * lvl.start_side
    pilot = Autopilot(game.course, max(push, 1e-9))     # (its input is an acceleration over push: none at 0)
    steps = math.floor(seconds / game.dt + 1e-9)
    taken = 0
    while taken < steps and not game.finished:
        pilot.step(game)
        taken += 1
    progress = game.course.project(game.marble.position, near=pilot.progress)
    return {"reached": bool(game.finished), "time": game.finish_time if game.finished else math.nan,
            "progress": progress, "falls": game.respawns, "steps": taken}
