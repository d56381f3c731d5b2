"""One world step: named stage functions over the step context, called in order by one compiled step per
collision-handling scheme.

Each scheme's step (:data:`STEPS`) reads as the list of its stages (``pipeline/stages.py`` names and
describes them).  A world compiles and calls only the step of its own scheme, so a world that never
uses the LCP or penalty scheme never compiles them.  The execution variant of the contact passes (one
scalar pass, coloured bundles solved eight at a time, regions on several threads) is chosen once per
step by the prepare stage and recorded in the context; the stages that differ by variant read it there.

The stages are compiled functions of their own, called by the step (``njit``); only the small helpers
and the scheme's step itself are inlined (``njit_inline``).  Inlined into one function, the stages made a
step that took Numba 100 s and 3 GB to compile on a first run, as calls 10 s (the whole first world
from 210 to 145 s), at no measured cost per step.  The stages whose contact passes may run on threads
(solve and relax) are not cached on their own but held in each step's cache entry
(``njit_calls_parallel``).  The stages take a view of the context (``_numba/record.py``), so that neither
passing it nor reading its tables counts references.  The step returns ``OK``, or ``GROW_PAIRS`` /
``GROW_CONTACTS`` having changed nothing but scratch (the needed sizes in ``stats``), so the caller can
grow the buffers and call again.

The stages, in order:

"""
import numpy as np

from .._numba.clock import cycle_counter
from .._numba.jit import njit, njit_calls_parallel, njit_inline
from .._numba.record import int64_array_at
from .._numba.wide import LANES
from ..collision.broadphase import GRID, find_pairs
from ..collision.shape_types import COVER_ALL, COVER_GROUND, COVER_MESHES, COVER_SPHERES, COVERAGES
from ..dynamics.breaking import break_overloaded
from ..dynamics.contact_bundles import (MIN_BUNDLED_CONTACTS, accumulate_bundles, bundle_capacity, deepest_overlap,
                                        load_bundle_bodies, refresh_bundle_masses, store_bundles, warm_start_bundles)
from ..dynamics.contact_cache import keep_resting_contacts, mark_resting, match_contacts, solved_rows
from ..dynamics.contact_regions import bundle_regions, order_contacts, solve_bundle_pass
from ..dynamics.contact_solver import (accumulate_applied, accumulate_listed, apply_push, apply_restitution,
                                       clear_push, has_turning_contacts, heavy_on_light, list_static_contacts,
                                       prepare_contacts, push_contacts, push_static, refresh_turning_masses,
                                       scale_contact_impulses,
                                       solve_contacts, solve_supported, store_friction_state, warm_start_contacts,
                                       warm_start_listed)
from ..dynamics.ccd import shape_reach
from ..dynamics.forces import is_driven, is_moving
from ..dynamics.integrators import SEMI_IMPLICIT_EULER, integrate_positions, integrate_velocities
from ..dynamics.joints import classify_springs, record_joint_forces, solve_joints, warm_start_joints
from ..dynamics.joint_tree import (T_MEMBER, build_joint_trees, factor_joint_trees, push_joint_trees,
                                   solve_joint_trees)
from ..dynamics.joint_rows import (RIGID_JOINT_RATE, clear_joint_sums, drop_joined_pairs, fill_joint_rows,
                                   push_rigid_joints,
                                   record_rigid_joint_forces, scale_joint_impulses, solve_rigid_joints,
                                   warm_start_rigid_joints)
from ..dynamics.lcp import solve_lcp
from ..dynamics.penalty import add_penalty_forces, restore_user_forces
from ..dynamics.sleep import update_sleep, wake_touched_islands
from ..dynamics.soft import soft_coefficients, soft_depth
from ..dynamics.solver_bodies import prepare_solver_bodies, store_velocities
from ..dynamics.springs import clear_spring_forces
from ..dynamics.support_depth import iteration_cap, order_bottom_up, stop_change, support_depth
from ..state.layout import (BOTTOM_UP, BUNDLE_ROWS, C_POINT, DTHETA, FLAGS, FORCE, F_ALIVE, F_JOINTED, F_SENSOR, GROUP,
                            K_IMPULSE, LCP, MASK, OMEGA, PENALTY, PF_CONTACT_HERTZ, PF_CONTACT_ZETA, PF_DT, PF_GRAVITY,
                            PF_JOINT_HERTZ, PF_JOINT_ZETA, PF_LCP_SOR, PF_MAX_PUSH, PF_PENALTY_HERTZ,
                            PF_RESTITUTION_SPEED, PF_SLEEP_ANGULAR, PF_SLEEP_LINEAR, PF_SLIDE_SPEED, PF_SPECULATIVE,
                            PF_STEP_DT, PF_SWEEP, PF_TIME_TO_SLEEP, PF_TOLERANCE, PI_BROADPHASE, PI_INTEGRATOR,
                            PI_ADAPTIVE, PI_ITERATIONS, PI_LCP_SWEEPS, PI_PAIR_CACHE, PI_PROFILE, PI_SOLVE_ORDER,
                            PI_SOLVER, PI_SUBSTEPS, PI_THREADS, PI_TURN_SUBSTEPS, POS, POS0, SEQUENTIAL_IMPULSE,
                            SHAPE_COUNT, SHAPE_START, STAT_CACHED, STAT_CACHE_SIDE, STAT_CONTACTS, STAT_PREVIOUS,
                            STAT_CYCLES, STAT_ITERATIONS, STAT_KEPT, STAT_PAIRS, STAT_PROFILED_STEPS, STAT_SUM_CONTACTS,
                            STAT_SUM_ITERATIONS, STAT_SUM_PAIRS, TORQUE, W_PREV_DT, W_TIME)
from .collide import MAX_PAIRS_PER_BODY, limit_pairs_per_body, narrow_phase, update_aabbs
from .context import context_at, view
from .impacts import stage_time_of_impact
from .stages import (ST_AABBS, ST_BREAK_CONSTRAINTS, ST_BROAD_PHASE, ST_INTEGRATE_POSITIONS, ST_TIME_OF_IMPACT,
                     ST_INTEGRATE_VELOCITIES, ST_ISLANDS_AND_SLEEP, ST_MATCH_AND_WAKE, ST_NARROW_PHASE, ST_PREPARE,
                     ST_RELAX, ST_RESTITUTION, ST_SOLVE, ST_STORE_IMPULSES, ST_SUM_IMPULSES, ST_WARM_START,
                     describe)

__doc__ += "\n".join("    " + line for line in describe().splitlines()) + "\n"

OK = 0
GROW_PAIRS = 1
GROW_CONTACTS = 2

#: The step's tiers.  A LEAN step is compiled without what a world of the default settings with no
#: constraint and few contacts cannot meet: joints, springs, rods and cables; coloured bundles and threads
#: (which need a contact table grown past its first rows); broad phases but the grid; integrators but
#: semi-implicit Euler.  A first world compiles about half as much.  ``world_state.scene_tier`` picks it.
LEAN = 0
FULL = 1


# --- the profile clock -------------------------------------------------------------------------------------
@njit_inline
def start_clock(ctx):
    """With profiling on, start the clock of the step's first stage."""
    if ctx.params_i[PI_PROFILE] != 0:
        ctx.clock = cycle_counter()


@njit_inline
def lap(ctx, stage):
    """With profiling on, add the cycles since the last lap to ``stage``'s total (``stats``)."""
    if ctx.params_i[PI_PROFILE] != 0:
        now = cycle_counter()
        stats = ctx.stats
        stats[STAT_CYCLES + stage] += now - ctx.clock
        ctx.clock = now


# --- collide -------------------------------------------------------------------------------------------------
@njit_inline
def _needs_pairs(bf, bi, nb):
    """True if some body is awake and dynamic, a kinematic body in motion, or a sensor, and another body
    lives: otherwise every pair
    is resting or static, or there is no pair at all, so the narrow phase would have nothing to test and
    the broad phase is skipped too (a sleeping world, or a lone body, costs next to nothing)."""
    alive = 0
    active = False
    for i in range(nb):
        f = bi[i, FLAGS]
        alive += (f & F_ALIVE) != 0
        active = (active or is_moving(bi, i) or ((f & F_ALIVE) != 0 and (f & F_SENSOR) != 0)
                  or is_driven(bf, bi, i))
        if active and alive > 1:
            return True
    return False


