"""The collide stage: bounding boxes, broad phase, narrow phase, at the poses the step began with.

It only reads the bodies, so when a buffer turns out too small the caller grows it and runs the step
again from the same state.

    shape pose          x_s = x + R p_local,  R_s = R R_local
    sweep of a body     d = |v| dt + |omega| r_sweep dt + |g| dt^2   (r_sweep: how far its surface
                        reaches from the centre of mass; 0 for a centred sphere, which turns in place)
    AABB                shape boxes grown by the speculative distance and the sweep
    prediction          speculative distance + d_a + d_b: contacts are made before bodies touch
"""
import math

import numpy as np

from .._jit import njit
from ..collision import shape_types as st
from ..collision.aabb import merge_aabb, shape_aabb
from ..collision.dispatch import collide_pair
from ..layout import (C_BODY_A, C_BODY_B, C_FEATURE, C_FLAGS, C_SHAPE_A, C_SHAPE_B, CP_SENSOR, F_ALIVE,
                      F_SENSOR, F_STATIC, FLAGS, OMEGA, POS, QUAT, S_LOCAL_POS, S_LOCAL_QUAT,
                      S_OFF_F, S_OFF_I, S_PARAMS, S_RADIUS, S_TYPE, SHAPE_COUNT, SHAPE_START, VEL)
from ..math3d import quat_mul, quat_rotate, quat_to_matrix
from ..dynamics.forces import is_moving


@njit
def shape_pose(bf, sf, s, b, pos, rot):
    """World position and rotation matrix of shape row ``s`` on body row ``b``."""
    q = np.empty(4)
    quat_mul(bf[b, QUAT:QUAT + 4], sf[s, S_LOCAL_QUAT:S_LOCAL_QUAT + 4], q)
    quat_to_matrix(q, rot)
    quat_rotate(bf[b, QUAT:QUAT + 4], sf[s, S_LOCAL_POS:S_LOCAL_POS + 3], pos)
    for k in range(3):
        pos[k] += bf[b, POS + k]


@njit
def update_aabbs(bf, bi, sf, si, nb, aabbs, sweep, dt, gravity_mag, speculative):
    """Fattened AABB and sweep distance (m) of every moving body; static bodies keep theirs."""
    pos = np.empty(3)
    rot = np.empty((3, 3))
    box = np.empty(6)
    for i in range(nb):
        if (bi[i, FLAGS] & F_ALIVE) == 0 or (bi[i, FLAGS] & F_STATIC) != 0:
            sweep[i] = 0.0
            continue
        reach = 0.0
        s0 = bi[i, SHAPE_START]
        for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
            offset = math.sqrt(sf[s, S_LOCAL_POS] ** 2 + sf[s, S_LOCAL_POS + 1] ** 2 + sf[s, S_LOCAL_POS + 2] ** 2)
            turning = 0.0 if si[s, S_TYPE] == st.SPHERE else sf[s, S_RADIUS]
            reach = max(reach, offset + turning)
            shape_pose(bf, sf, s, i, pos, rot)
            shape_aabb(si[s, S_TYPE], pos, rot, sf[s, S_PARAMS:S_PARAMS + 8], box)
            if s == s0:
                for k in range(6):
                    aabbs[i, k] = box[k]
            else:
                merge_aabb(aabbs[i], box)
        if is_moving(bi, i):
            v = math.sqrt(bf[i, VEL] ** 2 + bf[i, VEL + 1] ** 2 + bf[i, VEL + 2] ** 2)
            w = math.sqrt(bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2)
            sweep[i] = (v + w * reach) * dt + gravity_mag * dt * dt
        else:
            sweep[i] = 0.0
        grow = speculative + sweep[i]
        for k in range(3):
            aabbs[i, k] -= grow
            aabbs[i, 3 + k] += grow


@njit
def narrow_phase(bf, bi, sf, si, geom_f, geom_i, pairs, n_pairs, sweep, speculative, raw_f, raw_i, ci):
    """Contact points of every candidate pair into ``raw_f``/``raw_i`` (pair-test format) and ``ci``
    (bodies, shapes, sensor flag).  Returns the number of points (it may exceed the capacity)."""
    n = 0
    cap = raw_f.shape[0]
    pos_a = np.empty(3)
    pos_b = np.empty(3)
    rot_a = np.empty((3, 3))
    rot_b = np.empty((3, 3))
    for p in range(n_pairs):
        a = pairs[p, 0]
        b = pairs[p, 1]
        fa = bi[a, FLAGS]
        fb = bi[b, FLAGS]
        sensor = ((fa | fb) & F_SENSOR) != 0
        if not (is_moving(bi, a) or is_moving(bi, b)):
            # Resting or static pairs have nothing to solve; a sensor still reports a sleeping body.
            if not sensor or ((fa & F_STATIC) != 0 and (fb & F_STATIC) != 0):
                continue
        # Sensors report overlaps only; solid pairs also report gaps they may close within the step.
        prediction = 0.0 if sensor else speculative + sweep[a] + sweep[b]
        for sa in range(bi[a, SHAPE_START], bi[a, SHAPE_START] + bi[a, SHAPE_COUNT]):
            shape_pose(bf, sf, sa, a, pos_a, rot_a)
            for sb in range(bi[b, SHAPE_START], bi[b, SHAPE_START] + bi[b, SHAPE_COUNT]):
                shape_pose(bf, sf, sb, b, pos_b, rot_b)
                m = collide_pair(si[sa, S_TYPE], pos_a, rot_a, sf[sa, S_PARAMS:S_PARAMS + 8],
                                 si[sb, S_TYPE], pos_b, rot_b, sf[sb, S_PARAMS:S_PARAMS + 8],
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
    return n
