"""Where a step's time goes: the stages of ``pipeline/step.py`` called one by one from Python, timed.

The step is one compiled kernel, so it cannot be timed from outside stage by stage.  ``profile_step``
runs the same stage kernels in the same order on a world's own arrays (so the world advances exactly as
``World.step`` would: ``check_mirror`` compares the two bit for bit) with a clock around each.  Each
stage call pays a Python-to-Numba dispatch (about 1-3 us), which matters only for tiny scenes.

Run:  python -m bench.profile_stages [--quick]      (prints one row of per-stage ms per scene)
"""
import time

import numpy as np

from marbellous import layout as L
from marbellous.collision.broadphase import find_pairs
from marbellous.dynamics.breaking import break_overloaded
from marbellous.dynamics.contact_cache import match_contacts
from marbellous.dynamics.contact_solver import (accumulate_applied, apply_restitution, prepare_contacts,
                                                solve_contacts, store_friction_state, warm_start_contacts)
from marbellous.dynamics.integrators import integrate_positions, integrate_velocities
from marbellous.dynamics.joints import record_joint_forces, solve_joints, warm_start_joints
from marbellous.dynamics.sleep import update_sleep, wake_touched_islands
from marbellous.dynamics.soft import soft_coefficients
from marbellous.dynamics.solver_bodies import SB_COLS, prepare_solver_bodies
from marbellous.dynamics.springs import clear_spring_forces
from marbellous.pipeline import step as S
from marbellous.pipeline.collide import narrow_phase, update_aabbs

#: stage names in step order (sub-step stages summed over the sub-steps)
STAGES = ("aabbs", "broad", "narrow", "match", "prepare", "integrate_vel", "warm_start", "solve",
          "integrate_pos", "relax", "end_of_step")


def _params(world, dt):
    """The world's kernel parameters for a step of ``dt`` s, as ``World.step`` computes them."""
    world._refresh_params(dt)
    pf, pi = world._params_f, world._params_i
    if pi[S.P_SOLVER] != S.SEQUENTIAL_IMPULSE:
        raise ValueError(f"world: the stage profile follows the sequential-impulse solver, got {world.solver!r}")
    return pf, pi


