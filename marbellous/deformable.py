"""``Deformable``: what a cloth's and a soft body's handles share, a deformable object whose points are a set
of the world's particles (its vertices or nodes).

The handle reads copies and validates what it writes (through its set's :class:`~marbellous.particles.Particles`
handle); once its object is removed from the world (or dropped by a restore) it raises on use.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .particles import Particles


class Deformable:
    """A deformable object of a world: its ``_record`` holds its set of particles (``set``) and whether it is
    ``alive``.  Point indices count from 0 within the object."""

    __slots__ = ("_world", "_record", "_points", "__weakref__")

    #: what the object is called in messages ("cloth", "soft body")
    noun = "deformable object"

    def __init__(self, world, record):
        self._world = world
        self._record = record
        self._points = Particles(world, record.set)

    def _live(self):
        if self._world is None or not self._record.alive:
            raise ValueError(f"this {self.noun} has been removed from its world")
        return self._points

    def __len__(self):
        return len(self._live())

    @property
    def positions(self) -> np.ndarray:
        """The points' positions (m), ``(V, 3)``; assigning moves them (and the pins of those pinned to the
        world)."""
        return self._live().positions

    @positions.setter
    def positions(self, value: ArrayLike) -> None:
        self._live().positions = value

    @property
    def velocities(self) -> np.ndarray:
        """The points' velocities (m/s), ``(V, 3)``; assignable (points pinned to the world stay at rest)."""
        return self._live().velocities

    @velocities.setter
    def velocities(self, value: ArrayLike) -> None:
        self._live().velocities = value

    @property
    def mass(self) -> np.ndarray:
        """Each point's mass (kg), ``(V,)``."""
        return self._live().mass

    @property
    def pinned(self) -> np.ndarray:
        """Whether each point is pinned (to the world or to a body), ``(V,)`` bool."""
        return self._live().pinned

    def pin(self, indices: ArrayLike, body=None) -> None:
        """Hold the chosen points where they are now: fixed in the world (``body=None``), or at their place on
        ``body``, moving with it (two ways: the body carries them and feels their weight and pull)."""
        self._live().pin(indices, body)

    def unpin(self, indices: ArrayLike) -> None:
        """Let the chosen points go."""
        self._live().unpin(indices)

    def apply_force(self, force: ArrayLike, indices: ArrayLike = None) -> None:
        """Add the world force ``force`` (N, a 3-vector) on each chosen point (None: all) for the next step."""
        self._live().apply_force(force, indices)
