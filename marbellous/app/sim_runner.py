"""Stepping a world in real time for the viewer: a fixed step, paused or running, one step at a time,
back to the start."""
import time

from .._validate import as_float, as_int

#: Weight of the newest frame in the smoothed time per step.
SMOOTHING = 0.1


class SimRunner:
    """Steps ``world`` by ``dt`` seconds as real time passes, at most ``max_steps`` steps per frame
    (time beyond is dropped: a world slower than real time runs in slow motion rather than falling
    behind).  Starts ``paused`` or running; :meth:`reset` returns to the state it started from.
    """

    def __init__(self, world, dt, *, paused=False, max_steps=4):
        self.world = world
        self.dt = as_float("dt", dt, positive=True)
        self.max_steps = as_int("max_steps_per_frame", max_steps, lo=1)
        self.paused = paused
        self.start = world.snapshot()
        #: Steps taken since the start or the last reset.
        self.steps = 0
        #: Smoothed wall-clock seconds per step (None before the first step).
        self.step_seconds = None

    def advance(self, frame_time):
        """Let ``frame_time`` seconds of real time pass: as many steps as fit, unless paused."""
        if not self.paused:
            self._timed(lambda: self.world.advance(frame_time, self.dt, self.max_steps))

    def step_once(self):
        """Pause, and take exactly one step."""
        self.paused = True
        self._timed(lambda: self.world.step(self.dt))

    def reset(self):
        """Return the world to the state it started in (its snapshot at start)."""
        self.world.restore(self.start)
        self.steps = 0

    def _timed(self, run):
        """Call ``run()``, which steps the world, and count and time the steps it took."""
        t0 = self.world.time
        wall = time.perf_counter()
        run()
        wall = time.perf_counter() - wall
        n = round((self.world.time - t0) / self.dt)
        if n > 0:
            self.steps += n
            per_step = wall / n
            self.step_seconds = per_step if self.step_seconds is None else \
                (1.0 - SMOOTHING) * self.step_seconds + SMOOTHING * per_step
