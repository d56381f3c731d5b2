"""Snapshots: the whole mutable state of a world as plain arrays, and a restore that checks every value.

A snapshot holds what a step can change or a user can set: the body and constraint rows, the particles and
the networks' edges, the world's clock, the contact cache (so that warm starting repeats bit for bit), the
slots' allocation and the game-loop accumulator.  Shapes and their bulk geometry cannot change after they
are added, so a snapshot keeps only their rows' descriptions, which must match the world it is restored into.

A snapshot is a plain object that can be pickled, sent to another process and edited, so restoring
trusts nothing in it: every array's type, shape and values are checked against the world (indices in
range, rows alive where they are referenced, finite numbers, unit quaternions, the immutable columns of
each body unchanged) before anything is written, and a refused restore changes nothing.
"""
import hashlib
from dataclasses import dataclass

import numpy as np

from ..deformables.particle_state import TABLES as PARTICLE_TABLES
from . import layout as L

#: the flag bits a body row may carry
_BODY_FLAGS = (L.F_ALIVE | L.F_STATIC | L.F_SENSOR | L.F_SLEEPING | L.F_RESTART | L.F_ISOTROPIC | L.F_CCD_ALWAYS
               | L.F_CCD_NEVER | L.F_JOINTED | L.F_KINEMATIC)
#: body columns that never change after a body is added (mass properties)
_IMMUTABLE_BODY_COLUMNS = np.r_[L.INV_MASS, L.INV_I:L.INV_I + 9, L.MASS, L.I_BODY:L.I_BODY + 9]
_IMMUTABLE_BODY_INTS = np.array([L.SHAPE_START, L.SHAPE_COUNT])
#: body columns that must be finite (MASS is inf for static bodies)
_FINITE_BODY_COLUMNS = np.setdiff1d(np.arange(L.BF_COLS), [L.MASS])
#: the tables of a snapshot, their dtypes and column counts (None: one dimension)
TABLES = {"bf": (np.float64, L.BF_COLS), "bi": (np.int64, L.BI_COLS), "kf": (np.float64, L.KF_COLS),
          "ki": (np.int64, L.KI_COLS), "ws": (np.float64, None), "cache_f": (np.float64, L.CF_COLS),
          "cache_i": (np.int64, L.CI_COLS), "si": (np.int64, L.SI_COLS), "sf": (np.float64, L.SF_COLS),
          "body_slots": (np.int64, None), "shape_slots": (np.int64, None), "constraint_slots": (np.int64, None),
          "body_revisions": (np.int64, None), "constraint_revisions": (np.int64, None), **PARTICLE_TABLES}
#: tables that identify the objects (which handles are valid) rather than describe the physical state
_BOOKKEEPING = ("body_revisions", "constraint_revisions")


@dataclass
class Snapshot:
    """The whole state of a world at one instant (plain arrays: picklable, comparable by ``state_hash``).

    ``tables``: name -> array (see ``TABLES``); ``accumulator``: the game loop's leftover time (s);
    ``fluids``: each fluid's arrays (name -> array), in the order the world holds them."""

    tables: dict
    accumulator: float
    fluids: tuple = ()

    def state_hash(self):
        """A hash of every state array, bit for bit (hex string)."""
        h = hashlib.sha256()
        for key in sorted(self.tables):
            if key in _BOOKKEEPING:
                continue
            arr = np.ascontiguousarray(self.tables[key])
            h.update(key.encode())
            h.update(str(arr.shape).encode())
            h.update(arr.tobytes())
        h.update(np.float64(self.accumulator).tobytes())
        for fluid in self.fluids:
            for key in sorted(fluid):
                arr = np.ascontiguousarray(fluid[key])
                h.update(key.encode())
                h.update(str(arr.shape).encode())
                h.update(arr.tobytes())
        return h.hexdigest()


