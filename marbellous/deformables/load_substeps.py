"""How many sub-steps the particles' step needs to carry the bodies that rest on them.

A body of mass ``M`` resting on particles of mass ``m`` in all (those under it): each sub-step of ``h``, gravity
moves it ``g h^2`` into them, and the contact's position pass splits the overlap ``d`` by their inverse masses,
handing the body ``d m / (M + m)`` of it.  So the body rests with the overlap

    d = g h^2 (M + m) / m  ~  g h^2 r,    r = M / m

into the particles under it (the springs take the particles back up between the contact's passes, and the contact
finds the overlap again).  Too deep, and the vertices slip past the body's underside and it goes through the sheet.
Measured on a 1 m sheet of 21 x 21 vertices held at its corners, a 0.3 m box dropped from 0.5 m at 60 Hz (masses
tried: 1, 2, 3, 5, 7, 10, 15, 20, 30, 50 kg): at 16, 24, 32, 48 and 64 sub-steps the sheet of 0.2 kg carried 3, 7,
10, 20 and 30 kg and let the next mass through, that of 0.05 kg none, 1, 3, 5 and 10 kg.  With ``m`` the 49
vertices under the box (25 g and 6 g), every box carried has ``g h^2 r`` of at most 1.35 mm and every box that
went through at least 1.35 mm.  With ``World.particle_substeps`` left automatic, the step takes

    n >= dt sqrt(g r / LOAD_SAG)

for every dynamic body that lies on particles (candidates whose contact normal with it is within 60 degrees of
straight up; ``m`` the mass of those candidates), with ``LOAD_SAG`` about half that limit, at least the world's
count and at most ``MOST_LOAD_SUBSTEPS``.  As the load spreads over the vertices under the body, a small body needs
more than a large one of its mass: a 15 cm cube of 2 kg and a 10 cm ball of 1 kg, which went through the 0.2 kg
sheet at 16 sub-steps, take about 30 on average and stay on it; the 10 kg box of 0.3 m rests on it at 57.  A body
landing on an edge or a corner, one or two vertices under it, takes up to 128 for a step or two.  The cost of a
step grows with ``n``.  Not counted: a cloth lying on a body (draped over it), bodies on particles that the ground
or a pin holds (a box on a cloth lying on the floor), soft bodies' nodes (their implicit step carries a load,
soft_step.py), and cloth solved as a whole (``World.cloth_stretch_passes``: its solve hands a load to the pins
within the sub-step); nor a body held by a cloth's triangles or border edges alone, no vertex under it
(corner_contacts.py).  Beyond 128: a 15 cm cube or a 10 cm ball of 30 kg (150 times the sheet) goes through.
"""
import math

import numpy as np

from .._numba.jit import njit
from ..dynamics.forces import is_dynamic
from ..state.layout import INV_MASS, S_BODY
from .body_motion import pushable
from .particle_layout import P_CLOTH, P_FLAGS, P_MASS, PP_PINNED, PP_SOFT

#: the overlap ``g h^2 r`` (m) a body ``r`` times the mass of the particles under it may press into them: about half
#: the 1.35 mm at which the boxes measured went through
LOAD_SAG = 7e-4
#: the most sub-steps a step takes for a heavy load (8 times the default count)
MOST_LOAD_SUBSTEPS = 128


@njit
def load_substeps(pf, pi, n_particles, bf, bi, si, shape_pairs, n_shape, nb, dt, g, whole, least):
    """The sub-steps (``least`` to ``MOST_LOAD_SUBSTEPS``) a step of ``dt`` s under gravity ``g`` (m/s^2) needs for
    the dynamic bodies on the particles (module docstring), from the step's candidates ``shape_pairs``, rows
    ``(particle, shape, under)``, a particle's rows together.  A body lies on the particles ``under`` it: its ``m``
    is their mass (each counted once), and it needs none if one of them is held (pinned, or a candidate of a static
    or kinematic body: the ground under a sheet).  With ``whole`` the cloths are solved as a whole
    (``World.cloth_stretch_passes``), which hands a load to the pins within the sub-step: their vertices do not
    count."""
    held = np.zeros(n_particles, dtype=np.bool_)
    for p in range(n_particles):
        held[p] = (pi[p, P_FLAGS] & PP_PINNED) != 0
    for k in range(n_shape):
        if not is_dynamic(bi, si[shape_pairs[k, 1], S_BODY]):
            held[shape_pairs[k, 0]] = True
    under = np.zeros(max(nb, 1))
    carried = np.zeros(max(nb, 1), dtype=np.bool_)
    counted = np.full(max(nb, 1), -1)
    for k in range(n_shape):
        p, b = shape_pairs[k, 0], si[shape_pairs[k, 1], S_BODY]
        if shape_pairs[k, 2] == 0 or counted[b] == p or (pi[p, P_FLAGS] & PP_SOFT) != 0 \
                or (whole and pi[p, P_CLOTH] >= 0):
            continue
        # (the rows run particle by particle: a particle under two shapes of one body counts once)
        counted[b] = p
        under[b] += pf[p, P_MASS]
        carried[b] = carried[b] or held[p]
    n = least
    for b in range(nb):
        if under[b] <= 0.0 or carried[b] or not pushable(bf, bi, b):
            continue
        need = dt * math.sqrt(g / (bf[b, INV_MASS] * under[b] * LOAD_SAG))
        if need > n:
            n = min(int(math.ceil(need)), MOST_LOAD_SUBSTEPS)
    return n
