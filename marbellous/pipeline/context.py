"""The step context: a world's tables, counts and the step's scratch as one compiled record, so that a step
is one kernel call with one argument (Box2D v3's ``b2StepContext``).

The state (``state/world_state.py``) keeps its own references to the same arrays (reads from Python cost
nothing extra) and packs a new context with :func:`pack_context` whenever it replaces one of them (growth,
restore, a new broad phase); Python never writes the context.  Besides the tables, the context carries
the scratch of every stage (one row per body slot, constraint slot or contact) and the step's own scalars
(contacts found, the execution variant the prepare stage chose, the profile clock), which the stages
hand on to each other through it.  The step swaps the two contact tables inside the context and says in
``stats`` which one now holds the cache, so the state does no work per step.
"""
import numpy as np
from numba import types
from numba.experimental import structref

from .._numba.jit import njit
from .._numba.record import new_record_function, reader, viewer
from .._numba.wide import LANES
from ..dynamics.contact_bundles import MAX_COLOURS, MIN_BUNDLED_CONTACTS, bundle_capacity
from ..dynamics.integrators import SCRATCH_VECS
from ..dynamics.joint_rows import ROW_COLS
from ..dynamics.joint_tree import TREE_BODY_COLS, TREE_FLOAT_COLS, TREE_INT_COLS, TREE_ROWS, TREE_SCRATCH_COLS
from ..state.layout import BUNDLE_FIELDS, BUNDLE_ROWS, IMPACT_COLS, JOINT_ROWS, PB_COLS, SB_COLS, TIME_COLS
from .collide import pose_tables

#: most threads of the contact passes (World.threads)
MAX_THREADS = 64
#: rows of the time-of-impact search's contact buffer (a pair reporting more shrinks its search window)
TOI_ROWS = 256
#: most touching triangles of one mesh the search keeps apart
TOI_TOUCH = 32


@structref.register
class StepContextType(types.StructRef):
    """Numba type of the step context (fields as in ``FIELDS``)."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class StepContext(structref.StructRefProxy):
    """A world's tables, counts and step scratch, as the compiled step sees them (opaque from Python)."""


structref.define_boxing(StepContextType, StepContext)