@njit
def stage_aabbs(ctx):
    """Stage "aabbs": every body's box, swept over the step (continuous collision) and grown by the
    speculative distance; shapes posed for the narrow phase."""
    params_f = ctx.params_f
    gravity = params_f[PF_GRAVITY:PF_GRAVITY + 3]
    g_mag = np.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    update_aabbs(ctx.bf, ctx.bi, ctx.sf, ctx.si, ctx.nb, ctx.aabbs,
                 ctx.sweep, params_f[PF_DT] * params_f[PF_SWEEP], g_mag, params_f[PF_SPECULATIVE],
                 ctx.pose_pos, ctx.pose_rot, ctx.pose_quat)
    lap(ctx, ST_AABBS)


@njit_inline
def _broad_phase(ctx, tier):
    """Stage "broad phase": candidate pairs into ``pairs`` (their number in ``ctx.n_pairs``), by the world's
    broad phase (``LEAN``: the grid, the only one a lean world has)."""
    bi, nb = ctx.bi, ctx.nb
    n_pairs = 0
    if _needs_pairs(ctx.bf, bi, nb):
        # the filter columns copied to contiguous rows: the broad phase reads them per pair, and columns of
        # the body table would cost it a cache line per read
        filters = ctx.filters
        jointed = False
        for i in range(nb):
            filters[0, i] = bi[i, FLAGS]
            filters[1, i] = bi[i, GROUP]
            filters[2, i] = bi[i, MASK]
            jointed = jointed or (bi[i, FLAGS] & F_JOINTED) != 0
        if tier == FULL:
            n_pairs = find_pairs(ctx.params_i[PI_BROADPHASE], ctx.aabbs, filters[0], filters[1], filters[2],
                                 nb, ctx.bp_f, ctx.bp_i, ctx.pairs)
            if jointed and n_pairs <= ctx.pairs.shape[0]:
                n_pairs = drop_joined_pairs(ctx.pairs, n_pairs, bi, ctx.ki, ctx.nk, nb, ctx.joint_start,
                                            ctx.joint_other)
        else:
            n_pairs = find_pairs(GRID, ctx.aabbs, filters[0], filters[1], filters[2], nb, ctx.bp_f, ctx.bp_i,
                                 ctx.pairs)
    ctx.n_pairs = n_pairs
    ctx.stats[STAT_PAIRS] = n_pairs
    lap(ctx, ST_BROAD_PHASE)


@njit
def stage_broad_phase(ctx):
    """Stage "broad phase" (:func:`_broad_phase`)."""
    _broad_phase(ctx, FULL)


@njit
def stage_broad_phase_lean(ctx):
    """Stage "broad phase" of a lean step."""
    _broad_phase(ctx, LEAN)


@njit_inline
def stage_narrow_phase(ctx, coverage):
    """Stage "narrow phase": the contact points of the candidate pairs into the contact table (their
    number in ``ctx.nc``, which may exceed its capacity: the caller then grows it), by the pair tests of
    ``coverage``, or from last step's table where a pair has hardly moved (pipeline/pair_cache.py)."""
    raw_f, cf = ctx.raw_f, ctx.cf
    nc = 0
    if ctx.n_pairs > 0:     # (the call passes 21 arrays: ~50 ns, more than a lone body's whole narrow phase)
        nc = narrow_phase(coverage, ctx.bf, ctx.bi, ctx.sf, ctx.si, ctx.geom_f,
                          ctx.geom_i, ctx.pairs, ctx.n_pairs, ctx.sweep,
                          ctx.params_f[PF_SPECULATIVE], raw_f, ctx.raw_i, ctx.ci, cf, ctx.pcf, ctx.pci,
                          solved_rows(ctx.pci, ctx.stats[STAT_CACHED]) if ctx.params_i[PI_PAIR_CACHE] else 0,
                          ctx.pose_pos, ctx.pose_rot, ctx.pose_state, ctx.pose_quat)
    ctx.nc = nc
    ctx.stats[STAT_CONTACTS] = nc
    if nc <= cf.shape[0]:
        for c in range(nc):
            for k in range(7):
                cf[c, C_POINT + k] = raw_f[c, k]   # point, normal, depth are the first 7 columns
    lap(ctx, ST_NARROW_PHASE)


# --- the narrow phase and time-of-impact stages of each coverage: a world compiles the ones of its own, each a
# kernel of its own, so that two processes can compile them at once (pipeline/precompile.py) -----------------------
@njit
def stage_narrow_phase_spheres(ctx):
    """:func:`stage_narrow_phase` with the pair tests of ``COVER_SPHERES``."""
    stage_narrow_phase(ctx, COVER_SPHERES)


@njit
def stage_narrow_phase_meshes(ctx):
    """:func:`stage_narrow_phase` with the pair tests of ``COVER_MESHES``."""
    stage_narrow_phase(ctx, COVER_MESHES)


@njit
def stage_narrow_phase_ground(ctx):
    """:func:`stage_narrow_phase` with the pair tests of ``COVER_GROUND``."""
    stage_narrow_phase(ctx, COVER_GROUND)


@njit
def stage_narrow_phase_all(ctx):
    """:func:`stage_narrow_phase` with every pair test."""
    stage_narrow_phase(ctx, COVER_ALL)


@njit
def stage_time_of_impact_spheres(ctx):
    """``impacts.stage_time_of_impact`` with the pair tests of ``COVER_SPHERES``."""
    return stage_time_of_impact(ctx, COVER_SPHERES)


@njit
def stage_time_of_impact_meshes(ctx):
    """``impacts.stage_time_of_impact`` with the pair tests of ``COVER_MESHES``."""
    return stage_time_of_impact(ctx, COVER_MESHES)


@njit
def stage_time_of_impact_ground(ctx):
    """``impacts.stage_time_of_impact`` with the pair tests of ``COVER_GROUND``."""
    return stage_time_of_impact(ctx, COVER_GROUND)


@njit
def stage_time_of_impact_all(ctx):
    """``impacts.stage_time_of_impact`` with every pair test."""
    return stage_time_of_impact(ctx, COVER_ALL)


#: the narrow phase stage of each coverage, ``NARROW_PHASE[coverage]``
NARROW_PHASE = (stage_narrow_phase_spheres, stage_narrow_phase_meshes, stage_narrow_phase_ground,
                stage_narrow_phase_all)
#: the time-of-impact stage of each coverage, ``TIME_OF_IMPACT[coverage]``
TIME_OF_IMPACT = (stage_time_of_impact_spheres, stage_time_of_impact_meshes, stage_time_of_impact_ground,
                  stage_time_of_impact_all)


@njit_inline
def narrow_phase_stage(ctx, coverage):
    """The narrow phase stage of ``coverage`` (a constant where this is inlined)."""
    if coverage == COVER_SPHERES:
        stage_narrow_phase_spheres(ctx)
    elif coverage == COVER_MESHES:
        stage_narrow_phase_meshes(ctx)
    elif coverage == COVER_GROUND:
        stage_narrow_phase_ground(ctx)
    else:
        stage_narrow_phase_all(ctx)


@njit_inline
def time_of_impact_stage(ctx, coverage):
    """The time-of-impact stage of ``coverage`` (a constant where this is inlined)."""
    if coverage == COVER_SPHERES:
        return stage_time_of_impact_spheres(ctx)
    if coverage == COVER_MESHES:
        return stage_time_of_impact_meshes(ctx)
    if coverage == COVER_GROUND:
        return stage_time_of_impact_ground(ctx)
    return stage_time_of_impact_all(ctx)


