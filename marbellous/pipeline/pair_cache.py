"""The body-pair cache: last step's contact points of a pair, kept in the bodies' own frames, used again while
the two bodies have hardly moved relative to each other (Jolt's body pair cache; Bullet's persistent manifold).

A pair of boxes costs the narrow phase about 0.5 us (15 separating axes, then clipping a face against the
other); a stack that stays awake finds the same points step after step.  When the narrow phase writes a pair's
points it also writes, in each contact row, the pose of body ``b`` in body ``a``'s frame and the point's two
ends and its normal in the bodies' frames:

    r_ab = R_a^T (x_b - x_a),    q_ab = q_a^* q_b                         (b seen from a)
    l_a = R_a^T (p_a - x_a),     l_b = R_b^T (p_b - x_b),    l_n = R_a^T n

with ``p_a = p + n d / 2`` and ``p_b = p - n d / 2`` the points on each surface (``p`` the contact point midway,
``n`` the normal from a to b, ``d`` the depth).  The next step, a pair whose rows are in the cache is not tested
again while b has moved less than ``KEEP_DISTANCE`` and turned less than ``KEEP_ANGLE`` in a's frame since the
rows were found, and while its prediction (the speculative distance and the two bodies' motion over the step,
within which the pair test reports points) has not grown past the one they were found with (a body that speeds
up towards the other, or one that has just hit it, is tested again); its rows are rebuilt at today's poses,

    p_a = x_a + R_a l_a,    p_b = x_b + R_b l_b,    n = R_a l_n,    d = (p_a - p_b) . n,    p = p_a - n d / 2

keeping their features (so warm starting matches them) and the pose they were found at (so that a slow drift
adds up until the pair is tested again).  Only points the pair test found twice running are kept (each
warm-started from the step before): a manifold that changes from one test to the next, a corner touching for
one step, is not carried on (kept, a heavy box on a light one dipped by 1.3 mm at 13 cm/s).  Pairs of a lone
sphere are always tested: the sphere's test is about as cheap as the check, and a rolling sphere turns past
``KEEP_ANGLE`` every step anyway.  A new feature coming within the speculative distance is found once the pair
has moved by ``KEEP_DISTANCE`` or ``KEEP_ANGLE``.
"""
import math

from .._numba.jit import njit_inline
from ..collision import shape_types as st
from ..math3d import quat_product, rotated
from ..state.layout import (C_BODY_A, C_BODY_B, C_FEATURE, C_FLAGS, C_KEEP_A, C_KEEP_B, C_KEEP_N, C_KEEP_POSE,
                            C_KEEP_REACH, C_SHAPE_A, C_SHAPE_B, CP_MATCHED, POS, QUAT, S_TYPE, SHAPE_COUNT,
                            SHAPE_START)

#: how far (m) body b may move in body a's frame before the pair is tested again (Jolt's default is 1 mm: with
#: it, a crate riding a gently accelerating platform under penalty contacts slid by 1.0 mm, past its test's 1 mm)
KEEP_DISTANCE = 2e-4
#: how far (rad) body b may turn in body a's frame before the pair is tested again (Jolt's default: 2 degrees)
KEEP_ANGLE = math.radians(0.5)
#: the cosine of half of KEEP_ANGLE: the least |q_ab . q_ab'| of two relative orientations within it
_KEEP_COS = math.cos(0.5 * KEEP_ANGLE)


@njit_inline
def cacheable(bi, si, a, b):
    """Whether the pair of body rows ``a`` and ``b`` may use the cache: neither is a lone sphere."""
    for body in (a, b):
        start = bi[body, SHAPE_START]
        if bi[body, SHAPE_COUNT] == 1 and si[start, S_TYPE] == st.SPHERE:
            return False
    return True


@njit_inline
def relative_pose(bf, a, b):
    """``(r_ab, q_ab)``: body row ``b``'s centre of mass (m) and orientation in body row ``a``'s frame."""
    q_a = (bf[a, QUAT], -bf[a, QUAT + 1], -bf[a, QUAT + 2], -bf[a, QUAT + 3])
    r = rotated(q_a, (bf[b, POS] - bf[a, POS], bf[b, POS + 1] - bf[a, POS + 1], bf[b, POS + 2] - bf[a, POS + 2]))
    return r, quat_product(q_a, (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3]))


@njit_inline
def cached_rows(pci, start, npc, a, b):
    """``(start, end)``: the cache's rows of body pair ``(a, b)`` (none: ``end == start``), from row ``start``
    on (the cache is in the broad phase's pair order, as the pairs are: the caller keeps ``start`` for the
    next pair)."""
    while start < npc and (pci[start, C_BODY_A] < a or (pci[start, C_BODY_A] == a and pci[start, C_BODY_B] < b)):
        start += 1
    end = start
    while end < npc and pci[end, C_BODY_A] == a and pci[end, C_BODY_B] == b:
        end += 1
    return start, end