def profile_step(world, dt, times):
    """Advance ``world`` by ``dt`` s through the stage kernels, adding each stage's seconds to ``times``
    (a dict keyed by ``STAGES``).  Returns the number of contact points."""
    pf, pi = _params(world, dt)
    w = world
    clock = time.perf_counter
    while True:
        bf, bi, sf, si, kf, ki, ws = w._bf, w._bi, w._sf, w._si, w._kf, w._ki, w._ws
        nb, nk = w._nb, w._nk
        h = dt / pi[S.P_SUBSTEPS]
        gravity = pf[S.P_GRAVITY:S.P_GRAVITY + 3]
        t0 = clock()
        sweep = np.empty(nb)
        update_aabbs(bf, bi, sf, si, nb, w._aabbs, sweep, dt * pf[S.P_SWEEP], float(np.linalg.norm(gravity)), pf[S.P_SPECULATIVE])
        t1 = clock()
        n_pairs = find_pairs(pi[S.P_BROADPHASE], w._aabbs, bi[:, L.FLAGS], bi[:, L.GROUP], bi[:, L.MASK], nb,
                             w._bp_f, w._bp_i, w._pairs)
        t2 = clock()
        if n_pairs > w._pairs.shape[0]:
            w._pairs = np.zeros((n_pairs, 2), dtype=np.int64)
            continue
        nc = narrow_phase(bf, bi, sf, si, w._geom_f, w._geom_i, w._pairs, n_pairs, sweep, pf[S.P_SPECULATIVE],
                          w._raw_f, w._raw_i, w._ci)
        t3 = clock()
        if nc > w._cf.shape[0]:
            w._grow_contacts(nc)
            continue
        break
    times["aabbs"] += t1 - t0
    times["broad"] += t2 - t1
    times["narrow"] += t3 - t2
    cf, ci, pcf, pci = w._cf, w._ci, w._pcf, w._pci
    cf[:nc, L.C_POINT:L.C_POINT + 7] = w._raw_f[:nc, :7]
    t0 = clock()
    match_contacts(cf, ci, nc, pcf, pci, w._npc)
    t1 = clock()
    times["match"] += t1 - t0
    wake_touched_islands(bi, bf, ci, nc, nb)
    sb = np.empty((nb, SB_COLS))
    prepare_solver_bodies(bf, bi, nb, sb)
    prepare_contacts(bf, cf, ci, nc, sb, pf[S.P_SLIDE_SPEED])
    bf[:nb, L.POS0:L.POS0 + 3] = bf[:nb, L.POS:L.POS + 3]
    bf[:nb, L.DTHETA:L.DTHETA + 3] = 0.0
    times["prepare"] += clock() - t1
    contact_soft = np.empty(3)
    joint_soft = np.empty(3)
    soft_coefficients(pf[S.P_CONTACT_HERTZ], pf[S.P_CONTACT_ZETA], h, contact_soft)
    soft_coefficients(pf[S.P_JOINT_HERTZ], pf[S.P_JOINT_ZETA], h, joint_soft)
    F = np.empty((nb, 3))
    T = np.empty((nb, 3))
    joint_totals = np.zeros(nk)
    clear_spring_forces(kf, ki, nk)
    for _ in range(pi[S.P_SUBSTEPS]):
        t0 = clock()
        integrate_velocities(pi[S.P_INTEGRATOR], bf, bi, kf, ki, nb, nk, gravity, F, T, h, ws[L.W_PREV_DT],
                             1.0 / pi[S.P_SUBSTEPS])
        t1 = clock()
        prepare_solver_bodies(bf, bi, nb, sb)
        warm_start_joints(bf, kf, ki, nk, sb)
        warm_start_contacts(bf, cf, ci, nc, sb)
        t2 = clock()
        for _ in range(pi[S.P_ITERATIONS]):
            change = solve_joints(bf, kf, ki, nk, sb, h, True, joint_soft)
            change = max(change, solve_contacts(bf, cf, ci, nc, sb, h, True, contact_soft, pf[S.P_MAX_PUSH]))
            if change < pf[S.P_TOLERANCE]:
                break
        t3 = clock()
        integrate_positions(pi[S.P_INTEGRATOR], bf, bi, nb, h)
        bf[:nb, L.DTHETA:L.DTHETA + 3] += bf[:nb, L.OMEGA:L.OMEGA + 3] * h
        t4 = clock()
        prepare_solver_bodies(bf, bi, nb, sb)
        solve_joints(bf, kf, ki, nk, sb, h, False, joint_soft)
        solve_contacts(bf, cf, ci, nc, sb, h, False, contact_soft, pf[S.P_MAX_PUSH])
        accumulate_applied(cf, ci, nc)
        joint_totals += kf[:nk, L.K_IMPULSE]
        ws[L.W_PREV_DT] = h
        t5 = clock()
        times["integrate_vel"] += t1 - t0
        times["warm_start"] += t2 - t1
        times["solve"] += t3 - t2
        times["integrate_pos"] += t4 - t3
        times["relax"] += t5 - t4
    t0 = clock()
    apply_restitution(bf, cf, ci, nc, sb, pf[S.P_RESTITUTION_SPEED])
    store_friction_state(cf, ci, nc)
    record_joint_forces(bf, kf, ki, nk, dt, joint_totals)
    break_overloaded(kf, ki, nk)
    parent = np.empty(nb, dtype=np.int64)
    update_sleep(bf, bi, nb, cf, ci, nc, ki, nk, dt, pf[S.P_SLEEP_LINEAR], pf[S.P_SLEEP_ANGULAR],
                 pf[S.P_TIME_TO_SLEEP], parent)
    ws[L.W_TIME] += dt
    bf[:nb, L.FORCE:L.FORCE + 3] = 0.0
    bf[:nb, L.TORQUE:L.TORQUE + 3] = 0.0
    times["end_of_step"] += clock() - t0
    w._cf, w._pcf = w._pcf, w._cf
    w._ci, w._pci = w._pci, w._ci
    w._npc = nc
    return nc


def profile(world, dt, steps):
    """Median milliseconds per step of each stage over ``steps`` steps of ``world`` (which advances),
    and ``"total"``, the median of the stages' sum.  Medians, not means: the machine is shared and
    a step now and then is preempted."""
    rows = []
    for _ in range(steps):
        times = dict.fromkeys(STAGES, 0.0)
        profile_step(world, dt, times)
        rows.append([times[k] for k in STAGES])
    rows = np.array(rows) * 1e3
    out = dict(zip(STAGES, np.median(rows, axis=0).tolist()))
    out["total"] = float(np.median(rows.sum(axis=1)))
    return out


def check_mirror(build, dt, steps):
    """True if ``steps`` profiled steps leave a world built by ``build()`` bit-identical to ``World.step``."""
    a, _ = build()
    b, _ = build()
    times = dict.fromkeys(STAGES, 0.0)
    for _ in range(steps):
        a.step(dt)
        profile_step(b, dt, times)
    return bool(np.array_equal(a._bf[:a._nb], b._bf[:b._nb]))


def main(argv=None):
    import argparse

    from bench.scenes import DT, SCENES, build_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller scenes, fewer steps")
    ap.add_argument("--scenes", nargs="*", default=None, help="scene names (default: all with physics)")
    args = ap.parse_args(argv)
    names = args.scenes or [s for s in SCENES if SCENES[s].world]
    for name in names:
        spec = SCENES[name]
        world, _ = build_scene(name, quick=args.quick)
        steps = spec.profile_steps(args.quick)
        warm = spec.warmup_steps(args.quick)
        for _ in range(warm):
            world.step(DT)
        profile(world, DT, 2)              # compile every stage kernel once
        row = profile(world, DT, steps)
        print(f"{name:16s} " + "  ".join(f"{k} {v:.4f}" for k, v in row.items()) + "  (ms per step, medians)")


if __name__ == "__main__":
    main()
