"""How many sub-steps the particles' step needs to carry the bodies that rest on them.

One position pass per sub-step splits a contact's overlap between a body of mass ``M`` and a particle by their
inverse masses, and hands the particle's share on to its neighbours one spring per pass: the load a sheet carries
to its pins grows with its own mass and with the square of the sub-steps (the passes' stiffness goes as
``1 / h^2``).  A body too heavy for them presses the vertices under it down faster than the springs take them back,
and goes through the sheet.  Measured on a 1 m sheet of 21 x 21 vertices held at its corners, with a 0.3 m box
dropped from 0.5 m at 60 Hz (masses tried: 1, 2, 3, 5, 7, 10, 15, 20, 30, 50 kg): at 16, 24, 32, 48 and 64 sub-steps
the sheet of 0.2 kg carried 3, 7, 10, 20 and 30 kg and let the next mass through, that of 0.05 kg none, 1, 3, 5 and
10 kg; one of 11 x 11 vertices and 0.2 kg carried 5 kg at 16.  So the ratio ``r = M / m`` of a body to the
cloth it lies on (``m`` the cloth's or network's whole mass) that ``n`` sub-steps carry is about 15 (16 / n)^2 at
60 Hz, ``g h^2 r`` of 0.16 mm at ``h = dt / n``.  With ``World.particle_substeps`` left automatic, the step takes

    n >= dt sqrt(g r / LOAD_SAG)

for every dynamic body that lies on particles (candidates whose contact normal with it is within 60 degrees of
straight up), with ``LOAD_SAG`` half that (a load of twice the mass still
carried), at least the world's count and at most ``MOST_LOAD_SUBSTEPS``: a body of 10 kg on the 0.2 kg sheet takes
42 and rests on it, where 16 let it through.  The cost of a step grows with ``n``.  Not counted: a cloth lying on
a body (draped over it), bodies on particles that the ground or a pin holds (a box on a cloth lying on the floor),
soft bodies' nodes (their implicit step carries a load, soft_step.py), and cloth solved as a whole
(``World.cloth_stretch_passes``: its solve hands a load to the pins within the sub-step); nor a body held by a
cloth's triangles or border edges alone, no vertex under it (corner_contacts.py).  Small bodies (a 0.15 m
box of 2 kg, a 0.2 m ball of 2 kg on the 0.2 kg sheet) go through between the vertices whatever the count: more
sub-steps do not help them.  The rule has no term yet for the sheet's resolution: on a finer sheet the load crosses
more springs to the pins, and a 41 x 41 sheet of 0.2 kg lets a 30 kg box through at 72 sub-steps, a 61 x 61 one
the 10 kg box at 42.
"""
import math

import numpy as np

from .._numba.jit import njit
from ..dynamics.forces import is_dynamic
from ..state.layout import INV_MASS, S_BODY
from .particle_layout import P_CLOTH, P_FLAGS, P_MASS, P_SET, PP_PINNED, PP_SOFT

#: ``g h^2 r`` (m) a load of ``r`` times its cloth's mass may ask of the sub-steps: half the 0.16 mm measured
LOAD_SAG = 8e-5
#: the most sub-steps a step takes for a heavy load (8 times the default count)
MOST_LOAD_SUBSTEPS = 128


@njit
def load_substeps(pf, pi, n_particles, bf, bi, si, shape_pairs, n_shape, nb, dt, g, whole, least):
    """The sub-steps (``least`` to ``MOST_LOAD_SUBSTEPS``) a step of ``dt`` s under gravity ``g`` (m/s^2) needs for
    the dynamic bodies on the particles (module docstring), from the step's candidates ``shape_pairs``, rows
    ``(particle, shape, under)``.  A body lies on the particles ``under`` it: its ``m`` is the mass of the lightest
    set (cloth or network) among them, and it needs none if one of them is held (pinned, or a candidate of a static
    or kinematic body: the ground under a sheet).  With ``whole`` the cloths are solved as a whole
    (``World.cloth_stretch_passes``), which hands a load to the pins within the sub-step: their vertices do not
    count."""
    n_sets = 0
    for p in range(n_particles):
        n_sets = max(n_sets, pi[p, P_SET] + 1)
    set_mass = np.zeros(n_sets)
    held = np.zeros(n_particles, dtype=np.bool_)
    for p in range(n_particles):
        set_mass[pi[p, P_SET]] += pf[p, P_MASS]
        held[p] = (pi[p, P_FLAGS] & PP_PINNED) != 0
    for k in range(n_shape):
        if not is_dynamic(bi, si[shape_pairs[k, 1], S_BODY]):
            held[shape_pairs[k, 0]] = True
    lightest = np.full(max(nb, 1), np.inf)
    carried = np.zeros(max(nb, 1), dtype=np.bool_)
    for k in range(n_shape):
        p, b = shape_pairs[k, 0], si[shape_pairs[k, 1], S_BODY]
        if shape_pairs[k, 2] != 0 and (pi[p, P_FLAGS] & PP_SOFT) == 0 and not (whole and pi[p, P_CLOTH] >= 0):
            lightest[b] = min(lightest[b], set_mass[pi[p, P_SET]])
            carried[b] = carried[b] or held[p]
    n = least
    for b in range(nb):
        if lightest[b] == np.inf or carried[b] or not is_dynamic(bi, b) or bf[b, INV_MASS] <= 0.0:
            continue
        need = dt * math.sqrt(g / (bf[b, INV_MASS] * lightest[b] * LOAD_SAG))
        if need > n:
            n = min(int(math.ceil(need)), MOST_LOAD_SUBSTEPS)
    return n
