"""The collide stage: bounding boxes, broad phase, narrow phase, at the poses the step began with.

It only reads the bodies, so when a buffer turns out too small the caller grows it and runs the step
again from the same state.

    shape pose          x_s = x + R p_local,  R_s = R R_local
    sweep of a body     d = (|v| + |omega| r_sweep) dt + (|g| + |F| / m + |I^-1 T| r_sweep) dt^2
                        (r_sweep: how far its surface reaches from the centre of mass; 0 for a centred
                        sphere, which turns in place; F, T its user force and torque)
    AABB                shape boxes grown by the speculative distance and the sweep
    prediction          speculative distance + d_a + d_b: contacts are made before bodies touch

The narrow phase poses each shape once per call, when a pair first needs it, into scratch tables (a
sphere at its body's centre needs no pose at all: its centre is the body's position, and no pair test
reads a sphere's rotation).  A sphere against a sphere, capsule, box or plane, nearly every pair of a
pile, runs its pair test with every pose in registers and the row is written here: a call passes each
array as a struct of 7 to 9 words, and counts its references unless the array is borrowed
(``_numba.jit.borrow``, as the step's are), about as costly as the pair test itself, so the hot loop hands
none.  A sphere against a mesh (the marble) passes both poses by value too.  Other pairs go through
``collide_pair``.  Contacts, their order and their bits are those of posing both shapes of every pair
and calling ``collide_pair`` (tests/test_narrow_phase.py).
"""
import math

import numpy as np

from .._numba.jit import njit, njit_inline
from ..collision import shape_types as st
from ..collision.aabb import shape_bounds, sphere_aabb
from ..collision.mesh.mesh_collide import collide_sphere_mesh
from ..collision.pairs.contact_output import contact_point
from ..collision.pairs.dispatch import collide_pair_covering, flip_normals, sphere_primitive
from ..collision.shape_types import COVER_ALL, COVER_GROUND, COVER_MESHES, COVER_SPHERES, N_SHAPE_PARAMS
from ..dynamics.forces import is_driven, is_dynamic, is_moving, user_acceleration, user_angular_acceleration
from ..dynamics.integrators import limit_speeds
from ..math3d import quat_mul, quat_rotate, quat_to_matrix
from ..state.layout import (C_BODY_A, C_BODY_B, C_FEATURE, C_FLAGS, C_SHAPE_A, C_SHAPE_B, CP_SENSOR, F_ALIVE,
                            F_CCD_NEVER, F_SENSOR, F_STATIC, FLAGS, OMEGA, POS, QUAT, S_LOCAL_POS, S_LOCAL_QUAT,
                            S_OFF_F, S_OFF_I, S_PARAMS, S_RADIUS, S_TYPE, SHAPE_COUNT, SHAPE_START, VEL)
from .pair_cache import cacheable, cached_rows, relative_pose, remember_rows, reuse_rows, still_holds


@njit
def shape_position(bf, sf, s, b, pos):
    """World position (m) of shape row ``s`` on body row ``b`` into ``pos`` (3,): ``x + R p_local``."""
    q = (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3])
    quat_rotate(q, (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]), pos)
    for k in range(3):
        pos[k] += bf[b, POS + k]


@njit
def shape_rotation(bf, sf, s, b, q, rot):
    """World rotation matrix of shape row ``s`` on body row ``b`` into ``rot`` (3, 3):
    ``R_s = R R_local``, through the quaternion product into the scratch ``q`` (4,)."""
    quat_mul((bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3]),
             (sf[s, S_LOCAL_QUAT], sf[s, S_LOCAL_QUAT + 1], sf[s, S_LOCAL_QUAT + 2], sf[s, S_LOCAL_QUAT + 3]), q)
    quat_to_matrix(q, rot)


@njit
def shape_pose(bf, sf, s, b, pos, rot):
    """World position and rotation matrix of shape row ``s`` on body row ``b``."""
    shape_rotation(bf, sf, s, b, np.empty(4), rot)
    shape_position(bf, sf, s, b, pos)


#: States of a shape's row in the narrow phase's pose tables.
POSE_NONE = 0
POSE_POSITION = 1       # position only: a sphere seen only by the sphere fast paths
POSE_FULL = 2           # position and rotation


