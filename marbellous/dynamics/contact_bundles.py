"""Wide sequential impulses: contacts coloured so that no two of one colour share a movable body, then
solved ``LANES`` at a time with wide floats (Box2D v3's graph colouring and wide contact solver, in 3D).

The impulses are those of ``contact_solver.solve_contacts``, term for term and in the same floating-point
order, so a pass over the bundles gives bit for bit what the scalar pass gives visiting the same contacts
in bundle order.  Only the order differs from the scalar solver's: colour by colour.  Sequential impulses
converge for any order, and within one colour the order does not matter at all, since no two contacts
of a colour touch the same movable body.

    colour        first colour unused by both movable bodies (static and sleeping bodies are only read,
                  so any number of a colour's contacts may share them); at most ``MAX_COLOURS``
    bundle        ``LANES`` contacts of one colour; the last bundle of a colour is filled with pad lanes
                  that read an all-zero solver-body row and write a row nothing reads
    overflow      contacts beyond the last colour: solved by the scalar pass after the bundles

Per bundle the table ``wide_f`` holds ``BUNDLE_FIELDS`` blocks of ``LANES`` values (field ``f`` of lane
``l`` at ``bundle * BUNDLE_FIELDS * LANES + f * LANES + l``), and ``wide_i`` holds ``BUNDLE_ROWS`` blocks of
``LANES`` ints: the solver-body rows read for a and b, the rows written for a and b (the sink row for a
body that cannot move), the contact of each lane (-1 for a pad) and two flags of the whole bundle: some
lane's body turns (its world inertia is not isotropic), some lane has rolling or torsional friction (only
such bundles pay for the angular impulse ``lambda_r``).  The solver-body table has two rows
more than the world has body slots: the pad row (second to last) and the sink row (last).

Stages, as the step calls them: ``bundle_contacts`` (once per step, after ``prepare_contacts``),
``load_bundle_bodies`` (after every ``prepare_solver_bodies``: inverse masses and inertias, separations),
``warm_start_bundles``, ``solve_bundles`` (velocity passes), ``push_bundles`` (the split impulses' push passes
on the pseudo-velocities ``pb``), ``accumulate_bundles`` (end of each sub-step), ``store_bundles`` (end of the
step: impulses back to the contact table).
"""
from .._numba.jit import njit, njit_inline
from .._numba.wide import LANES, abs_w, gather_w, load_w, max_w, min_w, scatter_w, splat_w, sqrt_w, store_w, where_gt
from ..state.layout import (BUNDLE_FIELDS, BUNDLE_ROWS, CP_MATCHED, CP_SENSOR, CP_SLIDING, C_ADJ_SEP, C_BODY_A,
                            C_BODY_B, C_FLAGS, C_LAMBDA_N, C_LAMBDA_R, C_LAMBDA_T1, C_LAMBDA_T2, C_MASS_N, C_MASS_T1,
                            C_MASS_T2, C_MAX_N, C_MU_D, C_MU_S, C_NORMAL, C_RA, C_RB, C_ROLL, C_SUM_N, C_SUM_T, C_T1,
                            C_T2, C_TORSION, C_VN0, SB_DP, SB_INV_MASS, SB_ISO, SB_V, WB_ADJ_SEP, WB_INV_I_A,
                            WB_INV_I_B, WB_INV_MASS_A, WB_INV_MASS_B, WB_LAMBDA_N, WB_LAMBDA_R, WB_LAMBDA_T1,
                            WB_LAMBDA_T2, WB_MASS_N, WB_MASS_T1, WB_MASS_T2, WB_LAMBDA_P, WB_MAX_N, WB_MU, WB_NEW,
                            WB_NORMAL, WB_RA, WB_RB, WB_ROLL, WB_SEPARATION, WB_SUM_N, WB_SUM_T, WB_T1, WB_T2,
                            WB_TORSION, WB_VN0, WI_CONTACT, WI_READ_A, WI_READ_B, WI_ROLLING, WI_TURNING, WI_WRITE_A,
                            WI_WRITE_B)

# (gathered as blocks of columns: 1/m then I^-1 (10), v then omega (6), dx then dtheta (6))
from .contact_solver import angular_cofactors, rolling_split
from .solver_bodies import effective_mass_along, lighter, twist

#: most colours; contacts that find none free go to the overflow (one bit per colour in an int64 mask)
MAX_COLOURS = 63
#: fewest contacts for which the step solves in bundles (below, the scalar pass is as fast); the bundle
#: tables come with the step's record once the contact table has grown past its first 64 rows
MIN_BUNDLED_CONTACTS = 64