@njit_inline
def _find_contacts(ctx, coverage):
    """Stages "narrow phase" and "time of impact", by the pair tests of ``coverage``, with the resting
    pairs' contacts kept from the cache.  Returns OK, GROW_CONTACTS (nothing but scratch changed), or the
    time-of-impact stage's SPLIT or DETECTED (pipeline/impacts.py)."""
    narrow_phase_stage(ctx, coverage)
    if ctx.nc > ctx.cf.shape[0]:
        return GROW_CONTACTS
    # the resting pairs' contacts kept from the cache go after the step's own (counted first: the
    # time-of-impact stage may change velocities, so a table too small must be found before it)
    npc = ctx.stats[STAT_CACHED]
    resting = keep_resting_contacts(ctx.cf, ctx.ci, ctx.nc, ctx.pcf, ctx.pci, npc, ctx.bf, ctx.bi, False)
    if ctx.nc + resting > ctx.cf.shape[0]:
        ctx.stats[STAT_CONTACTS] = ctx.nc + resting
        return GROW_CONTACTS
    status = time_of_impact_stage(ctx, coverage)
    lap(ctx, ST_TIME_OF_IMPACT)
    if status == OK and resting > 0:
        if ctx.nc == 0 and resting == npc:      # nothing new, all at rest: the cache is the step's table
            mark_resting(ctx.pci, npc)
            ctx.kept = True
            ctx.n_resting = npc
        else:
            ctx.n_resting = keep_resting_contacts(ctx.cf, ctx.ci, ctx.nc, ctx.pcf, ctx.pci, npc, ctx.bf, ctx.bi,
                                                   True)
    return status


# --- the contact stages of each coverage: a world compiles the one of its own -----------------------------------
@njit
def find_contacts_spheres(ctx):
    """:func:`_find_contacts` with the pair tests of ``COVER_SPHERES``."""
    return _find_contacts(ctx, COVER_SPHERES)


@njit
def find_contacts_meshes(ctx):
    """:func:`_find_contacts` with the pair tests of ``COVER_MESHES``."""
    return _find_contacts(ctx, COVER_MESHES)


@njit
def find_contacts_ground(ctx):
    """:func:`_find_contacts` with the pair tests of ``COVER_GROUND``."""
    return _find_contacts(ctx, COVER_GROUND)


@njit
def find_contacts_all(ctx):
    """:func:`_find_contacts` with every pair test."""
    return _find_contacts(ctx, COVER_ALL)


#: the contact stages of each coverage, ``FIND_CONTACTS[coverage]``
FIND_CONTACTS = (find_contacts_spheres, find_contacts_meshes, find_contacts_ground, find_contacts_all)


@njit_inline
def find_contacts(ctx, coverage):
    """The contact stages of ``coverage`` (a constant where this is inlined)."""
    if coverage == COVER_SPHERES:
        return find_contacts_spheres(ctx)
    if coverage == COVER_MESHES:
        return find_contacts_meshes(ctx)
    if coverage == COVER_GROUND:
        return find_contacts_ground(ctx)
    return find_contacts_all(ctx)


@njit_inline
def collide(ctx, coverage, tier):
    """Stages "aabbs", "broad phase", "narrow phase" and "time of impact", at the poses the step began with,
    by the pair tests of ``coverage`` (``shape_types.COVER_*``).  Returns OK, or which buffer is too small
    (nothing but scratch changed), or the time-of-impact stage's SPLIT or DETECTED (pipeline/impacts.py)."""
    ctx.n_resting = 0
    ctx.kept = False
    stage_aabbs(ctx)
    if tier == FULL:
        stage_broad_phase(ctx)
    else:
        stage_broad_phase_lean(ctx)
    if ctx.n_pairs > ctx.pairs.shape[0]:
        return GROW_PAIRS
    if ctx.n_pairs > MAX_PAIRS_PER_BODY * ctx.nb:      # bodies spawned into one another: bound the contacts
        ctx.n_pairs = limit_pairs_per_body(ctx.pairs, ctx.n_pairs, ctx.bi, ctx.nb, MAX_PAIRS_PER_BODY)
    return find_contacts(ctx, coverage)


@njit
def stage_match_and_wake(ctx):
    """Stage "match and wake": warm-start impulses from last step's contacts; sleeping islands touched by
    awake bodies wake."""
    nc = ctx.nc
    if nc > 0:
        ci = ctx.ci
        match_contacts(ctx.cf, ci, nc, ctx.pcf, ctx.pci, ctx.stats[STAT_CACHED])
        wake_touched_islands(ctx.bi, ctx.bf, ci, nc, ctx.nb)
    lap(ctx, ST_MATCH_AND_WAKE)


# --- prepare -------------------------------------------------------------------------------------------------
#: the most an awake body may turn in one automatic sub-step (rad): contacts see a body's velocity as
#: constant over a sub-step, ``v + omega x r``, which describes a turn of a fraction of a radian only
MAX_TURN = 0.25


@njit
def _turns_a_surface(bi, sf, si, i):
    """True if turning moves a surface of body row ``i`` (any shape but a sphere at its centre of mass)."""
    s0 = bi[i, SHAPE_START]
    for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
        if shape_reach(sf, si, s) > 0.0:
            return True
    return False


@njit
def turning_substeps(bf, bi, sf, si, nb, dt, substeps, most):
    """Sub-steps of a step of ``dt`` s: ``substeps``, or with ``most > substeps`` (automatic sub-steps) enough
    that no awake body turns by more than ``MAX_TURN`` in one, ``ceil(dt max|omega| / MAX_TURN)``, at most
    ``most``.  A sphere turning about its centre does not count: its contacts do not move as it turns."""
    if most <= substeps:
        return substeps
    slow = (MAX_TURN * substeps / dt) ** 2
    fastest = slow
    for i in range(nb):
        if is_moving(bi, i):
            w2 = bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2
            if w2 > fastest and _turns_a_surface(bi, sf, si, i):
                fastest = w2
    if fastest <= slow:
        return substeps
    return min(most, int(np.ceil(dt * np.sqrt(fastest) / MAX_TURN)))


@njit_inline
def _nothing_moves(bf, bi, nb):
    """True if no body is awake and dynamic, nor a kinematic body in motion: the sub-steps would move nothing."""
    for i in range(nb):
        if is_moving(bi, i) or is_driven(bf, bi, i):
            return False
    return True


@njit_inline
def _rescale_warm_start(ctx):
    """The impulses the contacts and joints start from (the last sub-step's) scaled to this step's sub-step
    length, when it differs: the same forces are impulses in proportion to it.  (The intervals of a step
    cut at a time of impact are shorter; unscaled, a marble resting on a hinged bridge was kicked up by
    its last sub-step's contact impulse applied again in an interval a tenth as long.)"""
    prev_h = ctx.ws[W_PREV_DT]
    if prev_h > 0.0 and prev_h != ctx.h:
        scale = ctx.h / prev_h
        scale_contact_impulses(ctx.cf, ctx.nc, scale)
        scale_joint_impulses(ctx.kf, ctx.ki, ctx.nk, scale)