@njit
def pose_shape(bf, sf, si, s, b, rotation, q, pos_t, rot_t, state):
    """Fill row ``s`` of the pose tables ``pos_t`` (n, 3) and ``rot_t`` (n, 3, 3) once per narrow phase:
    the position always, the rotation unless ``s`` is a sphere and ``rotation`` is False (the sphere
    pair tests never read a sphere's rotation)."""
    have = state[s]
    if have == POSE_NONE:
        shape_position(bf, sf, s, b, pos_t[s])
        have = POSE_POSITION
    if have == POSE_POSITION and (rotation or si[s, S_TYPE] != st.SPHERE):
        shape_rotation(bf, sf, s, b, q, rot_t[s])
        have = POSE_FULL
    state[s] = have


@njit
def at_body_origin(sf, s):
    """True if shape row ``s`` sits at its body's centre of mass (``p_local = 0``): a sphere there is
    posed by its body's position alone.  Straight-line code (``&``, not ``and``), so a caller's
    arrays are not reference counted."""
    return (sf[s, S_LOCAL_POS] == 0.0) & (sf[s, S_LOCAL_POS + 1] == 0.0) & (sf[s, S_LOCAL_POS + 2] == 0.0)


@njit_inline
def _sphere_centre(bf, sf, si, s, b, q, pos_t, rot_t, state):
    """World centre (3-tuple, m) of sphere row ``s`` on body row ``b``: its body's position when the sphere
    is centred on it, else its position in the pose tables, posed there once."""
    if at_body_origin(sf, s):
        return (bf[b, POS], bf[b, POS + 1], bf[b, POS + 2])
    if state[s] == POSE_NONE:
        pose_shape(bf, sf, si, s, b, False, q, pos_t, rot_t, state)
    return (pos_t[s, 0], pos_t[s, 1], pos_t[s, 2])


@njit
def _row_matrix(rot_t, s):
    """Row ``s`` of the rotation table as a row-major 9-tuple."""
    return (rot_t[s, 0, 0], rot_t[s, 0, 1], rot_t[s, 0, 2], rot_t[s, 1, 0], rot_t[s, 1, 1], rot_t[s, 1, 2],
            rot_t[s, 2, 0], rot_t[s, 2, 1], rot_t[s, 2, 2])


@njit_inline
def update_aabbs(bf, bi, sf, si, nb, aabbs, sweep, dt, gravity_mag, speculative, pos_t, rot_t, q):
    """Fattened AABB and sweep distance (m) of every moving body, kinematic ones included (no sweep for
    ``ccd=False`` bodies, F_CCD_NEVER); static bodies keep theirs.  A dynamic body's speeds are first held to
    the speed limit (``integrators.limit_speeds``: the interval's sweeps and impacts are then finite).
    ``pos_t, rot_t, q`` are the scratch of :func:`pose_tables` (each shape posed into its rows)."""
    for i in range(nb):
        if (bi[i, FLAGS] & F_ALIVE) == 0 or (bi[i, FLAGS] & F_STATIC) != 0:
            sweep[i] = 0.0
            continue
        falls = is_moving(bi, i)
        if falls:
            limit_speeds(bf, i)
        reach = 0.0
        s0 = bi[i, SHAPE_START]
        for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
            offset = math.sqrt(sf[s, S_LOCAL_POS] ** 2 + sf[s, S_LOCAL_POS + 1] ** 2 + sf[s, S_LOCAL_POS + 2] ** 2)
            turning = 0.0 if si[s, S_TYPE] == st.SPHERE else sf[s, S_RADIUS]
            reach = max(reach, offset + turning)
            if si[s, S_TYPE] == st.SPHERE and at_body_origin(sf, s):
                # A centred sphere's box from its body's position (no call that takes arrays here:
                # passing them costs more than the box)
                lo, hi = sphere_aabb((bf[i, POS], bf[i, POS + 1], bf[i, POS + 2]), sf[s, S_PARAMS])
            else:
                shape_position(bf, sf, s, i, pos_t[s])
                if si[s, S_TYPE] != st.SPHERE:        # a sphere's box needs no rotation
                    shape_rotation(bf, sf, s, i, q, rot_t[s])
                lo, hi = shape_bounds(si[s, S_TYPE], pos_t[s], rot_t[s], sf[s, S_PARAMS:S_PARAMS + N_SHAPE_PARAMS])
            for k in range(3):
                if s == s0 or lo[k] < aabbs[i, k]:
                    aabbs[i, k] = lo[k]
                if s == s0 or hi[k] > aabbs[i, 3 + k]:
                    aabbs[i, 3 + k] = hi[k]
        if (falls or is_driven(bf, bi, i)) and (bi[i, FLAGS] & F_CCD_NEVER) == 0:
            v = math.sqrt(bf[i, VEL] ** 2 + bf[i, VEL + 1] ** 2 + bf[i, VEL + 2] ** 2)
            w = math.sqrt(bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2)
            sweep[i] = (v + w * reach) * dt
            if falls:
                speeding = gravity_mag + user_acceleration(bf, i) + user_angular_acceleration(bf, i) * reach
                sweep[i] += speeding * dt * dt
        else:
            sweep[i] = 0.0
        grow = speculative + sweep[i]
        for k in range(3):
            aabbs[i, k] -= grow
            aabbs[i, 3 + k] += grow