def _slots_array(slots):
    """A slot allocation as one array: ``[end, n_free, free rows...]``."""
    end, free, _ = slots.state()
    return np.concatenate([[end, free.size], free]).astype(np.int64)


def take(state, accumulator):
    """A :class:`Snapshot` of ``state`` (a ``WorldState``) and the game loop's ``accumulator``."""
    nb, ns, nk, npc = state.bodies.end, state.shapes.end, state.constraints.end, state.n_cached
    tables = {"bf": state.bf[:nb].copy(), "bi": state.bi[:nb].copy(), "kf": state.kf[:nk].copy(),
              "ki": state.ki[:nk].copy(), "ws": state.ws.copy(), "cache_f": state.cache_f[:npc].copy(),
              "cache_i": state.cache_i[:npc].copy(), "si": state.si[:ns].copy(), "sf": state.sf[:ns].copy(),
              "body_slots": _slots_array(state.bodies), "shape_slots": _slots_array(state.shapes),
              "constraint_slots": _slots_array(state.constraints),
              "body_revisions": state.bodies.revision[:nb].copy(),
              "constraint_revisions": state.constraints.revision[:nk].copy(), **state.particles.tables()}
    return Snapshot(tables, float(accumulator))


def _refuse(why):
    raise ValueError(f"snapshot {why}; restore a snapshot taken of this world or of one built the same way")


def _check_table(tables, name):
    if name not in tables:
        _refuse(f"has no table {name!r}")
    arr = tables[name]
    dtype, cols = TABLES[name]
    if not isinstance(arr, np.ndarray) or arr.dtype != dtype:
        _refuse(f"table {name!r} must be a {np.dtype(dtype).name} array")
    if (cols is None and arr.ndim != 1) or (cols is not None and (arr.ndim != 2 or arr.shape[1] != cols)):
        _refuse(f"table {name!r} has the wrong shape {arr.shape}")
    return arr


def _check_slots(arr, name, rows):
    """The slot allocation ``arr`` of a table whose snapshot has ``rows`` rows; returns (end, free rows)."""
    if arr.size < 2 or arr[0] != rows or arr[1] < 0 or arr.size != 2 + arr[1]:
        _refuse(f"has an inconsistent {name}")
    free = arr[2:]
    if free.size and (free.min() < 0 or free.max() >= rows or np.any(np.diff(free) <= 0)):
        _refuse(f"has an inconsistent {name}")
    return int(arr[0]), free


def _in_use(rows, free):
    mask = np.ones(rows, dtype=bool)
    mask[free] = False
    return mask


