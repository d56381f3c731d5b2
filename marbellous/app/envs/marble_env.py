"""The gymnasium environment ``"Marbellous-v0"``: roll the marble along a level's course to its goal.

* Observation (9 float32): marble position (m), marble velocity (m/s), goal centre (m), world frame.
* Action (2 float32 in [-1, 1]): the direction and strength of the push in the ground plane,
  ``(x, z)`` in world axes; inputs longer than 1 are scaled onto the unit disc.  Each action is held
  for ``frame_skip`` physics steps of 1/120 s.
* Reward: the progress (m) made along the course in the step, plus ``goal_reward`` on reaching the
  goal, minus ``fall_penalty`` on falling off.  The episode terminates at the goal or after a fall,
  and is truncated after ``max_episode_steps`` steps.
* Seeding: ``reset(seed=...)`` shifts the start by up to ``start_jitter`` metres sideways, drawn from
  the environment's generator, so equal seeds give equal episodes.
"""
import os

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ..._validate import as_float, as_int, as_vector
from ...game.controls import move_for_direction
from ...game.goal import BestTimes
from ...game.level import load_level
from ...game.session import Game


#: Bounds of the environment's options (see :class:`MarbellousEnv`).
MAX_FRAME_SKIP = 1000
MAX_EPISODE_STEPS = 10 ** 9
MAX_REWARD = 1e9
MAX_START_JITTER = 1e3
SIZE_RANGE = (16, 4096)


