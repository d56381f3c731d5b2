"""The native vector environment: env i of ``make_vec(..., vectorization_mode="vector_entry_point")`` reset with
seed s repeats, step for step, a single environment reset with seed s + i, autoresets included."""
import gymnasium as gym
import numpy as np
import pytest

import marbellous  # noqa: F401  (registers the environment)
from marbellous.app.envs.marble_vector_env import MarbellousVectorEnv

#: short episodes, so that the runs below end and restart episodes (truncated, and fallen with strong pushes)
OPTIONS = dict(max_episode_steps=12, frame_skip=3)


def _singles(n, seed, **options):
    envs = [gym.make("Marbellous-v0", **OPTIONS, **options) for _ in range(n)]
    first = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    return envs, np.stack(first)


def _actions(rng, n):
    return rng.uniform(-1.0, 1.0, size=(n, 2)).astype(np.float32) * 3.0   # beyond the unit disc: scaled onto it


@pytest.mark.parametrize("threads, flag", [(1, False), (2, False), (1, True)])
def test_next_step_autoreset_repeats_the_single_environments(threads, flag):
    # (without the flag, the marbles are pushed, stepped and judged together; with it, env by env)
    n, seed = 3, 11
    vec = gym.make_vec("Marbellous-v0", num_envs=n, vectorization_mode="vector_entry_point", threads=threads,
                       flag=flag, **OPTIONS)
    assert isinstance(vec.unwrapped, MarbellousVectorEnv)
    assert vec.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP
    singles, first = _singles(n, seed, flag=flag)
    obs, info = vec.reset(seed=seed)
    assert vec.unwrapped._together is not flag
    assert obs.shape == (n, 9) and obs.dtype == np.float32
    np.testing.assert_array_equal(obs, first)
    ended = np.zeros(n, dtype=bool)
    rng = np.random.default_rng(5)
    episodes_ended = 0
    for _ in range(40):
        actions = _actions(rng, n)
        obs, rewards, terminated, truncated, info = vec.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:                          # the vector env resets it now, ignoring the action
                want = env.reset()[0]
                assert rewards[i] == 0.0 and not terminated[i] and not truncated[i]
            else:
                want, r, term, trunc, single_info = env.step(actions[i])
                assert (rewards[i], terminated[i], truncated[i]) == (r, term, trunc)
                assert info["progress"][i] == single_info["progress"] and info["_progress"][i]
            np.testing.assert_array_equal(obs[i], want)
        ended = terminated | truncated
        episodes_ended += int(ended.sum())
    assert episodes_ended >= n                    # the autoreset was exercised
    vec.close()


def test_same_step_autoreset_repeats_the_single_environments():
    n, seed = 2, 3
    vec = gym.make_vec("Marbellous-v0", num_envs=n, vectorization_mode="vector_entry_point",
                       autoreset_mode="SameStep", **OPTIONS)
    singles, first = _singles(n, seed)
    np.testing.assert_array_equal(vec.reset(seed=seed)[0], first)
    rng = np.random.default_rng(9)
    finals = 0
    for _ in range(30):
        actions = _actions(rng, n)
        obs, rewards, terminated, truncated, info = vec.step(actions)
        for i, env in enumerate(singles):
            want, r, term, trunc, _ = env.step(actions[i])
            assert (rewards[i], terminated[i], truncated[i]) == (r, term, trunc)
            if term or trunc:
                np.testing.assert_array_equal(info["final_obs"][i], want)
                want = env.reset()[0]
                finals += 1
            np.testing.assert_array_equal(obs[i], want)
    assert finals >= n