@njit
def pose_tables(n_shapes):
    """Scratch of the narrow phase for ``n_shapes`` shape rows: ``(pos_t, rot_t, state, q)``, world
    positions (n, 3) m and rotations (n, 3, 3) of the shapes, each row's ``POSE_*`` state, and a quaternion."""
    return np.empty((n_shapes, 3)), np.empty((n_shapes, 3, 3)), np.zeros(n_shapes, np.int8), np.empty(4)


#: Most candidate pairs a movable body keeps in one step once the broad phase found more than this many
#: pairs per body in all (a degenerate scene: bodies spawned into one another).  A sphere touches at most 12
#: equal spheres, a box in a pile a few neighbours with 4 to 8 points each; 64 pairs let every real scene
#: through untouched, and 10,000 spheres spawned at one point make at most 320,000 pairs (and contacts)
#: instead of 50 million (14.5 GiB of contact tables).  Static bodies are not counted (a floor carries any
#: number).  Which pairs stay is deterministic: the first in the broad phase's canonical order.
MAX_PAIRS_PER_BODY = 64


@njit
def limit_pairs_per_body(pairs, n_pairs, bi, nb, limit):
    """Keep, in order, the pairs ``pairs[:n_pairs]`` whose movable bodies each take part in fewer than
    ``limit`` pairs kept so far; compacts them to the front and returns how many are kept."""
    count = np.zeros(nb, dtype=np.int64)
    kept = 0
    for p in range(n_pairs):
        a = pairs[p, 0]
        b = pairs[p, 1]
        full_a = is_moving(bi, a) and count[a] >= limit
        full_b = is_moving(bi, b) and count[b] >= limit
        if full_a or full_b:
            continue
        count[a] += 1
        count[b] += 1
        pairs[kept, 0] = a
        pairs[kept, 1] = b
        kept += 1
    return kept


