"""What a world reports: the contacts of the last step (``Contact``), what began and ended touching in it
(``ContactEvent``), ray hits (``RayHit``) and how the last step was taken (``StepReport``)."""
from dataclasses import dataclass

import numpy as np

from .body import Body


@dataclass(frozen=True)
class RayHit:
    """The nearest surface a ray hit: ``body``, ``point`` (m), unit ``normal`` there, ``distance`` (m).

    ``object`` is what was hit: the body, a set of ``Particles``, a ``Cloth`` or a ``SoftBody``, whose particle,
    triangle or surface triangle (``SoftBody.surface_triangles``) ``index`` it was (``body`` is then None;
    ``index`` is None for a body)."""

    body: Body | None
    point: np.ndarray
    normal: np.ndarray
    distance: float
    hit: object = None
    index: int | None = None

    @property
    def object(self):
        """What was hit: a ``Body`` or ``Particles``."""
        return self.body if self.hit is None else self.hit


@dataclass(frozen=True)
class Contact:
    """A contact point found by the last step's collision detection (at the poses the step began with).

    ``normal`` points from ``body_a`` to ``body_b``; ``depth > 0`` is overlap (m), ``depth <= 0`` a
    speculative contact with gap ``-depth``.  ``normal_impulse`` (N s) and ``tangent_impulse`` (N s,
    world vector) are what the solver applied at this point over the step.
    """

    body_a: Body
    body_b: Body
    point: np.ndarray
    normal: np.ndarray
    depth: float
    normal_impulse: float
    tangent_impulse: np.ndarray


@dataclass(frozen=True)
class ContactEvent:
    """Two bodies began (``kind == "begin"``) or stopped (``"end"``) touching during the last step.

    One event per pair of bodies (however many contact points they share).  ``point`` (m) and ``normal``
    (from ``body_a`` to ``body_b``) are those of the pair's deepest contact point (for an end: the last one
    it had); ``approach_speed`` (m/s, >= 0) is how fast the bodies closed along the normal as they met
    (0 for an end).
    """

    kind: str
    body_a: Body
    body_b: Body
    point: np.ndarray
    normal: np.ndarray
    approach_speed: float


@dataclass(frozen=True)
class StepReport:
    """How the last :meth:`World.step` was taken (``World.time_stepping``, ``World.ccd``).

    ``steps``: intervals the step was finally taken in (1 when nothing was halved or advanced; each halving
    and each advance to a time of impact adds one; intervals undone by the retroactive mode do not count);
    ``halvings``: intervals undone and taken again as two halves (``"retroactive"``); ``toi_events``:
    intervals that ended at a time of impact (continuous collision, ``"conservative"``); ``smallest_dt``:
    the shortest of the intervals (s), at least ``dt / 2**World.max_halvings``.
    """

    steps: int
    halvings: int
    toi_events: int
    smallest_dt: float
