"""The soft bodies of a world: each a set of particles (its nodes) and a run of tetrahedral elements (rows of the
particle state's ``tf`` / ``ti`` tables, corners in global particle rows), kept like a network's edges.

A node's mass is a quarter of the mass of each element it is a corner of (the lumped mass matrix); an
element's rest shape, volume and Lame parameters follow from the rest places of its corners
(``soft_elements.py``).
"""
import numpy as np

from . import particle_layout as P


class SoftRecord:
    """One soft body: its serial, its set of particles and its elements (``Group`` records, the elements' owner
    the set's serial), its rest volume (m^3) and its surface (``(T, 3)`` node numbers within the body,
    counter-clockwise seen from outside)."""

    __slots__ = ("serial", "set", "elements", "rest_volume", "surface", "alive")

    def __init__(self, serial, rest_volume, surface):
        self.serial, self.rest_volume, self.surface = serial, rest_volume, surface
        self.set = self.elements = None
        self.alive = True


def lame(young_modulus, poisson_ratio):
    """The Lame parameters ``(lambda, mu)`` (Pa) of Young's modulus ``E`` (Pa) and Poisson's ratio ``nu``:
    ``mu = E / (2 (1 + nu))``, ``lambda = E nu / ((1 + nu) (1 - 2 nu))``."""
    mu = young_modulus / (2.0 * (1.0 + poisson_ratio))
    return young_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio)), mu


def tet_volumes(positions, tets):
    """The signed volumes (m^3) of the tetrahedra ``tets`` ``(K, 4)`` at ``positions`` ``(V, 3)``:
    ``det([x1 - x0, x2 - x0, x3 - x0]) / 6``."""
    x0 = positions[tets[:, 0]]
    edges = np.stack([positions[tets[:, k]] - x0 for k in (1, 2, 3)], axis=2)
    return np.linalg.det(edges) / 6.0


def surface_triangles(tets):
    """The boundary of a tetrahedral mesh ``(K, 4)`` (positive volumes): the faces of one tetrahedron only,
    ``(T, 3)``, wound counter-clockwise seen from outside."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    _, inverse, count = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True, return_counts=True)
    return faces[count[inverse.reshape(-1)] == 1]


def element_rows(rest, tets, density, young_modulus, poisson_ratio, damping, orientation):
    """The rows ``(tf, ti)`` of a soft body's elements (corners in its own node numbering, positive rest
    volumes) and its nodes' masses (kg, ``(V,)``)."""
    k = tets.shape[0]
    tf = np.zeros((k, P.TF_COLS))
    ti = np.zeros((k, P.TI_COLS), dtype=np.int64)
    x0 = rest[tets[:, 0]]
    dm = np.stack([rest[tets[:, c]] - x0 for c in (1, 2, 3)], axis=2)       # columns X_c - X_0
    volume = np.linalg.det(dm) / 6.0
    tf[:, P.S_DM_INV:P.S_DM_INV + 9] = np.linalg.inv(dm).reshape(k, 9)
    tf[:, P.S_VOLUME] = volume
    tf[:, P.S_LAMBDA], tf[:, P.S_MU] = lame(young_modulus, poisson_ratio)
    tf[:, P.S_DAMPING] = damping
    tf[:, P.S_QUAT:P.S_QUAT + 4] = orientation
    ti[:, P.S_NODES:P.S_NODES + 4] = tets
    mass = np.zeros(rest.shape[0])
    np.add.at(mass, tets.reshape(-1), np.repeat(density * volume / 4.0, 4))
    return tf, ti, mass


# --- snapshots ------------------------------------------------------------------------------------------------
#: a snapshot's soft-body table: one row per soft body (serial, set serial, first element row, elements) and its
#: rest volume; the elements themselves are the particle state's ``soft_f`` / ``soft_i``
SOFT_TABLES = {"soft_bodies": (np.int64, 4), "soft_volumes": (np.float64, 1), "soft_f": (np.float64, P.TF_COLS),
               "soft_i": (np.int64, P.TI_COLS)}


def soft_tables(records, tf, ti, nt):
    """The soft-body tables of a snapshot (copies)."""
    return {"soft_bodies": np.array([(s.serial, s.set.serial, s.elements.start, s.elements.count) for s in records],
                                    dtype=np.int64).reshape(-1, 4),
            "soft_volumes": np.array([s.rest_volume for s in records]).reshape(-1, 1),
            "soft_f": tf[:nt].copy(), "soft_i": ti[:nt].copy()}


def check_soft_bodies(t, records, refuse):
    """Check a snapshot's soft-body tables: each soft body still alive here with its set, its elements a
    contiguous run of the element table whose corners are its own nodes, values finite."""
    live = {s.serial: s for s in records}
    sets = {int(serial): (int(first), int(count)) for serial, first, count in t["particle_sets"]}
    tf, ti = t["soft_f"], t["soft_i"]
    if tf.shape[0] != ti.shape[0] or t["soft_volumes"].shape[0] != t["soft_bodies"].shape[0]:
        refuse("has soft-body tables of mismatched lengths")
    start = 0
    for serial, set_serial, first, count in t["soft_bodies"]:
        s = live.get(int(serial))
        if s is None or s.set.serial != set_serial or set_serial not in sets or first != start or count <= 0:
            refuse("holds a soft body that was removed since (or that this world never had)")
        lo, n = sets[int(set_serial)]
        corners = ti[first:first + count, P.S_NODES:P.S_NODES + 4]
        if corners.min() < lo or corners.max() >= lo + n or np.any(ti[first:first + count, P.S_SOFT] != serial):
            refuse("holds a soft body whose elements name nodes it does not have")
        start += int(count)
    if start != tf.shape[0]:
        refuse("holds elements of no soft body")
    if not np.all(np.isfinite(tf)) or not np.all(np.isfinite(t["soft_volumes"])) \
            or np.any(tf[:, P.S_VOLUME] <= 0.0) or np.any(tf[:, P.S_MU] <= 0.0):
        refuse("holds a NaN, infinite or out-of-range soft-body value")


def load_soft_bodies(t, records):
    """The soft-body records a checked snapshot keeps, their element runs set from it (the others die);
    returns them in order."""
    by_serial = {s.serial: s for s in records}
    kept = []
    for (serial, _, first, count), (volume,) in zip(t["soft_bodies"], t["soft_volumes"]):
        s = by_serial[int(serial)]
        s.elements.start, s.elements.count, s.rest_volume = int(first), int(count), float(volume)
        kept.append(s)
    for s in records:
        if s not in kept:
            s.alive = s.elements.alive = False
    return kept