@njit_inline
def _narrow_phase(coverage, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                  cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """Contact points of every candidate pair into ``raw_f``/``raw_i`` (pair-test format) and ``ci``
    (bodies, shapes, sensor flag), with the pair tests of ``coverage`` (``shape_types.COVER_*``), and their
    body-pair cache columns into ``cf``; a pair whose rows in last step's table ``pcf``/``pci`` (its first
    ``npc`` rows) still hold is not tested again (pipeline/pair_cache.py; ``npc`` 0: every pair is tested).
    Returns the number of points (it may exceed the capacity).  ``pos_t, rot_t, state, q`` are the scratch of
    :func:`pose_tables` for at least ``sf``'s rows."""
    if n_pairs == 0:
        return 0
    n = 0
    cap = raw_f.shape[0]
    cached = 0                               # the pairs' walk through last step's table
    for s in range(sf.shape[0]):             # world poses, each shape's computed once, when first needed
        state[s] = POSE_NONE
    for p in range(n_pairs):
        a = pairs[p, 0]
        b = pairs[p, 1]
        fa = bi[a, FLAGS]
        fb = bi[b, FLAGS]
        sensor = ((fa | fb) & F_SENSOR) != 0
        if not (is_moving(bi, a) or is_moving(bi, b)):
            # Resting, static and kinematic pairs have nothing to solve; a sleeping body still meets a sensor
            # (reported) and a kinematic body in motion (which wakes it).
            if not ((is_dynamic(bi, a) or is_dynamic(bi, b))
                    and (sensor or is_driven(bf, bi, a) or is_driven(bf, bi, b))):
                continue
        # Sensors report overlaps only; solid pairs also report gaps they may close within the step.
        prediction = 0.0 if sensor else speculative + sweep[a] + sweep[b]
        keep = not sensor and cacheable(bi, si, a, b)
        if keep:
            r_ab, q_ab = relative_pose(bf, a, b)
            cached, end = cached_rows(pci, cached, npc, a, b)
            if end > cached and still_holds(pcf, pci, cached, end, r_ab, q_ab, prediction):
                n = reuse_rows(bf, pcf, pci, cached, end, raw_f, raw_i, cf, ci, n)
                continue
        first = n
        for sa in range(bi[a, SHAPE_START], bi[a, SHAPE_START] + bi[a, SHAPE_COUNT]):
            for sb in range(bi[b, SHAPE_START], bi[b, SHAPE_START] + bi[b, SHAPE_COUNT]):
                ta = si[sa, S_TYPE]
                tb = si[sb, S_TYPE]
                if (ta == st.SPHERE and tb <= st.PLANE) or (tb == st.SPHERE and ta <= st.PLANE):
                    # Fast path: the sphere (first, as collide_convex_pair orders them) against a
                    # primitive, every pose in registers.
                    flip = ta != st.SPHERE
                    s1, b1, s2, b2, t2 = (sb, b, sa, a, ta) if flip else (sa, a, sb, b, tb)
                    # Poses: a centred sphere is at its body's centre; any other shape's pose is
                    # computed once, into the tables (inline here: a call per pair with the arrays
                    # would pass them all, which costs more than the pair test).
                    c1 = _sphere_centre(bf, sf, si, s1, b1, q, pos_t, rot_t, state)
                    c2 = (bf[b2, POS], bf[b2, POS + 1], bf[b2, POS + 2])
                    if t2 != st.SPHERE or not at_body_origin(sf, s2):
                        if state[s2] == POSE_NONE:
                            pose_shape(bf, sf, si, s2, b2, False, q, pos_t, rot_t, state)
                        c2 = (pos_t[s2, 0], pos_t[s2, 1], pos_t[s2, 2])
                    hit, p_on_a, normal, depth = sphere_primitive(
                        c1, sf[s1, S_PARAMS], t2, c2, _row_matrix(rot_t, s2),
                        (sf[s2, S_PARAMS], sf[s2, S_PARAMS + 1], sf[s2, S_PARAMS + 2], sf[s2, S_PARAMS + 3]),
                        prediction)
                    m = n + 1 if hit else n
                    if hit and n < cap:
                        # The row add_contact writes, stored here: passing the buffers to a function in
                        # this loop costs more than the pair test.
                        point = contact_point(p_on_a, normal, depth)
                        side = -1.0 if flip else 1.0     # normals from a to b (collide_convex_pair)
                        for k in range(3):
                            raw_f[n, k] = point[k]
                            raw_f[n, 3 + k] = side * normal[k]
                        raw_f[n, 6] = depth
                        raw_i[n] = 0
                elif coverage != COVER_SPHERES and ((ta == st.SPHERE and tb == st.MESH)
                                                    or (tb == st.SPHERE and ta == st.MESH)):
                    # Fast path: a sphere against a mesh (the marble on its level), both poses by value.
                    flip = ta != st.SPHERE
                    s1, b1, s2, b2 = (sb, b, sa, a) if flip else (sa, a, sb, b)
                    c1 = _sphere_centre(bf, sf, si, s1, b1, q, pos_t, rot_t, state)
                    if state[s2] != POSE_FULL:
                        pose_shape(bf, sf, si, s2, b2, True, q, pos_t, rot_t, state)
                    m = collide_sphere_mesh(c1, sf[s1, S_PARAMS], (pos_t[s2, 0], pos_t[s2, 1], pos_t[s2, 2]),
                                            _row_matrix(rot_t, s2), sf[s2, S_PARAMS:S_PARAMS + N_SHAPE_PARAMS],
                                            geom_f, geom_i, si[s2, S_OFF_F], si[s2, S_OFF_I], prediction, raw_f,
                                            raw_i, n)
                    if flip:
                        flip_normals(raw_f, n, m)
                else:
                    if state[sa] != POSE_FULL:
                        pose_shape(bf, sf, si, sa, a, True, q, pos_t, rot_t, state)
                    if state[sb] != POSE_FULL:
                        pose_shape(bf, sf, si, sb, b, True, q, pos_t, rot_t, state)
                    m = collide_pair_covering(
                                     coverage, ta, pos_t[sa], rot_t[sa], sf[sa, S_PARAMS:S_PARAMS + N_SHAPE_PARAMS],
                                     tb, pos_t[sb], rot_t[sb], sf[sb, S_PARAMS:S_PARAMS + N_SHAPE_PARAMS],
                                     geom_f, geom_i, si[sa, S_OFF_F], si[sa, S_OFF_I], si[sb, S_OFF_F],
                                     si[sb, S_OFF_I], prediction, raw_f, raw_i, n)
                for c in range(n, min(m, cap)):
                    ci[c, C_BODY_A] = a
                    ci[c, C_BODY_B] = b
                    ci[c, C_SHAPE_A] = sa
                    ci[c, C_SHAPE_B] = sb
                    ci[c, C_FEATURE] = raw_i[c]
                    ci[c, C_FLAGS] = CP_SENSOR if sensor else 0
                n = m
        if keep:
            remember_rows(bf, a, b, r_ab, q_ab, prediction, raw_f, cf, first, n)
    return n


# --- the narrow phase of each coverage: a world compiles the one of its own -------------------------------------
@njit
def narrow_phase_spheres(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                         cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """:func:`narrow_phase` of a world whose moving shapes are all spheres, with no mesh or height field."""
    return _narrow_phase(COVER_SPHERES, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                         raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)


@njit
def narrow_phase_meshes(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                        cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """:func:`narrow_phase` of a world whose moving shapes are all spheres, over meshes but no height field or
    hull."""
    return _narrow_phase(COVER_MESHES, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                         raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)


@njit
def narrow_phase_ground(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                        cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """:func:`narrow_phase` of a world whose moving shapes are all spheres, over meshes, height fields or static
    hulls."""
    return _narrow_phase(COVER_GROUND, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                         raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)


@njit
def narrow_phase_all(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                     cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """:func:`narrow_phase` with every pair test."""
    return _narrow_phase(COVER_ALL, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                         raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)


@njit_inline
def narrow_phase(coverage, bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                 cf, pcf, pci, npc, pos_t, rot_t, state, q):
    """Contact points of every candidate pair into ``raw_f``/``raw_i`` (pair-test format) and ``ci``
    (bodies, shapes, sensor flag), reusing last step's rows in ``pcf``/``pci`` (its first ``npc``) that still
    hold (:func:`_narrow_phase`); returns the number of points (it may exceed the capacity).
    ``coverage`` (``shape_types.COVER_*``, a constant where this is inlined) picks the compiled narrow phase
    with the pair tests the world can meet.  ``pos_t, rot_t, state, q`` are the scratch of
    :func:`pose_tables` for at least ``sf``'s rows."""
    if coverage == COVER_SPHERES:
        return narrow_phase_spheres(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                                    raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)
    if coverage == COVER_MESHES:
        return narrow_phase_meshes(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                                   raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)
    if coverage == COVER_GROUND:
        return narrow_phase_ground(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f,
                                   raw_i, ci, cf, pcf, pci, npc, pos_t, rot_t, state, q)
    return narrow_phase_all(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci,
                            cf, pcf, pci, npc, pos_t, rot_t, state, q)
