"""The particle tables of a world: the sets of particles and the networks' edges, their growth and removal,
their snapshots, and the call of the compiled step.

The particles of a set are contiguous rows of ``pf`` / ``pi``, the edges of a network contiguous rows of
``ef`` / ``ei``; removing a set or a network closes the gap (the rows after it move down, and the edges'
particle rows with them).  Each set and network has a serial number, never reused: a handle holds its
record, and a snapshot names the sets and networks it holds by their serials.
"""
import numpy as np

from . import particle_layout as P
from .body_motion import BX_COLS
from .cloth_topology import border_edges
from .cloth_state import CLOTH_TABLES, check_cloths, cloth_tables, load_cloths, tear, torn_pairs
from .load_substeps import load_substeps
from .particle_step import KERNELS
from .stretch_solve import StretchSystem
from .soft_state import SOFT_TABLES, check_soft_bodies, load_soft_bodies, soft_tables
from .tethers import find_tethers

#: the soft bodies' solves stop when the residual is this fraction of the first (soft_step.py) ...
SOFT_TOLERANCE = 1e-3
#: ... or after this many conjugate-gradient iterations
SOFT_MAX_ITERATIONS = 500
#: the most pushes of cloth on cloth a sub-step records (the deepest of them are solved with the whole-cloth solve's
#: step, layer_contacts.py)
LAYER_PUSHES = 1024


class Group:
    """The record of one set of particles or one network: its serial number and its rows (``start``,
    ``count``); a network also knows the serial of its set.  ``alive`` turns False on removal."""

    __slots__ = ("serial", "start", "count", "owner", "alive")

    def __init__(self, serial, start, count, owner=-1):
        self.serial, self.start, self.count, self.owner, self.alive = serial, start, count, owner, True


def _grown(arr, rows):
    """``arr`` with room for at least ``rows`` rows (doubling), the new rows zero."""
    if arr.shape[0] >= rows:
        return arr
    out = np.zeros((max(rows, 2 * arr.shape[0]),) + arr.shape[1:], dtype=arr.dtype)
    out[:arr.shape[0]] = arr
    return out