_F1, _F2 = types.float64[::1], types.float64[:, ::1]
_I1, _I2 = types.int64[::1], types.int64[:, ::1]
#: The world's tables (state/layout.py) the context holds, in the order ``pack_context`` takes them.
TABLE_FIELDS = (
    ("bf", _F2), ("bi", _I2), ("sf", _F2), ("si", _I2), ("kf", _F2), ("ki", _I2), ("ws", _F1),
    ("geom_f", _F1), ("geom_i", _I1), ("aabbs", _F2), ("bp_f", _F1), ("bp_i", _I1), ("pairs", _I2),
    ("raw_f", _F2), ("raw_i", _I1), ("cf", _F2), ("ci", _I2), ("pcf", _F2), ("pci", _I2),
    ("params_f", _F1), ("params_i", _I1), ("stats", _I1),
)
#: The context's fields: the tables, the counts, the step's scalars and the stages' scratch.
FIELDS = TABLE_FIELDS + (
    ("nb", types.int64),      # body slots in use: the step visits rows 0 .. nb - 1 and skips free ones
    ("nk", types.int64),      # constraint slots, likewise
    # the step's scalars, written by one stage for the next
    ("h", types.float64),     # sub-step length (s)
    ("substeps", types.int64),      # sub-steps of the step (the parameter's, or more: stage prepare)
    ("n_pairs", types.int64),       # candidate pairs the broad phase found
    ("nc", types.int64),      # contact points the narrow phase found
    ("n_resting", types.int64),     # resting pairs' contacts kept from the cache, after the nc rows
    ("kept", types.boolean),        # no new contact and every cached one resting: the cache stays as it is
    ("constrained", types.boolean),  # the step has contacts or constraints (else the solver rests)
    ("at_rest", types.boolean),     # nothing moves and nothing is solved: the sub-steps are skipped
    ("bundled", types.boolean),      # contacts solved in coloured bundles (chosen once, by prepare)
    ("regions", types.int64),       # regions of the contact passes (1 unless threads)
    ("bundles", types.int64),       # bundles of the step
    ("n_overflow", types.int64),    # contacts no bundle takes
    ("iterations", types.int64),    # velocity iterations used so far in the step
    ("iteration_cap", types.int64),  # most velocity (and push) passes per sub-step (dynamics/support_depth.py)
    ("turning", types.boolean),     # some contact touches a body whose world inertia turns with it
    ("n_supported", types.int64),   # heavy-on-light contacts of the step (rows of ``supported``)
    ("n_static", types.int64),      # contacts of a movable body with a static or sleeping one
    ("clock", types.int64),         # cycle counter at the end of the last profiled stage
    # scratch, one row per body slot (or constraint slot), reused by every step
    ("sweep", _F1),           # sweep distance of each body over the step (m)
    ("filters", _I2),         # (3, slots): the bodies' flags, groups and masks as contiguous rows
    ("solver_bodies", _F2),   # solver body rows (dynamics/solver_bodies.py), and the bundles' pad and sink rows
    ("forces", _F2),          # total force on each body in the sub-step (N)
    ("torques", _F2),         # total torque (N m)
    ("user_forces", _F2),     # penalty scheme: the user's force and torque, kept while springs are added
    ("joint_totals", _F1),    # impulse of each constraint summed over the sub-steps (N s)
    ("soft", _F2),            # soft-constraint coefficients of contacts (row 0), rods and cables (row 1) and the
    #                           ball, hinge, slider and fixed joints (row 2)
    ("vecs", _F2),            # small vectors of the per-sub-step stages
    ("joint_cache", types.float64[:, :, ::1]),  # the rows of every ball, hinge, slider and fixed joint at the
    #                           poses the passes work at (slots x JOINT_ROWS x ROW_COLS, dynamics/joint_rows.py)
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
    ("supported", _F2),       # heavy-on-light contacts and their impulses (dynamics/contact_solver.py)
    ("light", types.boolean[::1]),  # solver-body rows that carry a body much heavier than themselves
    ("heavy", types.boolean[::1]),  # contacts of a heavy body on a light one
    # time stepping (pipeline/impacts.py): its report to the stepping loop, and the time-of-impact search's scratch
    ("time_f", _F1),          # what the time-of-impact stage reports (state/layout.py T_*), held by the state too
    ("impact_f", _F2),        # impulses of the impacts resolved at the interval's start, one row per contact
    ("toi_f", _F2),           # the search's contact buffer (TOI_ROWS, 7)
    ("toi_i", _I1),           # and its feature ids
    ("toi_pos", _F2),         # (2, 3) the two shapes' positions at the searched time (m)
    ("toi_rot", types.float64[:, :, ::1]),   # (2, 3, 3) and rotations
    ("toi_q", _F1),           # a quaternion
    ("toi_touch", _I1),       # the count and the triangles of a mesh that touch when the search starts
    ("push_bodies", _F2),     # pseudo-velocities of the split impulses, rows as the solver bodies'
    ("push_impulse", _F1),    # accumulated push impulse of each contact in the sub-step (N s)
    ("implicit", _F1),        # 1 for each spring the constraint solver takes (too stiff for a force), else 0
    ("static_contacts", _I1),  # the contacts of a movable body with one that cannot move (their count: n_static)
    # the support depth (dynamics/support_depth.py): breadth-first levels over the contact graph
    ("support_level", _I1),   # level of each body slot
    ("support_queue", _I1),   # the search's queue of body slots
    ("support_start", _I1),   # where each body's neighbours start in support_adjacent (slots + 1)
    ("support_adjacent", _I1),  # the bodies each body touches, body by body (two per contact)
    # the joints' adjacency (dynamics/joint_rows.drop_joined_pairs): the bodies each body is jointed to
    ("joint_start", _I1),     # where each body's jointed bodies start in joint_other (slots + 1)
    ("joint_other", _I1),     # the bodies each body is jointed to, body by body (two per joint)
    # the joint trees (dynamics/joint_tree.py): built in stage prepare, factored where the rows are filled for
    # the relax and push passes
    ("n_tree", types.int64),  # joints in the trees
    ("tree_factored", types.boolean),  # whether this step has factored them yet
    ("trees_alone", types.boolean),    # whether they are the only constraints, with no limit or motor rows
    ("tree_order", _I1),      # the tree joints, children first
    ("tree_i", _I2),          # each joint's tree columns (slots x TREE_INT_COLS)
    ("tree_f", _F2),          # each tree joint's factor (slots x TREE_FLOAT_COLS)
    ("tree_x", _F2),          # each tree joint's right-hand side, then impulses (slots x 2 TREE_ROWS)
    ("tree_body", _F2),       # each body's effective inverse mass and the solve's sums (slots x TREE_BODY_COLS)
    ("tree_start", _I1),      # where each body's tree joints start in tree_joints (slots + 1)
    ("tree_joints", _I1),     # the tree joints at each body, body by body (two per joint)
    ("tree_scratch", _I2),    # the build's union-find and queue (slots x TREE_SCRATCH_COLS)
    ("tree_work", types.float64[:, :, ::1]),  # the factor's 6 x 6 scratch (4 x 6 x 6)
)
STEP_CONTEXT = StepContextType(list(FIELDS))
_new_record = new_record_function()
#: ``context_at(address)``: inside a kernel, the context whose address ``record_address`` gave
context_at = reader(STEP_CONTEXT)
#: ``view(ctx)``: inside a kernel, the context seen without reference counting (``_numba/record.py``):
#: what the stages take, so that passing it and reading its tables cost nothing
view = viewer(STEP_CONTEXT)


