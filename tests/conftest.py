"""Shared fixtures: compile the kernels once per session so tests time physics, not compilation."""

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("marbellous", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("marbellous")


@pytest.fixture(scope="session", autouse=True)
def warm_kernels():
    """Take one step of a small world so the step kernel is compiled (or loaded from cache) once."""
    import marbellous as mb

    w = mb.World()
    w.add_body(mb.Sphere(0.5), position=(0.0, 1.0, 0.0))
    w.step(1.0 / 60.0)
    yield