def validate(state, snapshot):
    """Check ``snapshot`` against ``state`` (see the module docstring); raise ValueError naming what is wrong,
    or return its arrays.  Every body and constraint of the snapshot must still be in the world (the same
    row at the same revision): one removed since cannot come back, as its handle is gone."""
    if not isinstance(snapshot, Snapshot) or not isinstance(snapshot.tables, dict):
        raise TypeError(f"snapshot must be a Snapshot, got {snapshot!r}")
    t = snapshot.tables
    arrays = {name: _check_table(t, name) for name in TABLES}
    if set(t) != set(TABLES):
        _refuse(f"has unknown tables {sorted(set(t) - set(TABLES))}")
    acc = snapshot.accumulator
    if isinstance(acc, bool) or not isinstance(acc, (float, int, np.floating)) or not 0.0 <= acc < 1e300:
        _refuse("has an invalid accumulator")
    bf, bi, kf, ki = arrays["bf"], arrays["bi"], arrays["kf"], arrays["ki"]
    nb, ns, nk = bf.shape[0], arrays["sf"].shape[0], kf.shape[0]
    if bi.shape[0] != nb or arrays["si"].shape[0] != ns or ki.shape[0] != nk \
            or arrays["body_revisions"].shape[0] != nb or arrays["constraint_revisions"].shape[0] != nk \
            or arrays["ws"].shape[0] != L.WS_COLS or arrays["cache_i"].shape[0] != arrays["cache_f"].shape[0]:
        _refuse("has tables of mismatched lengths")
    _, body_free = _check_slots(arrays["body_slots"], "body allocation", nb)
    _, shape_free = _check_slots(arrays["shape_slots"], "shape allocation", ns)
    _, constraint_free = _check_slots(arrays["constraint_slots"], "constraint allocation", nk)
    bodies = _in_use(nb, body_free)
    shapes = _in_use(ns, shape_free)
    constraints = _in_use(nk, constraint_free)
    # --- bodies: alive exactly in used slots, known flags, finite values, unit quaternions, and the same
    # bodies (shapes, mass properties) as in this world
    flags = bi[:, L.FLAGS]
    if np.any(((flags & L.F_ALIVE) != 0) != bodies) or np.any(flags & ~_BODY_FLAGS):
        _refuse("has body rows whose flags do not match its allocation")
    if not np.all(np.isfinite(bf[np.ix_(bodies, _FINITE_BODY_COLUMNS)])) or not np.all(np.isfinite(arrays["ws"])):
        _refuse("holds a NaN or infinite value")
    q = bf[bodies, L.QUAT:L.QUAT + 4]
    if q.size and np.max(np.abs(np.einsum("ij,ij->i", q, q) - 1.0)) > 1e-9:
        _refuse("holds an orientation that is not a unit quaternion")
    static = (flags & (L.F_STATIC | L.F_KINEMATIC)) != 0
    if np.any(bf[bodies & static, L.MASS] != np.inf) or np.any(~np.isfinite(bf[bodies & ~static, L.MASS])):
        _refuse("holds a body mass that does not match its kind")
    if np.any(bi[bodies, L.ISLAND] < -1) or np.any(bi[bodies, L.ISLAND] >= nb):
        _refuse("holds an island index out of range")
    for i in np.flatnonzero(bodies):
        if not state.bodies.in_use(int(i)) or state.bodies.revision[i] != arrays["body_revisions"][i]:
            _refuse("holds a body that was removed since (or that this world never had)")
        if not np.array_equal(bf[i, _IMMUTABLE_BODY_COLUMNS], state.bf[i, _IMMUTABLE_BODY_COLUMNS]) \
                or not np.array_equal(bi[i, _IMMUTABLE_BODY_INTS], state.bi[i, _IMMUTABLE_BODY_INTS]) \
                or (bi[i, L.FLAGS] ^ state.bi[i, L.FLAGS]) & (L.F_STATIC | L.F_KINEMATIC | L.F_SENSOR | L.F_ISOTROPIC):
            _refuse(f"holds body row {i} with other mass properties or shapes than this world's")
    # --- shapes: the same rows as this world's for every body alive in the snapshot
    si, sf = arrays["si"], arrays["sf"]
    for i in np.flatnonzero(bodies):
        s0, n = int(bi[i, L.SHAPE_START]), int(bi[i, L.SHAPE_COUNT])
        if s0 < 0 or n < 1 or s0 + n > ns or not np.all(shapes[s0:s0 + n]) or np.any(si[s0:s0 + n, L.S_BODY] != i):
            _refuse(f"holds body row {i} whose shapes are not allocated")
        if s0 + n > state.shapes.end or not np.array_equal(si[s0:s0 + n], state.si[s0:s0 + n]) \
                or not np.array_equal(sf[s0:s0 + n], state.sf[s0:s0 + n]):
            _refuse(f"holds body row {i} with other shapes than this world's")
    # --- constraints: known types, live bodies, finite values
    kflags = ki[:, L.K_FLAGS]
    if np.any(((kflags & L.KF_ALIVE) != 0) != constraints) \
            or np.any(kflags & ~(L.KF_ALIVE | L.KF_BROKEN | L.KF_LIMITS | L.KF_MOTOR)):
        _refuse("has constraint rows whose flags do not match its allocation")
    live_k = np.flatnonzero(constraints)
    for c in live_k:
        if not state.constraints.in_use(int(c)) or state.constraints.revision[c] != arrays["constraint_revisions"][c]:
            _refuse("holds a constraint that was removed since (or that this world never had)")
    if live_k.size:
        a, b = ki[live_k, L.K_BODY_A], ki[live_k, L.K_BODY_B]
        if np.any(~np.isin(ki[live_k, L.K_TYPE], (L.KT_SPRING, L.KT_ROD, L.KT_CABLE, L.KT_BALL, L.KT_HINGE,
                                                   L.KT_SLIDER, L.KT_FIXED))) \
                or np.any((a < 0) | (a >= nb)) or np.any((b < -1) | (b >= nb)) or not np.all(bodies[a]) \
                or not np.all(bodies[b[b >= 0]]) or np.any(a == b):
            _refuse("holds a constraint between bodies it does not have")
        finite_cols = np.setdiff1d(np.arange(L.KF_COLS), [L.K_BREAKING])
        if not np.all(np.isfinite(kf[np.ix_(live_k, finite_cols)])) or np.any(np.isnan(kf[live_k, L.K_BREAKING])):
            _refuse("holds a NaN or infinite constraint value")
    # --- the contact cache: live bodies, their own shapes, finite values
    cf, ci = arrays["cache_f"], arrays["cache_i"]
    if ci.shape[0]:
        a, b = ci[:, L.C_BODY_A], ci[:, L.C_BODY_B]
        sa, sb = ci[:, L.C_SHAPE_A], ci[:, L.C_SHAPE_B]
        if np.any((a < 0) | (a >= nb) | (b < 0) | (b >= nb) | (sa < 0) | (sa >= ns) | (sb < 0) | (sb >= ns)) \
                or not np.all(bodies[a] & bodies[b]) or np.any(si[sa, L.S_BODY] != a) \
                or np.any(si[sb, L.S_BODY] != b):
            _refuse("holds a contact of bodies or shapes it does not have")
        if not np.all(np.isfinite(cf)):
            _refuse("holds a NaN or infinite contact value")
    # --- particles and networks
    state.particles.check(arrays, bodies, _refuse)
    return arrays


