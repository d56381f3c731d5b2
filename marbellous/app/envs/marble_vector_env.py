"""``"Marbellous-v0"`` as a native vector environment: ``gymnasium.make_vec("Marbellous-v0", num_envs=N,
vectorization_mode="vector_entry_point")``.

N copies of :class:`~marbellous.app.envs.marble_env.MarbellousEnv` (same options, one level loaded once) whose
worlds are stepped together: each physics step of all the copies still running is one call of the compiled
step (``batch.step_checked``, one call per kind of world, optionally on several threads), rather than N calls
of ``World.step``.  When the marbles are alone on their levels (no goal flag, stream or soft body; from
``TOGETHER_FROM`` envs on), the rest of an action is taken for all the envs at once as well: the control
forces worked out as arrays, the marbles pushed and read back by one kernel call each
(``pipeline/body_rows.py``), the falls and goals tested, rewards and observations made as arrays; only an env
that falls, reaches the goal or resets runs Python of its own.  Otherwise each copy's own code runs around the
batched step.  Either way env ``i`` does exactly what a single environment does, bit for bit:
``reset(seed=s)`` seeds env ``i`` with ``s + i``, and each env then repeats, step for step,
``gymnasium.make("Marbellous-v0")`` reset with that seed and given the same actions.

Autoreset (gymnasium's ``AutoresetMode``): ``"NextStep"`` (the default; an env that ended is reset by the
next ``step``, which ignores its action and returns the first observation with reward 0) or ``"SameStep"``
(reset within the step that ended it; the last observation and info are in ``info["final_obs"]`` and
``info["final_info"]``).
"""
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..._validate import as_int, as_vector
from ...batch import MAX_THREADS, packed_addresses, plain_entry, step_checked, step_plain, step_worlds
from ...game.controls import control_forces
from ...pipeline.body_rows import add_forces_at, motions_at
from .marble_env import MarbellousEnv

