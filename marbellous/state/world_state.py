"""``WorldState``: the tables of one world, their slots, growth, and the step context packed from them.

Every table is a NumPy array whose columns ``state/layout.py`` names.  Bodies, their shapes and
constraints take rows through :class:`~marbellous.state.slots.Slots`: a removed object's rows are freed
and reused, so a world's step costs what is alive now, not what was ever made.  The tables grow by
capacity doubling outside the kernels; whenever one is replaced the step context is packed again
(``pipeline/context.py``), otherwise a step is one call of the compiled entry with an int.

Nothing here validates user input: the World facade does, then calls these operations, which cannot
fail on what it passes.
"""
import numba
import numpy as np

from .._numba.progress import compiling
from .._numba.progress import install as install_compile_progress
from .._numba.record import array_address, compiled_entry, record_address
from ..collision import shape_types as st
from ..collision.broadphase import make_state as make_broadphase_state
from ..deformables.particle_state import ParticleState
from ..pipeline.context import pack_context, pack_kernel
from ..pipeline.precompile import ahead, shared
from ..pipeline.stages import STAGES
from ..collision.broadphase import GRID
from ..dynamics.contact_bundles import MIN_BUNDLED_CONTACTS
from ..dynamics.integrators import SEMI_IMPLICIT_EULER
from ..pipeline.step import FULL, GROW_CONTACTS, GROW_PAIRS, LEAN, OK, STEPS
from . import layout as L
from .shared_geometry import shared_array
from .slots import Slots

install_compile_progress()


def _live_shapes(bi, si, end):
    """``(kinds, moving)``: the shape kind of every shape of the live bodies in rows ``0 .. end - 1``, and whether
    its body can move."""
    flags = bi[:end, L.FLAGS]
    rows = np.flatnonzero((flags & L.F_ALIVE) != 0)
    starts, counts = bi[rows, L.SHAPE_START], bi[rows, L.SHAPE_COUNT]
    first = np.concatenate(([0], np.cumsum(counts)[:-1]))
    shapes = np.repeat(starts - first, counts) + np.arange(counts.sum())
    return si[shapes, L.S_TYPE], np.repeat((flags[rows] & L.F_STATIC) == 0, counts)


def _sphere_coverage(kinds):
    """The coverage a sphere needs among shapes of ``kinds`` (``shape_types.sphere_coverage`` of each)."""
    return max((st.sphere_coverage(kind) for kind in np.unique(kinds)), default=st.COVER_SPHERES)


def scene_coverage(bi, si, end):
    """``shape_types.COVER_*`` of the bodies in rows ``0 .. end - 1``: which pair tests their step can need
    (static shapes never meet each other).  ``COVER_ALL`` if a moving body has a shape other than a sphere,
    else :func:`_sphere_coverage`."""
    kinds, moving = _live_shapes(bi, si, end)
    if np.any(moving & (kinds != st.SPHERE)):
        return st.COVER_ALL
    return _sphere_coverage(kinds)


def shape_coverage(bi, si, end):
    """The pair tests a sphere (a moving one, a particle) can need against the shapes of the bodies in rows
    ``0 .. end - 1`` (:func:`_sphere_coverage`)."""
    return _sphere_coverage(_live_shapes(bi, si, end)[0])


#: most moving bodies of a world that steps lean: more, and its contacts will soon pass the first rows of its
#: contact table (16 boxes on the ground make 64 points), so it starts with the full step rather than
#: compiling, or loading, the full step in the middle of its run
LEAN_MAX_BODIES = 16


def scene_tier(solver, params_i, n_constraints, contact_rows, moving_bodies):
    """``pipeline.step.LEAN`` if the step of a world can leave out all the step's lean tier leaves out, else
    ``FULL``: sequential impulses, no constraint row in use (``n_constraints``: the constraint slots'
    end), the grid broad phase, semi-implicit Euler, and contact tables of ``contact_rows`` still at
    their first rows (the context then has no bundle tables, ``pipeline/context.py``, so no step could
    bundle), and at most ``LEAN_MAX_BODIES`` ``moving_bodies``.  A world that outgrows it
    (a joint added, contacts past the first rows) is packed again and steps with the full tier, with
    the same results: the lean step differs only in what it cannot meet."""
    lean = (solver == L.SEQUENTIAL_IMPULSE and n_constraints == 0 and params_i[L.PI_BROADPHASE] == GRID
            and params_i[L.PI_INTEGRATOR] == SEMI_IMPLICIT_EULER and contact_rows <= MIN_BUNDLED_CONTACTS
            and moving_bodies <= LEAN_MAX_BODIES)
    return LEAN if lean else FULL


