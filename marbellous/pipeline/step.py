"""One world step as a list of named stages, compiled as one kernel so its fixed cost stays small.

    collide                 AABBs, broad phase, narrow phase at the poses the step began with
    match                   warm-start contacts from last step's by (bodies, shapes, feature)
    wake                    awake bodies touching sleeping islands wake them
    prepare                 contact basis, effective masses, materials; many contacts are coloured into
                            bundles (dynamics/contact_bundles.py), in regions for several threads
    for each sub-step of h = dt / substeps:
        integrate velocities    forces (gravity, user, springs) -> velocities, by the chosen integrator
        warm start              apply last sub-step's impulses (joints, contacts)
        solve                   sequential impulses with soft position correction, adaptive iterations
                                (solver "lcp": all rows as one assembled LCP; "penalty": contact springs
                                added to the forces before integrating, joints by impulses)
        integrate positions     velocities -> poses, quaternions renormalised
        relax                   sequential impulses without position bias (removes correction velocity)
        store impulses          add the sub-step's impulses to the step's totals
    store bundles           the bundles' impulses back to the contact table
    restitution             closing contacts bounce with -e times their approach speed
    store friction state    contacts at the friction cone slide in the next step
    break constraints       springs, rods and cables over their breaking force snap
    islands and sleep       resting islands fall asleep
    clear force accumulators
"""
import numpy as np

from .._numba.clock import cycle_counter
from .._numba.jit import borrow, njit, njit_inline
from .._numba.wide import LANES
from ..collision.broadphase import find_pairs
from ..dynamics.breaking import break_overloaded
from ..dynamics.contact_bundles import (
    BUNDLE_ROWS,
    MIN_BUNDLED_CONTACTS,
    accumulate_bundles,
    bundle_capacity,
    load_bundle_bodies,
    refresh_bundle_masses,
    store_bundles,
    warm_start_bundles,
)
from ..dynamics.contact_cache import match_contacts
from ..dynamics.contact_regions import bundle_regions, order_contacts, solve_bundle_pass
from ..dynamics.contact_solver import (
    accumulate_applied,
    accumulate_listed,
    apply_restitution,
    has_turning_contacts,
    heavy_on_light,
    prepare_contacts,
    refresh_turning_masses,
    solve_contacts,
    solve_supported,
    store_friction_state,
    warm_start_contacts,
    warm_start_listed,
)
from ..dynamics.forces import is_moving
from ..dynamics.integrators import integrate_positions, integrate_velocities
from ..dynamics.joints import record_joint_forces, solve_joints, warm_start_joints
from ..dynamics.lcp import solve_lcp
from ..dynamics.penalty import add_penalty_forces, restore_user_forces
from ..dynamics.sleep import update_sleep, wake_touched_islands
from ..dynamics.soft import soft_coefficients
from ..dynamics.solver_bodies import prepare_solver_bodies, store_velocities
from ..dynamics.springs import clear_spring_forces
from ..state.layout import (
    C_POINT,
    DTHETA,
    F_ALIVE,
    F_SENSOR,
    FLAGS,
    FORCE,
    GROUP,
    K_IMPULSE,
    MASK,
    OMEGA,
    POS,
    POS0,
    TORQUE,
    W_PREV_DT,
    W_TIME,
)
from .collide import MAX_PAIRS_PER_BODY, limit_pairs_per_body, narrow_phase, update_aabbs
from .tables import record_at

