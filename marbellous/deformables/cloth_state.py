"""The cloths of a world: each a set of particles (its vertices), a network of springs (its edges), and its
triangles and hinges (bends), kept in the cloth's own vertex numbering and laid out for the kernels on demand.

A cloth's mass is spread over its vertices by area, its springs and hinges follow from its rest shape
(``cloth_topology.py``).  When edges tear, the cloth's vertices split along the tear: its set of particles
grows (the new vertices copy the position, velocity and pin of the vertex they came from, the masses follow
the new fans' areas), and its edges and hinges are derived again.
"""
import numpy as np

from . import particle_layout as P
from .bend_constraints import hinge_angle
from .cloth_topology import edge_stiffness, edges_and_hinges, hinge_stiffness, split_torn, vertex_masses


class ClothRecord:
    """One cloth: its serial, its set of particles and network (``Group`` records), its triangles ``(T, 3)``
    and hinges ``(H, 4)`` (vertex numbers within the set), the hinges' rest angles (rad) and compliances, and
    its material: ``density`` (kg/m^2), ``stretch`` (N/m), ``bend`` (N m), ``thickness`` (m), ``tear`` (strain; inf: never), ``self_collision``; ``torn`` counts its torn edges,
    ``still_torn`` those of its springs that are torn but still join two triangles (a tear's tip)."""

    __slots__ = ("serial", "set", "network", "triangles", "hinges", "hinge_f", "density", "stretch", "bend",
                 "thickness", "tear", "self_collision", "torn", "still_torn", "alive")

    def __init__(self, serial, triangles, density, stretch, bend, thickness, tear, self_collision):
        self.serial, self.triangles, self.density = serial, triangles, density
        self.stretch, self.bend, self.thickness = stretch, bend, thickness
        self.tear, self.self_collision = tear, self_collision
        self.set = self.network = None
        self.hinges = np.zeros((0, 4), dtype=np.int64)
        self.hinge_f = np.zeros((0, P.BENDF_COLS))
        self.torn = self.still_torn = 0
        self.alive = True


def edge_table(record, rest, torn):
    """The rows ``(ef, ei)`` of the cloth's springs, in its own vertex numbering, and its hinges (set on
    ``record``), from its triangles and the torn edges ``torn`` (sorted vertex pairs)."""
    edges, edge_torn, hinges = edges_and_hinges(record.triangles, torn)
    k, length = edge_stiffness(rest, record.triangles, edges, record.stretch)
    ef = np.zeros((edges.shape[0], P.EF_COLS))
    ei = np.zeros((edges.shape[0], P.EI_COLS), dtype=np.int64)
    ef[:, P.E_REST] = length
    ef[:, P.E_COMPLIANCE] = 1.0 / k
    ef[:, P.E_BREAKING] = np.inf
    ef[:, P.E_TEAR] = length * (1.0 + record.tear)
    ei[:, P.E_A:P.E_B + 1] = edges
    ei[:, P.E_KIND] = P.EK_SPRING
    ei[edge_torn, P.E_FLAGS] = P.EB_BROKEN
    record.hinges = hinges
    record.hinge_f = np.zeros((hinges.shape[0], P.BENDF_COLS))
    record.hinge_f[:, P.BN_COMPLIANCE] = 1.0 / np.maximum(hinge_stiffness(rest, hinges, record.bend), 1e-300)
    record.hinge_f[:, P.BN_ANGLE] = [hinge_angle(*(rest[v] for v in h)) for h in hinges]
    return ef, ei


def vertex_rows(record, positions, rest, friction, static_friction):
    """The rows ``(pf, pi)`` of a new cloth's vertices at ``positions`` (m), rest shape ``rest``."""
    n = positions.shape[0]
    f = np.zeros((n, P.PF_COLS))
    i = np.zeros((n, P.PI_COLS), dtype=np.int64)
    f[:, P.P_POS:P.P_POS + 3] = positions
    f[:, P.P_REST:P.P_REST + 3] = rest
    f[:, P.P_MASS] = vertex_masses(rest, record.triangles, n, record.density)
    f[:, P.P_INV_MASS] = 1.0 / f[:, P.P_MASS]
    f[:, P.P_RADIUS] = 0.5 * record.thickness
    f[:, P.P_FRICTION] = friction
    f[:, P.P_STATIC_FRICTION] = static_friction
    i[:, P.P_PIN_BODY] = -1
    i[:, P.P_CLOTH] = -1
    return f, i


def torn_pairs(ps, record):
    """The cloth's torn edges (sorted vertex pairs in its own numbering)."""
    g = record.network
    ei = ps.ei[g.start:g.start + g.count]
    torn = ei[(ei[:, P.E_FLAGS] & P.EB_BROKEN) != 0, P.E_A:P.E_B + 1] - record.set.start
    return np.sort(torn, axis=1)


def tear(ps, record):
    """After the step broke some of the cloth's edges: split its vertices along the tears, grow its set of
    particles, and derive its springs and hinges again (module docstring)."""
    torn = torn_pairs(ps, record)
    record.torn += torn.shape[0] - record.still_torn
    g = record.set
    old = ps.pf[g.start:g.start + g.count]
    triangles, source = split_torn(record.triangles, torn, g.count)
    record.triangles = triangles
    f = old[source].copy()
    i = ps.pi[g.start:g.start + g.count][source].copy()
    rest = f[:, P.P_REST:P.P_REST + 3]
    f[:, P.P_MASS] = vertex_masses(rest, triangles, source.shape[0], record.density)
    free = f[:, P.P_INV_MASS] > 0.0
    f[free, P.P_INV_MASS] = 1.0 / f[free, P.P_MASS]
    ps.replace_set(g, f, i)
    # (a torn edge still held by two triangles has kept both its vertices' numbers: the ends that split no
    # longer share it)
    ef, ei = edge_table(record, rest, torn)
    record.still_torn = int(np.count_nonzero(ei[:, P.E_FLAGS] & P.EB_BROKEN))
    ei[:, P.E_A:P.E_B + 1] += g.start
    ps.replace_network(record.network, ef, ei)
    ps.cloth_tables = None
