"""The particles of a world as spheres and its particle networks as lines.

Every particle of every set is one sphere of its radius (:class:`Spheres`: a point each, ray-cast on the
GPU, so a 16k-particle net is one draw call), teal, or raspberry while pinned (palette.py).  Every edge of
every network that has not broken is a line between its two particles, coloured by kind as the springs,
rods and cables between bodies are; the lines are drawn in the scene (hidden behind the bodies and
particles in front of them), not over it, so a net shows its near side.  Both read the world's
particle tables at once (``world_internals.py``), not set by set; a cloth's vertices and edges are left out
(a cloth is drawn as its surface, ``cloth_drawing.py``).
"""
import numpy as np

from . import palette
from .draw_lists import Lines, Spheres
from .world_internals import EDGE_KIND_NAMES, network_edges, particle_table

#: Width (pixels) of a network's edges.
EDGE_WIDTH = 2.0
#: Colour of each kind of edge, indexed by its code in the edge table.
_EDGE_COLORS = np.zeros((max(EDGE_KIND_NAMES) + 1, 3))
for _code, _name in EDGE_KIND_NAMES.items():
    _EDGE_COLORS[_code] = {"spring": palette.SPRING, "rod": palette.ROD, "cable": palette.CABLE}[_name]


def particle_spheres(frame):
    """A :class:`Spheres` of every particle of ``frame.world``, pinned ones in their own colour."""
    centers, radii, pinned = particle_table(frame.world)
    if not len(centers):
        return []
    colors = np.where(pinned[:, None], np.asarray(palette.PINNED_PARTICLE), np.asarray(palette.PARTICLE))
    return [Spheres(centers, radii, colors)]


def network_lines(frame):
    """:class:`Lines` (in the scene) along every edge of every network of ``frame.world`` that has not
    broken, coloured by kind."""
    ends, kinds = network_edges(frame.world)
    if not len(ends):
        return []
    return [Lines(ends, _EDGE_COLORS[kinds], EDGE_WIDTH, in_scene=True)]