@njit_inline
def _prepare(ctx, tier, may_bundle, may_turn, shock):
    """Stage "prepare": the step's start poses, the solver bodies, the contacts' basis, masses and materials,
    and the execution variant of the contact passes, chosen once: coloured bundles (``may_bundle``, the
    sequential-impulse scheme, and enough contacts, in regions when ``threads`` > 1) or one scalar pass
    (from the ground up with ``World.solve_order = "bottom_up"``).
    With ``may_turn`` the contacts of turning bodies are marked for fresh effective masses after each
    position update; with ``shock`` the contacts of a heavy body on a light one are found for the passes
    with the light one held.  Also the soft-constraint coefficients of the sub-step, the springs too
    stiff for explicit forces (solved implicitly by the constraint solver) and the springs' force
    records."""
    bf, bi, nb, nc, nk = ctx.bf, ctx.bi, ctx.nb, ctx.nc, ctx.nk
    params_f = ctx.params_f
    dt = params_f[PF_DT]
    ctx.substeps = turning_substeps(bf, bi, ctx.sf, ctx.si, nb, dt, ctx.params_i[PI_SUBSTEPS],
                                    ctx.params_i[PI_TURN_SUBSTEPS])
    ctx.h = dt / ctx.substeps
    _rescale_warm_start(ctx)
    ctx.iterations = 0
    if tier == FULL:
        joint_totals = ctx.joint_totals
        for c in range(nk):
            joint_totals[c] = 0.0
        clear_joint_sums(ctx.kf, ctx.ki, nk)
    for i in range(nb):
        for k in range(3):
            bf[i, POS0 + k] = bf[i, POS + k]
            bf[i, DTHETA + k] = 0.0
    # Without contacts and rods/cables the solver has nothing to do: its body rows are not even filled.
    ctx.constrained = nc > 0 or nk > 0
    ctx.at_rest = not ctx.constrained and _nothing_moves(bf, bi, nb)
    sb = ctx.solver_bodies
    if ctx.constrained:
        prepare_solver_bodies(bf, bi, nb, sb)
    # Many contacts are solved in coloured bundles, LANES at a time, in regions on several threads
    # (dynamics/contact_regions.py); the bundles' overflow and fewer contacts go through the scalar pass.
    # (The context has bundle tables once the contact table has grown past its first rows, sized for the
    # world's threads: pipeline/context.py.)
    wide_i = ctx.wide_i
    bottom_up = ctx.params_i[PI_SOLVE_ORDER] == BOTTOM_UP
    bundled = False
    if tier == FULL:
        bundled = (may_bundle and not bottom_up and nc >= MIN_BUNDLED_CONTACTS
                   and bundle_capacity(nc, 2) * BUNDLE_ROWS * LANES <= wide_i.shape[0])
    threads = 1
    if bundled:
        threads = ctx.params_i[PI_THREADS]
        if bundle_capacity(nc, threads + 1) * BUNDLE_ROWS * LANES > wide_i.shape[0]:
            threads = 1
    ctx.bundled = bundled
    regions = 1
    bundles = 0
    if nc > 0:
        cf, ci, order = ctx.cf, ctx.ci, ctx.contact_order
        prepare_contacts(bf, cf, ci, nc, sb, params_f[PF_SLIDE_SPEED])
        if tier == FULL:
            regions = order_contacts(bf, bi, ci, nc, nb, threads, ctx.slab, order, ctx.region_starts)
            if bundled:
                wide_f = ctx.wide_f
                bundles = bundle_regions(cf, ci, order, ctx.region_starts, regions, sb, ctx.colour_used,
                                         ctx.colour_of, ctx.colour_fill, wide_f, wide_i,
                                         ctx.part_bundles, ctx.overflow, ctx.part_overflow)
                load_bundle_bodies(wide_f, wide_i, bundles, sb, True)
        else:
            regions = order_contacts(bf, bi, ci, nc, nb, 1, ctx.slab, order, ctx.region_starts)
    ctx.regions = regions
    ctx.bundles = bundles
    adaptive = ctx.params_i[PI_ADAPTIVE] == 1
    depth = 0
    if (adaptive or bottom_up) and nc > 0:
        depth = support_depth(bi, ctx.ci, nc, nb, ctx.support_level, ctx.support_start, ctx.support_adjacent,
                              ctx.support_queue)
        if bottom_up:
            order_bottom_up(bi, ctx.ci, nc, ctx.support_level, depth, ctx.support_start, ctx.contact_order)
    ctx.iteration_cap = iteration_cap(ctx.params_i[PI_ITERATIONS], adaptive, depth)
    ctx.n_overflow = ctx.part_overflow[regions + 1] if bundled else 0
    # contacts on bodies whose world inertia turns get their effective masses again after each position
    # update; contacts of a heavy body on a light one get passes with the light one held
    ctx.turning = nc > 0 and may_turn and has_turning_contacts(ctx.ci, nc, sb)
    ctx.n_supported = 0
    ctx.n_static = 0
    if nc > 0 and shock:
        ctx.n_supported = heavy_on_light(ctx.cf, ctx.ci, nc, sb, params_f[PF_GRAVITY:PF_GRAVITY + 3], ctx.light,
                                         ctx.heavy, ctx.supported)
        ctx.n_static = list_static_contacts(ctx.ci, nc, sb, ctx.static_contacts)
    soft = ctx.soft
    soft_coefficients(params_f[PF_CONTACT_HERTZ], params_f[PF_CONTACT_ZETA], ctx.h, soft[0])
    soft_coefficients(params_f[PF_JOINT_HERTZ], params_f[PF_JOINT_ZETA], ctx.h, soft[1])
    # (the joints' frequency is the whole step's sub-step rate's: an interval cut short at a time of impact
    # keeps it, as the other soft constraints keep theirs; at the interval's own rate, a hinged chain's bias
    # velocities in a 40 us interval were metres per second, and the relax pass left part of them)
    soft_coefficients(RIGID_JOINT_RATE * ctx.params_i[PI_SUBSTEPS] / params_f[PF_STEP_DT], params_f[PF_JOINT_ZETA],
                      ctx.h, soft[2])
    ctx.n_tree = 0
    ctx.tree_factored = False
    ctx.trees_alone = False
    if tier == FULL:
        if nk > 0:
            clear_spring_forces(ctx.kf, ctx.ki, nk)
            classify_springs(bf, ctx.kf, ctx.ki, nk, sb, ctx.h, ctx.implicit, ctx.vecs)
            ctx.n_tree, ctx.trees_alone = build_joint_trees(ctx.ki, nk, sb, ctx.nb, ctx.tree_order, ctx.tree_i,
                                                            ctx.tree_start, ctx.tree_joints, ctx.tree_scratch)
    lap(ctx, ST_PREPARE)


@njit
def stage_prepare(ctx, may_bundle, may_turn, shock):
    """Stage "prepare" (:func:`_prepare`)."""
    _prepare(ctx, FULL, may_bundle, may_turn, shock)


@njit
def stage_prepare_lean(ctx):
    """Stage "prepare" of a lean step (sequential impulses: no bundles, turning and shock passes on)."""
    _prepare(ctx, LEAN, False, True, True)


# --- sub-step stages -----------------------------------------------------------------------------------------
@njit_inline
def _integrate_velocities(ctx, tier, penalty):
    """Stage "integrate velocities": all forces over the sub-step by the chosen integrator (with the penalty
    scheme's contact springs added to the user's forces for its duration, when ``penalty``).  A lean step
    integrates by semi-implicit Euler, with no springs (its world has none)."""
    bf, bi, nb = ctx.bf, ctx.bi, ctx.nb
    params_f, params_i = ctx.params_f, ctx.params_i
    h = ctx.h
    sb, user_forces = ctx.solver_bodies, ctx.user_forces
    gravity = params_f[PF_GRAVITY:PF_GRAVITY + 3]
    if tier == FULL:
        if penalty:
            add_penalty_forces(bf, ctx.cf, ctx.ci, ctx.nc, sb, nb, h, params_f[PF_PENALTY_HERTZ], user_forces,
                               params_f[PF_RESTITUTION_SPEED])
        integrate_velocities(params_i[PI_INTEGRATOR], bf, bi, ctx.kf, ctx.ki, nb, ctx.nk, gravity, ctx.forces,
                             ctx.torques, h, ctx.ws[W_PREV_DT], 1.0 / ctx.substeps, ctx.implicit, ctx.vecs)
        if penalty:
            restore_user_forces(bf, nb, user_forces)
    else:
        integrate_velocities(SEMI_IMPLICIT_EULER, bf, bi, ctx.kf, ctx.ki, nb, 0, gravity, ctx.forces,
                             ctx.torques, h, ctx.ws[W_PREV_DT], 1.0 / ctx.substeps, ctx.implicit, ctx.vecs)
    if ctx.constrained:
        prepare_solver_bodies(bf, bi, nb, sb)
    lap(ctx, ST_INTEGRATE_VELOCITIES)


@njit
def stage_integrate_velocities(ctx, penalty):
    """Stage "integrate velocities" (:func:`_integrate_velocities`)."""
    _integrate_velocities(ctx, FULL, penalty)


