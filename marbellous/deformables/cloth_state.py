"""The cloths of a world: each a set of particles (its vertices), a network of springs (its edges), and its
triangles and hinges (bends), kept in the cloth's own vertex numbering and laid out for the kernels on demand.

A cloth's mass is spread over its vertices by area, its springs and hinges follow from its rest shape
(``cloth_topology.py``).  When edges tear, the cloth's vertices split along the tear: its set of particles
grows (the new vertices copy the position and velocity of the vertex they came from, the masses follow the new
fans' areas; a pin stays with the vertex that keeps its number), and its edges and hinges are derived again.  An
edge on the border that tears starts a crack into the cloth (``crack_from_border``).
"""
import numpy as np

from . import particle_layout as P
from .bend_constraints import hinge_angle
from .cloth_topology import edge_stiffness, edges_and_hinges, hinge_stiffness, split_torn, vertex_masses


class ClothRecord:
    """One cloth: its serial, its set of particles and network (``Group`` records), its triangles ``(T, 3)``
    and hinges ``(H, 4)`` (vertex numbers within the set), the hinges' rest angles (rad) and compliances, and
    its material: ``density`` (kg/m^2), ``stretch`` (N/m), ``bend`` (N m), ``thickness`` (m), ``tear`` (strain;
    inf: never), ``self_collision``; ``torn`` counts its torn edges,
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


def crack_from_border(ps, record, torn):
    """Where an edge on the border (held by one triangle) has torn, the crack runs into the cloth: the more
    stretched of its triangle's two other edges that are held by two triangles tears too, so the vertex on the
    border splits and the cloth opens there (a border edge alone separates nothing).  ``torn``: the torn edges
    (sorted vertex pairs); returns them with the edges torn here."""
    triangles = record.triangles
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    keys, held = np.unique(edges, axis=0, return_counts=True)
    inner = {(int(a), int(b)) for a, b in keys[held == 2]}
    g, net = record.set, record.network
    x = ps.pf[g.start:g.start + g.count, P.P_POS:P.P_POS + 3]
    ei = ps.ei[net.start:net.start + net.count]
    row = {(int(a), int(b)): r for r, (a, b) in enumerate(np.sort(ei[:, P.E_A:P.E_B + 1] - g.start, axis=1))}
    rest = ps.ef[net.start:net.start + net.count, P.E_REST]
    cracked = set()
    for a, b in torn:
        if (int(a), int(b)) in inner:
            continue
        corners = triangles[np.flatnonzero(np.isin(triangles, (a, b)).sum(axis=1) == 2)[0]]
        c = int(corners[(corners != a) & (corners != b)][0])
        onward = [pair for pair in (tuple(sorted((int(a), c))), tuple(sorted((int(b), c)))) if pair in inner]
        if onward:
            # the strain |x_u - x_v| / L - 1 of each edge the crack can run on along
            strain = [np.linalg.norm(x[u] - x[v]) / rest[row[(u, v)]] - 1.0 for u, v in onward]
            cracked.add(onward[int(np.argmax(strain))])
    for u, v in cracked:
        ps.ei[net.start + row[(u, v)], P.E_FLAGS] |= P.EB_BROKEN
    return torn_pairs(ps, record) if cracked else torn


def tear(ps, record):
    """After the step broke some of the cloth's edges: run the cracks on from the border, split its vertices
    along the tears, grow its set of particles, and derive its springs and hinges again (module docstring)."""
    torn = crack_from_border(ps, record, torn_pairs(ps, record))
    # (a torn edge on the border is derived again from its triangle below and acts on, and is not counted; the
    # tears are the edges held by two)
    record.torn += int(np.count_nonzero(edges_and_hinges(record.triangles, torn)[1])) - record.still_torn
    g = record.set
    old = ps.pf[g.start:g.start + g.count]
    triangles, source = split_torn(record.triangles, torn, g.count)
    record.triangles = triangles
    f = old[source].copy()
    i = ps.pi[g.start:g.start + g.count][source].copy()
    # a pinned vertex that splits keeps its pin on the fan that keeps its number: the others come away (pinned
    # too, the cloth could never tear off its pins, and a crack would run round a pin one edge a step)
    came_away = (np.arange(source.shape[0]) >= g.count) & ((i[:, P.P_FLAGS] & P.PP_PINNED) != 0)
    i[came_away, P.P_FLAGS] &= ~P.PP_PINNED
    i[came_away, P.P_PIN_BODY] = -1
    rest = f[:, P.P_REST:P.P_REST + 3]
    f[:, P.P_MASS] = vertex_masses(rest, triangles, source.shape[0], record.density)
    free = (f[:, P.P_INV_MASS] > 0.0) | came_away
    f[free, P.P_INV_MASS] = 1.0 / f[free, P.P_MASS]
    ps.replace_set(g, f, i)
    # (a torn edge still held by two triangles has kept both its vertices' numbers: the ends that split no
    # longer share it)
    ef, ei = edge_table(record, rest, torn)
    record.still_torn = int(np.count_nonzero(ei[:, P.E_FLAGS] & P.EB_BROKEN))
    ei[:, P.E_A:P.E_B + 1] += g.start
    ps.replace_network(record.network, ef, ei)
    ps.cloth_tables = None


# --- snapshots ------------------------------------------------------------------------------------------------
#: a snapshot's cloth tables: one row per cloth (serial, set serial, network serial, triangles, hinges, torn,
#: still torn, self-collision) and its materials (density, stretch, bend, thickness, tear), then the triangles and
#: hinges of all cloths one after the other (their own vertex numbers)
CLOTH_TABLES = {"cloths": (np.int64, 8), "cloth_f": (np.float64, 5), "cloth_triangles": (np.int64, 3),
                "cloth_hinges": (np.int64, 4), "cloth_hinge_f": (np.float64, P.BENDF_COLS)}


def cloth_tables(records):
    """The cloth tables of a snapshot (copies)."""
    return {"cloths": np.array([(c.serial, c.set.serial, c.network.serial, c.triangles.shape[0], c.hinges.shape[0],
                                 c.torn, c.still_torn, int(c.self_collision)) for c in records],
                               dtype=np.int64).reshape(-1, 8),
            "cloth_f": np.array([(c.density, c.stretch, c.bend, c.thickness, c.tear) for c in records]).reshape(-1, 5),
            "cloth_triangles": np.concatenate([np.zeros((0, 3), np.int64)] + [c.triangles for c in records]),
            "cloth_hinges": np.concatenate([np.zeros((0, 4), np.int64)] + [c.hinges for c in records]),
            "cloth_hinge_f": np.concatenate([np.zeros((0, P.BENDF_COLS))] + [c.hinge_f for c in records])}


def check_cloths(t, records, refuse):
    """Check a snapshot's cloth tables: each cloth still alive here, with its set and network, its triangles
    and hinges within its set's vertices in the snapshot, counts that add up, values finite."""
    rows = t["cloths"]
    live = {c.serial: c for c in records}
    sizes = {int(s): int(n) for s, _, n in t["particle_sets"]}
    if rows[:, 3].sum() != t["cloth_triangles"].shape[0] or rows[:, 4].sum() != t["cloth_hinges"].shape[0] \
            or t["cloth_hinge_f"].shape[0] != t["cloth_hinges"].shape[0] or t["cloth_f"].shape[0] != rows.shape[0]:
        refuse("has cloth tables of mismatched lengths")
    tri_at = hinge_at = 0
    for serial, set_serial, net_serial, n_tri, n_hinge, torn, still, self_collision in rows:
        c = live.get(int(serial))
        if c is None or c.set.serial != set_serial or c.network.serial != net_serial or set_serial not in sizes:
            refuse("holds a cloth that was removed since (or that this world never had)")
        n_vertices = sizes[int(set_serial)]
        tri = t["cloth_triangles"][tri_at:tri_at + n_tri]
        hinges = t["cloth_hinges"][hinge_at:hinge_at + n_hinge]
        if n_tri == 0 or tri.min() < 0 or tri.max() >= n_vertices \
                or (n_hinge and (hinges.min() < 0 or hinges.max() >= n_vertices)) \
                or torn < 0 or still < 0 or self_collision not in (0, 1):
            refuse("holds a cloth whose triangles or hinges name vertices it does not have")
        tri_at += int(n_tri)
        hinge_at += int(n_hinge)
    f = t["cloth_f"]
    if not np.all(np.isfinite(f[:, :4])) or np.any(f[:, :4] < 0.0) or np.any(np.isnan(f[:, 4])) \
            or not np.all(np.isfinite(t["cloth_hinge_f"])):
        refuse("holds a NaN, infinite or negative cloth value")


def load_cloths(t, records):
    """The cloth records a checked snapshot keeps, their triangles, hinges and counts set from it (the others
    die); returns them in order."""
    by_serial = {c.serial: c for c in records}
    kept = []
    tri_at = hinge_at = 0
    for row, f in zip(t["cloths"], t["cloth_f"]):
        c = by_serial[int(row[0])]
        n_tri, n_hinge = int(row[3]), int(row[4])
        c.triangles = t["cloth_triangles"][tri_at:tri_at + n_tri].copy()
        c.hinges = t["cloth_hinges"][hinge_at:hinge_at + n_hinge].copy()
        c.hinge_f = t["cloth_hinge_f"][hinge_at:hinge_at + n_hinge].copy()
        c.torn, c.still_torn, c.self_collision = int(row[5]), int(row[6]), bool(row[7])
        c.density, c.stretch, c.bend, c.thickness, c.tear = (float(x) for x in f)
        tri_at += n_tri
        hinge_at += n_hinge
        kept.append(c)
    for c in records:
        if c not in kept:
            c.alive = False
    return kept
