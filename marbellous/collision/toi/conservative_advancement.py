"""Conservative advancement of two shapes along their extrapolated motion to their first contact (Mirtich).

The pair test (``pairs.dispatch.collide_pair``) is the distance oracle: called with a prediction, it reports
every *piece* of the pair within that distance (a convex pair is one piece; against a mesh or a height field
each triangle is one, its feature id ``triangle * 16 + code``), with its gap ``g`` and normal ``n`` (from a to
b).  Along a fixed direction the support of a convex piece moves linearly with translation and by at most
``|omega| r_reach`` with turning (``motion``), so a piece's gap closes no faster than

    c   = -(v_b(t) - v_a(t)) . n + |omega_a| r_a + |omega_b| r_b        (m/s)
    a_n = -(a_b - a_a) . n                                                (m/s^2)

and cannot close before ``time_to_close(g, c, a_n)``.  From t = 0, with horizon T:

    1. pose both shapes at t and report every piece within reach of the window w = T - t:
           prediction = (|v_b(t) - v_a(t)| + turning speeds) w + |a_b - a_a| w^2 / 2 + hit tolerance
       (a piece not reported cannot be reached within the window; when the buffer overflows, the window
       shrinks four-fold and the pair test runs again);
    2. a piece whose gap is at most the hit tolerance is reached: an IMPACT if its contact point closes
       faster than the impact speed, else a slow TOUCH (resting, sliding, grazing);
    3. otherwise t advances by the least time any piece needs to close (at most w); past T: a MISS.

At t = 0, pieces already touching (gap at most the touching tolerance) do not count: a convex pair that
touches is reported as TOUCH at once; a mesh's touching triangles are listed in ``touch`` (count first)
and skipped afterwards.  Every advance is conservative, so t never passes the motion's first contact; the
search takes one advance for a face met head on (the bound is then exact) and converges geometrically
otherwise; after ``MAX_ITERATIONS`` advances t is returned as an impact (early, never late).
"""
import math

from ..._numba.jit import njit, njit_inline
from .. import shape_types as st
from ..pairs.dispatch import collide_pair_covering
from .closing_time import time_to_close
from .motion import pose_shape_at, position_at, turning_speed, velocity_at

#: outcomes of :func:`time_of_impact`
MISS = 0        # nothing reached within the horizon: speculative contacts of the pair act on nothing
TOUCH = 1       # touching at the start, or reached slowly: a resting or sliding contact, no impact
IMPACT = 2      # reached at t closing faster than the impact speed
#: most pair tests of one search
MAX_ITERATIONS = 48


@njit
def _listed(touch, piece):
    """True if ``piece`` is among the ``touch[0]`` pieces listed in ``touch[1:]``."""
    for k in range(1, touch[0] + 1):
        if touch[k] == piece:
            return True
    return False


@njit
def made_of_pieces(stype):
    """True for the shapes whose contacts name a triangle (feature id // 16): meshes and height fields."""
    return stype == st.HEIGHTFIELD or stype == st.MESH


