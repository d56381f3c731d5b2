"""Handles of constraints between bodies: ``Spring`` (Hooke), ``Rod`` (fixed distance), ``Cable`` (at most a length)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .state import layout as L

if TYPE_CHECKING:
    from .body import Body


class Constraint:
    """Base of the constraint handles: a thin view over one row of the world's constraint table."""

    __slots__ = ("_world", "_index", "_revision", "_body_a", "_body_b", "__weakref__")

    def __init__(self, world, index, revision, body_a, body_b):
        self._world = world
        self._index = index
        self._revision = revision
        self._body_a = body_a
        self._body_b = body_b

    @property
    def body_a(self) -> Body:
        """The first body (``Body``)."""
        return self._body_a

    @property
    def body_b(self) -> Body | None:
        """The second body (``Body``), or None when the constraint is attached to the world."""
        return self._body_b

    def _rows(self):
        w = self._world
        if w is None or w._state.constraints.revision[self._index] != self._revision:
            raise ValueError("this constraint has been removed from its world")
        return w._state.kf[self._index], w._state.ki[self._index]

    @property
    def broken(self) -> bool:
        """True once the force exceeded the breaking force; a broken constraint applies no force."""
        return bool(self._rows()[1][L.K_FLAGS] & L.KF_BROKEN)

    @property
    def force(self) -> np.ndarray:
        """Force (N) the constraint applied to body_a in the last step (body_b got the opposite)."""
        return np.array(self._rows()[0][L.K_FORCE:L.K_FORCE + 3])

    @property
    def anchor_a(self) -> np.ndarray:
        """Where the constraint holds ``body_a``: a point in body_a's frame (m)."""
        return np.array(self._rows()[0][L.K_ANCHOR_A:L.K_ANCHOR_A + 3])

    @property
    def anchor_b(self) -> np.ndarray:
        """Where the constraint holds ``body_b``: a point in body_b's frame, or a fixed world point when
        ``body_b`` is None (m)."""
        return np.array(self._rows()[0][L.K_ANCHOR_B:L.K_ANCHOR_B + 3])

    @property
    def length(self) -> float:
        """Rest length (spring), length (rod) or maximum length (cable), m."""
        return float(self._rows()[0][L.K_LENGTH])

    def __repr__(self):
        return f"<{type(self).__name__} #{self._index} length={self.length:.4g}>"


class Spring(Constraint):
    """Hooke spring with damping: ``F = -k (l - l0) - c dl/dt`` along the line between the anchors."""

    __slots__ = ()

    @property
    def stiffness(self) -> float:
        """Spring constant k (N/m)."""
        return float(self._rows()[0][L.K_STIFFNESS])

    @property
    def damping(self) -> float:
        """Damping coefficient c (N s/m)."""
        return float(self._rows()[0][L.K_DAMPING])


class Rod(Constraint):
    """A massless rigid rod: the distance between the anchors stays ``length``."""

    __slots__ = ()


class Cable(Constraint):
    """A massless inextensible cable: the distance between the anchors is at most ``length``; slack below."""

    __slots__ = ()