# params_f layout (tunables travel as arguments, never as globals)
P_DT = 0
P_GRAVITY = 1           # 3 values (m/s^2)
P_SPECULATIVE = 4       # speculative distance (m)
P_CONTACT_HERTZ = 5     # stiffness of contact position correction (Hz)
P_CONTACT_ZETA = 6      # its damping ratio
P_JOINT_HERTZ = 7       # stiffness of rod/cable position correction (Hz)
P_JOINT_ZETA = 8        # its damping ratio
P_MAX_PUSH = 9          # fastest overlap removal (m/s)
P_SLIDE_SPEED = 10      # tangential speed above which a new contact slides (m/s)
P_TOLERANCE = 11        # adaptive iterations stop when no velocity changes more than this (m/s)
P_SLEEP_LINEAR = 12     # rest tolerance, linear (m/s)
P_SLEEP_ANGULAR = 13    # rest tolerance, angular (rad/s)
P_TIME_TO_SLEEP = 14    # seconds at rest before an island sleeps (<= 0: never)
P_RESTITUTION_SPEED = 15  # closing speed below which no bounce is applied (m/s)
P_SWEEP = 16            # 1: predict contacts along the step's motion (continuous collision), 0: only at rest
P_PENALTY_HERTZ = 17    # penalty scheme: frequency of the contact springs (Hz)
P_LCP_SOR = 18          # LCP scheme: over-relaxation factor of projected Gauss-Seidel, in (0, 2)
PF_LEN = 19
# params_i layout
P_INTEGRATOR = 0
P_SUBSTEPS = 1
P_ITERATIONS = 2        # most velocity iterations per sub-step
P_BROADPHASE = 3
P_SOLVER = 4            # SEQUENTIAL_IMPULSE, PENALTY or LCP (the order of world.SOLVERS)
P_LCP_SWEEPS = 5        # LCP scheme: most projected Gauss-Seidel sweeps per solve
P_PROFILE = 6           # 1: add each stage's processor cycles to stats (World.profiling)
P_THREADS = 7           # threads of the sequential-impulse contact passes (dynamics/contact_regions.py)
PI_LEN = 8
SEQUENTIAL_IMPULSE = 0
PENALTY = 1
LCP = 2
# stats (int64) written by the step
S_PAIRS = 0             # candidate pairs found by the broad phase
S_CONTACTS = 1          # contact points found by the narrow phase
S_ITERATIONS = 2        # velocity iterations used in the step (all sub-steps)
S_CACHED = 3            # contact points of the last completed step: the rows of the cache table
S_CACHE_SIDE = 4        # which of the world's two contact tables is the cache (0 or 1); flips every step
# with P_PROFILE on, the step also adds to these running totals (the World clears them):
S_PROFILED_STEPS = 5    # steps profiled
S_SUM_PAIRS = 6         # candidate pairs, summed over the profiled steps
S_SUM_CONTACTS = 7      # contact points, summed
S_SUM_ITERATIONS = 8    # velocity iterations, summed
S_CYCLES = 9            # processor cycles spent in each of STAGES, summed (one slot per stage)
#: the step's stages as the profile names them, in step order (sub-step stages summed over sub-steps)
STAGES = ("aabbs", "broad_phase", "narrow_phase", "match_and_wake", "prepare", "integrate_velocities",
          "warm_start", "solve", "integrate_positions", "relax", "restitution_and_joints", "islands_and_sleep")
(ST_AABBS, ST_BROAD, ST_NARROW, ST_MATCH, ST_PREPARE, ST_INTEGRATE_V, ST_WARM, ST_SOLVE, ST_INTEGRATE_X,
 ST_RELAX, ST_RESTITUTION, ST_SLEEP) = range(len(STAGES))
STATS_LEN = S_CYCLES + len(STAGES)
OK = 0
GROW_PAIRS = 1
GROW_CONTACTS = 2


@njit_inline
def _lap(stats, stage, since, on):
    """With profiling ``on``: add the cycles from ``since`` to now to ``stage``'s total; returns now."""
    if not on:
        return 0
    now = cycle_counter()
    stats[S_CYCLES + stage] += now - since
    return now


@njit_inline
def _needs_pairs(bi, nb):
    """True if some body is awake and dynamic, or is a sensor, and another body lives: otherwise every pair
    is resting or static, or there is no pair at all, so the narrow phase would have nothing to test and
    the broad phase is skipped too (a sleeping world, or a lone body, costs next to nothing)."""
    alive = 0
    active = False
    for i in range(nb):
        f = bi[i, FLAGS]
        alive += (f & F_ALIVE) != 0
        active = active or is_moving(bi, i) or ((f & F_ALIVE) != 0 and (f & F_SENSOR) != 0)
        if active and alive > 1:
            return True
    return False


