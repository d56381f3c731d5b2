"""``"Marbellous-v0"`` as a native vector environment: ``gymnasium.make_vec("Marbellous-v0", num_envs=N,
vectorization_mode="vector_entry_point")``.

N copies of :class:`~marbellous.app.envs.marble_env.MarbellousEnv` (same options, one level loaded once) whose
worlds are stepped together: each physics step of all the copies still running is one call of
``marbellous.step_worlds`` (one compiled call per kind of world, optionally on several threads), rather
than N calls of ``World.step``.  Everything else is each copy's own code, so env ``i`` does exactly what a
single environment does: ``reset(seed=s)`` seeds env ``i`` with ``s + i``, and each env then repeats, step
for step, ``gymnasium.make("Marbellous-v0")`` reset with that seed and given the same actions.

Autoreset (gymnasium's ``AutoresetMode``): ``"NextStep"`` (the default; an env that ended is reset by the
next ``step``, which ignores its action and returns the first observation with reward 0) or ``"SameStep"``
(reset within the step that ended it; the last observation and info are in ``info["final_obs"]`` and
``info["final_info"]``).
"""
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..._validate import as_int
from ...batch import MAX_THREADS, step_worlds
from .marble_env import MarbellousEnv

#: the most environments one vector environment holds
MAX_ENVS = 1 << 16