#: the most environments one vector environment holds
MAX_ENVS = 1 << 16
#: the fewest environments whose marbles are stepped and judged together (measured: at 3 envs as fast as env by
#: env, at 8 envs 1.5 times as fast)
TOGETHER_FROM = 3


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
        # marbles alone on their levels (no flag, stream or soft body to step, blow or pump): their pushes, steps,
        # judging and outcomes can be taken for all the envs at once (_step_together), which pays from
        # TOGETHER_FROM envs on (its fixed cost, ~0.3 ms a step, is more than the Python of one or two envs)
        self._together = self.num_envs >= TOGETHER_FROM and all(
            env._game.flag is None and not env._game.streams and not env._game.soft_blocks for env in self.envs)
        return np.stack(observations), info

    def step(self, actions):
        """Take one action per env (``actions``: ``(num_envs, 2)`` finite numbers); returns ``(observations,
        rewards, terminations, truncations, info)`` as arrays over the envs."""
        if not self._started:
            raise RuntimeError("call reset() before step()")
        given = actions
        try:
            actions = np.asarray(actions)
        except (TypeError, ValueError) as error:
            raise TypeError(f"actions must be an array of shape ({self.num_envs}, 2), got {actions!r}") from error
        if actions.shape != (self.num_envs, 2):
            raise ValueError(f"actions must have shape ({self.num_envs}, 2), got {actions.shape}")
        if isinstance(given, (list, tuple)):
            # (NumPy turns a True among numbers into 1.0: each env's action is checked as the env checks it)
            for i, action in enumerate(given):
                as_vector(f"actions[{i}]", action, 2)
        resetting = self._ended.copy() if self.autoreset_mode == AutoresetMode.NEXT_STEP else np.zeros_like(self._ended)
        stepping = [i for i in range(self.num_envs) if not resetting[i]]
        if self._together:
            return self._step_together(stepping, self._forces(stepping, actions))
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

    def _step_together(self, stepping, forces):
        """:meth:`step` of marbles alone on their levels (``_together``): the physics of the envs ``stepping``
        with their control ``forces`` (N) taken together (:meth:`_physics_together`), and their outcomes worked
        out together, by the single environment's rules (``MarbellousEnv._outcome``) element by element; the
        other envs are reset."""
        n = self.num_envs
        fell = self._physics_together(stepping, forces)
        observations = np.zeros((n,) + self.single_observation_space.shape, dtype=np.float32)
        rewards = np.zeros(n)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        progress = np.zeros(n)
        ran = np.zeros(n, dtype=bool)
        ran[stepping] = True
        if stepping:
            envs = [self.envs[i] for i in stepping]
            games = [env._game for env in envs]
            if self.render_mode is not None:
                for env in envs:
                    env._game.update_camera(env.frame_skip * env._game.dt)
            motion = np.empty((len(stepping), 6))
            motions_at(packed_addresses([g.world for g in games]),
                       np.array([g.marble._index for g in games], dtype=np.int64), motion)
            fallen = fell[stepping]
            old = np.array([env._progress for env in envs])
            new = old.copy()
            if not fallen.all():
                new[~fallen] = games[0].course.project_many(motion[~fallen, :3], old[~fallen])
            finished = np.array([g.finished for g in games])
            steps = np.array([env._steps for env in envs]) + 1
            for env, taken, s in zip(envs, steps.tolist(), new.tolist()):
                env._steps, env._progress = taken, s
            observations[stepping, 0:6] = motion
            observations[stepping, 6:9] = self.envs[0].level.goal_center
            rewards[stepping], terminations[stepping], truncations[stepping] = self.envs[0]._outcomes(
                old, new, fallen, finished, steps)
            progress[stepping] = new
            fell_info, reached_info = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
            fell_info[stepping], reached_info[stepping] = fallen, finished
        info = {}
        ended = terminations | truncations
        for i in np.flatnonzero(~ran | ended if self.autoreset_mode == AutoresetMode.SAME_STEP else ~ran).tolist():
            if ran[i]:
                final_info = {"progress": float(progress[i]), "reached_goal": bool(reached_info[i]),
                              "fell": bool(fell[i])}
                info = self._add_info(info, {"final_obs": observations[i].copy(), "final_info": final_info}, i)
                ran[i] = False
            observations[i], reset_info = self.envs[i].reset()
            progress[i] = reset_info["progress"]
        info["progress"], info["_progress"] = progress, np.ones(n, dtype=bool)
        if stepping:
            info["reached_goal"], info["_reached_goal"] = reached_info & ran, ran.copy()
            info["fell"], info["_fell"] = fell_info & ran, ran.copy()
        self._ended = ended
        return observations, rewards, terminations, truncations, info

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

    def _forces(self, stepping, actions):
        """The control force (N) of each env of ``stepping`` for its action, (len(stepping), 3), as the single
        environment's ``_move`` and the game's ``push`` work it out; every action checked before any force."""
        if not stepping:
            return np.zeros((0, 3))
        chosen = actions[stepping]
        if chosen.dtype.kind not in "iuf" or not np.isfinite(chosen).all():
            for i in stepping:
                self.envs[i]._move(actions[i])                       # raises, naming the action
        games = [self.envs[i]._game for i in stepping]
        return control_forces(chosen, [g.camera.heading for g in games], games[0].marble.mass,
                              games[0].spec.push)

    def _physics_together(self, stepping, forces):
        """:meth:`_physics` for marbles alone on their levels (``_together``), with the control ``forces`` (N) of
        the envs ``stepping``: each physics step pushes every marble still running with one kernel call
        (``pipeline/body_rows.py``), steps their worlds with another (``batch.step_plain``), reads the
        marbles back with a third and judges them together (a fall, the goal: ``Game.judge``'s rules);
        only an env that falls or reaches the goal takes a Python call of its own.  Returns which fell."""
        fell = np.zeros(self.num_envs, dtype=bool)
        if not stepping:
            return fell
        games = [self.envs[i]._game for i in stepping]              # (none has finished: it would have ended)
        first = games[0]
        dt, goal, radius, fall_height = first.dt, first.goal, first.spec.radius, first.level.fall_height
        worlds = [g.world for g in games]
        rows = np.array([g.marble._index for g in games], dtype=np.int64)
        # the games' clocks and physics steps, run as Game.judge runs them (the same sums) and written back at
        # the end, or when a game falls or reaches the goal
        elapsed = np.array([g.elapsed for g in games])
        taken = np.zeros(len(games), dtype=np.int64)
        live = np.arange(len(games))                                # the games still stepping ...
        live_worlds, live_rows, live_forces = worlds, rows, forces  # ... and their worlds, rows and forces
        addresses = packed_addresses(worlds)
        # (worlds with nothing but their bodies to step are stepped with no Python of their own: batch.step_plain)
        plain = plain_entry(worlds, dt)
        for _ in range(self.envs[0].frame_skip):
            if not live.size:
                break
            add_forces_at(addresses, live_rows, live_forces)
            if plain is not None:
                addresses, still_plain = step_plain(live_worlds, addresses, plain, dt, self.threads)
                plain = plain if still_plain else None
            else:
                addresses = step_checked(live_worlds, dt, self.threads)
            elapsed[live] += dt
            taken[live] += 1
            motion = np.empty((live.size, 6))
            motions_at(addresses, live_rows, motion)
            position = motion[:, :3]
            # Game.judge for the games that may have fallen or reached the goal
            judged = (position[:, 1] < fall_height) | goal.may_reach(position, radius)
            if not judged.any():
                continue
            leaving = np.zeros(live.size, dtype=bool)
            for j in np.flatnonzero(judged).tolist():
                k = int(live[j])
                g = games[k]
                if position[j, 1] < fall_height:
                    g.elapsed = float(elapsed[k])
                    g.respawn()
                    fell[stepping[k]] = leaving[j] = True
                elif goal.reached(position[j], radius):
                    g.elapsed = float(elapsed[k])
                    g.finish()
                    leaving[j] = True
            if leaving.any():
                keep = ~leaving
                live, live_rows, live_forces = live[keep], live_rows[keep], live_forces[keep]
                addresses = addresses[keep]
                live_worlds = [worlds[k] for k in live.tolist()]
        for g, seconds, steps in zip(games, elapsed.tolist(), taken.tolist()):
            g.elapsed = seconds
            g.physics_steps += steps
        return fell

    def render(self):
        """Each env's frame (``render_mode="rgb_array"``), as a tuple; None otherwise."""
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs):
        for env in self.envs:
            env.close()