@njit
def pack_kernel(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf, ci, pcf, pci,
                params_f, params_i, stats, nb, nk, threads, time_f, impact_f):
    """The compiled part of :func:`pack_context` (its arguments checked and completed)."""
    t = _new_record(STEP_CONTEXT)
    t.bf, t.bi, t.sf, t.si, t.kf, t.ki, t.ws = bf, bi, sf, si, kf, ki, ws
    t.geom_f, t.geom_i, t.aabbs, t.bp_f, t.bp_i, t.pairs = geom_f, geom_i, aabbs, bp_f, bp_i, pairs
    t.raw_f, t.raw_i, t.cf, t.ci, t.pcf, t.pci = raw_f, raw_i, cf, ci, pcf, pci
    t.params_f, t.params_i, t.stats = params_f, params_i, stats
    t.nb, t.nk = nb, nk
    t.h, t.substeps, t.n_pairs, t.nc, t.constrained, t.bundled = 0.0, 1, 0, 0, False, False
    t.n_resting = 0
    t.kept = False
    t.at_rest = False
    t.regions, t.bundles, t.n_overflow, t.iterations, t.clock = 1, 0, 0, 0, 0
    t.iteration_cap = 1
    t.turning, t.n_supported, t.n_static = False, 0, 0
    n_slots = bf.shape[0]
    t.sweep = np.zeros(n_slots)
    t.filters = np.zeros((3, n_slots), dtype=np.int64)
    t.solver_bodies = np.zeros((n_slots + 2, SB_COLS))
    t.forces = np.zeros((n_slots, 3))
    t.torques = np.zeros((n_slots, 3))
    t.user_forces = np.zeros((n_slots, 6))
    t.joint_totals = np.zeros(kf.shape[0])
    t.soft = np.zeros((3, 3))
    t.vecs = np.zeros((SCRATCH_VECS, 4))
    t.joint_cache = np.zeros((kf.shape[0], JOINT_ROWS, ROW_COLS))
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
    t.supported = np.zeros((contacts, 2))
    t.light = np.zeros(n_slots + 2, dtype=np.bool_)
    t.heavy = np.zeros(contacts, dtype=np.bool_)
    t.time_f, t.impact_f = time_f, impact_f
    t.toi_f = np.zeros((TOI_ROWS, 7))
    t.toi_i = np.zeros(TOI_ROWS, dtype=np.int64)
    t.toi_pos = np.zeros((2, 3))
    t.toi_rot = np.zeros((2, 3, 3))
    t.toi_q = np.zeros(4)
    t.toi_touch = np.zeros(TOI_TOUCH + 1, dtype=np.int64)
    t.push_bodies = np.zeros((n_slots + 2, PB_COLS))
    t.push_impulse = np.zeros(contacts)
    t.implicit = np.zeros(kf.shape[0])
    t.static_contacts = np.zeros(contacts, dtype=np.int64)
    t.support_level = np.zeros(n_slots, dtype=np.int64)
    t.support_queue = np.zeros(n_slots, dtype=np.int64)
    t.support_start = np.zeros(n_slots + 1, dtype=np.int64)
    t.support_adjacent = np.zeros(2 * contacts, dtype=np.int64)
    t.joint_start = np.zeros(n_slots + 1, dtype=np.int64)
    t.joint_other = np.zeros(2 * kf.shape[0], dtype=np.int64)
    t.n_tree = 0
    t.tree_factored = False
    t.trees_alone = False
    t.tree_order = np.zeros(kf.shape[0], dtype=np.int64)
    t.tree_i = np.zeros((kf.shape[0], TREE_INT_COLS), dtype=np.int64)
    t.tree_f = np.zeros((kf.shape[0], TREE_FLOAT_COLS))
    t.tree_x = np.zeros((kf.shape[0], 2 * TREE_ROWS))
    t.tree_body = np.zeros((n_slots, TREE_BODY_COLS))
    t.tree_start = np.zeros(n_slots + 1, dtype=np.int64)
    t.tree_joints = np.zeros(2 * kf.shape[0], dtype=np.int64)
    t.tree_scratch = np.zeros((n_slots, TREE_SCRATCH_COLS), dtype=np.int64)
    t.tree_work = np.zeros((4, 6, 6))
    return t


