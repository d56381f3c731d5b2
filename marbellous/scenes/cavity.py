"""The lid-driven cavity: a unit square of fluid whose top wall slides at 1 m/s, and the benchmark it is
checked against.

``GHIA_*`` are Ghia, Ghia & Shin's centre-line profiles (1982, J. Comput. Phys. 48, 387-411, tables I and II):
u along the vertical centre line at the heights ``GHIA_Y``, v along the horizontal one at ``GHIA_X``, for
Re = 100 and 400.  Table II's v = -0.23827 at x = 0.9063 for Re = 400 does not fit its neighbours (-0.22847 at
0.9453 and -0.44993 at 0.8594 bound a convex stretch of the profile there; fine-grid solutions have about
-0.38), so ``GHIA_V_SKIP`` leaves it out.  ``FINE_EXTREMA_RE100`` are the extrema of the Re = 100 profiles on
fine grids (Botella-Peyret-class and 1024^2 solutions): min u, max v, min v.
"""
import numpy as np

from ..fluid import Fluid

GHIA_Y = (1.0, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5, 0.4531, 0.2813, 0.1719, 0.1016,
          0.0703, 0.0625, 0.0547, 0.0)
GHIA_X = (1.0, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5, 0.2344, 0.2266, 0.1563, 0.0938,
          0.0781, 0.0703, 0.0625, 0.0)
GHIA_U = {100: (1.0, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090, -0.15662,
                -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.0),
          400: (1.0, 0.75837, 0.68439, 0.61756, 0.55892, 0.29093, 0.16256, 0.02135, -0.11477, -0.17119, -0.32726,
                -0.24299, -0.14612, -0.10338, -0.09266, -0.08186, 0.0)}
GHIA_V = {100: (0.0, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454, 0.17527,
                0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.0),
          400: (0.0, -0.12146, -0.15663, -0.19254, -0.22847, -0.23827, -0.44993, -0.38598, 0.05186, 0.30174,
                0.30203, 0.28124, 0.22965, 0.20920, 0.19713, 0.18360, 0.0)}
GHIA_V_SKIP = {100: (), 400: (5,)}
FINE_EXTREMA_RE100 = (-0.21404, 0.17957, -0.25380)
#: resolutions (cells per side) and how long (s) each is run to come to a steady state, coarse to fine
SCHEDULE = {100: ((32, 20.0), (64, 8.0), (128, 4.0)), 400: ((32, 30.0), (64, 15.0), (128, 5.0))}


def lid_driven_cavity(reynolds, cells):
    """A 2D cavity of side 1 m, ``cells`` per side, its lid (y+) sliding at 1 m/s, viscosity 1 / ``reynolds``
    m^2/s, density 1 kg/m^3."""
    fluid = Fluid((cells, cells), 1.0 / cells, viscosity=1.0 / reynolds, density=1.0)
    fluid.set_wall_velocity("y+", (1.0, 0.0))
    return fluid


def steady_cavities(reynolds, schedule=None, after_step=None):
    """Steady cavities at each resolution of ``schedule`` (default ``SCHEDULE[reynolds]``), each started from
    the coarser one's flow and stepped at a Courant number of 1: ``{cells: Fluid}``.  ``after_step(fluid, dt)``
    is called after every step (a test's check)."""
    out, previous = {}, None
    for cells, seconds in schedule or SCHEDULE[reynolds]:
        fluid = lid_driven_cavity(reynolds, cells)
        if previous is not None:
            ratio = cells // previous.shape[0]
            fluid.velocity = np.repeat(np.repeat(previous, ratio, 0), ratio, 1)
        dt = 1.0 / cells
        for _ in range(round(seconds / dt)):
            fluid.step(dt)
            if after_step is not None:
                after_step(fluid, dt)
        out[cells], previous = fluid, fluid.velocity
    return out


def ghia_differences(fluid, reynolds):
    """The largest differences (m/s) of ``fluid``'s centre-line profiles from Ghia et al.'s points: ``(u, v)``,
    v without the points in ``GHIA_V_SKIP``."""
    u = fluid.velocity_at(np.stack([np.full(17, 0.5), GHIA_Y], 1))[:, 0] - GHIA_U[reynolds]
    v = fluid.velocity_at(np.stack([GHIA_X, np.full(17, 0.5)], 1))[:, 1] - GHIA_V[reynolds]
    return float(np.abs(u).max()), float(np.abs(np.delete(v, GHIA_V_SKIP[reynolds])).max())
