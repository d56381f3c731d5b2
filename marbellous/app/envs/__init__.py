"""Gymnasium environments of Marbellous.

``import marbellous`` registers ``"Marbellous-v0"`` with gymnasium without importing gymnasium (0.15 s of
every start, which a program that never uses gymnasium need not pay): if gymnasium is already imported the
environment is registered at once, otherwise as soon as gymnasium is (:func:`register_when_imported`), and
so before any ``gymnasium.make`` can look it up.
"""
import importlib.abc
import importlib.util
import sys

#: The id under which :func:`register_envs` registers :class:`~marbellous.app.envs.marble_env.MarbellousEnv` (and,
#: for ``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``,
#: :class:`~marbellous.app.envs.marble_vector_env.MarbellousVectorEnv`).
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
                           vector_entry_point="marbellous.app.envs.marble_vector_env:MarbellousVectorEnv",
                           max_episode_steps=None)


class _RegisterOnImport(importlib.abc.MetaPathFinder):
    """An import hook that registers the environment right after the module ``gymnasium`` has run (then it
    removes itself)."""

    def find_spec(self, name, path, target=None):
        if name != "gymnasium":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None and hasattr(spec.loader, "exec_module"):
            run = spec.loader.exec_module

            def run_then_register(module):
                run(module)
                register_envs()
            spec.loader.exec_module = run_then_register
        return spec


def register_when_imported():
    """Register the environment now if gymnasium is imported, else once it is (the module docstring)."""
    if "gymnasium" in sys.modules:
        register_envs()
    elif not any(isinstance(finder, _RegisterOnImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _RegisterOnImport())