def restore(state, arrays):
    """Write a validated snapshot (``arrays`` from :func:`validate`) into ``state``.  Objects added since the
    snapshot are dropped (with their rows' bulk geometry)."""
    from .world_state import grow
    nb, ns, nk = arrays["bf"].shape[0], arrays["sf"].shape[0], arrays["kf"].shape[0]
    npc = arrays["cache_f"].shape[0]
    state.invalidate()
    shape_rows = _in_use(ns, arrays["shape_slots"][2:])
    for row in sorted(state.geom_sizes):
        if row >= ns or not shape_rows[row]:
            state._free_geometry(row)
    for slots, name in ((state.bodies, "body"), (state.shapes, "shape"), (state.constraints, "constraint")):
        arr = arrays[name + "_slots"]
        end = int(arr[0])
        # (shape rows have no handles: their revisions stay as they are)
        revision = arrays[name + "_revisions"] if name != "shape" else np.zeros(end, dtype=np.int64)
        slots.set_state(end, arr[2:], revision)
    for name, rows in (("bf", nb), ("bi", nb), ("kf", nk), ("ki", nk), ("sf", ns), ("si", ns)):
        table = grow(getattr(state, name), rows)
        table[rows:] = 0
        table[:rows] = arrays[name]
        setattr(state, name, table)
    state.aabbs = grow(state.aabbs, state.bf.shape[0])
    state.ws[:] = arrays["ws"]
    state.grow_contacts(npc)
    state.cache_f[:npc] = arrays["cache_f"]
    state.cache_i[:npc] = arrays["cache_i"]
    state.stats[L.STAT_CACHED] = npc
    state.particles.load(arrays)
    # the broad phase rebuilds from a fresh state
    state.set_broadphase(state.broadphase_code)
