"""Gymnasium environments of Marbellous."""

#: The id under which :func:`register_envs` registers :class:`~marbellous.app.envs.marble_env.MarbellousEnv`.
ENV_ID = "Marbellous-v0"


def register_envs():
    """Register ``"Marbellous-v0"`` with gymnasium (once; later calls do nothing).  Without
    gymnasium installed this does nothing, so ``import marbellous`` never needs it."""
    try:
        import gymnasium
    except ImportError:
        return
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(id=ENV_ID, entry_point="marbellous.app.envs.marble_env:MarbellousEnv",
                           max_episode_steps=None)