def grow(arr, needed):
    """``arr`` with at least ``needed`` rows (capacity doubling); new rows are zero."""
    cap = arr.shape[0]
    if needed <= cap:
        return arr
    new_cap = max(needed, 2 * cap, 8)
    out = np.zeros((new_cap,) + arr.shape[1:], dtype=arr.dtype)
    out[:cap] = arr
    return out


class WorldState:
    """The tables of a world (bodies, shapes, constraints, contacts, broad phase, parameters, statistics)
    and the compiled step over them."""

    def __init__(self, broadphase_code):
        self.params_f = np.zeros(L.PF_LEN)
        self.params_i = np.zeros(L.PI_LEN, dtype=np.int64)
        self.stats = np.zeros(L.STAT_CYCLES + len(STAGES), dtype=np.int64)
        self.bf = np.zeros((8, L.BF_COLS))
        self.bi = np.zeros((8, L.BI_COLS), dtype=np.int64)
        self.sf = np.zeros((8, L.SF_COLS))
        self.si = np.zeros((8, L.SI_COLS), dtype=np.int64)
        self.kf = np.zeros((8, L.KF_COLS))
        self.ki = np.zeros((8, L.KI_COLS), dtype=np.int64)
        self.ws = np.zeros(L.WS_COLS)
        # Bulk geometry of meshes and height fields, one segment per shape row (geom_sizes: its lengths)
        self.geom_f = np.zeros(0)
        self.geom_i = np.zeros(0, dtype=np.int64)
        self.geom_sizes = {}
        self.bodies = Slots()
        self.shapes = Slots()
        self.constraints = Slots()
        # Collision detection: body boxes, broad-phase state, candidate pairs, the narrow phase's points,
        # and two contact tables: the step fills one and keeps the other as its warm-start cache, then
        # they swap roles (stats[STAT_CACHE_SIDE] says which is the cache).
        self.aabbs = np.zeros((8, 6))
        self.broadphase_code = broadphase_code
        self.bp_f, self.bp_i = make_broadphase_state(broadphase_code, self.aabbs.shape[0])
        self.pairs = np.zeros((64, 2), dtype=np.int64)
        self.raw_f = np.zeros((64, 7))
        self.raw_i = np.zeros(64, dtype=np.int64)
        self.contact_f = [np.zeros((64, L.CF_COLS)), np.zeros((64, L.CF_COLS))]
        self.contact_i = [np.zeros((64, L.CI_COLS), dtype=np.int64), np.zeros((64, L.CI_COLS), dtype=np.int64)]
        # What the step's time-of-impact stage reports (layout T_*), and the impulses of the impacts it
        # resolved, one row per contact of the interval (pipeline/impacts.py)
        self.time_f = np.zeros(L.TIME_COLS)
        self.impact_f = np.zeros((64, L.IMPACT_COLS))
        self.threads = 1
        self.solver = L.SEQUENTIAL_IMPULSE
        self.particles = ParticleState()     # particles and networks (deformables/particle_state.py)
        # The step context of the current tables (None whenever one of them is replaced), its address (an
        # array of one), that step's entry point and the arguments it takes (the addresses of that array and
        # of the one where it writes its status, and their length).
        self.context = self.entry = self.addresses = self.arguments = None
        self.statuses = np.zeros(1, dtype=np.int64)
        self.tier = None      # the tier of that step (pipeline/step.py: LEAN or FULL)
        self.sharing = None   # a step compiling ahead in a helper process (compile_ahead), until the first pack
        self.packed_coverage = st.COVER_GROUND    # shape_coverage at the last packing

    # --- the step -----------------------------------------------------------------------------------------
    def invalidate(self):
        """Forget the packed context (a table was replaced, or the step's variant changed)."""
        self.context = None

    def step_variant(self):
        """``(coverage, tier, step)``: the pair tests the bodies can need (``scene_coverage``), the step's tier
        (``scene_tier``) and the scheme's step kernel of them."""
        coverage = scene_coverage(self.bi, self.si, self.bodies.end)
        flags = self.bi[:self.bodies.end, L.FLAGS]
        tier = scene_tier(self.solver, self.params_i, self.constraints.end,
                          max(self.contact_f[0].shape[0], self.contact_f[1].shape[0]),
                          np.count_nonzero((flags & (L.F_ALIVE | L.F_STATIC)) == L.F_ALIVE))
        return coverage, tier, STEPS[self.solver][coverage][tier]

    def sphere_coverage(self):
        """:func:`shape_coverage` of the bodies as they are (kept from the last packing while it holds)."""
        if self.context is None:
            return shape_coverage(self.bi, self.si, self.bodies.end)
        return self.packed_coverage

    def compile_ahead(self, first):
        """Start compiling the step as it would be taken now in helper processes, when it is not in the kernel
        cache, after ``first`` (``[(kernel, arguments)]`` that the program calls before its step;
        ``pipeline/precompile.ahead``); the first :meth:`pack` finishes it."""
        coverage, tier, _ = self.step_variant()
        if self.sharing is None:
            self.sharing = ahead((self.solver, coverage, tier), first)

    def pack(self):
        """The step context of the current tables and the compiled entry of the scheme's step for the pair
        tests the bodies can need (``scene_coverage``; compiled on first use: a progress line, then a notice,
        ``_numba/progress.py``)."""
        coverage, self.tier, step = self.step_variant()
        self.packed_coverage = shape_coverage(self.bi, self.si, self.bodies.end)
        sharing, self.sharing = self.sharing, None
        with compiling(), shared(pack_kernel, (self.solver, coverage, self.tier),
                                 lambda: self.particles.kernel_work(self), sharing) as sharing:
            self.context = pack_context(self.bf, self.bi, self.sf, self.si, self.kf, self.ki, self.ws, self.geom_f,
                                        self.geom_i, self.aabbs, self.bp_f, self.bp_i, self.pairs, self.raw_f,
                                        self.raw_i, self.contact_table_f(False), self.contact_table_i(False),
                                        self.cache_f, self.cache_i, self.params_f, self.params_i, self.stats,
                                        self.bodies.end, self.constraints.end, self.threads, self.time_f,
                                        self.impact_f)
            self.addresses = np.array([record_address(self.context)],
                                      dtype=object if numba.config.DISABLE_JIT else np.int64)
            self.arguments = (array_address(self.addresses), array_address(self.statuses), 1)
            sharing.wait(step)
            self.entry = compiled_entry(step, *self.arguments)

    def step(self):
        """One step (or interval) with the parameters in ``params_f``/``params_i``; buffers that turn out too
        small are grown and the step is run again (it changed nothing but scratch).  Returns OK, or SPLIT
        (the time-of-impact stage asks for an interval of ``time_f[T_LIMIT]`` seconds and nothing was solved)
        or DETECTED (a detection pass: ``params_i[PI_DETECT]``), from ``pipeline/impacts.py``."""
        if self.context is None:
            self.pack()
        status = self.entry(*self.arguments)
        return status if status == OK else self.settle(status)

    def settle(self, status):
        """The step's status once the buffers that ``status`` (the entry's) says were too small are grown and
        the step run again, as often as needed (:meth:`step`; a batch of worlds stepped by one call settles
        each one's status after it, ``marbellous/batch.py``)."""
        while status == GROW_PAIRS or status == GROW_CONTACTS:
            if status == GROW_PAIRS:
                self.pairs = grow(self.pairs, int(self.stats[L.STAT_PAIRS]))
            else:
                self.grow_contacts(int(self.stats[L.STAT_CONTACTS]))
            self.pack()
            status = self.entry(*self.arguments)
        return status

    # --- contacts -------------------------------------------------------------------------------------------
    def contact_table_f(self, cache):
        """The float contact table in the role ``cache`` (True: last step's contacts) or the one the next
        step fills (False)."""
        side = int(self.stats[L.STAT_CACHE_SIDE])
        return self.contact_f[side if cache else 1 - side]

    def contact_table_i(self, cache):
        """The int contact table in that role."""
        side = int(self.stats[L.STAT_CACHE_SIDE])
        return self.contact_i[side if cache else 1 - side]

    @property
    def cache_f(self):
        """Last step's contacts (float columns); its first :attr:`n_cached` rows are valid."""
        return self.contact_table_f(True)

    @property
    def cache_i(self):
        """Last step's contacts (int columns)."""
        return self.contact_table_i(True)

    @property
    def n_cached(self):
        """Contact points of the last step."""
        return int(self.stats[L.STAT_CACHED])

    def grow_contacts(self, n):
        """Room for ``n`` contact points in the narrow-phase buffer and both contact tables, all grown to one
        capacity (the tables swap roles every step, so the step's scratch is sized by either)."""
        self.invalidate()
        n = max(n, self.contact_f[0].shape[0], self.contact_f[1].shape[0], self.raw_f.shape[0])
        self.raw_f = grow(self.raw_f, n)
        self.raw_i = grow(self.raw_i, n)
        self.contact_f = [grow(t, n) for t in self.contact_f]
        self.contact_i = [grow(t, n) for t in self.contact_i]
        self.impact_f = grow(self.impact_f, n)

    def forget_contacts_of(self, body_row):
        """Drop last step's contacts of a body (it is being removed): nothing reports or warm-starts them."""
        n = self.n_cached
        cf, ci = self.cache_f, self.cache_i
        keep = (ci[:n, L.C_BODY_A] != body_row) & (ci[:n, L.C_BODY_B] != body_row)
        m = int(keep.sum())
        if m < n:
            cf[:m] = cf[:n][keep]
            ci[:m] = ci[:n][keep]
            self.stats[L.STAT_CACHED] = m

    # --- broad phase ------------------------------------------------------------------------------------------
    def set_broadphase(self, code):
        """Switch the broad phase (a fresh state, rebuilt by the next step)."""
        self.broadphase_code = code
        self.bp_f, self.bp_i = make_broadphase_state(code, self.aabbs.shape[0])
        self.params_i[L.PI_BROADPHASE] = code
        self.invalidate()

    # --- bodies -------------------------------------------------------------------------------------------------
    def insert_body(self, parts, pos, quat, vel, omega, mass, inertia, inverse_inertia, material, flags,
                    static_box, group, mask):
        """Write a validated body and its shapes into free rows; returns the body's row.

        ``parts``: (shape, local position, local orientation) in the body's frame (centre of mass);
        ``mass`` (kg, inf for static), ``inertia``/``inverse_inertia`` (3x3 body frame, None for static);
        ``material``: the values of the columns ``layout.MATERIAL``; ``flags``: F_* bits
        besides F_ALIVE; ``static_box``: the world AABB of a static body (None for dynamic ones);
        ``group``/``mask``: the collision filter's bits."""
        self.invalidate()
        i = self.bodies.allocate()
        self.bf = grow(self.bf, self.bodies.end)
        self.bi = grow(self.bi, self.bodies.end)
        if self.aabbs.shape[0] < self.bf.shape[0]:
            self.aabbs = grow(self.aabbs, self.bf.shape[0])
            self.bp_f, self.bp_i = make_broadphase_state(self.broadphase_code, self.bf.shape[0])
        s0 = self._insert_shapes(parts, i)
        bf = self.bf[i]
        bf[:] = 0.0
        bf[L.POS:L.POS + 3] = pos
        bf[L.PREV_POS:L.PREV_POS + 3] = pos
        bf[L.QUAT:L.QUAT + 4] = quat
        bf[L.VEL:L.VEL + 3] = vel
        bf[L.OMEGA:L.OMEGA + 3] = omega
        bf[L.MASS] = mass
        bf[list(L.MATERIAL)] = material
        if inertia is not None:
            bf[L.INV_MASS] = 1.0 / mass
            bf[L.I_BODY:L.I_BODY + 9] = inertia.ravel()
            bf[L.INV_I:L.INV_I + 9] = inverse_inertia.ravel()
        self.bi[i] = (flags | L.F_ALIVE | L.F_RESTART, s0, len(parts), group, mask, -1)
        self.aabbs[i] = 0.0 if static_box is None else static_box
        return i

    def _insert_shapes(self, parts, body_row):
        """Shape rows (consecutive) and bulk geometry for ``parts`` of body ``body_row``; returns the first row."""
        s0 = self.shapes.allocate(len(parts))
        self.sf = grow(self.sf, self.shapes.end)
        self.si = grow(self.si, self.shapes.end)
        geom_f, geom_i = [self.geom_f], [self.geom_i]
        off_f, off_i = self.geom_f.size, self.geom_i.size
        for k, (s, p, q) in enumerate(parts):
            row = s0 + k
            self.sf[row] = 0.0
            self.sf[row, L.S_PARAMS:L.S_PARAMS + 8] = s._params()
            self.sf[row, L.S_LOCAL_POS:L.S_LOCAL_POS + 3] = p
            self.sf[row, L.S_LOCAL_QUAT:L.S_LOCAL_QUAT + 4] = q
            self.sf[row, L.S_RADIUS] = s.bounding_radius()
            gf, gi = s._geometry()
            self.si[row] = (s._type, body_row, off_f, off_i)
            self.geom_sizes[row] = (gf.size, gi.size)
            geom_f.append(gf)
            geom_i.append(gi)
            off_f += gf.size
            off_i += gi.size
        if off_f > self.geom_f.size or off_i > self.geom_i.size:
            self.geom_f = shared_array(np.concatenate(geom_f))
            self.geom_i = shared_array(np.concatenate(geom_i).astype(np.int64))
        return s0

    def free_body(self, i):
        """Free body row ``i``, its shape rows and their geometry, and forget its contacts."""
        self.invalidate()
        s0, ns = int(self.bi[i, L.SHAPE_START]), int(self.bi[i, L.SHAPE_COUNT])
        for row in range(s0, s0 + ns):
            self._free_geometry(row)
            self.si[row] = (0, -1, 0, 0)
        self.shapes.free(s0, ns)
        self.forget_contacts_of(i)
        self.bf[i] = 0.0
        self.bi[i] = 0
        self.aabbs[i] = 0.0
        self.bodies.free(i)

    def _free_geometry(self, row):
        """Cut shape ``row``'s segment out of the bulk geometry; later segments move down."""
        nf, ni = self.geom_sizes.pop(row)
        off_f, off_i = int(self.si[row, L.S_OFF_F]), int(self.si[row, L.S_OFF_I])
        end = self.shapes.end
        live = self.si[:end, L.S_BODY] >= 0
        if nf:
            self.geom_f = shared_array(np.concatenate([self.geom_f[:off_f], self.geom_f[off_f + nf:]]))
            moved = live & (self.si[:end, L.S_OFF_F] > off_f)
            self.si[:end, L.S_OFF_F][moved] -= nf
        if ni:
            self.geom_i = shared_array(np.concatenate([self.geom_i[:off_i], self.geom_i[off_i + ni:]]))
            moved = live & (self.si[:end, L.S_OFF_I] > off_i)
            self.si[:end, L.S_OFF_I][moved] -= ni

    def wake(self, i):
        """Wake body row ``i`` (and reset its rest timer)."""
        self.bi[i, L.FLAGS] &= ~L.F_SLEEPING
        self.bf[i, L.SLEEP_TIME] = 0.0

    # --- constraints ---------------------------------------------------------------------------------------
    def insert_constraint(self, ctype, ia, ib, anchor_a, anchor_b, length, stiffness, damping, breaking_force):
        """Write a validated constraint between body rows ``ia`` and ``ib`` (-1: the world); returns its row."""
        self.invalidate()
        c = self.constraints.allocate()
        self.kf = grow(self.kf, self.constraints.end)
        self.ki = grow(self.ki, self.constraints.end)
        row = self.kf[c]
        row[:] = 0.0
        row[L.K_ANCHOR_A:L.K_ANCHOR_A + 3] = anchor_a
        row[L.K_ANCHOR_B:L.K_ANCHOR_B + 3] = anchor_b
        row[L.K_LENGTH] = length
        row[L.K_STIFFNESS] = stiffness
        row[L.K_DAMPING] = damping
        row[L.K_BREAKING] = breaking_force
        self.ki[c] = (ctype, ia, ib, L.KF_ALIVE)
        return c

    def free_constraint(self, c):
        """Free constraint row ``c``."""
        self.invalidate()
        self.kf[c] = 0.0
        self.ki[c] = 0
        self.constraints.free(c)
