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
import math

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ...game.controls import move_for_direction
from ...game.goal import BestTimes
from ...game.level import load_level
from ...game.session import Game


class MarbellousEnv(gym.Env):
    """Marble-rolling task on a Marbellous level (default: the course)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, level=None, *, frame_skip=4, max_episode_steps=1500, goal_reward=10.0,
                 fall_penalty=5.0, start_jitter=0.3, render_mode=None, size=(320, 180)):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if int(frame_skip) < 1:
            raise ValueError(f"frame_skip must be >= 1, got {frame_skip!r}")
        self.level = load_level(level) if level is None or not hasattr(level, "colliders") else level
        if self.level.path is None:
            raise ValueError(f"level {self.level.name!r} has no [course] path to measure progress along")
        self.frame_skip, self.max_episode_steps = int(frame_skip), int(max_episode_steps)
        self.goal_reward, self.fall_penalty = float(goal_reward), float(fall_penalty)
        self.start_jitter = float(start_jitter)
        self.render_mode, self.size = render_mode, tuple(size)
        bound = np.full(9, np.finfo(np.float32).max, np.float32)
        self.observation_space = spaces.Box(-bound, bound, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._game = None
        self._renderer = None

    def _obs(self):
        b = self._game.marble
        return np.concatenate([b.position, b.velocity, self.level.goal_center]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if self._game is None:
            self._game = Game(self.level, best_times=BestTimes(persistent=False))
        g = self._game
        g.restart()
        h = self.level.start_heading
        side = np.array([-math.sin(h), 0.0, math.cos(h)])
        g.marble.position = self.level.start_position + side * self.np_random.uniform(-1, 1) * self.start_jitter
        self._steps = 0
        self._progress = g.course.project(g.marble.position, near=0.0)
        return self._obs(), {"progress": self._progress}

    def step(self, action):
        a = np.asarray(action, np.float64).reshape(2)
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action must be 2 finite numbers, got {action!r}")
        g = self._game
        move = move_for_direction(np.array([a[0], 0.0, a[1]]), g.camera.heading)
        fell = False
        for _ in range(self.frame_skip):
            g.step(move)
            if g.respawns:
                fell = True
                break
            if g.finished:
                break
        if self.render_mode is not None:
            g.update_camera(self.frame_skip * g.dt)
        self._steps += 1
        reward = 0.0
        if not fell:
            s = g.course.project(g.marble.position, near=self._progress)
            reward += s - self._progress
            self._progress = s
        if g.finished:
            reward += self.goal_reward
        if fell:
            reward -= self.fall_penalty
        terminated = bool(g.finished or fell)
        truncated = bool(not terminated and self._steps >= self.max_episode_steps)
        info = {"progress": self._progress, "reached_goal": bool(g.finished), "fell": fell}
        return self._obs(), float(reward), terminated, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            from ...render.context import headless_context
            from ...render.renderer import Renderer

            self._renderer = Renderer(headless_context(), self.level, self._game.spec.radius, self.size)
        g = self._game
        return self._renderer.render_to_array(g.camera.view(), g.marble.position, g.marble_rotation(), g.hud_lines())

    def close(self):
        if self._renderer is not None:
            self._renderer.ctx.release()
            self._renderer = None