@njit
def step_world(tables):
    """Advance the world in the record ``tables`` (pipeline/tables.py) by ``params_f[P_DT]`` seconds.
    Returns OK, or GROW_PAIRS / GROW_CONTACTS (with the needed sizes in ``stats``) having changed nothing
    but scratch, so the caller can grow the buffers and call again.  On OK the contacts found become the
    cache of the next step: the record's two contact tables swap, and ``stats`` tells the caller which is
    which (S_CACHE_SIDE) and how many rows the cache holds (S_CACHED)."""
    # Every table borrowed (_jit.borrow): the record keeps them alive through the step, and the stages
    # then pass them on without counting references (about a quarter of a small scene's step otherwise).
    bf, bi, sf, si = borrow(tables.bf), borrow(tables.bi), borrow(tables.sf), borrow(tables.si)
    kf, ki, ws = borrow(tables.kf), borrow(tables.ki), borrow(tables.ws)
    geom_f, geom_i = borrow(tables.geom_f), borrow(tables.geom_i)
    aabbs, pairs = borrow(tables.aabbs), borrow(tables.pairs)
    bp_f, bp_i, raw_f, raw_i = borrow(tables.bp_f), borrow(tables.bp_i), borrow(tables.raw_f), borrow(tables.raw_i)
    cf, ci, pcf, pci = borrow(tables.cf), borrow(tables.ci), borrow(tables.pcf), borrow(tables.pci)
    params_f, params_i, stats = borrow(tables.params_f), borrow(tables.params_i), borrow(tables.stats)
    nb, nk, npc = tables.nb, tables.nk, stats[S_CACHED]
    sweep, filters, sb = borrow(tables.sweep), borrow(tables.filters), borrow(tables.solver_bodies)
    F, T, user_forces = borrow(tables.forces), borrow(tables.torques), borrow(tables.user_forces)
    joint_totals, soft, vecs = borrow(tables.joint_totals), borrow(tables.soft), borrow(tables.vecs)
    parent, least_rest, slab = borrow(tables.parent), borrow(tables.least_rest), borrow(tables.slab)
    order, starts = borrow(tables.contact_order), borrow(tables.region_starts)
    region_change = borrow(tables.region_change)
    part_bundles, overflow = borrow(tables.part_bundles), borrow(tables.overflow)
    part_overflow = borrow(tables.part_overflow)
    wide_f, wide_i, wide_change = borrow(tables.wide_f), borrow(tables.wide_i), borrow(tables.wide_change)
    colour_used, colour_of = borrow(tables.colour_used), borrow(tables.colour_of)
    colour_fill = borrow(tables.colour_fill)
    pose_pos, pose_rot = borrow(tables.pose_pos), borrow(tables.pose_rot)
    pose_state, pose_quat = borrow(tables.pose_state), borrow(tables.pose_quat)
    dt = params_f[P_DT]
    substeps = params_i[P_SUBSTEPS]
    h = dt / substeps
    gravity = params_f[P_GRAVITY:P_GRAVITY + 3]
    g_mag = np.sqrt(gravity[0] ** 2 + gravity[1] ** 2 + gravity[2] ** 2)
    prof = params_i[P_PROFILE] != 0
    t = cycle_counter() if prof else 0
    # The per-body and per-contact scratch comes with the record: rows beyond nb / nk are unused.
    contact_soft = soft[0]
    joint_soft = soft[1]
    for c in range(nk):
        joint_totals[c] = 0.0

    # --- collide -----------------------------------------------------------------------------------
    update_aabbs(bf, bi, sf, si, nb, aabbs, sweep, dt * params_f[P_SWEEP], g_mag, params_f[P_SPECULATIVE],
                 pose_pos, pose_rot, pose_quat)
    t = _lap(stats, ST_AABBS, t, prof)
    n_pairs = 0
    if _needs_pairs(bi, nb):
        # the filter columns copied to contiguous rows: the broad phase reads them per pair, and columns of
        # the body table would cost it a cache line per read
        for i in range(nb):
            filters[0, i] = bi[i, FLAGS]
            filters[1, i] = bi[i, GROUP]
            filters[2, i] = bi[i, MASK]
        n_pairs = find_pairs(params_i[P_BROADPHASE], aabbs, filters[0], filters[1], filters[2], nb, bp_f, bp_i,
                             pairs)
    stats[S_PAIRS] = n_pairs
    t = _lap(stats, ST_BROAD, t, prof)
    if n_pairs > pairs.shape[0]:
        return GROW_PAIRS
    if n_pairs > MAX_PAIRS_PER_BODY * nb:      # bodies spawned into one another: bound the contacts
        n_pairs = limit_pairs_per_body(pairs, n_pairs, bi, nb, MAX_PAIRS_PER_BODY)
    nc = narrow_phase(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, params_f[P_SPECULATIVE],
                      raw_f, raw_i, ci, pose_pos, pose_rot, pose_state, pose_quat)
    stats[S_CONTACTS] = nc
    t = _lap(stats, ST_NARROW, t, prof)
    if nc > cf.shape[0]:
        return GROW_CONTACTS
    for c in range(nc):
        for k in range(7):
            cf[c, C_POINT + k] = raw_f[c, k]   # point, normal, depth are the first 7 columns

    # --- match, wake, prepare -------------------------------------------------------------------------
    if nc > 0:
        match_contacts(cf, ci, nc, pcf, pci, npc)
        wake_touched_islands(bi, bf, ci, nc, nb)
    t = _lap(stats, ST_MATCH, t, prof)
    for i in range(nb):
        for k in range(3):
            bf[i, POS0 + k] = bf[i, POS + k]
            bf[i, DTHETA + k] = 0.0
    # Without contacts and rods/cables the solver has nothing to do: its body rows are not even filled.
    constrained = nc > 0 or nk > 0
    if constrained:
        prepare_solver_bodies(bf, bi, nb, sb)
    solver = params_i[P_SOLVER]
    # Sequential impulses solve many contacts in coloured bundles, LANES at a time, in regions on several
    # threads (dynamics/contact_regions.py); the bundles' overflow, fewer contacts and the other schemes
    # go through the scalar pass.  (The record has bundle tables once the contact table has grown past
    # its first rows, and sized for the world's threads: pipeline/tables.py.)
    wide = (solver == SEQUENTIAL_IMPULSE and nc >= MIN_BUNDLED_CONTACTS
            and bundle_capacity(nc, 2) * BUNDLE_ROWS * LANES <= wide_i.shape[0])
    threads = 1
    if wide:
        threads = params_i[P_THREADS]
        if bundle_capacity(nc, threads + 1) * BUNDLE_ROWS * LANES > wide_i.shape[0]:
            threads = 1
    regions = 1
    bundles = 0
    if nc > 0:
        prepare_contacts(bf, cf, ci, nc, sb, params_f[P_SLIDE_SPEED])
        regions = order_contacts(bf, bi, ci, nc, nb, threads, slab, order, starts)
        if wide:
            bundles = bundle_regions(cf, ci, order, starts, regions, sb, colour_used, colour_of, colour_fill,
                                     wide_f, wide_i, part_bundles, overflow, part_overflow)
            load_bundle_bodies(wide_f, wide_i, bundles, sb, True)
    n_over = part_overflow[regions + 1] if wide else 0
    # contacts on bodies whose world inertia turns get their effective masses again after each position update
    turning = nc > 0 and solver != LCP and has_turning_contacts(ci, nc, sb)
    # contacts of a heavy body on a light one get a pass with the light one held (contact_solver.solve_supported)
    supported = None
    if nc > 0 and solver == SEQUENTIAL_IMPULSE and not wide:
        supported = heavy_on_light(bi, cf, ci, nc, sb, gravity)

    # --- sub-steps ---------------------------------------------------------------------------------------
    soft_coefficients(params_f[P_CONTACT_HERTZ], params_f[P_CONTACT_ZETA], h, contact_soft)
    soft_coefficients(params_f[P_JOINT_HERTZ], params_f[P_JOINT_ZETA], h, joint_soft)
    if nk > 0:
        clear_spring_forces(kf, ki, nk)
    iterations_used = 0
    t = _lap(stats, ST_PREPARE, t, prof)
    for _ in range(substeps):
        if solver == PENALTY:
            add_penalty_forces(bf, cf, ci, nc, sb, nb, h, params_f[P_PENALTY_HERTZ], params_f[P_SLIDE_SPEED],
                               user_forces, params_f[P_RESTITUTION_SPEED])
        integrate_velocities(params_i[P_INTEGRATOR], bf, bi, kf, ki, nb, nk, gravity, F, T, h, ws[W_PREV_DT],
                             1.0 / substeps, vecs)
        if solver == PENALTY:
            restore_user_forces(bf, nb, user_forces)
        if constrained:
            prepare_solver_bodies(bf, bi, nb, sb)
        t = _lap(stats, ST_INTEGRATE_V, t, prof)
        # (kernels are only called when they have rows to work on: every call passes its arrays' fields)
        if nk > 0:
            warm_start_joints(bf, kf, ki, nk, sb, vecs)
        if solver == SEQUENTIAL_IMPULSE:
            if wide:
                load_bundle_bodies(wide_f, wide_i, bundles, sb, False)
                warm_start_bundles(wide_f, wide_i, bundles, sb)
                warm_start_listed(cf, ci, overflow, n_over, sb)
            elif nc > 0:
                warm_start_contacts(cf, ci, nc, sb)
            t = _lap(stats, ST_WARM, t, prof)
            for _ in range(params_i[P_ITERATIONS]):
                iterations_used += 1
                change = 0.0
                if nk > 0:
                    change = solve_joints(bf, kf, ki, nk, sb, h, True, joint_soft, vecs)
                if wide:
                    change = max(change, solve_bundle_pass(cf, ci, wide_f, wide_i, part_bundles, overflow,
                                                           part_overflow, regions, sb, h, True, contact_soft,
                                                           params_f[P_MAX_PUSH], wide_change, region_change))
                elif nc > 0:
                    change = max(change, solve_contacts(cf, ci, order, 0, nc, sb, h, True, contact_soft,
                                                        params_f[P_MAX_PUSH]))
                if change < params_f[P_TOLERANCE]:
                    break
            if supported is not None:
                solve_supported(cf, ci, supported, sb, h, True, contact_soft, params_f[P_MAX_PUSH], gravity)
        elif solver == PENALTY:
            for _ in range(params_i[P_ITERATIONS]):
                iterations_used += 1
                if solve_joints(bf, kf, ki, nk, sb, h, True, joint_soft, vecs) < params_f[P_TOLERANCE]:
                    break
        else:
            if constrained:
                warm_start_contacts(cf, ci, nc, sb)
                store_velocities(bf, bi, nb, sb)       # the LCP scheme works on the body table
                iterations_used += solve_lcp(bf, cf, ci, nc, kf, ki, nk, sb, nb, h, True, contact_soft,
                                             joint_soft, params_f[P_MAX_PUSH], params_i[P_LCP_SWEEPS],
                                             params_f[P_LCP_SOR], params_f[P_TOLERANCE])
        if solver != LCP and constrained:
            store_velocities(bf, bi, nb, sb)
        t = _lap(stats, ST_SOLVE, t, prof)
        integrate_positions(params_i[P_INTEGRATOR], bf, bi, nb, h)
        for i in range(nb):
            for k in range(3):
                bf[i, DTHETA + k] += bf[i, OMEGA + k] * h
        if constrained:
            prepare_solver_bodies(bf, bi, nb, sb)
        if turning:     # (the contact table's too when bundled: the overflow and restitution read it)
            refresh_turning_masses(cf, ci, None, nc, sb)
            if wide:
                refresh_bundle_masses(wide_f, wide_i, bundles, sb)
        t = _lap(stats, ST_INTEGRATE_X, t, prof)
        if solver == LCP and constrained:
            solve_lcp(bf, cf, ci, nc, kf, ki, nk, sb, nb, h, False, contact_soft, joint_soft, params_f[P_MAX_PUSH],
                      params_i[P_LCP_SWEEPS], params_f[P_LCP_SOR], params_f[P_TOLERANCE])
        elif solver != LCP:
            if nk > 0:
                solve_joints(bf, kf, ki, nk, sb, h, False, joint_soft, vecs)
            if wide:
                load_bundle_bodies(wide_f, wide_i, bundles, sb, False)
                solve_bundle_pass(cf, ci, wide_f, wide_i, part_bundles, overflow, part_overflow, regions, sb, h,
                                  False, contact_soft, params_f[P_MAX_PUSH], wide_change, region_change)
            elif solver == SEQUENTIAL_IMPULSE and nc > 0:
                solve_contacts(cf, ci, order, 0, nc, sb, h, False, contact_soft, params_f[P_MAX_PUSH])
                if supported is not None:
                    solve_supported(cf, ci, supported, sb, h, False, contact_soft, params_f[P_MAX_PUSH], gravity)
            if constrained:
                store_velocities(bf, bi, nb, sb)
        if wide:
            accumulate_bundles(wide_f, bundles)
            accumulate_listed(cf, overflow, n_over)
        elif nc > 0:
            accumulate_applied(cf, ci, nc)
        for c in range(nk):
            joint_totals[c] += kf[c, K_IMPULSE]
        ws[W_PREV_DT] = h
        t = _lap(stats, ST_RELAX, t, prof)
    stats[S_ITERATIONS] = iterations_used

    # --- end of step ---------------------------------------------------------------------------------------
    if wide:
        store_bundles(wide_f, wide_i, bundles, cf)
    if nc > 0:
        if solver != PENALTY:     # the penalty springs' damping gives the restitution
            if solver == LCP:     # its relax pass worked on the body table
                prepare_solver_bodies(bf, bi, nb, sb)
            apply_restitution(cf, ci, nc, sb, params_f[P_RESTITUTION_SPEED])
            store_velocities(bf, bi, nb, sb)
        store_friction_state(cf, ci, nc)
    if nk > 0:
        record_joint_forces(bf, kf, ki, nk, dt, joint_totals, vecs)
        break_overloaded(kf, ki, nk)
    t = _lap(stats, ST_RESTITUTION, t, prof)
    update_sleep(bf, bi, nb, cf, ci, nc, ki, nk, dt, params_f[P_SLEEP_LINEAR], params_f[P_SLEEP_ANGULAR],
                 params_f[P_TIME_TO_SLEEP], parent, least_rest)
    ws[W_TIME] += dt
    for i in range(nb):
        for k in range(3):
            bf[i, FORCE + k] = 0.0
            bf[i, TORQUE + k] = 0.0
    _lap(stats, ST_SLEEP, t, prof)
    if prof:
        stats[S_PROFILED_STEPS] += 1
        stats[S_SUM_PAIRS] += n_pairs
        stats[S_SUM_CONTACTS] += nc
        stats[S_SUM_ITERATIONS] += iterations_used
    # (the record's own references swap, not the borrowed views)
    tables.cf, tables.pcf = tables.pcf, tables.cf
    tables.ci, tables.pci = tables.pci, tables.ci
    stats[S_CACHED] = nc
    stats[S_CACHE_SIDE] = 1 - stats[S_CACHE_SIDE]
    return OK


@njit
def step_world_at(address):
    """:func:`step_world` on the record at ``address`` (``tables.record_address``): the World's entry,
    which passes an int rather than the record (~0.1 us less per call)."""
    return step_world(record_at(address))