@njit
def stage_integrate_velocities_lean(ctx):
    """Stage "integrate velocities" of a lean step."""
    _integrate_velocities(ctx, LEAN, False)


@njit_inline
def _warm_start_joints(ctx):
    """The joints' impulses of the last sub-step again, at rows filled at the sub-step's poses; the joint trees'
    factors where the step has none yet.  Later sub-steps solve with the factors of the rows filled after the
    last position update (:func:`_fill_joints_at_new_poses`), which only the pushes have moved since: an
    inverse that close leaves little for the next pass."""
    if ctx.nk > 0:
        warm_start_joints(ctx.bf, ctx.kf, ctx.ki, ctx.nk, ctx.solver_bodies, ctx.implicit, ctx.vecs)
        warm_start_rigid_joints(ctx.bf, ctx.kf, ctx.ki, ctx.nk, ctx.solver_bodies, ctx.joint_cache)
        if not ctx.tree_factored:
            _factor_trees(ctx)


@njit_inline
def _warm_start(ctx, tier):
    """Stage "warm start" (sequential impulses): last sub-step's impulses of joints and contacts again."""
    sb, cf, ci = ctx.solver_bodies, ctx.cf, ctx.ci
    if tier == FULL:
        _warm_start_joints(ctx)
        if ctx.bundled:
            wide_f, wide_i = ctx.wide_f, ctx.wide_i
            load_bundle_bodies(wide_f, wide_i, ctx.bundles, sb, False)
            warm_start_bundles(wide_f, wide_i, ctx.bundles, sb)
            warm_start_listed(cf, ci, ctx.overflow, ctx.n_overflow, sb)
        elif ctx.nc > 0:
            warm_start_contacts(cf, ci, ctx.nc, sb)
    elif ctx.nc > 0:
        warm_start_contacts(cf, ci, ctx.nc, sb)
    lap(ctx, ST_WARM_START)


@njit
def stage_warm_start(ctx):
    """Stage "warm start" (:func:`_warm_start`)."""
    _warm_start(ctx, FULL)


@njit
def stage_warm_start_lean(ctx):
    """Stage "warm start" of a lean step."""
    _warm_start(ctx, LEAN)


@njit_inline
def _push_depth(ctx):
    """Overlap (m) the pushes leave to the velocity passes: for sequential impulses what their solve passes
    open softly (``soft.soft_depth``); none for the LCP, whose rows only stop closing."""
    if ctx.params_i[PI_SOLVER] == LCP:
        return 0.0
    return soft_depth(ctx.soft[0, 0], ctx.params_f[PF_MAX_PUSH])


@njit_inline
def solve_softness(ctx):
    """``(bias_rate, mass_scale, impulse_scale, max_bias)`` of the solve passes (``contact_solver.soft_bias``):
    shallow overlap opened softly at the contacts' bias rate, as deep as the pushes leave to them."""
    rate = ctx.soft[0, 0]
    return rate, ctx.soft[0, 1], ctx.soft[0, 2], rate * _push_depth(ctx)


@njit_inline
def _contact_pass(ctx, tier, pushing, first_pass, softened):
    """One sequential-impulse pass over the contacts in the step's execution variant: on the velocities
    (solve: ``softened``, shallow overlap opened softly; relax: rigid), or, when ``pushing``, on the
    pseudo-velocities of the split impulses (``first_pass``: the sub-step's first); returns the largest
    velocity change (m/s)."""
    sb, cf, ci = ctx.solver_bodies, ctx.cf, ctx.ci
    h = ctx.h
    rate = ctx.soft[0, 0]
    max_push = ctx.params_f[PF_MAX_PUSH]
    soft = solve_softness(ctx) if softened else (0.0, 1.0, 0.0, 0.0)
    if tier == FULL:
        if ctx.bundled:
            return solve_bundle_pass(cf, ci, ctx.wide_f, ctx.wide_i, ctx.part_bundles, ctx.overflow,
                                     ctx.part_overflow, ctx.regions, sb, ctx.push_bodies, ctx.push_impulse, h,
                                     pushing, rate, max_push, first_pass, soft, ctx.wide_change, ctx.region_change)
    if ctx.nc == 0:
        return 0.0
    if pushing:
        return push_contacts(cf, ci, ctx.contact_order, 0, ctx.nc, sb, ctx.push_bodies, ctx.push_impulse, h, rate,
                             max_push, _push_depth(ctx), first_pass)
    return solve_contacts(cf, ci, ctx.contact_order, 0, ctx.nc, sb, h, soft)


@njit_inline
def _joint_pass(ctx, tier, use_bias):
    """One sequential-impulse pass over the rods, cables, implicit springs and joints (none in a lean step);
    returns the largest velocity change (m/s)."""
    if tier == LEAN:
        return 0.0
    if ctx.nk == 0:
        return 0.0
    bf, kf, ki, nk, sb, h = ctx.bf, ctx.kf, ctx.ki, ctx.nk, ctx.solver_bodies, ctx.h
    max_push = ctx.params_f[PF_MAX_PUSH]
    change = max(solve_joints(bf, kf, ki, nk, sb, h, use_bias, ctx.soft[1], max_push, ctx.implicit, ctx.vecs),
                 solve_rigid_joints(kf, ki, nk, sb, h, use_bias, ctx.soft[2], max_push, ctx.joint_cache,
                                    ctx.tree_i[:, T_MEMBER]))
    if use_bias and ctx.n_tree > 0:      # (rigid rows, whose sub-step's pushes close what is left)
        change = max(change, solve_joint_trees(kf, ki, sb, ctx.tree_order, ctx.n_tree, ctx.tree_i, ctx.tree_f,
                                               ctx.joint_cache, ctx.tree_body, ctx.tree_x))
    return change


@njit_inline
def _supported_pass(ctx, pushing, softened):
    """The heavy-on-light contacts' passes with the light body held (``contact_solver.solve_supported``), on
    the velocities (``softened``: after the solve passes, with their bias; else after a rigid pass) or
    (``pushing``) the pseudo-velocities."""
    if ctx.n_supported > 0:
        solve_supported(ctx.cf, ctx.ci, ctx.supported[:ctx.n_supported], ctx.solver_bodies, ctx.push_bodies,
                        ctx.h, pushing, ctx.soft[0, 0] if pushing or softened else 0.0, ctx.params_f[PF_MAX_PUSH],
                        _push_depth(ctx), ctx.params_f[PF_GRAVITY:PF_GRAVITY + 3])


#: most push passes that include the joints (later ones, up to ``iterations``, push the contacts alone): the
#: contacts' passes follow the joints' correction within them, and a bridge of 30 hinged planks under a
#: ball, with 30 passes of both, fed the ball energy (the joints' pushes raised the planks into it faster
#: than the contacts' took it out again)
JOINT_PUSH_PASSES = 4


@njit_inline
def _push_pass(ctx, tier, contacts, first_pass, joints, trees):
    """One push pass over the contacts (when ``contacts``), (when ``joints``) the joints' own rows, and (when
    ``trees``) the joint trees; returns the largest change."""
    change = _contact_pass(ctx, tier, True, first_pass, False) if contacts else 0.0
    if tier == FULL:
        if joints and ctx.nk > 0:
            sb, pb, h, max_push = ctx.solver_bodies, ctx.push_bodies, ctx.h, ctx.params_f[PF_MAX_PUSH]
            change = max(change, push_rigid_joints(ctx.kf, ctx.ki, ctx.nk, sb, pb, h, max_push, ctx.joint_cache,
                                                   ctx.tree_i[:, T_MEMBER]))
        if trees and ctx.n_tree > 0:
            change = max(change, _push_trees(ctx))
    return change


@njit_inline
def _push_trees(ctx):
    """The joint trees' push (``joint_tree.push_joint_trees``, exact in one pass); returns the largest change."""
    return push_joint_trees(ctx.ki, ctx.solver_bodies, ctx.push_bodies, ctx.h, ctx.params_f[PF_MAX_PUSH],
                            ctx.tree_order, ctx.n_tree, ctx.tree_i, ctx.tree_f, ctx.joint_cache, ctx.tree_body,
                            ctx.tree_x)