class MarbellousVectorEnv(VectorEnv):
    """``num_envs`` (1 .. 65536) marble-rolling environments stepped together.  ``threads`` (1 .. 256): the
    threads that share each batched physics step (see ``marbellous.step_worlds``); ``autoreset_mode``
    ``"NextStep"`` or ``"SameStep"`` (or the ``AutoresetMode``); the other keyword arguments are
    :class:`~marbellous.app.envs.marble_env.MarbellousEnv`'s, the same for every env.  Observations are
    ``(num_envs, 9)`` float32, actions ``(num_envs, 2)`` float32; ``info`` holds each key of the single
    environment's info as an array with its mask ``"_key"`` (gymnasium's convention)."""

    def __init__(self, num_envs=1, level=None, *, threads=1, autoreset_mode="NextStep", **options):
        num_envs = as_int("num_envs", num_envs, lo=1, hi=MAX_ENVS)
        self.threads = as_int("threads", threads, lo=1, hi=MAX_THREADS)
        try:
            self.autoreset_mode = AutoresetMode(autoreset_mode)
        except ValueError:
            raise ValueError(f"autoreset_mode must be 'NextStep' or 'SameStep', got {autoreset_mode!r}") from None
        if self.autoreset_mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ValueError(f"autoreset_mode must be 'NextStep' or 'SameStep', got {autoreset_mode!r}")
        first = MarbellousEnv(level, **options)
        if level is None or not hasattr(level, "colliders"):
            level = first.level                                      # loaded once, shared
        self.envs = [first] + [MarbellousEnv(level, **options) for _ in range(num_envs - 1)]
        self.num_envs = num_envs
        self.render_mode = first.render_mode
        self.metadata = {**MarbellousEnv.metadata, "autoreset_mode": self.autoreset_mode}
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._ended = np.zeros(num_envs, dtype=bool)     # ended in the last step (reset by the next one)
        self._started = False

    def reset(self, *, seed=None, options=None):
        """Reset every env: ``seed`` None, an int ``s`` (env ``i`` gets ``s + i``) or a list of ``num_envs``
        ints or Nones; ``options`` as the single environment's (None).  Returns ``(observations, info)``."""
        if seed is None or isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [None] * self.num_envs if seed is None else [as_int("seed", seed, lo=0) + i
                                                                   for i in range(self.num_envs)]
        elif isinstance(seed, (list, tuple)) and len(seed) == self.num_envs:
            seeds = [None if s is None else as_int(f"seed[{i}]", s, lo=0) for i, s in enumerate(seed)]
        else:
            raise TypeError(f"seed must be None, an int >= 0 or a list of {self.num_envs} of them, got {seed!r}")
        if options is not None and (not isinstance(options, dict) or options):
            self.envs[0].reset(options=options)                     # raises as the single environment does
        observations, info = [], {}
        for i, (env, s) in enumerate(zip(self.envs, seeds)):
            obs, env_info = env.reset(seed=s)
            observations.append(obs)
            info = self._add_info(info, env_info, i)
        self._ended[:] = False
        self._started = True
        return np.stack(observations), info

    def step(self, actions):
        """Take one action per env (``actions``: ``(num_envs, 2)`` finite numbers); returns ``(observations,
        rewards, terminations, truncations, info)`` as arrays over the envs."""
        if not self._started:
            raise RuntimeError("call reset() before step()")
        try:
            actions = np.asarray(actions)
        except (TypeError, ValueError) as error:
            raise TypeError(f"actions must be an array of shape ({self.num_envs}, 2), got {actions!r}") from error
        if actions.shape != (self.num_envs, 2):
            raise ValueError(f"actions must have shape ({self.num_envs}, 2), got {actions.shape}")
        resetting = self._ended.copy() if self.autoreset_mode == AutoresetMode.NEXT_STEP else np.zeros_like(self._ended)
        stepping = [i for i in range(self.num_envs) if not resetting[i]]
        moves = {i: self.envs[i]._move(actions[i]) for i in stepping}      # all checked before anything moves
        fell = self._physics(stepping, moves)
        progress = self._progress([i for i in stepping if not fell[i]])
        n = self.num_envs
        observations = np.zeros((n,) + self.single_observation_space.shape, dtype=np.float32)
        rewards = np.zeros(n)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        infos, info = [], {}
        for i, env in enumerate(self.envs):
            if resetting[i]:
                observations[i], env_info = env.reset()
            else:
                _, rewards[i], terminations[i], truncations[i], env_info = env._outcome(fell[i], progress[i],
                                                                                       observations[i])
                if self.autoreset_mode == AutoresetMode.SAME_STEP and (terminations[i] or truncations[i]):
                    info = self._add_info(info, {"final_obs": observations[i].copy(), "final_info": env_info}, i)
                    observations[i], env_info = env.reset()
            infos.append(env_info)
        self._ended = terminations | truncations
        return observations, rewards, terminations, truncations, self._gather(infos, info)

    def _progress(self, envs):
        """The course's arc length (m) nearest each marble of the envs ``envs``, each searched near its last
        progress, in one projection (the envs share one level, so one course); a list over all envs (0.0 for
        the others)."""
        progress = np.zeros(self.num_envs)
        if envs:
            positions = np.array([self.envs[i]._game.marble.position for i in envs])
            near = np.array([self.envs[i]._progress for i in envs])
            progress[envs] = self.envs[envs[0]]._game.course.project_many(positions, near)
        return progress.tolist()

    def _gather(self, infos, info):
        """``info`` with the envs' ``infos`` (one dict per env) added as gymnasium's ``_add_info`` adds them env
        by env (each key an array over the envs, with its mask ``"_key"``), a key of Python numbers at once."""
        columns = {}
        for i, env_info in enumerate(infos):
            for key, value in env_info.items():
                columns.setdefault(key, []).append((i, value))
        for key, column in columns.items():
            kind = type(column[0][1])
            if key in info or kind not in (bool, int, float) or any(type(v) is not kind for _, v in column):
                for i, value in column:
                    info = self._add_info(info, {key: value}, i)
                continue
            array = np.zeros(self.num_envs, dtype=kind)
            mask = np.zeros(self.num_envs, dtype=bool)
            at = [i for i, _ in column]
            array[at] = [v for _, v in column]
            mask[at] = True
            info[key], info[f"_{key}"] = array, mask
        return info

    def _physics(self, stepping, moves):
        """The ``frame_skip`` physics steps of the envs ``stepping`` with their control inputs ``moves``, each
        env's ending early as a single environment's does (a fall, the goal); returns which fell."""
        fell = np.zeros(self.num_envs, dtype=bool)
        running = list(stepping)
        for _ in range(self.envs[0].frame_skip):
            if not running:
                break
            games = [self.envs[i]._game for i in running]
            for i, g in zip(running, games):
                g.push(moves[i])
            step_worlds([g.world for g in games], games[0].dt, threads=self.threads)
            still = []
            for i, g in zip(running, games):
                g.judge()
                if g.respawns:
                    fell[i] = True
                elif not g.finished:
                    still.append(i)
            running = still
        return fell

    def render(self):
        """Each env's frame (``render_mode="rgb_array"``), as a tuple; None otherwise."""
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs):
        for env in self.envs:
            env.close()

