"""``"Marbellous-v0"``'s task with PyBullet as the physics: a peer environment for ``bench_vector_env.py``.

The same level (its mesh as Bullet's static concave triangle mesh, through ``PyBulletRun``), the same marble
(radius, mass, friction), the same actions, observation, reward and episode ends as
:class:`marbellous.app.envs.marble_env.MarbellousEnv`: the control force of an action is applied before each
of the ``frame_skip`` physics steps of 1/120 s, the episode ends when the marble falls below the level's
``fall_height`` or touches the goal box, and the reward is the progress along the course.  Only the physics
differs, so gymnasium's wrappers around it time PyBullet's step plus the same Python around it.

MuJoCo has no peer here: it collides a mesh as its convex hull, and the course is concave.
"""

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from marbellous.game.controls import control_force, move_for_direction
from marbellous.game.goal import BestTimes
from marbellous.game.level import load_level
from marbellous.game.session import Game

from .axes import from_peer, to_peer
from .pybullet_world import PyBulletRun


class PyBulletMarbleEnv(gym.Env):
    """The marble-rolling task on ``level`` with PyBullet stepping it (options as ``MarbellousEnv``'s)."""

    metadata = {"render_modes": []}

    def __init__(self, level="course", *, frame_skip=4, max_episode_steps=1500, goal_reward=10.0, fall_penalty=5.0,
                 start_jitter=0.3):
        self.level = load_level(level)
        game = Game(self.level, best_times=BestTimes(persistent=False), flag=False)
        self.dt, self.push, self.mass = game.dt, game.spec.push, game.marble.mass
        self.course, self.goal, self.radius = game.course, game.goal, game.spec.radius
        self.heading = game.camera.heading
        self.run = PyBulletRun(game.world, self.dt)
        self.p, self.kw = self.run.p, self.run.kw
        self.marble = self.run.dynamic[0]
        self.frame_skip, self.max_episode_steps = frame_skip, max_episode_steps
        self.goal_reward, self.fall_penalty, self.start_jitter = goal_reward, fall_penalty, start_jitter
        bound = np.full(9, np.finfo(np.float32).max, np.float32)
        self.observation_space = spaces.Box(-bound, bound, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)

    def _state(self):
        """The marble's position (m) and velocity (m/s), in Marbellous' axes."""
        position, _ = self.p.getBasePositionAndOrientation(self.marble, **self.kw)
        velocity, _ = self.p.getBaseVelocity(self.marble, **self.kw)
        return from_peer(position), from_peer(velocity)

    def _obs(self):
        position, velocity = self._state()
        return np.concatenate([position, velocity, self.level.goal_center]).astype(np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        start = self.level.start_position + self.level.start_side * self.np_random.uniform(-1, 1) * self.start_jitter
        self.p.resetBasePositionAndOrientation(self.marble, list(to_peer(start)), [0, 0, 0, 1], **self.kw)
        self.p.resetBaseVelocity(self.marble, [0, 0, 0], [0, 0, 0], **self.kw)
        self._steps = 0
        self._progress = self.course.project(start, near=0.0)
        return self._obs(), {"progress": self._progress}

    def step(self, action):
        a = np.asarray(action, np.float64)
        force = to_peer(control_force(move_for_direction((a[0], 0.0, a[1]), self.heading), self.heading, self.mass,
                                      self.push))
        fell = reached = False
        for _ in range(self.frame_skip):
            position, _ = self.p.getBasePositionAndOrientation(self.marble, **self.kw)
            self.p.applyExternalForce(self.marble, -1, list(force), list(position), self.p.WORLD_FRAME, **self.kw)
            self.p.stepSimulation(**self.kw)
            position, _ = self._state()
            if position[1] < self.level.fall_height:
                fell = True
                break
            if self.goal.reached(position, self.radius):
                reached = True
                break
        self._steps += 1
        reward = 0.0
        if not fell:
            s = self.course.project(position, near=self._progress)
            reward += s - self._progress
            self._progress = s
        reward += self.goal_reward if reached else 0.0
        reward -= self.fall_penalty if fell else 0.0
        terminated = reached or fell
        truncated = not terminated and self._steps >= self.max_episode_steps
        return self._obs(), reward, terminated, truncated, {"progress": self._progress, "reached_goal": reached,
                                                           "fell": fell}

    def close(self):
        self.run.close()
