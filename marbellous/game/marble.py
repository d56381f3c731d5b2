"""The marble: a glass sphere with friction, rolling friction and restitution that feel like a marble."""
from dataclasses import dataclass

from ..shapes import Sphere


@dataclass(frozen=True)
class MarbleSpec:
    """Physical and control properties of the player's marble.

    ``radius`` (m) and ``density`` (kg/m^3, glass) give the mass ``4/3 pi r^3 rho``.  ``friction``,
    ``static_friction`` and ``rolling_friction`` combine with the level's materials (geometric mean
    for the Coulomb coefficients, max for rolling friction); ``restitution`` lets it bounce a little
    off walls.  ``push`` (m/s^2) is the acceleration a full control input applies as a force
    ``F = m push`` in the ground plane; ``jump_speed`` (m/s) is the upward speed change of a jump.
    """

    radius: float = 0.3
    density: float = 2500.0
    friction: float = 0.5
    static_friction: float = 0.7
    restitution: float = 0.35
    rolling_friction: float = 0.005
    push: float = 9.0
    jump_speed: float = 4.0

    def add_to(self, world, position):
        """Add the marble to ``world`` at ``position`` (m) and return its body."""
        return world.add_body(Sphere(self.radius), position=position, density=self.density,
                              friction=self.friction, static_friction=self.static_friction,
                              restitution=self.restitution, rolling_friction=self.rolling_friction)