@njit_inline
def _pushes_nothing(ctx, tier):
    """True if the first push pass is known to push nothing without running it: only bundled contacts (no joints,
    no overflow), none overlapping deeper than the solve passes open softly.  From zero pseudo-velocities a lane's
    push is ``max(m_n target, 0)``, and its target is positive only for an overlap deeper than that
    (``contact_bundles.push_bundles``); the scan costs a few loads per bundle, the pass a solve pass's work."""
    if tier != FULL or not ctx.bundled or ctx.n_overflow > 0 or ctx.nk > 0:
        return False
    rate = ctx.soft[0, 0]
    return rate <= 0.0 or deepest_overlap(ctx.wide_f, ctx.bundles) <= soft_depth(rate, ctx.params_f[PF_MAX_PUSH])


@njit_inline
def _push_out(ctx, tier, contacts):
    """The position correction by split impulses (``contact_solver``) of the contacts (when ``contacts``)
    and the joints (``joint_rows.push_rigid_joints``): push passes on the pseudo-velocities, from zero,
    until none changes by more than the tolerance or ``iterations`` passes are done.  The joint trees, whose
    push is exact in one pass (``joint_tree.push_joint_trees``), take part in the first pass only and are
    pushed once more after the last (sixteen ragdolls: the relax stage 27 % cheaper than with the trees in
    every joint pass, the joints' widest gap the same).  Then the contacts' heavy-on-light pushes, the
    static world's contacts last (no push into it), and every body moved by its pseudo-velocity (capped at
    ``max_push_speed``), which is then forgotten.  Needs the solver bodies of the poses just integrated.  A
    first pass that pushes nothing (no overlap deeper than the velocity passes take, no joint apart, the usual
    case) leaves every pseudo-velocity zero, and so would the rest: then it is the only one, and with bundled
    contacts alone it is not even run (:func:`_pushes_nothing`)."""
    contacts = contacts and ctx.nc > 0
    if not contacts and ctx.nk == 0:
        return
    if contacts and _pushes_nothing(ctx, tier):
        return
    clear_push(ctx.push_bodies, ctx.nb)
    change = _push_pass(ctx, tier, contacts, True, True, True)
    if change == 0.0:
        return
    if ctx.trees_alone and not contacts:      # (the trees' pass was exact)
        change = 0.0
    tolerance = ctx.params_f[PF_TOLERANCE]
    passes = 1
    while change >= stop_change(passes, ctx.params_i[PI_ITERATIONS], tolerance) and passes < ctx.iteration_cap:
        change = _push_pass(ctx, tier, contacts, False, passes < JOINT_PUSH_PASSES, False)
        passes += 1
    if passes > 1 and tier == FULL and ctx.n_tree > 0:      # (the trees exact again after the others' pushes)
        _push_trees(ctx)
    if contacts:
        _supported_pass(ctx, True, False)
        if ctx.n_static > 0:
            push_static(ctx.cf, ctx.ci, ctx.static_contacts[:ctx.n_static], ctx.solver_bodies, ctx.push_bodies,
                        ctx.h, ctx.soft[0, 0], ctx.params_f[PF_MAX_PUSH], _push_depth(ctx))
    apply_push(ctx.bf, ctx.bi, ctx.nb, ctx.push_bodies, ctx.h, ctx.params_f[PF_MAX_PUSH])


@njit_inline
def _solve(ctx, tier, contacts):
    """Stage "solve" (sequential impulses): passes over the joints and (when ``contacts``) the contacts,
    until no velocity changes by more than the tolerance or ``iterations`` passes are done; one pass when
    the joint trees are all there is to solve (it solves them, to within how far the pushes have moved the
    poses since the trees were factored)."""
    tolerance = ctx.params_f[PF_TOLERANCE]
    base = ctx.params_i[PI_ITERATIONS]
    for k in range(ctx.iteration_cap):
        ctx.iterations += 1
        change = _joint_pass(ctx, tier, True)
        if contacts:
            change = max(change, _contact_pass(ctx, tier, False, False, True))
        if change < stop_change(k, base, tolerance) or (ctx.trees_alone and ctx.nc == 0):
            break
    if contacts:
        _supported_pass(ctx, False, True)
    if ctx.constrained:
        store_velocities(ctx.bf, ctx.bi, ctx.nb, ctx.solver_bodies)
    lap(ctx, ST_SOLVE)


@njit_calls_parallel
def stage_solve(ctx, contacts):
    """Stage "solve" (:func:`_solve`)."""
    _solve(ctx, FULL, contacts)


@njit
def stage_solve_lean(ctx):
    """Stage "solve" of a lean step (no joints, one scalar pass: nothing runs on threads, so it is cached)."""
    _solve(ctx, LEAN, True)


@njit_inline
def _lcp_pass(ctx, use_bias):
    """The LCP scheme: all contact and joint rows of the sub-step solved as one assembled LCP (with the
    position bias, or without it to relax); returns the projected Gauss-Seidel sweeps used."""
    params_f, params_i, soft = ctx.params_f, ctx.params_i, ctx.soft
    return solve_lcp(ctx.bf, ctx.cf, ctx.ci, ctx.nc, ctx.kf, ctx.ki, ctx.nk,
                     ctx.solver_bodies, ctx.nb, ctx.h, use_bias, soft[1], soft[2], params_f[PF_MAX_PUSH], ctx.implicit,
                     params_i[PI_LCP_SWEEPS], params_f[PF_LCP_SOR], params_f[PF_TOLERANCE])


@njit
def stage_solve_lcp(ctx):
    """Stage "solve" of the LCP scheme: joints' and contacts' warm start on the solver bodies, then the
    assembled LCP, which works on the body table; then the heavy-on-light passes on the solver bodies."""
    if ctx.constrained:
        _warm_start_joints(ctx)
        bf, bi, nb, sb = ctx.bf, ctx.bi, ctx.nb, ctx.solver_bodies
        warm_start_contacts(ctx.cf, ctx.ci, ctx.nc, sb)
        store_velocities(bf, bi, nb, sb)
        ctx.iterations += _lcp_pass(ctx, True)
        if ctx.n_supported > 0:
            prepare_solver_bodies(bf, bi, nb, sb)
            _supported_pass(ctx, False, False)
            store_velocities(bf, bi, nb, sb)
    lap(ctx, ST_SOLVE)


@njit_inline
def _integrate_positions(ctx, tier):
    """Stage "integrate positions": poses from velocities by the chosen integrator (semi-implicit Euler in a
    lean step), and the rotation since the step began (for the solver's separations)."""
    bf, bi, nb, h = ctx.bf, ctx.bi, ctx.nb, ctx.h
    if tier == FULL:
        integrate_positions(ctx.params_i[PI_INTEGRATOR], bf, bi, nb, h)
    else:
        integrate_positions(SEMI_IMPLICIT_EULER, bf, bi, nb, h)
    for i in range(nb):
        for k in range(3):
            bf[i, DTHETA + k] += bf[i, OMEGA + k] * h
    if ctx.constrained:
        sb = ctx.solver_bodies
        prepare_solver_bodies(bf, bi, nb, sb)
        if ctx.turning:     # (the contact table's too when bundled: the overflow and restitution read it)
            refresh_turning_masses(ctx.cf, ctx.ci, None, ctx.nc, sb)
            if tier == FULL:
                if ctx.bundled:
                    refresh_bundle_masses(ctx.wide_f, ctx.wide_i, ctx.bundles, sb)
    lap(ctx, ST_INTEGRATE_POSITIONS)


@njit
def stage_integrate_positions(ctx):
    """Stage "integrate positions" (:func:`_integrate_positions`)."""
    _integrate_positions(ctx, FULL)


@njit
def stage_integrate_positions_lean(ctx):
    """Stage "integrate positions" of a lean step."""
    _integrate_positions(ctx, LEAN)