class MarbellousEnv(gym.Env):
    """Marble-rolling task on a Marbellous level (default: the course).

    ``level``: a shipped level's name, a level file's path, or a loaded ``Level`` with a ``[course]``;
    ``frame_skip`` (int, 1 .. 1000) physics steps per action; ``max_episode_steps`` (int >= 1);
    ``goal_reward``, ``fall_penalty`` (finite, within +-1e9); ``start_jitter`` (m, 0 .. 1000);
    ``render_mode`` None or ``"rgb_array"``; ``size`` (width, height) pixels, each 16 .. 4096; ``flag``: whether
    the goal's cloth flag waves in the world (None: only when rendering; it is scenery that costs more to
    step than the marble, and touches the marble only at the goal).
    Bad options raise ValueError or TypeError naming the option.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, level=None, *, frame_skip=4, max_episode_steps=1500, goal_reward=10.0,
                 fall_penalty=5.0, start_jitter=0.3, render_mode=None, size=(320, 180), flag=None):
        if not (render_mode is None or (isinstance(render_mode, str) and render_mode == "rgb_array")):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        frame_skip = as_int("frame_skip", frame_skip, lo=1, hi=MAX_FRAME_SKIP)
        max_episode_steps = as_int("max_episode_steps", max_episode_steps, lo=1, hi=MAX_EPISODE_STEPS)
        goal_reward = as_float("goal_reward", goal_reward, lo=-MAX_REWARD, hi=MAX_REWARD)
        fall_penalty = as_float("fall_penalty", fall_penalty, lo=-MAX_REWARD, hi=MAX_REWARD)
        start_jitter = as_float("start_jitter", start_jitter, lo=0.0, hi=MAX_START_JITTER, unit="m")
        if isinstance(size, (str, bytes)) or not hasattr(size, "__len__") or len(size) != 2:
            raise TypeError(f"size must be (width, height) in pixels, got {size!r}")
        size = tuple(as_int(f"size[{k}]", v, lo=SIZE_RANGE[0], hi=SIZE_RANGE[1]) for k, v in enumerate(size))
        if level is not None and not isinstance(level, (str, os.PathLike)) and not hasattr(level, "colliders"):
            raise TypeError(f"level must be a level name, a path or a loaded Level, got {level!r}")
        self.level = load_level(level) if level is None or not hasattr(level, "colliders") else level
        if self.level.path is None:
            raise ValueError(f"level {self.level.name!r} has no [course] path to measure progress along")
        self.frame_skip, self.max_episode_steps = frame_skip, max_episode_steps
        self.goal_reward, self.fall_penalty = goal_reward, fall_penalty
        self.start_jitter = start_jitter
        self.render_mode, self.size = render_mode, size
        if flag is not None and not isinstance(flag, bool):
            raise TypeError(f"flag must be None, True or False, got {flag!r}")
        self.flag = render_mode is not None if flag is None else flag
        bound = np.full(9, np.finfo(np.float32).max, np.float32)
        self.observation_space = spaces.Box(-bound, bound, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._game = None
        self._renderer = None

    def _obs(self, out=None):
        """The observation (9 float32), written into ``out`` when given."""
        b = self._game.marble
        out = np.empty(9, np.float32) if out is None else out
        out[0:3], out[3:6], out[6:9] = b.position, b.velocity, self.level.goal_center
        return out

    def reset(self, *, seed=None, options=None):
        """Start an episode (``seed``: None or an int); ``options`` must be None or an empty dict (this
        environment has no reset options; unknown ones are refused rather than ignored)."""
        if options is not None:
            if not isinstance(options, dict):
                raise TypeError(f"options must be None or a dict, got {options!r}")
            if options:
                raise ValueError(f"options: unknown option(s) {sorted(map(str, options))} (this environment "
                                 "takes none)")
        if seed is not None:
            seed = as_int("seed", seed, lo=0)
        super().reset(seed=seed)
        if self._game is None:
            self._game = Game(self.level, best_times=BestTimes(persistent=False), flag=self.flag)
        g = self._game
        g.restart()
        g.marble.position = (self.level.start_position
                             + self.level.start_side * self.np_random.uniform(-1, 1) * self.start_jitter)
        self._steps = 0
        self._progress = g.course.project(g.marble.position, near=0.0)
        return self._obs(), {"progress": self._progress}

    def step(self, action):
        """Hold ``action`` (2 finite numbers: the push direction and strength in x and z) for
        ``frame_skip`` physics steps; returns ``(observation, reward, terminated, truncated, info)``."""
        g = self._game
        move = self._move(action)
        fell = False
        for _ in range(self.frame_skip):
            g.step(move)
            if g.respawns:
                fell = True
                break
            if g.finished:
                break
        return self._outcome(fell)

    def _move(self, action):
        """The game's control input for ``action`` (checked: 2 finite numbers)."""
        a = as_vector("action", action, 2)
        return move_for_direction((a[0], 0.0, a[1]), self._game.camera.heading)

    def _outcome(self, fell, progress=None, obs=None):
        """``(observation, reward, terminated, truncated, info)`` once the physics steps of an action are taken
        (``fell``: the marble fell off in them; ``progress``: the course's arc length (m) nearest the marble,
        None to work it out here; ``obs``: where to write the observation, None for a new array)."""
        g = self._game
        if self.render_mode is not None:
            g.update_camera(self.frame_skip * g.dt)
        self._steps += 1
        old = self._progress
        if not fell:
            self._progress = g.course.project(g.marble.position, near=old) if progress is None else progress
        reward, terminated, truncated = self._outcomes(np.array([old]), np.array([self._progress]), np.array([fell]),
                                                      np.array([g.finished]), np.array([self._steps]))
        info = {"progress": self._progress, "reached_goal": bool(g.finished), "fell": bool(fell)}
        return self._obs(obs), float(reward[0]), bool(terminated[0]), bool(truncated[0]), info

    def _outcomes(self, old, new, fell, finished, steps):
        """``(rewards, terminated, truncated)`` (arrays) of actions of this environment's kind: ``old`` and
        ``new`` the progress (m) before and after each, ``fell`` and ``finished`` whether its marble fell or
        reached the goal, ``steps`` the actions taken in its episode so far (arrays over the actions).  The
        reward is the progress gained unless the marble fell, plus ``goal_reward`` at the goal, minus
        ``fall_penalty`` after a fall."""
        reward = np.zeros(len(old))
        reward[~fell] += new[~fell] - old[~fell]
        reward[finished] += self.goal_reward
        reward[fell] -= self.fall_penalty
        terminated = finished | fell
        return reward, terminated, ~terminated & (steps >= self.max_episode_steps)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            from ...render.context import headless_context
            from ...render.renderer import Renderer

            self._renderer = Renderer(headless_context(), self.level, self._game.spec.radius, self.size,
                                      flag=self._game.flag, soft_bodies=self._game.soft_blocks)
        g = self._game
        return self._renderer.render_to_array(g.camera.view(), g.marble.position, g.marble_rotation(), g.hud_lines())

    def close(self):
        if self._renderer is not None:
            self._renderer.ctx.release()
            self._renderer = None