@njit_inline
def time_of_impact(coverage, type_a, params_a, off_f_a, off_i_a, motion_a, local_pos_a, local_quat_a, reach_a,
                   type_b, params_b, off_f_b, off_i_b, motion_b, local_pos_b, local_quat_b, reach_b,
                   geom_f, geom_i, horizon, touch_tolerance, hit_tolerance, impact_speed,
                   out_f, out_i, pos_t, rot_t, q_scratch, touch):
    """First contact of shapes a and b within ``horizon`` (s) along their motions (``motion``): returns
    ``(outcome, t)``, outcome ``MISS``, ``TOUCH`` or ``IMPACT`` (module docstring) and t (s) when reached.

    Each shape: its type, kernel record ``params`` and blob offsets, its body's ``motion``, its pose in the
    body (``local_pos`` m, ``local_quat``) and ``reach`` (``motion.rotation_reach``, m).  Tolerances in m,
    ``impact_speed`` in m/s.  Scratch: ``out_f`` (rows, 7) and ``out_i`` (rows,) a contact buffer,
    ``pos_t`` (2, 3), ``rot_t`` (2, 3, 3), ``q_scratch`` (4,); ``touch`` (1 + k,) receives the count and
    the touching pieces of a mesh or height field at t = 0.  ``coverage`` (``shape_types.COVER_*``, a
    constant where this is inlined): the pair tests the world can meet.
    """
    pieces = made_of_pieces(type_a) or made_of_pieces(type_b)
    touch[0] = 0
    turn = turning_speed(motion_a, reach_a) + turning_speed(motion_b, reach_b)
    acc_a, acc_b = motion_a[2], motion_b[2]
    ar = (acc_b[0] - acc_a[0], acc_b[1] - acc_a[1], acc_b[2] - acc_a[2])
    ar_len = math.sqrt(ar[0] * ar[0] + ar[1] * ar[1] + ar[2] * ar[2])
    wa, wb = motion_a[4], motion_b[4]
    t = 0.0
    window = horizon
    first = True
    for _ in range(MAX_ITERATIONS):
        pose_shape_at(motion_a, t, local_pos_a, local_quat_a, pos_t[0], rot_t[0], q_scratch)
        pose_shape_at(motion_b, t, local_pos_b, local_quat_b, pos_t[1], rot_t[1], q_scratch)
        w = min(window, horizon - t)
        va = velocity_at(motion_a, t)
        vb = velocity_at(motion_b, t)
        vr = (vb[0] - va[0], vb[1] - va[1], vb[2] - va[2])
        speed = math.sqrt(vr[0] * vr[0] + vr[1] * vr[1] + vr[2] * vr[2]) + turn
        prediction = speed * w + 0.5 * ar_len * w * w + hit_tolerance
        n = collide_pair_covering(coverage, type_a, pos_t[0], rot_t[0], params_a, type_b, pos_t[1], rot_t[1],
                                  params_b, geom_f, geom_i, off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f,
                                  out_i, 0)
        if n > out_f.shape[0]:
            if w <= 1e-9 * horizon:
                return IMPACT, t                # cannot tell: early is safe
            window = 0.25 * w
            continue
        xa = position_at(motion_a, t)
        xb = position_at(motion_b, t)
        step = math.inf
        slow = False
        for k in range(n):
            gap = -out_f[k, 6]
            nx, ny, nz = out_f[k, 3], out_f[k, 4], out_f[k, 5]
            piece = out_i[k] // 16 if pieces else 0
            if first and gap <= touch_tolerance:
                if not pieces or touch[0] + 1 >= touch.shape[0]:
                    return TOUCH, 0.0
                if not _listed(touch, piece):
                    touch[0] += 1
                    touch[touch[0]] = piece
                continue
            if pieces and _listed(touch, piece):
                continue
            if gap <= hit_tolerance:
                # the contact point's closing speed: (v_b + w_b x rb) - (v_a + w_a x ra) along -n
                px, py, pz = out_f[k, 0], out_f[k, 1], out_f[k, 2]
                rax, ray, raz = px - xa[0], py - xa[1], pz - xa[2]
                rbx, rby, rbz = px - xb[0], py - xb[1], pz - xb[2]
                ux = vr[0] + (wb[1] * rbz - wb[2] * rby) - (wa[1] * raz - wa[2] * ray)
                uy = vr[1] + (wb[2] * rbx - wb[0] * rbz) - (wa[2] * rax - wa[0] * raz)
                uz = vr[2] + (wb[0] * rby - wb[1] * rbx) - (wa[0] * ray - wa[1] * rax)
                if -(ux * nx + uy * ny + uz * nz) > impact_speed:
                    return IMPACT, t
                slow = True
                continue
            c = -(vr[0] * nx + vr[1] * ny + vr[2] * nz) + turn
            an = -(ar[0] * nx + ar[1] * ny + ar[2] * nz)
            step = min(step, time_to_close(gap, c, an))
        first = False
        if slow:
            return TOUCH, t
        if step >= w:
            if t + w >= horizon:
                return MISS, horizon
            t += w
        else:
            t += step
    return IMPACT, t
