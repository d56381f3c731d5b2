"""The gymnasium environment "Marbellous-v0"."""
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from marbellous.app.envs import ENV_ID, register_envs
from marbellous.app.envs.marble_env import MarbellousEnv


@pytest.fixture(scope="module", autouse=True)
def registered():
    register_envs()


def test_registered_and_passes_the_checker():
    assert ENV_ID in gym.registry
    env = gym.make(ENV_ID)
    check_env(env.unwrapped)
    env.close()


def test_spaces():
    env = MarbellousEnv()
    obs, info = env.reset(seed=0)
    assert env.observation_space.shape == (9,) and obs.dtype == np.float32
    assert env.action_space.shape == (2,)
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)
    assert np.allclose(obs[6:], env.level.goal_center)
    assert np.allclose(obs[:3], env.level.start_position, atol=0.31)


def test_seeding_reproduces_episodes():
    def run(seed):
        env = MarbellousEnv(level="blocks")
        obs, _ = env.reset(seed=seed)
        out = [obs]
        rng = np.random.default_rng(5)
        for _ in range(20):
            obs, r, *_ = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
            out.append(obs)
        return np.array(out)

    a, b, c = run(3), run(3), run(4)
    assert np.array_equal(a, b)
    assert not np.array_equal(a[0], c[0])


def test_progress_reward_and_truncation():
    env = MarbellousEnv(level="blocks", max_episode_steps=40, start_jitter=0.0)
    env.reset(seed=1)
    total, steps = 0.0, 0
    while True:
        obs, r, term, trunc, info = env.step(np.array([1.0, 0.0], np.float32))   # towards +x: along the course
        total += r
        steps += 1
        if term or trunc:
            break
    assert trunc and not term and steps == 40
    assert total > 1.0 and info["progress"] == pytest.approx(total, abs=1e-9)
    # pushing backwards off the start costs progress
    env.reset(seed=1)
    _, r, *_ = env.step(np.array([-1.0, 0.0], np.float32))
    for _ in range(10):
        _, r2, *_ = env.step(np.array([-1.0, 0.0], np.float32))
    assert r2 <= 0.0


def test_goal_terminates_with_bonus():
    env = MarbellousEnv(level="blocks", goal_reward=10.0, start_jitter=0.0)
    env.reset(seed=0)
    env._game.marble.position = env.level.goal_center
    _, r, term, trunc, info = env.step(np.zeros(2, np.float32))
    assert term and not trunc and info["reached_goal"] and r > 9.0


def test_falling_off_terminates_with_penalty():
    env = MarbellousEnv(level="course", fall_penalty=5.0, start_jitter=0.0)
    env.reset(seed=0)
    env._game.marble.position = (0.0, env.level.fall_height + 0.05, -30.0)
    env._game.marble.velocity = (0.0, -5.0, 0.0)
    _, r, term, _, info = env.step(np.zeros(2, np.float32))
    assert term and info["fell"] and r == pytest.approx(-5.0)


def test_bad_action_rejected():
    env = MarbellousEnv(level="blocks")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.array([np.nan, 0.0]))


def test_rgb_render():
    env = MarbellousEnv(level="blocks", render_mode="rgb_array", size=(160, 90))
    env.reset(seed=0)
    img = env.render()
    assert img.shape == (90, 160, 3) and img.dtype == np.uint8 and img.std() > 5
    env.close()
    assert env._renderer is None


def test_import_marbellous_registers_the_environment_without_importing_gymnasium():
    # gymnasium costs a start 0.15 s: it is imported by those who use it, and the environment is there then
    code = ("import sys\n"
            "import marbellous\n"
            "print('gymnasium' in sys.modules)\n"
            "from gymnasium.spaces import Box\n"
            "import gymnasium\n"
            "print('Marbellous-v0' in gymnasium.registry)\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["False", "True"]


def test_the_goal_flag_waves_only_when_the_environment_renders_unless_asked():
    from marbellous.app.envs.marble_env import MarbellousEnv

    cases = [(dict(), False), (dict(render_mode="rgb_array"), True), (dict(flag=True), True),
             (dict(render_mode="rgb_array", flag=False), False)]
    for options, waving in cases:
        env = MarbellousEnv(level="blocks", **options)
        env.reset(seed=0)
        assert (env._game.flag is not None) == waving, options
        assert bool(env._game.world.cloths) == waving, options
        env.close()