@njit_inline
def _fill_joints_at_new_poses(ctx):
    """The joints' rows at the poses just integrated (``joint_rows.fill_joint_rows``) and their trees'
    factors (``joint_tree.factor_joint_trees``), for the relax and push passes."""
    fill_joint_rows(ctx.bf, ctx.kf, ctx.ki, ctx.nk, ctx.solver_bodies, ctx.joint_cache)
    _factor_trees(ctx)


@njit_inline
def _factor_trees(ctx):
    """The joint trees' factors (``joint_tree.factor_joint_trees``) from the rows just filled."""
    if ctx.n_tree > 0:
        factor_joint_trees(ctx.solver_bodies, ctx.tree_order, ctx.n_tree, ctx.tree_i, ctx.tree_f, ctx.joint_cache,
                           ctx.tree_body, ctx.tree_work)
    ctx.tree_factored = True


@njit_inline
def _relax(ctx, tier, contacts):
    """Stage "relax" (sequential impulses): one pass over the joints without position bias, so that their
    correction leaves no velocity behind, and (when ``contacts``) one rigid pass over the contacts, which
    stops what the soft solve passes let close; then the contacts' overlap pushed out by split impulses,
    which move the poses and leave the velocities alone."""
    if tier == FULL:
        if ctx.nk > 0:
            _fill_joints_at_new_poses(ctx)
            _joint_pass(ctx, tier, False)
    if contacts and ctx.nc > 0:
        if tier == FULL:
            if ctx.bundled:      # (the bundles' masses and separations, from the poses just integrated)
                load_bundle_bodies(ctx.wide_f, ctx.wide_i, ctx.bundles, ctx.solver_bodies, False)
        _contact_pass(ctx, tier, False, False, False)
        _supported_pass(ctx, False, False)
    if ctx.constrained:
        store_velocities(ctx.bf, ctx.bi, ctx.nb, ctx.solver_bodies)
    _push_out(ctx, tier, contacts)
    lap(ctx, ST_RELAX)


@njit_calls_parallel
def stage_relax(ctx, contacts):
    """Stage "relax" (:func:`_relax`)."""
    _relax(ctx, FULL, contacts)


@njit
def stage_relax_lean(ctx):
    """Stage "relax" of a lean step (no joints, one scalar pass; cached)."""
    _relax(ctx, LEAN, True)


@njit_calls_parallel
def stage_relax_lcp(ctx):
    """Stage "relax" of the LCP scheme: the assembled LCP without position bias (in steps with rods, cables or
    implicit springs, whose correction it takes out of the velocities); then the contacts' overlap pushed
    out by the split impulses of the sequential-impulse solver."""
    if ctx.nk > 0:
        _lcp_pass(ctx, False)
        _fill_joints_at_new_poses(ctx)     # (for the push passes)
    _push_out(ctx, FULL, True)
    lap(ctx, ST_RELAX)


@njit_inline
def _sum_impulses(ctx, tier):
    """Stage "sum impulses": the sub-step's impulses of contacts and joints added to the step's totals."""
    cf = ctx.cf
    if tier == FULL:
        if ctx.bundled:
            accumulate_bundles(ctx.wide_f, ctx.bundles)
            accumulate_listed(cf, ctx.overflow, ctx.n_overflow)
        elif ctx.nc > 0:
            accumulate_applied(cf, ctx.ci, ctx.nc)
        kf, joint_totals = ctx.kf, ctx.joint_totals
        for c in range(ctx.nk):
            joint_totals[c] += kf[c, K_IMPULSE]
    elif ctx.nc > 0:
        accumulate_applied(cf, ctx.ci, ctx.nc)
    ctx.ws[W_PREV_DT] = ctx.h
    lap(ctx, ST_SUM_IMPULSES)


@njit
def stage_sum_impulses(ctx):
    """Stage "sum impulses" (:func:`_sum_impulses`)."""
    _sum_impulses(ctx, FULL)


@njit
def stage_sum_impulses_lean(ctx):
    """Stage "sum impulses" of a lean step."""
    _sum_impulses(ctx, LEAN)


@njit_inline
def rest_substeps(ctx):
    """The sub-steps of a world at rest (``ctx.at_rest``, stage prepare: no contact or constraint to solve and
    no body that moves), skipped: they would integrate, warm-start, solve and relax nothing.  What they would
    leave behind is the sub-step length, for the next step's warm start (as :func:`_sum_impulses` does)."""
    if ctx.at_rest:
        ctx.ws[W_PREV_DT] = ctx.h


# --- end of step -----------------------------------------------------------------------------------------------
@njit_inline
def _restitution(ctx, tier, on_body_table):
    """Stage "restitution": the bundles' impulses back to the contact table, then closing contacts bounce.
    ``on_body_table``: the scheme's last pass worked on the body table (LCP), so the solver bodies are
    loaded from it first."""
    bf, bi, nb, nc = ctx.bf, ctx.bi, ctx.nb, ctx.nc
    cf, ci, sb = ctx.cf, ctx.ci, ctx.solver_bodies
    if tier == FULL:
        if ctx.bundled:
            store_bundles(ctx.wide_f, ctx.wide_i, ctx.bundles, cf)
    if nc > 0:
        if on_body_table:
            prepare_solver_bodies(bf, bi, nb, sb)
        apply_restitution(cf, ci, nc, sb, ctx.params_f[PF_RESTITUTION_SPEED])
        store_velocities(bf, bi, nb, sb)
    lap(ctx, ST_RESTITUTION)


@njit
def stage_restitution(ctx, on_body_table):
    """Stage "restitution" (:func:`_restitution`)."""
    _restitution(ctx, FULL, on_body_table)


@njit
def stage_restitution_lean(ctx):
    """Stage "restitution" of a lean step."""
    _restitution(ctx, LEAN, False)


@njit_inline
def _store_impulses(ctx, tier):
    """Stage "store impulses": each contact's friction state for the next step's warm start (a contact at
    the cone whose points slide, slides); the joints' forces over the step."""
    if ctx.nc > 0:
        store_friction_state(ctx.bf, ctx.cf, ctx.ci, ctx.nc, ctx.params_f[PF_SLIDE_SPEED])
    if tier == FULL:
        if ctx.nk > 0:
            record_joint_forces(ctx.bf, ctx.kf, ctx.ki, ctx.nk, ctx.params_f[PF_DT],
                                ctx.joint_totals, ctx.implicit, ctx.vecs)
            record_rigid_joint_forces(ctx.bf, ctx.bi, ctx.kf, ctx.ki, ctx.nk, ctx.params_f[PF_DT])
    lap(ctx, ST_STORE_IMPULSES)


@njit
def stage_store_impulses(ctx):
    """Stage "store impulses" (:func:`_store_impulses`)."""
    _store_impulses(ctx, FULL)


@njit
def stage_store_impulses_lean(ctx):
    """Stage "store impulses" of a lean step."""
    _store_impulses(ctx, LEAN)


@njit
def stage_break_constraints(ctx):
    """Stage "break constraints": springs, rods and cables over their breaking force snap."""
    if ctx.nk > 0:
        break_overloaded(ctx.kf, ctx.ki, ctx.nk)
    lap(ctx, ST_BREAK_CONSTRAINTS)


@njit
def stage_islands_and_sleep(ctx):
    """Stage "islands and sleep": islands, rest timers, resting islands asleep; the clock advances and the
    force accumulators are cleared."""
    bf, bi, nb = ctx.bf, ctx.bi, ctx.nb
    params_f = ctx.params_f
    update_sleep(bf, bi, nb, ctx.cf, ctx.ci, ctx.nc, ctx.ki, ctx.nk, params_f[PF_DT],
                 params_f[PF_SLEEP_LINEAR], params_f[PF_SLEEP_ANGULAR], params_f[PF_TIME_TO_SLEEP],
                 ctx.parent, ctx.least_rest)
    ctx.ws[W_TIME] += params_f[PF_DT]
    for i in range(nb):
        for k in range(3):
            bf[i, FORCE + k] = 0.0
            bf[i, TORQUE + k] = 0.0
    lap(ctx, ST_ISLANDS_AND_SLEEP)


