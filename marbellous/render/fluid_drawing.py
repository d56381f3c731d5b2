"""Every fluid of a world: its box and surface, its velocity as arrows on the middle slices, its dye as puffs.

The arrows sample the velocity (``Fluid.velocity_at``) on a lattice of at most ``ARROWS`` points per side in
the box's middle planes across x and z, each drawn from the sample point along ``v * ARROW_TIME`` (the
distance the flow covers in that time) and coloured by speed, from :data:`palette.FLUID_SLOW` at rest to
:data:`palette.FLUID_FAST` at the fastest sample.  Dye is drawn as lit spheres at the cells holding more than
:data:`DYE_FLOOR` of the largest amount, the radius and depth of colour growing with the amount (at most
:data:`MAX_PUFFS` of them, every k-th cell beyond that), so smoke reads as a volume from any side.
"""
import numpy as np

from . import palette
from .draw_lists import Lines, Spheres

#: most arrows along a side of a slice
ARROWS = 12
#: the arrows' length: how far the flow moves in this time (s)
ARROW_TIME = 0.15
#: the share of the largest amount of dye below which a cell is not drawn
DYE_FLOOR = 0.05
#: most dye puffs drawn per fluid
MAX_PUFFS = 20000


def _box_edges(lo, hi):
    """The 12 edges (12, 2, 3) of the box ``lo .. hi``."""
    corners = np.array([[(hi if (k >> a) & 1 else lo)[a] for a in range(3)] for k in range(8)])
    pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
    return np.array([[corners[a], corners[b]] for a, b in pairs])


def fluid_boxes(frame):
    """The edges of each fluid's box and, with a surface, the outline of the surface inside it."""
    segments = []
    for fluid in frame.world.fluids:
        lo = fluid.origin
        hi = lo + fluid.size
        segments.append(_box_edges(lo, hi))
        if fluid.surface is not None and lo[1] <= fluid.surface <= hi[1]:
            y = fluid.surface
            ring = np.array([[lo[0], y, lo[2]], [hi[0], y, lo[2]], [hi[0], y, hi[2]], [lo[0], y, hi[2]]])
            segments.append(np.stack([ring, np.roll(ring, -1, axis=0)], axis=1))
    if not segments:
        return []
    edges = np.concatenate(segments)
    return [Lines(edges, np.tile(palette.FLUID_BOX, (len(edges), 1)), 1.5, in_scene=True)]


def _slice_points(fluid):
    """Sample points (N, 3) on the middle planes of ``fluid``'s box across x and across z."""
    lo, size = fluid.origin, fluid.size
    ticks = [lo[a] + (np.arange(min(ARROWS, n)) + 0.5) * size[a] / min(ARROWS, n)
             for a, n in enumerate(fluid.resolution)]
    middle = lo + 0.5 * size
    across_z = np.stack(np.meshgrid(ticks[0], ticks[1], [middle[2]], indexing="ij"), -1).reshape(-1, 3)
    across_x = np.stack(np.meshgrid([middle[0]], ticks[1], ticks[2], indexing="ij"), -1).reshape(-1, 3)
    return np.concatenate([across_z, across_x])


def fluid_arrows(frame):
    """Each fluid's velocity as arrows on its middle slices, coloured by speed."""
    out = []
    for fluid in frame.world.fluids:
        points = _slice_points(fluid)
        velocity = fluid.velocity_at(points)
        speed = np.linalg.norm(velocity, axis=1)
        top = float(speed.max())
        if top <= 0.0:
            continue
        tips = points + velocity * ARROW_TIME
        share = (speed / top)[:, None]
        colors = (1.0 - share) * np.asarray(palette.FLUID_SLOW) + share * np.asarray(palette.FLUID_FAST)
        out.append(Lines(np.stack([points, tips], axis=1), colors, 1.5, in_scene=True))
    return out


def fluid_dye(frame):
    """Each fluid's dye as puffs at the cells that hold it."""
    out = []
    for fluid in frame.world.fluids:
        dye = fluid.dye
        top = float(np.abs(dye).max())
        if top <= 0.0:
            continue
        cells = np.argwhere(np.abs(dye) > DYE_FLOOR * top)
        if len(cells) > MAX_PUFFS:
            cells = cells[::-(-len(cells) // MAX_PUFFS)]
        amount = (np.abs(dye[tuple(cells.T)]) / top)[:, None]
        centres = fluid.origin + (cells + 0.5) * fluid.cell_size
        colors = (1.0 - amount) * np.asarray(palette.DYE_THIN) + amount * np.asarray(palette.DYE_THICK)
        out.append(Spheres(centres, fluid.cell_size * (0.2 + 0.35 * amount[:, 0]), colors))
    return out


def fluids(frame):
    """Every fluid: its box, surface and dye."""
    return fluid_boxes(frame) + fluid_dye(frame)