def pack_context(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf, ci,
                pcf, pci, params_f, params_i, stats, nb, nk, threads=1, time_f=None, impact_f=None):
    """A context of the world's tables (the same arrays, not copies), its counts ``nb`` bodies and ``nk``
    constraints, and fresh scratch for as many body and constraint slots as the tables have rows, and for
    contact passes on up to ``threads`` threads.  Every table must be C-contiguous with the dtype and
    dimensions of ``TABLE_FIELDS``.  ``time_f`` (TIME_COLS,) and ``impact_f`` (contact rows, IMPACT_COLS)
    receive the time-of-impact stage's report (None: the context's own, unread)."""
    arrays = locals()
    for name, typ in TABLE_FIELDS:
        a = arrays[name]
        if not (isinstance(a, np.ndarray) and a.dtype == typ.dtype.name and a.ndim == typ.ndim
                and a.flags.c_contiguous):
            raise TypeError(f"{name} must be a C-contiguous {typ.dtype} array of {typ.ndim} dimensions")
    if time_f is None:
        time_f = np.zeros(TIME_COLS)
    if impact_f is None or impact_f.shape[0] < max(cf.shape[0], pcf.shape[0]):
        impact_f = np.zeros((max(cf.shape[0], pcf.shape[0]), IMPACT_COLS))
    return pack_kernel(bf, bi, sf, si, kf, ki, ws, geom_f, geom_i, aabbs, bp_f, bp_i, pairs, raw_f, raw_i, cf,
                       ci, pcf, pci, params_f, params_i, stats, int(nb), int(nk), max(1, int(threads)), time_f,
                       impact_f)