@pytest.mark.parametrize("mode", ["NextStep", "SameStep"])
def test_marbles_dropped_into_the_goal_end_their_episodes_as_alone(mode):
    n, seed = 3, 4
    vec = MarbellousVectorEnv(n, autoreset_mode=mode, **OPTIONS)
    singles, _ = _singles(n, seed)
    vec.reset(seed=seed)
    level = vec.envs[0].level
    # env 0 above the goal's centre, env 1 beside it (0.1 m from its side, nearer than its corners), env 2 left
    # on the course
    drops = [level.goal_center + (0.0, 0.5, 0.0), level.goal_center + level.goal_half_extents * (1.0, 0.0, 0.0)
             + (0.4, 0.0, 0.0)]
    for envs in (vec.envs, [env.unwrapped for env in singles]):
        for env, drop in zip(envs, drops):
            env._game.marble.position = drop
    obs, rewards, terminated, truncated, info = vec.step(np.zeros((n, 2), np.float32))
    for i, env in enumerate(singles):
        want, r, term, trunc, single_info = env.step(np.zeros(2, np.float32))
        assert (rewards[i], terminated[i], truncated[i]) == (r, term, trunc)
        if mode == "SameStep" and term:
            np.testing.assert_array_equal(info["final_obs"][i], want)
            assert info["final_info"]["reached_goal"][i] == single_info["reached_goal"]
            want = env.reset()[0]
        else:
            assert info["reached_goal"][i] == single_info["reached_goal"] and info["_reached_goal"][i]
        np.testing.assert_array_equal(obs[i], want)
        game, alone = vec.envs[i]._game, env.unwrapped._game          # the clocks ran as alone
        assert (game.elapsed, game.physics_steps, game.finished) == (alone.elapsed, alone.physics_steps,
                                                                    alone.finished)
    assert terminated[0] and rewards[0] >= OPTIONS.get("goal_reward", 10.0) - 1.0
    assert not terminated[1] and not terminated[2]


def test_seeds_may_be_given_one_per_env():
    vec = MarbellousVectorEnv(2, **OPTIONS)
    a = vec.reset(seed=[7, 7])[0]
    np.testing.assert_array_equal(a[0], a[1])
    b = vec.reset(seed=7)[0]
    np.testing.assert_array_equal(a[0], b[0])
    assert np.any(a[1] != b[1])                   # seed 8 starts elsewhere


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(num_envs=0), ValueError, "num_envs"),
    (dict(num_envs=2.5), TypeError, "num_envs"),
    (dict(num_envs=2, threads=0), ValueError, "threads"),
    (dict(num_envs=2, autoreset_mode="Later"), ValueError, "autoreset_mode"),
    (dict(num_envs=2, autoreset_mode="Disabled"), ValueError, "autoreset_mode"),
    (dict(num_envs=2, frame_skip=0), ValueError, "frame_skip"),
    (dict(num_envs=2, flag="yes"), TypeError, "flag"),
])
def test_bad_options_are_refused(kwargs, error, match):
    with pytest.raises(error, match=match):
        MarbellousVectorEnv(**kwargs)


def test_bad_calls_are_refused_and_change_nothing():
    vec = MarbellousVectorEnv(2, **OPTIONS)
    with pytest.raises(RuntimeError, match="reset"):
        vec.step(np.zeros((2, 2)))
    obs = vec.reset(seed=1)[0]
    for bad, error, match in [(np.zeros((3, 2)), ValueError, "shape"), (np.zeros(2), ValueError, "shape"),
                              (np.array([[0.0, 0.0], [np.nan, 0.0]]), ValueError, "action")]:
        with pytest.raises(error, match=match):
            vec.step(bad)
    for seed, error in [([1], TypeError), ("1", TypeError), (-1, ValueError), ([1, -2], ValueError)]:
        with pytest.raises(error, match="seed"):
            vec.reset(seed=seed)
    with pytest.raises(ValueError, match="options"):
        vec.reset(options={"level": "hills"})
    assert obs.shape == (2, 9)
    ref = MarbellousVectorEnv(2, **OPTIONS)
    ref.reset(seed=1)
    np.testing.assert_array_equal(vec.step(np.zeros((2, 2)))[0], ref.step(np.zeros((2, 2)))[0])


def test_the_infos_are_arrays_of_their_kind_and_undrawn_envs_build_no_second_world():
    vec = gym.make_vec("Marbellous-v0", num_envs=2, vectorization_mode="vector_entry_point", **OPTIONS)
    vec.reset(seed=0)
    _, _, _, _, info = vec.step(np.zeros((2, 2), np.float32))
    assert info["progress"].dtype == np.float64
    assert info["reached_goal"].dtype == bool and info["fell"].dtype == bool and info["_fell"].all()
    # the level-only world for the camera's rays is made only when something draws or casts rays
    assert all("scenery" not in vars(env._game) for env in vec.unwrapped.envs)
    vec.close()
