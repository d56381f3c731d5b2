"""The step's tables as one compiled record, so that a step is one kernel call with one argument.

A call from Python into a compiled kernel unboxes every array argument (its data pointer, shape and
strides read and a reference taken): about 35 ns per array through the compiled entry point, 60 ns
through Numba's dispatcher, which also types each argument first.  The 22 tables of a world plus its
scratch cost ~1.6 us per step that way, more than a free body's whole physics.  A Numba StructRef
holding them crosses the boundary as one pointer (~0.17 us per call), and it also owns the step's
per-body and per-contact scratch, so the step allocates none of it.

The World keeps its own references to the same arrays (reads from Python cost nothing extra) and builds
a new record with :func:`pack_tables` whenever it replaces one of them (growth, restore, a new broad
phase); the record is never written from Python.  The step swaps the two contact tables inside the
record and says in ``stats`` which one now holds the cache, so the World does no work per step.
"""
from types import SimpleNamespace

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.experimental import structref
from numba.extending import intrinsic

from .._numba.jit import njit
from .._numba.wide import LANES
from ..dynamics.contact_bundles import BUNDLE_FIELDS, BUNDLE_ROWS, MAX_COLOURS, MIN_BUNDLED_CONTACTS, bundle_capacity
from ..dynamics.integrators import SCRATCH_VECS
from ..dynamics.solver_bodies import SB_COLS
from .collide import pose_tables

#: most threads of the contact passes (World.threads)
MAX_THREADS = 64


@structref.register
class StepTablesType(types.StructRef):
    """Numba type of the step's record (fields as in ``FIELDS``)."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class StepTables(structref.StructRefProxy):
    """A world's tables, counts and step scratch, as the compiled step sees them (opaque from Python)."""


structref.define_boxing(StepTablesType, StepTables)

_F1, _F2 = types.float64[::1], types.float64[:, ::1]
_I1, _I2 = types.int64[::1], types.int64[:, ::1]
#: The world's tables (layout.py) the record holds, in the order ``pack_tables`` takes them.
TABLE_FIELDS = (
    ("bf", _F2), ("bi", _I2), ("sf", _F2), ("si", _I2), ("kf", _F2), ("ki", _I2), ("ws", _F1),
    ("geom_f", _F1), ("geom_i", _I1), ("aabbs", _F2), ("bp_f", _F1), ("bp_i", _I1), ("pairs", _I2),
    ("raw_f", _F2), ("raw_i", _I1), ("cf", _F2), ("ci", _I2), ("pcf", _F2), ("pci", _I2),
    ("params_f", _F1), ("params_i", _I1), ("stats", _I1),
)
#: The record's fields: the tables, the counts, and the step's scratch.
FIELDS = TABLE_FIELDS + (
    ("nb", types.int64), ("nk", types.int64),
    # scratch, one row per body slot (or constraint slot), reused by every step
    ("sweep", _F1),           # sweep distance of each body over the step (m)
    ("filters", _I2),         # (3, slots): the bodies' flags, groups and masks as contiguous rows
    ("solver_bodies", _F2),   # solver body rows (dynamics/solver_bodies.py), and the bundles' pad and sink rows
    ("forces", _F2),          # total force on each body in the sub-step (N)
    ("torques", _F2),         # total torque (N m)
    ("user_forces", _F2),     # penalty scheme: the user's force and torque, kept while springs are added
    ("joint_totals", _F1),    # impulse of each constraint summed over the sub-steps (N s)
    ("soft", _F2),            # soft-constraint coefficients of contacts (row 0) and joints (row 1)
    ("vecs", _F2),            # small vectors of the per-sub-step stages
    ("parent", _I1),          # union-find forest of the islands
    ("least_rest", _F1),      # least rest time of each island (s)
    ("slab", _I1),            # slab of each body for the parallel contact passes (dynamics/contact_regions.py)
    ("contact_order", _I1),   # the contacts in the order of the step's passes
    ("region_starts", _I1),   # where each region's contacts start in that order
    ("region_change", _F1),   # largest velocity change of each region in a pass (m/s)
    ("part_bundles", _I1),    # where each region's bundles (then the boundary's) start
    ("overflow", _I1),        # the contacts no bundle takes, region by region
    ("part_overflow", _I1),   # where each region's overflow starts
    ("wide_f", _F1),          # the contact bundles (dynamics/contact_bundles.py)
    ("wide_i", _I1),          # their body rows and contacts
    ("colour_used", _I1),     # colours taken at each solver-body row (bit masks)
    ("colour_of", _I1),       # colour of each contact
    ("colour_fill", _I1),     # contacts (then next slot) of each colour
    ("wide_change", _F1),     # largest velocity change of each lane of each region in a pass (m/s)
    ("pose_pos", _F2),        # narrow phase: world position of each shape row (m)
    ("pose_rot", types.float64[:, :, ::1]),   # and its rotation matrix
    ("pose_state", types.int8[::1]),          # which of the two each row holds (pipeline/collide.py)
    ("pose_quat", _F1),       # a quaternion
)
STEP_TABLES = StepTablesType(list(FIELDS))

_new_record = structref.new
if numba.config.DISABLE_JIT:          # kernels run as Python: the record is a plain namespace
    def _new_record(_type):
        return SimpleNamespace()