@njit
def finish_step(ctx):
    """The step's counts into ``stats``, and this step's contacts become the next step's cache (the caller
    swaps the context's two contact tables: :func:`swap_contact_tables`; not when the step kept the cache
    as it stood, ``ctx.kept``)."""
    stats = ctx.stats
    stats[STAT_ITERATIONS] = ctx.iterations
    if ctx.params_i[PI_PROFILE] != 0:
        stats[STAT_PROFILED_STEPS] += 1
        stats[STAT_SUM_PAIRS] += ctx.n_pairs
        stats[STAT_SUM_CONTACTS] += ctx.nc
        stats[STAT_SUM_ITERATIONS] += ctx.iterations
    stats[STAT_PREVIOUS] = stats[STAT_CACHED]
    stats[STAT_KEPT] = ctx.kept
    if not ctx.kept:
        stats[STAT_CACHED] = ctx.nc + ctx.n_resting
        stats[STAT_CACHE_SIDE] = 1 - stats[STAT_CACHE_SIDE]
    return OK


@njit_inline
def swap_contact_tables(record):
    """After a completed step: the contact table the step filled becomes the cache, and the cache the
    table the next step fills (the record's own references swap; ``stats`` already says which is which)."""
    record.cf, record.pcf = record.pcf, record.cf
    record.ci, record.pci = record.pci, record.ci


# --- the steps of the three collision-handling schemes ----------------------------------------------------------
@njit_inline
def step_sequential_impulse(ctx, coverage):
    """A step with contacts and joints solved by sequential impulses (the default scheme)."""
    start_clock(ctx)
    status = collide(ctx, coverage, FULL)
    if status != OK:
        return status
    stage_match_and_wake(ctx)
    stage_prepare(ctx, may_bundle=True, may_turn=True, shock=True)
    for _ in range(0 if ctx.at_rest else ctx.substeps):
        stage_integrate_velocities(ctx, penalty=False)
        stage_warm_start(ctx)
        stage_solve(ctx, contacts=True)
        stage_integrate_positions(ctx)
        stage_relax(ctx, contacts=True)
        stage_sum_impulses(ctx)
    rest_substeps(ctx)
    stage_restitution(ctx, on_body_table=False)
    stage_store_impulses(ctx)
    stage_break_constraints(ctx)
    stage_islands_and_sleep(ctx)
    return finish_step(ctx)


@njit_inline
def step_lean(ctx, coverage):
    """The sequential-impulse step of a lean world (:func:`scene_tier`): the same stages, each compiled
    without what such a world cannot meet (joints and springs, coloured bundles, the other broad phases
    and integrators); its results are those of :func:`step_sequential_impulse`, bit for bit."""
    start_clock(ctx)
    status = collide(ctx, coverage, LEAN)
    if status != OK:
        return status
    stage_match_and_wake(ctx)
    stage_prepare_lean(ctx)
    for _ in range(0 if ctx.at_rest else ctx.substeps):
        stage_integrate_velocities_lean(ctx)
        stage_warm_start_lean(ctx)
        stage_solve_lean(ctx)
        stage_integrate_positions_lean(ctx)
        stage_relax_lean(ctx)
        stage_sum_impulses_lean(ctx)
    rest_substeps(ctx)
    stage_restitution_lean(ctx)
    stage_store_impulses_lean(ctx)
    stage_islands_and_sleep(ctx)
    return finish_step(ctx)


@njit_inline
def step_penalty(ctx, coverage):
    """A step with contacts as penalty springs (their damping gives the restitution) and joints by
    sequential impulses."""
    start_clock(ctx)
    status = collide(ctx, coverage, FULL)
    if status != OK:
        return status
    stage_match_and_wake(ctx)
    stage_prepare(ctx, may_bundle=False, may_turn=True, shock=False)
    for _ in range(ctx.substeps):
        stage_integrate_velocities(ctx, penalty=True)
        _warm_start_joints(ctx)
        lap(ctx, ST_WARM_START)
        stage_solve(ctx, contacts=False)
        stage_integrate_positions(ctx)
        stage_relax(ctx, contacts=False)
        stage_sum_impulses(ctx)
    stage_store_impulses(ctx)
    stage_break_constraints(ctx)
    stage_islands_and_sleep(ctx)
    return finish_step(ctx)


@njit_inline
def step_lcp(ctx, coverage):
    """A step with contacts and joints solved as one assembled LCP per sub-step (projected Gauss-Seidel)."""
    start_clock(ctx)
    status = collide(ctx, coverage, FULL)
    if status != OK:
        return status
    stage_match_and_wake(ctx)
    stage_prepare(ctx, may_bundle=False, may_turn=True, shock=True)
    for _ in range(ctx.substeps):
        stage_integrate_velocities(ctx, penalty=False)
        stage_solve_lcp(ctx)
        stage_integrate_positions(ctx)
        stage_relax_lcp(ctx)
        stage_sum_impulses(ctx)
    stage_restitution(ctx, on_body_table=True)
    stage_store_impulses(ctx)
    stage_break_constraints(ctx)
    stage_islands_and_sleep(ctx)
    return finish_step(ctx)


@njit_inline
def _completed(record, status):
    """After a step on ``record``: swap its contact tables if the step completed and did not keep its cache
    as it stood; returns ``status``."""
    if status == OK and not view(record).kept:
        swap_contact_tables(record)
    return status


def _entry(scheme, coverage, tier):
    """The compiled entry of ``scheme``'s step (SEQUENTIAL_IMPULSE, PENALTY, LCP) with the pair tests of
    ``coverage`` (``shape_types.COVER_*``), the lean step (:func:`step_lean`) when ``tier`` is LEAN:
    ``step_at(addresses_at, statuses_at, n)`` runs one step on each of the ``n`` contexts whose addresses
    (``_numba.record.record_address``) are in the int64 array at ``addresses_at``, in order, writes each one's
    status into the int64 array at ``statuses_at`` and returns the first that is not OK (OK if none); the two
    arrays are passed by address (``_numba.record.array_address``).  One world passes one context; a batch
    of worlds that share this step passes theirs and is stepped by one call (``marbellous/batch.py``).
    Addresses rather than contexts and arrays: an int crosses into a kernel ~0.1 us faster than a record,
    ~50 ns faster than an array.  The codes are constants
    of the compiled function, so it holds only its own scheme's stages and its coverage's pair tests
    (Numba caches each such closure apart, keyed by them)."""
    @njit
    def step_at(addresses_at, statuses_at, n):
        addresses = int64_array_at(addresses_at, n)
        statuses = int64_array_at(statuses_at, n)
        first = OK
        for k in range(n):
            record = context_at(addresses[k])
            if tier == LEAN:
                status = step_lean(view(record), coverage)
            elif scheme == SEQUENTIAL_IMPULSE:
                status = step_sequential_impulse(view(record), coverage)
            elif scheme == PENALTY:
                status = step_penalty(view(record), coverage)
            else:
                status = step_lcp(view(record), coverage)
            statuses[k] = _completed(record, status)
            if first == OK:
                first = statuses[k]
        return first
    return step_at


#: the compiled entry of each scheme's step, ``STEPS[scheme][coverage][tier]`` (scheme: SEQUENTIAL_IMPULSE,
#: PENALTY, LCP; coverage: ``shape_types.COVER_*``; tier: LEAN or FULL, a lean step for sequential impulses
#: only, None for the others); each compiles on its first call
STEPS = tuple(tuple((_entry(scheme, coverage, LEAN) if scheme == SEQUENTIAL_IMPULSE else None,
                     _entry(scheme, coverage, FULL))
                    for coverage in range(COVERAGES))
              for scheme in (SEQUENTIAL_IMPULSE, PENALTY, LCP))
assert (SEQUENTIAL_IMPULSE, PENALTY, LCP) == (0, 1, 2) and (LEAN, FULL) == (0, 1)
