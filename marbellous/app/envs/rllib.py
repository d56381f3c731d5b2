"""``"Marbellous-v0"`` for RLlib: :func:`register_rllib` puts the environment into Ray Tune's registry, where
RLlib looks up an environment by name on every worker of a cluster:

    from marbellous.app.envs.rllib import register_rllib
    from ray.rllib.algorithms.ppo import PPOConfig
    register_rllib()
    config = PPOConfig().environment("Marbellous-v0", env_config={"level": "hills", "frame_skip": 4})

``env_config`` holds :class:`~marbellous.app.envs.marble_env.MarbellousEnv`'s options.  Needs Ray with Tune
(``pip install "marbellous[cluster]"``).
"""
from . import ENV_ID
from .marble_env import MarbellousEnv


def make_env(env_config=None):
    """A :class:`~marbellous.app.envs.marble_env.MarbellousEnv` with the options of ``env_config`` (a dict,
    or RLlib's ``EnvContext``, a dict that also knows its worker; None: the defaults)."""
    if env_config is not None and not isinstance(env_config, dict):
        raise TypeError(f"env_config must be a dict of the environment's options, got {env_config!r}")
    return MarbellousEnv(**dict(env_config or {}))


def register_rllib(name=ENV_ID):
    """Register :func:`make_env` in Ray Tune's registry under ``name`` (``"Marbellous-v0"``); call it in the
    driver before building an RLlib algorithm (Ray ships the registry to its workers)."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"name must be a non-empty str, got {name!r}")
    try:
        from ray.tune.registry import register_env
    except ImportError:
        raise ImportError('RLlib\'s registry needs Ray with Tune: pip install "marbellous[cluster]"') from None
    register_env(name, make_env)