@njit_inline
def still_holds(pcf, pci, row, end, r, q, prediction):
    """Whether the pair's cached rows ``row .. end - 1`` still hold at its relative pose ``(r, q)`` for today's
    ``prediction`` (m): each was warm-started from the step before (the pair test found the same features
    twice running), and they were found reaching at least as far apart."""
    for c in range(row, end):
        if (pci[c, C_FLAGS] & CP_MATCHED) == 0:
            return False
    if prediction > pcf[row, C_KEEP_REACH]:
        return False
    dx = r[0] - pcf[row, C_KEEP_POSE]
    dy = r[1] - pcf[row, C_KEEP_POSE + 1]
    dz = r[2] - pcf[row, C_KEEP_POSE + 2]
    if dx * dx + dy * dy + dz * dz > KEEP_DISTANCE * KEEP_DISTANCE:
        return False
    dot = (q[0] * pcf[row, C_KEEP_POSE + 3] + q[1] * pcf[row, C_KEEP_POSE + 4] + q[2] * pcf[row, C_KEEP_POSE + 5]
           + q[3] * pcf[row, C_KEEP_POSE + 6])
    return abs(dot) >= _KEEP_COS


@njit_inline
def reuse_rows(bf, pcf, pci, start, end, raw_f, raw_i, cf, ci, n):
    """Rebuild the cached rows ``start .. end - 1`` of a pair at today's poses (module docstring) into the
    narrow phase's rows from ``n`` (those past the tables' capacity only counted); returns the new count."""
    cap = min(raw_f.shape[0], cf.shape[0])
    for row in range(start, end):
        if n < cap:
            a, b = pci[row, C_BODY_A], pci[row, C_BODY_B]
            q_a = (bf[a, QUAT], bf[a, QUAT + 1], bf[a, QUAT + 2], bf[a, QUAT + 3])
            q_b = (bf[b, QUAT], bf[b, QUAT + 1], bf[b, QUAT + 2], bf[b, QUAT + 3])
            la = rotated(q_a, (pcf[row, C_KEEP_A], pcf[row, C_KEEP_A + 1], pcf[row, C_KEEP_A + 2]))
            lb = rotated(q_b, (pcf[row, C_KEEP_B], pcf[row, C_KEEP_B + 1], pcf[row, C_KEEP_B + 2]))
            normal = rotated(q_a, (pcf[row, C_KEEP_N], pcf[row, C_KEEP_N + 1], pcf[row, C_KEEP_N + 2]))
            depth = 0.0
            for k in range(3):
                depth += (bf[a, POS + k] + la[k] - bf[b, POS + k] - lb[k]) * normal[k]
            for k in range(3):
                raw_f[n, k] = bf[a, POS + k] + la[k] - normal[k] * 0.5 * depth
                raw_f[n, 3 + k] = normal[k]
            raw_f[n, 6] = depth
            raw_i[n] = pci[row, C_FEATURE]
            for k in range(C_KEEP_POSE, C_KEEP_REACH + 1):
                cf[n, k] = pcf[row, k]
            ci[n, C_BODY_A] = a
            ci[n, C_BODY_B] = b
            ci[n, C_SHAPE_A] = pci[row, C_SHAPE_A]
            ci[n, C_SHAPE_B] = pci[row, C_SHAPE_B]
            ci[n, C_FEATURE] = pci[row, C_FEATURE]
            ci[n, C_FLAGS] = 0
        n += 1
    return n


@njit_inline
def remember_rows(bf, a, b, r, q, prediction, raw_f, cf, first, end):
    """Write the pose ``(r, q)`` of body ``b`` in body ``a``'s frame, the pair test's ``prediction`` (m) and the
    rows' ends and normals in the bodies' frames (module docstring) into the cache columns of the narrow
    phase's new rows ``first .. end - 1`` of the pair (those within the tables' capacity)."""
    q_a = (bf[a, QUAT], -bf[a, QUAT + 1], -bf[a, QUAT + 2], -bf[a, QUAT + 3])     # R_a^T
    q_b = (bf[b, QUAT], -bf[b, QUAT + 1], -bf[b, QUAT + 2], -bf[b, QUAT + 3])     # R_b^T
    for n in range(first, min(end, raw_f.shape[0], cf.shape[0])):
        half = 0.5 * raw_f[n, 6]
        la = rotated(q_a, (raw_f[n, 0] + raw_f[n, 3] * half - bf[a, POS],
                           raw_f[n, 1] + raw_f[n, 4] * half - bf[a, POS + 1],
                           raw_f[n, 2] + raw_f[n, 5] * half - bf[a, POS + 2]))
        lb = rotated(q_b, (raw_f[n, 0] - raw_f[n, 3] * half - bf[b, POS],
                           raw_f[n, 1] - raw_f[n, 4] * half - bf[b, POS + 1],
                           raw_f[n, 2] - raw_f[n, 5] * half - bf[b, POS + 2]))
        ln = rotated(q_a, (raw_f[n, 3], raw_f[n, 4], raw_f[n, 5]))
        for k in range(3):
            cf[n, C_KEEP_POSE + k] = r[k]
            cf[n, C_KEEP_A + k] = la[k]
            cf[n, C_KEEP_B + k] = lb[k]
            cf[n, C_KEEP_N + k] = ln[k]
        for k in range(4):
            cf[n, C_KEEP_POSE + 3 + k] = q[k]
        cf[n, C_KEEP_REACH] = prediction