@njit
def _pack(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf, ci, pcf, pci,
          params_f, params_i, stats, nb, nk, threads):
    t = _new_record(STEP_TABLES)
    t.bf, t.bi, t.sf, t.si, t.kf, t.ki, t.ws = bf, bi, sf, si, kf, ki, ws
    t.geom_f, t.geom_i, t.aabbs, t.bp_f, t.bp_i, t.pairs = geom_f, geom_i, aabbs, bp_f, bp_i, pairs
    t.raw_f, t.raw_i, t.cf, t.ci, t.pcf, t.pci = raw_f, raw_i, cf, ci, pcf, pci
    t.params_f, t.params_i, t.stats = params_f, params_i, stats
    t.nb, t.nk = nb, nk
    n_slots = bf.shape[0]
    t.sweep = np.zeros(n_slots)
    t.filters = np.zeros((3, n_slots), dtype=np.int64)
    t.solver_bodies = np.zeros((n_slots + 2, SB_COLS))
    t.forces = np.zeros((n_slots, 3))
    t.torques = np.zeros((n_slots, 3))
    t.user_forces = np.zeros((n_slots, 6))
    t.joint_totals = np.zeros(kf.shape[0])
    t.soft = np.zeros((2, 3))
    t.vecs = np.zeros((SCRATCH_VECS, 4))
    t.parent = np.zeros(n_slots, dtype=np.int64)
    t.least_rest = np.zeros(n_slots)
    t.slab = np.zeros(n_slots, dtype=np.int64)
    contacts = max(cf.shape[0], pcf.shape[0])      # (the two contact tables swap roles)
    t.contact_order = np.zeros(contacts, dtype=np.int64)
    t.region_starts = np.zeros(MAX_THREADS + 2, dtype=np.int64)
    t.region_change = np.zeros(MAX_THREADS)
    t.part_bundles = np.zeros(MAX_THREADS + 2, dtype=np.int64)
    t.overflow = np.zeros(contacts, dtype=np.int64)
    t.part_overflow = np.zeros(MAX_THREADS + 2, dtype=np.int64)
    # bundles for the regions and the boundary; none while the contact table has its first rows only, as
    # the step then solves its few contacts by the scalar pass (a small world keeps ~0.5 MB)
    bundles = bundle_capacity(contacts, threads + 1) if contacts > MIN_BUNDLED_CONTACTS else 0
    t.wide_f = np.zeros(bundles * BUNDLE_FIELDS * LANES)
    t.wide_i = np.zeros(bundles * BUNDLE_ROWS * LANES, dtype=np.int64)
    t.colour_used = np.zeros(n_slots + 2, dtype=np.int64)
    t.colour_of = np.zeros(contacts, dtype=np.int64)
    t.colour_fill = np.zeros(MAX_COLOURS + 1, dtype=np.int64)
    t.wide_change = np.zeros((MAX_THREADS + 1) * LANES)
    t.pose_pos, t.pose_rot, t.pose_state, t.pose_quat = pose_tables(sf.shape[0])
    return t


def pack_tables(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf, ci,
                pcf, pci, params_f, params_i, stats, nb, nk, threads=1):
    """A record of the world's tables (the same arrays, not copies), its counts ``nb`` bodies and ``nk``
    constraints, and fresh scratch for as many body and constraint slots as the tables have rows, and for
    contact passes on up to ``threads`` threads.  Every table must be C-contiguous with the dtype and
    dimensions of ``TABLE_FIELDS``."""
    arrays = locals()
    for name, typ in TABLE_FIELDS:
        a = arrays[name]
        if not (isinstance(a, np.ndarray) and a.dtype == typ.dtype.name and a.ndim == typ.ndim
                and a.flags.c_contiguous):
            raise TypeError(f"{name} must be a C-contiguous {typ.dtype} array of {typ.ndim} dimensions")
    return _pack(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf, ci,
                 pcf, pci, params_f, params_i, stats, int(nb), int(nk), max(1, int(threads)))


@intrinsic
def _meminfo_address(typingctx, record):
    def codegen(context, builder, signature, args):
        ref = cgutils.create_struct_proxy(signature.args[0])(context, builder, value=args[0])
        return builder.ptrtoint(ref.meminfo, context.get_value_type(types.intp))
    return types.intp(record), codegen


@intrinsic
def record_at(typingctx, address):
    """The record whose memory-info block is at ``address`` (:func:`record_address`), as a new reference."""
    def codegen(context, builder, signature, args):
        ref = cgutils.create_struct_proxy(STEP_TABLES)(context, builder)
        ref.meminfo = builder.inttoptr(args[0], ref.meminfo.type)
        value = ref._getvalue()
        context.nrt.incref(builder, STEP_TABLES, value)
        return value
    return STEP_TABLES(types.intp), codegen


if numba.config.DISABLE_JIT:        # kernels run as Python: the "address" is the record itself
    def record_at(address):
        return address


@njit
def _address(record):
    return _meminfo_address(record)


def record_address(record):
    """The address (an int) of ``record``'s memory-info block, which :func:`record_at` turns back into
    the record inside a kernel.  A Python int crosses into compiled code in ~10 ns, a record in ~120 ns
    (its proxy's attribute is read and unboxed).  The address is only valid while the caller keeps
    ``record`` alive.  With ``NUMBA_DISABLE_JIT`` the record itself."""
    if numba.config.DISABLE_JIT:
        return record
    return _address(record)


def compiled_entry(kernel, argument):
    """The compiled entry point of ``kernel`` for ``argument``'s type (compiled or loaded from the cache on
    first use): calling it skips the dispatcher's typing of the argument (~60 ns for an int, ~0.5 us for
    a record).  With ``NUMBA_DISABLE_JIT`` the kernel itself."""
    if numba.config.DISABLE_JIT:
        return kernel
    key = (numba.typeof(argument),)
    if key not in kernel.overloads:
        kernel.compile(key)
    return kernel.overloads[key].entry_point