@njit
def bundle_capacity(contacts, parts):
    """Most bundles ``contacts`` contacts laid out in ``parts`` parts (regions) can need: full bundles plus
    one part-filled bundle per colour of each part."""
    return contacts // LANES + parts * (MAX_COLOURS + 1)


@njit_inline
def _at(bundle, field):
    """Offset of ``field``'s block of lanes of ``bundle`` in ``wide_f``."""
    return (bundle * BUNDLE_FIELDS + field) * LANES


@njit
def bundle_contacts(cf, ci, order, first, last, sb, used, colour_of, colour_fill, wide_f, wide_i, first_bundle,
                    overflow, first_overflow):
    """Stage "prepare", wide part: colour the contacts ``order[first:last]``, lay them out in bundles from
    bundle ``first_bundle`` on, and copy what the passes need from the contact table.  Writes the
    overflow contacts to ``overflow`` from ``first_overflow`` on (in the order given) and returns
    ``(bundles, overflow count)`` written.  Scratch: ``used`` (``sb.shape[0]`` ints, colour masks of the
    bodies), ``colour_of`` (one int per contact), ``colour_fill`` (``MAX_COLOURS + 1`` ints)."""
    pad, sink = sb.shape[0] - 2, sb.shape[0] - 1
    for position in range(first, last):
        used[ci[order[position], C_BODY_A]] = 0
        used[ci[order[position], C_BODY_B]] = 0
    for k in range(MAX_COLOURS + 1):
        colour_fill[k] = 0
    n_over = 0
    for position in range(first, last):
        c = order[position]
        colour = MAX_COLOURS                         # the overflow, unless a colour is free
        if (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            colour = -1                              # sensors are reported, not solved
        else:
            a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
            move_a, move_b = sb[a, SB_ISO] != 0.0, sb[b, SB_ISO] != 0.0
            taken = (used[a] if move_a else 0) | (used[b] if move_b else 0)
            colour = 0
            while colour < MAX_COLOURS and (taken >> colour) & 1:
                colour += 1
            if colour < MAX_COLOURS:
                if move_a:
                    used[a] |= 1 << colour
                if move_b:
                    used[b] |= 1 << colour
        colour_of[c] = colour
        if colour == MAX_COLOURS:
            overflow[first_overflow + n_over] = c
            n_over += 1
        elif colour >= 0:
            colour_fill[colour] += 1
    # each colour's first slot (slots = bundle * LANES + lane), colours in order, bundles padded
    bundles = 0
    for k in range(MAX_COLOURS):
        count = colour_fill[k]
        colour_fill[k] = (first_bundle + bundles) * LANES
        bundles += (count + LANES - 1) // LANES
    for j in range(first_bundle * LANES, (first_bundle + bundles) * LANES):
        bundle, lane = j // LANES, j % LANES
        i0 = bundle * BUNDLE_ROWS * LANES + lane
        wide_i[i0 + WI_READ_A * LANES] = pad
        wide_i[i0 + WI_READ_B * LANES] = pad
        wide_i[i0 + WI_WRITE_A * LANES] = sink
        wide_i[i0 + WI_WRITE_B * LANES] = sink
        wide_i[i0 + WI_CONTACT * LANES] = -1
        wide_i[i0 + WI_TURNING * LANES] = 0
        wide_i[i0 + WI_ROLLING * LANES] = 0
    for position in range(first, last):
        c = order[position]
        colour = colour_of[c]
        if colour < 0 or colour == MAX_COLOURS:
            continue
        j = colour_fill[colour]
        colour_fill[colour] += 1
        bundle, lane = j // LANES, j % LANES
        a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
        i0 = bundle * BUNDLE_ROWS * LANES + lane
        wide_i[i0 + WI_READ_A * LANES] = a
        wide_i[i0 + WI_READ_B * LANES] = b
        wide_i[i0 + WI_WRITE_A * LANES] = a if sb[a, SB_ISO] != 0.0 else sink
        wide_i[i0 + WI_WRITE_B * LANES] = b if sb[b, SB_ISO] != 0.0 else sink
        wide_i[i0 + WI_CONTACT * LANES] = c
        if sb[a, SB_ISO] < 0.0 or sb[b, SB_ISO] < 0.0:    # not isotropic: the whole bundle turns
            for k in range(LANES):
                wide_i[bundle * BUNDLE_ROWS * LANES + WI_TURNING * LANES + k] = 1
        if (cf[c, C_ROLL] > 0.0 or cf[c, C_TORSION] > 0.0 or cf[c, C_LAMBDA_R] != 0.0 or cf[c, C_LAMBDA_R + 1] != 0.0
                or cf[c, C_LAMBDA_R + 2] != 0.0):     # the whole bundle solves and warm-starts lambda_r
            for k in range(LANES):
                wide_i[bundle * BUNDLE_ROWS * LANES + WI_ROLLING * LANES + k] = 1
        for k in range(3):
            wide_f[_at(bundle, WB_NORMAL + k) + lane] = cf[c, C_NORMAL + k]
            wide_f[_at(bundle, WB_LAMBDA_R + k) + lane] = cf[c, C_LAMBDA_R + k]
            wide_f[_at(bundle, WB_RA + k) + lane] = cf[c, C_RA + k]
            wide_f[_at(bundle, WB_RB + k) + lane] = cf[c, C_RB + k]
            wide_f[_at(bundle, WB_T1 + k) + lane] = cf[c, C_T1 + k]
            wide_f[_at(bundle, WB_T2 + k) + lane] = cf[c, C_T2 + k]
        wide_f[_at(bundle, WB_MASS_N) + lane] = cf[c, C_MASS_N]
        wide_f[_at(bundle, WB_MASS_T1) + lane] = cf[c, C_MASS_T1]
        wide_f[_at(bundle, WB_MASS_T2) + lane] = cf[c, C_MASS_T2]
        sliding = (ci[c, C_FLAGS] & CP_SLIDING) != 0
        wide_f[_at(bundle, WB_MU) + lane] = cf[c, C_MU_D] if sliding else cf[c, C_MU_S]
        wide_f[_at(bundle, WB_ROLL) + lane] = cf[c, C_ROLL]
        wide_f[_at(bundle, WB_TORSION) + lane] = cf[c, C_TORSION]
        wide_f[_at(bundle, WB_LAMBDA_N) + lane] = cf[c, C_LAMBDA_N]
        wide_f[_at(bundle, WB_LAMBDA_T1) + lane] = cf[c, C_LAMBDA_T1]
        wide_f[_at(bundle, WB_LAMBDA_T2) + lane] = cf[c, C_LAMBDA_T2]
        wide_f[_at(bundle, WB_MAX_N) + lane] = cf[c, C_MAX_N]
        wide_f[_at(bundle, WB_VN0) + lane] = cf[c, C_VN0]
        wide_f[_at(bundle, WB_NEW) + lane] = 0.0 if (ci[c, C_FLAGS] & CP_MATCHED) != 0 else 1.0
        wide_f[_at(bundle, WB_ADJ_SEP) + lane] = cf[c, C_ADJ_SEP]
        for k in range(4):
            wide_f[_at(bundle, WB_SUM_N + k) + lane] = 0.0
    for j in range(first_bundle * LANES, (first_bundle + bundles) * LANES):   # pad lanes: all zero
        bundle, lane = j // LANES, j % LANES
        if wide_i[bundle * BUNDLE_ROWS * LANES + WI_CONTACT * LANES + lane] < 0:
            for f in range(BUNDLE_FIELDS):
                wide_f[_at(bundle, f) + lane] = 0.0
    return bundles, n_over


@njit_inline
def _gather_u(sb, wide_i, rows, column):
    """The 6-vector ``(v, omega)`` (or, from ``SB_DP``, ``(dx, dtheta)``) of each lane's body."""
    return gather_w(sb, wide_i, rows, column, 6)


@njit_inline
def _scatter_u(sb, wide_i, rows, u):
    """Write each lane's ``(v, omega)`` to its body's row."""
    scatter_w(sb, wide_i, rows, SB_V, u)


@njit_inline
def _vector(wide_f, at):
    """The 3-vector field whose block starts at ``at``, as three FloatW."""
    return load_w(wide_f, at), load_w(wide_f, at + LANES), load_w(wide_f, at + 2 * LANES)


@njit_inline
def _relative_velocity(ua, ra, ub, rb):
    """``(v_b + w_b x rb) - (v_a + w_a x ra)``, lane by lane, rounded as ``relative_velocity_at``."""
    return ((ub[0] + ub[4] * rb[2] - ub[5] * rb[1]) - (ua[0] + ua[4] * ra[2] - ua[5] * ra[1]),
            (ub[1] + ub[5] * rb[0] - ub[3] * rb[2]) - (ua[1] + ua[5] * ra[0] - ua[3] * ra[2]),
            (ub[2] + ub[3] * rb[1] - ub[4] * rb[0]) - (ua[2] + ua[3] * ra[1] - ua[4] * ra[0]))


@njit_inline
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit_inline
def _push(u, inv_mass, inv_i, r, p, sign, turning):
    """``u`` after the impulse ``sign p`` at offset ``r``:  v += sign p / m,  omega += sign I^-1 (r x p),
    rounded as ``solver_bodies.push``.  Unless ``turning``, every lane's I^-1 is ``inv_i[0] E``."""
    cx = r[1] * p[2] - r[2] * p[1]
    cy = r[2] * p[0] - r[0] * p[2]
    cz = r[0] * p[1] - r[1] * p[0]
    im = inv_mass * sign
    v = (u[0] + im * p[0], u[1] + im * p[1], u[2] + im * p[2])
    if not turning:
        s = inv_i[0] * sign
        return v + (u[3] + s * cx, u[4] + s * cy, u[5] + s * cz)
    return v + (u[3] + (inv_i[0] * cx + inv_i[1] * cy + inv_i[2] * cz) * sign,
                u[4] + (inv_i[3] * cx + inv_i[4] * cy + inv_i[5] * cz) * sign,
                u[5] + (inv_i[6] * cx + inv_i[7] * cy + inv_i[8] * cz) * sign)


@njit_inline
def _inertia(wide_f, at, turning):
    """The 9 FloatW of a row-major inverse inertia whose block starts at ``at``.  Unless ``turning`` only the
    first block ``s`` is read: every lane's inverse inertia is then ``s E``, its other entries zero."""
    first = load_w(wide_f, at)
    if not turning:
        zero = splat_w(0.0)
        return first, zero, zero, zero, first, zero, zero, zero, first
    return (first, load_w(wide_f, at + LANES), load_w(wide_f, at + 2 * LANES),
            load_w(wide_f, at + 3 * LANES), load_w(wide_f, at + 4 * LANES), load_w(wide_f, at + 5 * LANES),
            load_w(wide_f, at + 6 * LANES), load_w(wide_f, at + 7 * LANES), load_w(wide_f, at + 8 * LANES))


@njit_inline
def _turning(wide_i, bundle):
    """True if some lane of ``bundle`` has a body whose world inertia turns with it."""
    return wide_i[bundle * BUNDLE_ROWS * LANES + WI_TURNING * LANES] != 0


@njit_inline
def _rolling(wide_i, bundle):
    """True if some lane of ``bundle`` has rolling or torsional friction or an angular impulse to warm-start."""
    return wide_i[bundle * BUNDLE_ROWS * LANES + WI_ROLLING * LANES] != 0


@njit
def _solve_rolling(wide_f, bundle, ua, inv_i_a, ub, inv_i_b, normal_impulse):
    """Rolling and torsional friction of every lane, as ``contact_solver._solve_rolling`` (term for term):

        K = I_a^-1 + I_b^-1,   lambda_r := lambda_r - K^-1 (w_b - w_a),   K^-1 = adj(K) / det K,
        lambda_r := clamp(lambda_r - (lambda_r.n) n, rho lambda_n) + clamp(lambda_r.n, tau lambda_n) n

    with ``lambda_n`` the lane's ``normal_impulse`` and ``I^-1`` the bodies' ``inv_i_a``, ``inv_i_b``
    (:func:`_inertia`).  A lane without rolling or torsional friction (``rho = tau = 0``: the scalar pass
    skips it) and one whose ``K`` is singular (a pad lane) keep their ``lambda_r``.  Returns the bodies'
    updated ``(v, omega)``.  (A kernel of its own, called: inlined into :func:`solve_bundles`, it took 40 %
    longer over bundles without rolling friction, which never run it.)"""
    zero = splat_w(0.0)
    cofactors, det = angular_cofactors(inv_i_a, inv_i_b)
    old, n = _vector(wide_f, _at(bundle, WB_LAMBDA_R)), _vector(wide_f, _at(bundle, WB_NORMAL))
    across, spin = rolling_split(cofactors, det, (ub[3] - ua[3], ub[4] - ua[4], ub[5] - ua[5]), old, n)
    roll, torsion = load_w(wide_f, _at(bundle, WB_ROLL)), load_w(wide_f, _at(bundle, WB_TORSION))
    rolling_bound, torsion_bound = roll * normal_impulse, torsion * normal_impulse
    length = sqrt_w(_dot(across, across))
    scale = where_gt(length, rolling_bound, rolling_bound / length, splat_w(1.0))
    spin = min_w(max_w(spin, -torsion_bound), torsion_bound)
    solved = where_gt(det, zero, max_w(roll, torsion), zero)      # > 0: the lane solves lambda_r
    new = (where_gt(solved, zero, across[0] * scale + spin * n[0], old[0]),
           where_gt(solved, zero, across[1] * scale + spin * n[1], old[1]),
           where_gt(solved, zero, across[2] * scale + spin * n[2], old[2]))
    for k in range(3):
        store_w(wide_f, _at(bundle, WB_LAMBDA_R + k), new[k])
    change = (new[0] - old[0], new[1] - old[1], new[2] - old[2])
    return twist(ua, inv_i_a, change, -1.0), twist(ub, inv_i_b, change, 1.0)


@njit
def load_bundle_bodies(wide_f, wide_i, bundles, sb, all_masses):
    """After the solver bodies are filled: each lane's current separation
    s = s0 + n . ((dx_b + dtheta_b x rb) - (dx_a + dtheta_a x ra))  (as ``contact_separation``), and its
    inverse masses and inertias: in every bundle if ``all_masses`` (first in the step), else only in those
    with a body whose world inertia turns with it (the others' are constant through the step)."""
    for bundle in range(bundles):
        rows = bundle * BUNDLE_ROWS * LANES
        read_a, read_b = rows + WI_READ_A * LANES, rows + WI_READ_B * LANES
        if all_masses or _turning(wide_i, bundle):
            mass_a = gather_w(sb, wide_i, read_a, SB_INV_MASS, 10)      # 1/m, then I^-1 row-major
            mass_b = gather_w(sb, wide_i, read_b, SB_INV_MASS, 10)
            for k in range(10):
                store_w(wide_f, _at(bundle, WB_INV_MASS_A + k), mass_a[k])
                store_w(wide_f, _at(bundle, WB_INV_MASS_B + k), mass_b[k])
        motion_a, motion_b = _gather_u(sb, wide_i, read_a, SB_DP), _gather_u(sb, wide_i, read_b, SB_DP)
        moved = _relative_velocity(motion_a, _vector(wide_f, _at(bundle, WB_RA)),
                                   motion_b, _vector(wide_f, _at(bundle, WB_RB)))
        store_w(wide_f, _at(bundle, WB_SEPARATION),
                load_w(wide_f, _at(bundle, WB_ADJ_SEP)) + _dot(moved, _vector(wide_f, _at(bundle, WB_NORMAL))))


@njit
def refresh_bundle_masses(wide_f, wide_i, bundles, sb):
    """The effective masses along the normal and tangents of every lane of the bundles whose bodies turn,
    and the accumulated impulses scaled with them (``contact_solver.refresh_turning_masses``, lane by lane
    with the same arithmetic, so the bundles stay bit for bit the scalar pass): after each sub-step's
    position update."""
    for bundle in range(bundles):
        if not _turning(wide_i, bundle):
            continue
        rows = bundle * BUNDLE_ROWS * LANES
        for lane in range(LANES):
            if wide_i[rows + WI_CONTACT * LANES + lane] < 0:
                continue
            a = wide_i[rows + WI_READ_A * LANES + lane]
            b = wide_i[rows + WI_READ_B * LANES + lane]
            if sb[a, SB_ISO] >= 0.0 and sb[b, SB_ISO] >= 0.0:
                continue
            ra = (wide_f[_at(bundle, WB_RA) + lane], wide_f[_at(bundle, WB_RA + 1) + lane],
                  wide_f[_at(bundle, WB_RA + 2) + lane])
            rb = (wide_f[_at(bundle, WB_RB) + lane], wide_f[_at(bundle, WB_RB + 1) + lane],
                  wide_f[_at(bundle, WB_RB + 2) + lane])
            for field, direction, impulse in ((WB_MASS_N, WB_NORMAL, WB_LAMBDA_N), (WB_MASS_T1, WB_T1, WB_LAMBDA_T1),
                                              (WB_MASS_T2, WB_T2, WB_LAMBDA_T2)):
                d = (wide_f[_at(bundle, direction) + lane], wide_f[_at(bundle, direction + 1) + lane],
                     wide_f[_at(bundle, direction + 2) + lane])
                m = effective_mass_along(sb, a, ra, b, rb, d)
                wide_f[_at(bundle, impulse) + lane] *= lighter(m, wide_f[_at(bundle, field) + lane])
                wide_f[_at(bundle, field) + lane] = m


@njit
def warm_start_bundles(wide_f, wide_i, bundles, sb):
    """Stage "warm start": apply each lane's accumulated impulse  p = lambda_n n + lambda_1 t1 + lambda_2 t2,
    and in bundles with rolling or torsional friction its angular impulse lambda_r:
    omega_a -= I_a^-1 lambda_r,  omega_b += I_b^-1 lambda_r  (``contact_solver.warm_start_listed``, term for term)."""
    for bundle in range(bundles):
        rows = bundle * BUNDLE_ROWS * LANES
        ln, l1, l2 = (load_w(wide_f, _at(bundle, WB_LAMBDA_N)), load_w(wide_f, _at(bundle, WB_LAMBDA_T1)),
                      load_w(wide_f, _at(bundle, WB_LAMBDA_T2)))
        n, t1, t2 = (_vector(wide_f, _at(bundle, WB_NORMAL)), _vector(wide_f, _at(bundle, WB_T1)),
                     _vector(wide_f, _at(bundle, WB_T2)))
        p = (ln * n[0] + l1 * t1[0] + l2 * t2[0], ln * n[1] + l1 * t1[1] + l2 * t2[1],
             ln * n[2] + l1 * t1[2] + l2 * t2[2])
        turning = _turning(wide_i, bundle)
        ia, ib = _inertia(wide_f, _at(bundle, WB_INV_I_A), turning), _inertia(wide_f, _at(bundle, WB_INV_I_B), turning)
        ua = _push(_gather_u(sb, wide_i, rows + WI_READ_A * LANES, SB_V), load_w(wide_f, _at(bundle, WB_INV_MASS_A)),
                   ia, _vector(wide_f, _at(bundle, WB_RA)), p, -1.0, turning)
        ub = _push(_gather_u(sb, wide_i, rows + WI_READ_B * LANES, SB_V), load_w(wide_f, _at(bundle, WB_INV_MASS_B)),
                   ib, _vector(wide_f, _at(bundle, WB_RB)), p, 1.0, turning)
        if _rolling(wide_i, bundle):
            lambda_r = _vector(wide_f, _at(bundle, WB_LAMBDA_R))
            ua = twist(ua, ia, lambda_r, -1.0)
            ub = twist(ub, ib, lambda_r, 1.0)
        _scatter_u(sb, wide_i, rows + WI_WRITE_A * LANES, ua)
        _scatter_u(sb, wide_i, rows + WI_WRITE_B * LANES, ub)


@njit
def solve_bundles(wide_f, wide_i, first, last, sb, h, soft, largest):
    """Stage "solve" (``soft`` = (bias_rate, mass_scale, impulse_scale, max_bias)) or "relax" (rigid:
    (0, 1, 0, 0)): one pass of sequential impulses over the bundles ``first:last``, as
    ``contact_solver.solve_contacts`` (normal impulse closing a speculative gap exactly or opening overlap
    softly, then Coulomb friction on the tangent disc, then in bundles that have them rolling and torsional
    friction: :func:`_solve_rolling`).  Returns the largest velocity change (m/s);
    ``largest`` is scratch of ``LANES`` floats."""
    zero = splat_w(0.0)
    one = splat_w(1.0)
    bias_rate = soft[0]
    twice_max_bias = splat_w(2.0 * soft[3])
    touching_mass, touching_impulse = splat_w(soft[1]), splat_w(soft[2])
    store_w(largest, 0, zero)
    for bundle in range(first, last):
        rows = bundle * BUNDLE_ROWS * LANES
        ua = _gather_u(sb, wide_i, rows + WI_READ_A * LANES, SB_V)
        ub = _gather_u(sb, wide_i, rows + WI_READ_B * LANES, SB_V)
        ima, imb = load_w(wide_f, _at(bundle, WB_INV_MASS_A)), load_w(wide_f, _at(bundle, WB_INV_MASS_B))
        turning = _turning(wide_i, bundle)
        ia, ib = _inertia(wide_f, _at(bundle, WB_INV_I_A), turning), _inertia(wide_f, _at(bundle, WB_INV_I_B), turning)
        ra, rb = _vector(wide_f, _at(bundle, WB_RA)), _vector(wide_f, _at(bundle, WB_RB))
        n = _vector(wide_f, _at(bundle, WB_NORMAL))
        # --- normal: a speculative gap s > 0 closes exactly in the sub-step; shallow overlap opens softly -
        s = load_w(wide_f, _at(bundle, WB_SEPARATION))
        r = (zero - s) * bias_rate        # contact_solver.soft_bias, term for term
        bias = where_gt(s, zero, s / h, zero - max_w(min_w(r, twice_max_bias - r), zero))
        soft_mass = where_gt(s, zero, one, touching_mass)
        soft_impulse = where_gt(s, zero, zero, touching_impulse)
        vn = _dot(_relative_velocity(ua, ra, ub, rb), n)
        mass_n = load_w(wide_f, _at(bundle, WB_MASS_N))
        old = load_w(wide_f, _at(bundle, WB_LAMBDA_N))
        new = max_w(old - mass_n * soft_mass * (vn + bias) - soft_impulse * old, zero)
        store_w(wide_f, _at(bundle, WB_LAMBDA_N), new)
        max_n, vn0 = load_w(wide_f, _at(bundle, WB_MAX_N)), load_w(wide_f, _at(bundle, WB_VN0))
        # a new contact engages (new > 0, max_n == 0, WB_NEW = 1): the approach speed at impact
        engaging = where_gt(new, zero, where_gt(max_n, zero, zero, load_w(wide_f, _at(bundle, WB_NEW))), zero)
        store_w(wide_f, _at(bundle, WB_VN0), where_gt(engaging, zero, min_w(vn, vn0), vn0))
        store_w(wide_f, _at(bundle, WB_MAX_N), max_w(new, max_n))
        d = new - old
        store_w(largest, 0, max_w(load_w(largest, 0), where_gt(mass_n, zero, abs_w(d) / mass_n, zero)))
        p = (d * n[0], d * n[1], d * n[2])
        ua = _push(ua, ima, ia, ra, p, -1.0, turning)
        ub = _push(ub, imb, ib, rb, p, 1.0, turning)
        # --- friction: Coulomb disc on the tangent plane ------------------------------------------------
        bound = load_w(wide_f, _at(bundle, WB_MU)) * new
        t1, t2 = _vector(wide_f, _at(bundle, WB_T1)), _vector(wide_f, _at(bundle, WB_T2))
        dv = _relative_velocity(ua, ra, ub, rb)
        o1, o2 = load_w(wide_f, _at(bundle, WB_LAMBDA_T1)), load_w(wide_f, _at(bundle, WB_LAMBDA_T2))
        n1 = o1 - load_w(wide_f, _at(bundle, WB_MASS_T1)) * _dot(dv, t1)
        n2 = o2 - load_w(wide_f, _at(bundle, WB_MASS_T2)) * _dot(dv, t2)
        length = sqrt_w(n1 * n1 + n2 * n2)
        scale = where_gt(length, bound, bound / length, one)
        n1 = n1 * scale
        n2 = n2 * scale
        store_w(wide_f, _at(bundle, WB_LAMBDA_T1), n1)
        store_w(wide_f, _at(bundle, WB_LAMBDA_T2), n2)
        d1, d2 = n1 - o1, n2 - o2
        p = (d1 * t1[0] + d2 * t2[0], d1 * t1[1] + d2 * t2[1], d1 * t1[2] + d2 * t2[2])
        ua = _push(ua, ima, ia, ra, p, -1.0, turning)
        ub = _push(ub, imb, ib, rb, p, 1.0, turning)
        # --- rolling and torsional friction: an angular impulse bounded by rho and tau times lambda_n ------
        if _rolling(wide_i, bundle):
            ua, ub = _solve_rolling(wide_f, bundle, ua, ia, ub, ib, new)
        _scatter_u(sb, wide_i, rows + WI_WRITE_A * LANES, ua)
        _scatter_u(sb, wide_i, rows + WI_WRITE_B * LANES, ub)
    change = 0.0
    for lane in range(LANES):
        change = max(change, largest[lane])
    return change


@njit
def push_bundles(wide_f, wide_i, first, last, sb, pb, h, rate, max_push, depth, first_pass, largest):
    """Stage "relax", contacts: one pass of split impulses over the bundles ``first:last`` on the
    pseudo-velocities ``pb``, as ``contact_solver.push_contacts`` (term for term):

        lambda_p := max(lambda_p + m_n (target - dv_p . n), 0),
        target = -s / h for a gap s >= 0, else min(rate max(-s - depth, 0), max_push)

    (``lambda_p`` taken as 0 on the ``first_pass`` of a sub-step).  Returns the largest pseudo-velocity
    change (m/s); ``largest`` is scratch of ``LANES`` floats."""
    zero = splat_w(0.0)
    depth = splat_w(depth)
    store_w(largest, 0, zero)
    for bundle in range(first, last):
        rows = bundle * BUNDLE_ROWS * LANES
        ua = gather_w(pb, wide_i, rows + WI_READ_A * LANES, 0, 6)
        ub = gather_w(pb, wide_i, rows + WI_READ_B * LANES, 0, 6)
        ima, imb = load_w(wide_f, _at(bundle, WB_INV_MASS_A)), load_w(wide_f, _at(bundle, WB_INV_MASS_B))
        turning = _turning(wide_i, bundle)
        ia, ib = _inertia(wide_f, _at(bundle, WB_INV_I_A), turning), _inertia(wide_f, _at(bundle, WB_INV_I_B), turning)
        ra, rb = _vector(wide_f, _at(bundle, WB_RA)), _vector(wide_f, _at(bundle, WB_RB))
        n = _vector(wide_f, _at(bundle, WB_NORMAL))
        s = load_w(wide_f, _at(bundle, WB_SEPARATION))
        overlap = zero - s
        target = where_gt(zero, s, min_w(max_w(overlap - depth, zero) * rate, splat_w(max_push)), overlap / h)
        vn = _dot(_relative_velocity(ua, ra, ub, rb), n)
        mass_n = load_w(wide_f, _at(bundle, WB_MASS_N))
        old = zero if first_pass else load_w(wide_f, _at(bundle, WB_LAMBDA_P))
        new = max_w(old + mass_n * (target - vn), zero)
        store_w(wide_f, _at(bundle, WB_LAMBDA_P), new)
        d = new - old
        store_w(largest, 0, max_w(load_w(largest, 0), where_gt(mass_n, zero, abs_w(d) / mass_n, zero)))
        p = (d * n[0], d * n[1], d * n[2])
        scatter_w(pb, wide_i, rows + WI_WRITE_A * LANES, 0, _push(ua, ima, ia, ra, p, -1.0, turning))
        scatter_w(pb, wide_i, rows + WI_WRITE_B * LANES, 0, _push(ub, imb, ib, rb, p, 1.0, turning))
    change = 0.0
    for lane in range(LANES):
        change = max(change, largest[lane])
    return change


@njit
def deepest_overlap(wide_f, bundles):
    """The largest overlap ``-s`` (m) of the lanes of the bundles ``0 .. bundles - 1`` at their separations now
    (``load_bundle_bodies``); a pad lane counts as touching (0), a lane with a gap as a negative overlap."""
    deepest = 0.0
    for bundle in range(bundles):
        at = _at(bundle, WB_SEPARATION)
        for lane in range(LANES):
            deepest = max(deepest, -wide_f[at + lane])
    return deepest


@njit
def accumulate_bundles(wide_f, bundles):
    """After each sub-step: add the sub-step's impulses to the step's totals (normal, and friction as a
    world vector)."""
    for bundle in range(bundles):
        ln = load_w(wide_f, _at(bundle, WB_LAMBDA_N))
        l1, l2 = load_w(wide_f, _at(bundle, WB_LAMBDA_T1)), load_w(wide_f, _at(bundle, WB_LAMBDA_T2))
        store_w(wide_f, _at(bundle, WB_SUM_N), load_w(wide_f, _at(bundle, WB_SUM_N)) + ln)
        for k in range(3):
            total = _at(bundle, WB_SUM_T + k)
            store_w(wide_f, total, load_w(wide_f, total) + (l1 * load_w(wide_f, _at(bundle, WB_T1 + k))
                                                           + l2 * load_w(wide_f, _at(bundle, WB_T2 + k))))


@njit
def store_bundles(wide_f, wide_i, bundles, cf):
    """Stage "store impulses": the bundles' impulses (normal, friction, rolling), largest normal impulse,
    approach speed and totals back to the contact table."""
    for j in range(bundles * LANES):
        bundle, lane = j // LANES, j % LANES
        c = wide_i[bundle * BUNDLE_ROWS * LANES + WI_CONTACT * LANES + lane]
        if c < 0:
            continue
        cf[c, C_LAMBDA_N] = wide_f[_at(bundle, WB_LAMBDA_N) + lane]
        cf[c, C_LAMBDA_T1] = wide_f[_at(bundle, WB_LAMBDA_T1) + lane]
        cf[c, C_LAMBDA_T2] = wide_f[_at(bundle, WB_LAMBDA_T2) + lane]
        cf[c, C_MAX_N] = wide_f[_at(bundle, WB_MAX_N) + lane]
        cf[c, C_VN0] = wide_f[_at(bundle, WB_VN0) + lane]
        cf[c, C_SUM_N] += wide_f[_at(bundle, WB_SUM_N) + lane]
        for k in range(3):
            cf[c, C_LAMBDA_R + k] = wide_f[_at(bundle, WB_LAMBDA_R + k) + lane]
            cf[c, C_SUM_T + k] += wide_f[_at(bundle, WB_SUM_T + k) + lane]