class ParticleState:
    """Particle and edge tables with their sets and networks, and the step's scratch."""

    def __init__(self):
        self.pf = np.zeros((0, P.PF_COLS))
        self.pi = np.zeros((0, P.PI_COLS), dtype=np.int64)
        self.ef = np.zeros((0, P.EF_COLS))
        self.ei = np.zeros((0, P.EI_COLS), dtype=np.int64)
        self.n = 0                       # particle rows in use
        self.ne = 0                      # edge rows in use
        self.sets = []                   # Group records of the live sets, in row order
        self.networks = []               # Group records of the live networks, in row order
        self.serial = 0
        self.params = np.zeros(P.Q_LEN)
        self.shape_pairs = np.zeros((64, 3), dtype=np.int64)   # (particle, shape, under)
        self.particle_pairs = np.zeros((64, 2), dtype=np.int64)
        self.kf = np.zeros((64, P.KF_COLS))
        self.ki = np.zeros((64, P.KI_COLS), dtype=np.int64)
        self.scratch_f = np.zeros((16, 7))
        self.scratch_i = np.zeros(16, dtype=np.int64)
        self.sphere = np.zeros(8)
        self.rot_a = np.eye(3)
        self.vec = np.zeros((3, 3))
        self.rot_s = np.zeros((3, 3))
        self.q_s = np.zeros(4)
        self.broken = 0                  # edges broken in the last step
        self.substeps_taken = 0          # sub-steps of the last step (none before the first)
        self.tethers = None              # (particles, pins, lengths) of tethers.py; None: to be found again
        self.stretch = None              # the cloths' factored stretch (StretchSystem) ...
        self.stretch_key = None          # ... for these tethers (found again on the same changes), h and passes
        self.cloths = []                 # ClothRecord of the live cloths, in creation order
        self.cloth_tables = None         # (tri, bend_f, bend_i, cloth_f) for the kernels; None: to be laid out
        self.triangle_pairs = np.zeros((64, 3), dtype=np.int64)
        self.edge_pairs = np.zeros((64, 3), dtype=np.int64)
        self.corner_pairs = np.zeros((64, 3), dtype=np.int64)
        self.lf = np.zeros((LAYER_PUSHES, P.LF_COLS))     # a sub-step's pushes of cloth on cloth (layer_contacts.py)
        self.li = np.zeros((LAYER_PUSHES, P.LI_COLS), dtype=np.int64)
        self.tf = np.zeros((0, P.TF_COLS))
        self.ti = np.zeros((0, P.TI_COLS), dtype=np.int64)
        self.nt = 0                      # element rows in use
        self.softs = []                  # SoftRecord of the live soft bodies, in row order
        self.soft_solve = (0, 0.0)       # the last step's soft solves: (most iterations, largest residual ratio)

    # --- sets and networks ----------------------------------------------------------------------------------
    def _next_serial(self):
        self.serial += 1
        return self.serial

    def add_set(self, rows_f, rows_i):
        """Append a set of particles (its rows of ``pf`` and ``pi``); returns its record."""
        n = rows_f.shape[0]
        self.pf = _grown(self.pf, self.n + n)
        self.pi = _grown(self.pi, self.n + n)
        group = Group(self._next_serial(), self.n, n)
        rows_i[:, P.P_SET] = len(self.sets)
        self.pf[self.n:self.n + n] = rows_f
        self.pi[self.n:self.n + n] = rows_i
        self.n += n
        self.sets.append(group)
        self.tethers = self.cloth_tables = None
        return group

    def add_network(self, owner, rows_f, rows_i):
        """Append a network's edges (rows of ``ef`` and ``ei``, particle rows already global) on the set
        ``owner``; returns its record."""
        n = rows_f.shape[0]
        self.ef = _grown(self.ef, self.ne + n)
        self.ei = _grown(self.ei, self.ne + n)
        group = Group(self._next_serial(), self.ne, n, owner.serial)
        rows_i[:, P.E_NETWORK] = group.serial
        self.ef[self.ne:self.ne + n] = rows_f
        self.ei[self.ne:self.ne + n] = rows_i
        self.ne += n
        self.networks.append(group)
        self.tethers = None
        return group

    def remove_network(self, group):
        """Remove a network's edges; the later edges move down."""
        a, n = group.start, group.count
        for table in (self.ef, self.ei):
            table[a:self.ne - n] = table[a + n:self.ne]
            table[self.ne - n:self.ne] = 0
        self.ne -= n
        self.networks.remove(group)
        for g in self.networks:
            if g.start > a:
                g.start -= n
        group.alive = False
        self.tethers = None

    def remove_set(self, group):
        """Remove a set (and the networks on it); the later particles move down, their edges with them."""
        for net in [g for g in self.networks if g.owner == group.serial]:
            self.remove_network(net)
        a, n = group.start, group.count
        for table in (self.pf, self.pi):
            table[a:self.n - n] = table[a + n:self.n]
            table[self.n - n:self.n] = 0
        self.n -= n
        self.sets.remove(group)
        for g in self.sets:
            if g.start > a:
                g.start -= n
        for k, g in enumerate(self.sets):
            self.pi[g.start:g.start + g.count, P.P_SET] = k
        for ends in (self.ei[:self.ne, P.E_A:P.E_B + 1], self.ti[:self.nt, P.S_NODES:P.S_NODES + 4]):
            ends[ends > a] -= n
        group.alive = False
        self.tethers = self.cloth_tables = None

    def forget_body(self, row):
        """Body row ``row`` is gone: particles pinned to it are free again."""
        held = (self.pi[:self.n, P.P_FLAGS] & P.PP_PINNED != 0) & (self.pi[:self.n, P.P_PIN_BODY] == row)
        self.pi[:self.n, P.P_FLAGS][held] &= ~P.PP_PINNED
        self.pi[:self.n, P.P_PIN_BODY][held] = -1
        self.tethers = None

    def replace_set(self, group, rows_f, rows_i):
        """Give the set ``group`` the rows ``rows_f`` / ``rows_i`` (as many or more than it had: a torn cloth's
        vertices); the later particles move up, their edges with them."""
        a, old, new = group.start, group.count, rows_f.shape[0]
        grow = new - old
        self.pf = _grown(self.pf, self.n + grow)
        self.pi = _grown(self.pi, self.n + grow)
        for table, rows in ((self.pf, rows_f), (self.pi, rows_i)):
            table[a + new:self.n + grow] = table[a + old:self.n].copy()
            table[a:a + new] = rows
        self.n += grow
        group.count = new
        for g in self.sets:
            if g.start > a:
                g.start += grow
        for ends in (self.ei[:self.ne, P.E_A:P.E_B + 1], self.ti[:self.nt, P.S_NODES:P.S_NODES + 4]):
            ends[ends >= a + old] += grow
        self.tethers = self.cloth_tables = None

    def replace_network(self, group, rows_f, rows_i):
        """Give the network ``group`` the edges ``rows_f`` / ``rows_i`` (particle rows global)."""
        a, old, new = group.start, group.count, rows_f.shape[0]
        grow = new - old
        self.ef = _grown(self.ef, self.ne + grow)
        self.ei = _grown(self.ei, self.ne + grow)
        rows_i[:, P.E_NETWORK] = group.serial
        for table, rows in ((self.ef, rows_f), (self.ei, rows_i)):
            table[a + new:self.ne + grow] = table[a + old:self.ne].copy()
            table[a:a + new] = rows
            table[self.ne + grow:self.ne] = 0
        self.ne += grow
        group.count = new
        for g in self.networks:
            if g.start > a:
                g.start += grow
        self.tethers = None

    def add_cloth(self, record, rows_f, rows_i, edge_f, edge_i):
        """Append a cloth: its vertices' rows, its springs' rows (vertex numbers its own) and its record."""
        record.serial = self._next_serial()
        record.set = self.add_set(rows_f, rows_i)
        record.set.owner = record.serial
        edge_i[:, P.E_A:P.E_B + 1] += record.set.start
        record.network = self.add_network(record.set, edge_f, edge_i)
        self.cloths.append(record)
        self.cloth_tables = None

    def remove_cloth(self, record):
        """Remove a cloth (its vertices and springs)."""
        self.remove_set(record.set)
        self.cloths.remove(record)
        record.alive = False
        self.cloth_tables = None

    def add_soft(self, record, rows_f, rows_i, element_f, element_i):
        """Append a soft body: its nodes' rows, its elements' rows (corners its own node numbers) and its
        record."""
        record.serial = self._next_serial()
        record.set = self.add_set(rows_f, rows_i)
        record.set.owner = record.serial
        n = element_f.shape[0]
        element_i[:, P.S_NODES:P.S_NODES + 4] += record.set.start
        element_i[:, P.S_SOFT] = record.serial
        self.tf = _grown(self.tf, self.nt + n)
        self.ti = _grown(self.ti, self.nt + n)
        self.tf[self.nt:self.nt + n] = element_f
        self.ti[self.nt:self.nt + n] = element_i
        record.elements = Group(self._next_serial(), self.nt, n, record.set.serial)
        self.nt += n
        self.softs.append(record)

    def remove_soft(self, record):
        """Remove a soft body (its elements and nodes); the later elements move down."""
        a, n = record.elements.start, record.elements.count
        for table in (self.tf, self.ti):
            table[a:self.nt - n] = table[a + n:self.nt]
            table[self.nt - n:self.nt] = 0
        self.nt -= n
        self.softs.remove(record)
        for s in self.softs:
            if s.elements.start > a:
                s.elements.start -= n
        self.remove_set(record.set)
        record.alive = record.elements.alive = False

    def kernel_cloth_tables(self):
        """The cloths' triangles, hinges and parameters for the kernels, in global particle rows (and each
        cloth vertex's ``P_CLOTH``).  The soft bodies' surfaces follow the cloths' triangles, as cloths
        without hinges or springs, each as thick as its nodes' diameter and not meeting its own nodes (they
        keep other soft bodies, cloths and particles out)."""
        if self.cloth_tables is None:
            self.pi[:self.n, P.P_CLOTH] = -1
            tri = [np.zeros((0, P.TRI_COLS), dtype=np.int64)]
            bend_f = [np.zeros((0, P.BENDF_COLS))]
            bend_i = [np.zeros((0, P.BENDI_COLS), dtype=np.int64)]
            cloth_f = np.zeros((max(len(self.cloths) + len(self.softs), 1), P.CL_COLS))
            for j, s in enumerate(self.softs):
                k, start = len(self.cloths) + j, s.set.start
                self.pi[start:start + s.set.count, P.P_CLOTH] = k
                tri.append(np.column_stack([s.surface + start, np.full(s.surface.shape[0], k),
                                            border_edges(s.surface)]))
                cloth_f[k, P.CL_THICKNESS] = 2.0 * self.pf[start, P.P_RADIUS]
            for k, c in enumerate(self.cloths):
                start = c.set.start
                self.pi[start:start + c.set.count, P.P_CLOTH] = k
                tri.append(np.column_stack([c.triangles + start, np.full(c.triangles.shape[0], k),
                                            border_edges(c.triangles)]))
                bend_f.append(c.hinge_f)
                bend_i.append(c.hinges + start)
                cloth_f[k, P.CL_THICKNESS] = c.thickness
                cloth_f[k, P.CL_SELF] = 1.0 if c.self_collision else 0.0
            tri = tri[:1] + tri[1 + len(self.softs):] + tri[1:1 + len(self.softs)]    # cloths first
            self.cloth_tables = (np.concatenate(tri).astype(np.int64), np.concatenate(bend_f),
                                 np.concatenate(bend_i).astype(np.int64), cloth_f)
        return self.cloth_tables

    def soft_table(self):
        """The soft-body table the kernel reads: per soft body its first node row, node count, first element row
        and element count."""
        out = np.zeros((max(len(self.softs), 1), 4), dtype=np.int64)
        for k, s in enumerate(self.softs):
            out[k] = (s.set.start, s.set.count, s.elements.start, s.elements.count)
        return out

    def set_table(self):
        """The set table the kernel reads (``SETS_COLS`` columns per live set)."""
        out = np.zeros((max(len(self.sets), 1), P.SETS_COLS), dtype=np.int64)
        for k, g in enumerate(self.sets):
            out[k] = (g.start, g.count, g.serial)
        return out

    # --- the step ---------------------------------------------------------------------------------------------
    def _step_scratch(self, st):
        """The cloth tables, the tethers (found from the tables' cloth column, so after them) and the per-step
        scratch of the kernels (adjacency, hash cells, the bodies' boxes and motion):
        ``(tri, bend_f, bend_i, cloth_f, scratch)``."""
        nb = st.bodies.end
        tri, bend_f, bend_i, cloth_f = self.kernel_cloth_tables()
        if self.tethers is None:
            self.tethers = find_tethers(self.pf, self.pi, self.n, self.ef, self.ei, self.ne)
        n, ne = self.n, self.ne
        table = 1 << max(4, int(2 * n - 1).bit_length())
        aabbs = st.aabbs if st.aabbs.shape[0] >= max(nb, 1) else np.zeros((max(nb, 1), 6))
        scratch = (np.zeros(n + 1, dtype=np.int64), np.zeros(max(2 * ne, 1), dtype=np.int64),
                   np.zeros(table + 1, dtype=np.int64), np.zeros(n, dtype=np.int64), aabbs,
                   np.zeros((max(nb, 1), BX_COLS)))
        return tri, bend_f, bend_i, cloth_f, scratch

    def _candidate_arguments(self, st, tri, cloth_f, scratch):
        """The arguments of ``find_candidates``."""
        adjacent_start, adjacent, cell_start, cell_entries, aabbs, bx = scratch
        return (self.params, self.pf, self.pi, self.n, self.ei, self.ne, tri, tri.shape[0], cloth_f, st.bf, st.bi,
                st.sf, st.si, st.geom_f, st.geom_i, st.bodies.end, aabbs, bx, self.shape_pairs, self.particle_pairs,
                self.triangle_pairs, self.edge_pairs, self.corner_pairs, adjacent_start, adjacent, cell_start,
                cell_entries,
                self.scratch_f, self.scratch_i, self.sphere, self.vec[0], self.rot_a, self.vec[1], self.rot_s, self.q_s)

    def _stretch_system(self, bend_f, bend_i, h, passes):
        """The cloths' stretch factored for sub-steps of ``h`` s (over no edge when ``passes`` is 0), kept while
        the tethers are (they are found again whenever the edges, masses or pins change)."""
        key = (h, passes > 0)
        if self.stretch is None or self.stretch_key[0] is not self.tethers or self.stretch_key[1:] != key:
            self.stretch = StretchSystem(self.pf, self.pi, self.n, self.ef, self.ei, self.ne, bend_f, bend_i, h,
                                         passes > 0)
            self.stretch_key = (self.tethers,) + key
        return self.stretch

    def _step_arguments(self, st, tri, bend_f, bend_i, cloth_f, scratch, counts, body_start, stretch):
        """The arguments of ``step_particles`` (``counts`` those ``find_candidates`` returned, ``stretch`` a
        ``StretchSystem``)."""
        n_shape, n_pair, n_triangle, n_edge, n_corner = counts
        bx = scratch[-1]
        return (self.params, self.pf, self.pi, self.n, self.set_table(), len(self.sets), self.ef, self.ei, self.ne,
                bend_f, bend_i, bend_f.shape[0], tri, cloth_f, *self.tethers, st.bf, st.bi, st.bodies.end, st.sf,
                st.si, st.geom_f, st.geom_i, bx, self.shape_pairs, n_shape, self.particle_pairs, n_pair,
                self.triangle_pairs, n_triangle, self.edge_pairs, n_edge, self.corner_pairs, n_corner, self.kf, self.ki,
                self.scratch_f, self.scratch_i, self.sphere, self.vec[0], self.rot_a, self.vec[1], self.rot_s, self.q_s,
                body_start, self.soft_table(), len(self.softs), self.tf, self.ti, SOFT_TOLERANCE, SOFT_MAX_ITERATIONS,
                np.empty((self.nt, 9)), np.empty((9, self.n if self.nt else 0, 3)), *stretch.arrays, self.lf, self.li)

    def meeting(self):
        """Whether particles here can meet each other: soft bodies, two cloths, a cloth that collides with itself,
        or particles made to collide (else the step's kernels without those paths will do,
        ``particle_step._kernels``)."""
        return bool(self.softs) or len(self.cloths) > 1 or any(c.self_collision for c in self.cloths) \
            or bool(np.any(self.pi[:self.n, P.P_FLAGS] & P.PP_COLLIDE))

    def _kernels(self, st):
        """``(find_candidates, step_particles)`` for the particles as they are (:meth:`meeting`) among the shapes
        of ``st`` (the world's ``WorldState``: ``sphere_coverage``)."""
        return KERNELS[self.meeting()][st.sphere_coverage()]

    def kernel_work(self, st):
        """``[(kernel, argument types)]`` of the particles' step kernels as the next step will call them (for
        compiling them ahead, ``pipeline/precompile.py``); empty without particles."""
        if self.n == 0:
            return []
        tri, bend_f, bend_i, cloth_f, scratch = self._step_scratch(st)
        body_start = np.zeros((st.bodies.end, 9))
        candidates, step = self._kernels(st)
        no_stretch = StretchSystem(self.pf, self.pi, self.n, self.ef, self.ei, self.ne, bend_f, bend_i, 1.0, False)
        return [(step, self._step_arguments(st, tri, bend_f, bend_i, cloth_f, scratch, (0, 0, 0, 0, 0), body_start,
                                            no_stretch)),
                (candidates, self._candidate_arguments(st, tri, cloth_f, scratch)),
                (load_substeps, self._load_arguments(st, (0, 0, 0, 0, 0), 1.0, 1.0, False, 1))]

    def _load_arguments(self, st, counts, dt, g, whole, least):
        """The arguments of ``load_substeps`` (``counts`` those ``find_candidates`` returned)."""
        return (self.pf, self.pi, self.n, st.bf, st.bi, st.si, self.shape_pairs, counts[0], st.bodies.end, dt, g,
                whole, least)

    def step(self, st, dt, gravity, substeps, automatic, stretch_passes, body_start):
        """The particles' step of ``dt`` s after the bodies' (``st`` the world's ``WorldState``; ``substeps`` the
        sub-steps, or with ``automatic`` the least, raised for heavy bodies on the particles, load_substeps.py;
        ``stretch_passes`` the global passes of the cloths' stretch per sub-step, stretch_solve.py;
        ``body_start`` (nb, 9) the bodies' positions, m, velocities, m/s, and user forces, N, before theirs)."""
        if self.n == 0:
            self.substeps_taken = 0
            return
        q = self.params
        q[P.Q_DT] = dt
        q[P.Q_GRAVITY:P.Q_GRAVITY + 3] = gravity
        q[P.Q_STRETCH_PASSES] = stretch_passes
        q[P.Q_LOADS] = 1.0 if automatic else 0.0
        tri, bend_f, bend_i, cloth_f, scratch = self._step_scratch(st)
        candidates, step = self._kernels(st)
        while True:
            counts = candidates(*self._candidate_arguments(st, tri, cloth_f, scratch))
            n_shape, n_pair, n_triangle, n_edge, n_corner = counts
            if n_shape <= self.shape_pairs.shape[0] and n_pair <= self.particle_pairs.shape[0] \
                    and n_triangle <= self.triangle_pairs.shape[0] and n_edge <= self.edge_pairs.shape[0] \
                    and n_corner <= self.corner_pairs.shape[0]:
                break
            self.shape_pairs = _grown(self.shape_pairs, n_shape)
            self.particle_pairs = _grown(self.particle_pairs, n_pair)
            self.triangle_pairs = _grown(self.triangle_pairs, n_triangle)
            self.edge_pairs = _grown(self.edge_pairs, n_edge)
            self.corner_pairs = _grown(self.corner_pairs, n_corner)
        if automatic:
            substeps = load_substeps(*self._load_arguments(st, counts, dt, float(np.linalg.norm(gravity)),
                                                           stretch_passes > 0, substeps))
        q[P.Q_SUBSTEPS] = self.substeps_taken = substeps
        stretch = self._stretch_system(bend_f, bend_i, dt / substeps, stretch_passes)
        self.kf = _grown(self.kf, 2 * (n_shape + n_pair) + 16)
        self.ki = _grown(self.ki, self.kf.shape[0])
        self.broken, most, *soft_solve = step(*self._step_arguments(st, tri, bend_f, bend_i, cloth_f, scratch, counts,
                                                                    body_start, stretch))
        self.soft_solve = tuple(soft_solve)
        if self.broken:
            self.tethers = None
            for record in list(self.cloths):
                if torn_pairs(self, record).shape[0] > record.still_torn:
                    tear(self, record)
        if most > self.kf.shape[0]:         # (a sub-step had more contacts than rows: room for them next step)
            self.kf = _grown(self.kf, most)
            self.ki = _grown(self.ki, most)

    # --- snapshots ------------------------------------------------------------------------------------------
    def tables(self):
        """The particle tables of a snapshot (copies)."""
        return {"particle_f": self.pf[:self.n].copy(), "particle_i": self.pi[:self.n].copy(),
                "edge_f": self.ef[:self.ne].copy(), "edge_i": self.ei[:self.ne].copy(),
                "particle_sets": np.array([(g.serial, g.start, g.count) for g in self.sets],
                                          dtype=np.int64).reshape(-1, 3),
                "networks": np.array([(g.serial, g.start, g.count, g.owner) for g in self.networks],
                                     dtype=np.int64).reshape(-1, 4),
                **cloth_tables(self.cloths), **soft_tables(self.softs, self.tf, self.ti, self.nt)}

    def check(self, t, bodies_alive, refuse):
        """Check a snapshot's particle tables ``t`` (see ``state/snapshot.py``): every set and network in it
        still alive here with its size, rows consistent, values finite and in range; ``bodies_alive`` the
        snapshot's live body rows (bool array); ``refuse(why)`` raises."""
        sets, nets = t["particle_sets"], t["networks"]
        pf, pi, ef, ei = t["particle_f"], t["particle_i"], t["edge_f"], t["edge_i"]
        live = {g.serial: g for g in self.sets}
        cloth_sets = {c.set.serial for c in self.cloths}
        cloth_nets = {c.network.serial for c in self.cloths}
        start = 0
        for serial, first, count in sets:
            g = live.get(int(serial))
            # (a cloth's set grows as it tears: the snapshot's may be smaller than it is now)
            if g is None or (g.count != count and g.serial not in cloth_sets) or first != start:
                refuse("holds a set of particles that was removed since (or that this world never had)")
            start += int(count)
        if pf.shape[0] != start or pi.shape[0] != start:
            refuse("has particle tables of mismatched lengths")
        live_nets = {g.serial: g for g in self.networks}
        start = 0
        for serial, first, count, owner in nets:
            g = live_nets.get(int(serial))
            if g is None or (g.count != count and g.serial not in cloth_nets) or first != start or g.owner != owner \
                    or owner not in set(int(s) for s in sets[:, 0]):
                refuse("holds a network that was removed since (or that this world never had)")
            start += int(count)
        if ef.shape[0] != start or ei.shape[0] != start:
            refuse("has edge tables of mismatched lengths")
        finite = np.setdiff1d(np.arange(P.EF_COLS), [P.E_BREAKING, P.E_TEAR])
        if not np.all(np.isfinite(pf)) or not np.all(np.isfinite(ef[:, finite])) or np.any(np.isnan(ef)):
            refuse("holds a NaN or infinite particle value")
        if np.any(pf[:, P.P_MASS] <= 0.0) or np.any(pf[:, P.P_RADIUS] <= 0.0) or np.any(pf[:, P.P_INV_MASS] < 0.0):
            refuse("holds a particle with a mass or radius out of range")
        if np.any(pi[:, P.P_FLAGS] & ~(P.PP_PINNED | P.PP_COLLIDE | P.PP_SOFT)) or np.any(pi[:, P.P_SET] < 0) \
                or np.any(pi[:, P.P_SET] >= max(len(sets), 1)):
            refuse("holds particle rows with unknown flags or sets")
        pinned_to = pi[:, P.P_PIN_BODY]
        held = (pi[:, P.P_FLAGS] & P.PP_PINNED) != 0
        nb = bodies_alive.shape[0]
        if np.any(pinned_to < -1) or np.any(pinned_to >= nb) \
                or not np.all(bodies_alive[pinned_to[held & (pinned_to >= 0)]]):
            refuse("holds a particle pinned to a body it does not have")
        if ei.shape[0] and (np.any(ei[:, P.E_A:P.E_B + 1] < 0) or np.any(ei[:, P.E_A:P.E_B + 1] >= pf.shape[0])
                            or np.any(~np.isin(ei[:, P.E_KIND], (P.EK_SPRING, P.EK_ROD, P.EK_CABLE)))
                            or np.any(ei[:, P.E_FLAGS] & ~P.EB_BROKEN)):
            refuse("holds edges between particles it does not have")
        check_cloths(t, self.cloths, refuse)
        check_soft_bodies(t, self.softs, refuse)

    def load(self, t):
        """Write a checked snapshot's particle tables; sets and networks not in it are removed (their
        records die)."""
        keep = set(int(s) for s in t["particle_sets"][:, 0])
        keep_nets = set(int(s) for s in t["networks"][:, 0])
        for g in self.sets:
            if g.serial not in keep:
                g.alive = False
        for g in self.networks:
            if g.serial not in keep_nets:
                g.alive = False
        self.sets = [g for g in self.sets if g.alive]
        self.networks = [g for g in self.networks if g.alive]
        for g, (_, start, count) in zip(self.sets, t["particle_sets"]):
            g.start, g.count = int(start), int(count)
        for g, (_, start, count, _) in zip(self.networks, t["networks"]):
            g.start, g.count = int(start), int(count)
        self.n, self.ne = t["particle_f"].shape[0], t["edge_f"].shape[0]
        self.pf = _grown(np.zeros((0, P.PF_COLS)), self.n)
        self.pi = _grown(np.zeros((0, P.PI_COLS), dtype=np.int64), self.n)
        self.ef = _grown(np.zeros((0, P.EF_COLS)), self.ne)
        self.ei = _grown(np.zeros((0, P.EI_COLS), dtype=np.int64), self.ne)
        self.tethers = None
        self.pf[:self.n] = t["particle_f"]
        self.pi[:self.n] = t["particle_i"]
        self.ef[:self.ne] = t["edge_f"]
        self.ei[:self.ne] = t["edge_i"]
        self.cloths = load_cloths(t, self.cloths)
        self.cloth_tables = None
        self.softs = load_soft_bodies(t, self.softs)
        self.nt = t["soft_f"].shape[0]
        self.tf = _grown(np.zeros((0, P.TF_COLS)), self.nt)
        self.ti = _grown(np.zeros((0, P.TI_COLS), dtype=np.int64), self.nt)
        self.tf[:self.nt] = t["soft_f"]
        self.ti[:self.nt] = t["soft_i"]


#: the particle tables of a snapshot, their dtypes and column counts (for state/snapshot.py)
TABLES = {"particle_f": (np.float64, P.PF_COLS), "particle_i": (np.int64, P.PI_COLS),
          "edge_f": (np.float64, P.EF_COLS), "edge_i": (np.int64, P.EI_COLS), "particle_sets": (np.int64, 3),
          "networks": (np.int64, 4), **CLOTH_TABLES, **SOFT_TABLES}
