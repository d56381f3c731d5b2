"""Stage "time of impact": after the narrow phase, before anything else of the step moves a body.

1. **Impacts resolved now** (``PI_TOI_MODE`` TOI_FAST or TOI_ALL).  Contacts that touch (gap at most
   ``TOUCH_TOLERANCE``) and whose points close faster than the impact speed, on a fast body (TOI_FAST,
   ``dynamics/ccd.py``) or on any body (TOI_ALL), are resolved at once (``dynamics/impact_resolution.py``):
   an interval that ended at a time of impact goes on from the impact's resolution.
2. **Speculative contacts that nothing reaches are dropped** (every mode).  A speculative contact with gap
   ``g`` lets its bodies approach by ``g`` along its normal in the step, and that stops a body that would
   have passed the other shape (a ghost collision).  The bodies close along the normal by at most

       D = (c + |w_a| r_a + |w_b| r_b) tau + max(a_n, 0) tau^2 / 2,   c = -(v_b - v_a) . n,  a_n = -(g_b - g_a) . n

   over the time tau = T + h the contact acts (the step T and one sub-step h = T / substeps beyond it: the relax
   pass after the last sub-step lets a speculative contact close its gap in the sub-step that would
   follow): a contact with ``D <= g`` cannot act and stays; otherwise the pair's time of impact decides
   (closed forms for centred spheres and a sphere on a plane, ``collision/toi/closed_forms.py``; else the
   search of ``collision/toi/conservative_advancement.py``): a MISS (no piece of the pair reached within T + h)
   drops it, unless its triangle touches already; so does an IMPACT of a swept body (step 3) at or after
   T: the next interval takes it in time order, and the sub-step beyond T would make it bounce early.
3. **The earliest impact ends the interval**: with ``PI_TOI_SPLIT`` the step returns ``SPLIT`` before
   anything is solved, asking in ``time_f[T_LIMIT]`` for an interval that ends at that impact (at least
   ``PF_MIN_INTERVAL``).  TOI_FAST counts impacts of fast bodies; TOI_ALL (conservative advancement) every
   impact, and also bounds the pairs the narrow phase did not report: without the step's motion in their
   boxes (continuous collision off, ``ccd=False`` bodies) such a pair is farther apart than the speculative
   distance ``d_s``, so it cannot touch before ``d_s / (2 max_i s_i)`` with ``s_i`` the bodies' speed bounds
   (``dynamics/ccd.speed_bound``).  Only the velocities of step 1 have changed then, and a rerun finds
   those impacts resolved.  Nor does an interval let a body with contacts turn by more than
   ``MAX_CONTACT_TURN`` (a shape that turning moves: not a centred sphere): the contact points are found
   once per interval, and a box spinning at 660 rad/s after hitting a 1 cm wall at 100 m/s turned 11 rad
   in the rest of the step; the corners that came round had no contact point, and it went through.
4. ``PI_DETECT``: the step returns ``DETECTED`` right after the narrow phase (the retroactive mode's
   detection pass: the contacts at the current poses, nothing else).
"""
import math

from .._numba.jit import njit, njit_inline
from ..collision import shape_types as st
from ..collision.shape_types import COVER_ALL, COVER_GROUND, COVER_MESHES, COVER_SPHERES
from ..collision.toi.closed_forms import gap_comes_within, spheres_come_within
from ..collision.toi.conservative_advancement import IMPACT, MISS, made_of_pieces, time_of_impact
from ..collision.toi.motion import pose_shape_at
from ..collision.toi.sphere_mesh_reach import sphere_reaches_triangle
from ..collision.vec3 import matrix
from ..dynamics.ccd import body_motion, is_fast, shape_reach, speed_bound
from ..dynamics.forces import is_moving
from ..dynamics.impact_resolution import closing_speed, resolve_impacts
from ..dynamics.integrators import VERLET, restart_at_end, velocity_at_end
from ..state.layout import (CI_COLS, CP_SENSOR, C_BODY_A, C_BODY_B, C_DEPTH, C_FEATURE, C_FLAGS, C_KEEP_POSE,
                            C_KEEP_REACH, C_NORMAL, C_SHAPE_A, FLAGS, F_JOINTED, F_KINEMATIC, SHAPE_COUNT, SHAPE_START,
                            C_SHAPE_B, IMPACT_COLS, OMEGA, PF_DT, PF_GRAVITY, PF_MIN_INTERVAL, PF_RESTITUTION_SPEED,
                            PF_SPECULATIVE, PF_STEP_DT, PF_TOLERANCE, PI_DETECT, PI_INTEGRATOR, PI_SUBSTEPS,
                            PI_TOI_MODE, PI_TOI_SPLIT, POS, STAT_CONTACTS, S_LOCAL_POS, S_LOCAL_QUAT, S_OFF_F, S_OFF_I,
                            S_PARAMS, S_TYPE, TOI_ALL, TOI_FAST, TOI_NONE, T_DROPPED, T_LIMIT, T_RESOLVED, W_PREV_DT)

#: statuses of the step besides OK (0), GROW_PAIRS (1) and GROW_CONTACTS (2) of ``pipeline/step.py``
SPLIT = 3
DETECTED = 4
#: a contact whose gap is at most this (m) touches: it is never dropped and never ends an interval
TOUCH_TOLERANCE = 5e-4
#: the time-of-impact search has reached a piece when its gap is at most this (m)
HIT_TOLERANCE = 5e-5
#: an impact at or after this fraction of the interval is at its end (rounding of the time-of-impact search)
LATE = 1.0 - 1e-9
#: contacts closing slower than this (m/s; or the restitution speed, if more) are not impacts
MIN_IMPACT_SPEED = 0.01


@njit
def impact_speed(params_f):
    """Closing speed (m/s) above which a contact is an impact: the restitution threshold (gravity of one
    sub-step), at least MIN_IMPACT_SPEED."""
    return max(params_f[PF_RESTITUTION_SPEED], MIN_IMPACT_SPEED)


@njit_inline
def _swept(mode, bi, sf, si, sweep, a, b, stretch):
    """Whether a contact of bodies ``a`` and ``b`` takes part in time-of-impact ordering in ``mode``
    (``stretch``: the step's length over the interval's, ``dynamics/ccd.is_fast``).  Never when a body is
    held by a joint: an impact resolved at its time treats both bodies as free, and the joint's pull comes
    only from the solver (resolved free, a 1 kg plank of a hinged bridge took a falling 5 kg ball's
    momentum alone, and the joints then threw the ball metres up); the solver takes such a pair by its
    speculative contacts.  Nor with a kinematic body: its motion is given, not found by a sweep."""
    if ((bi[a, FLAGS] | bi[b, FLAGS]) & (F_JOINTED | F_KINEMATIC)) != 0:
        return False
    if mode == TOI_ALL:
        return True
    return mode == TOI_FAST and (is_fast(bi, sf, si, sweep, a, stretch) or is_fast(bi, sf, si, sweep, b, stretch))


@njit_inline
def _list_impacts(ctx, mode, speed, stretch):
    """The touching contacts that close faster than ``speed`` (m/s) on swept bodies, into
    ``ctx.contact_order`` (scratch until the prepare stage); returns how many."""
    cf, ci, bf, bi, sf, si, sweep = ctx.cf, ctx.ci, ctx.bf, ctx.bi, ctx.sf, ctx.si, ctx.sweep
    listed = ctx.contact_order
    m = 0
    for c in range(ctx.nc):
        if cf[c, C_DEPTH] < -TOUCH_TOLERANCE or (ci[c, C_FLAGS] & CP_SENSOR) != 0:
            continue
        a = ci[c, C_BODY_A]
        b = ci[c, C_BODY_B]
        if closing_speed(bf, bi, cf, ci, c) > speed and _swept(mode, bi, sf, si, sweep, a, b, stretch):
            listed[m] = c
            m += 1
    return m


@njit
def _turning(bf, bi, sf, si, i, s):
    """``|omega| r_reach`` (m/s) of shape row ``s`` on body row ``i`` (0 unless it moves and turns)."""
    if not is_moving(bi, i):
        return 0.0
    w = math.sqrt(bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2)
    return w * shape_reach(sf, si, s) if w > 0.0 else 0.0


#: the most a body with contacts turns in one interval (rad), with ``PI_TOI_SPLIT`` (module docstring, 3.)
MAX_CONTACT_TURN = 0.5


@njit
def turn_limit(bf, bi, sf, si, ci, c, horizon):
    """Seconds in which a body of contact ``c`` turns by ``MAX_CONTACT_TURN``, when that is within ``horizon``
    (s); inf if neither body turns that far in it, or moves a surface by turning (static, asleep, or a
    centred sphere).  A body's ``|omega|^2`` is compared first: most turn far less in an interval."""
    fastest = (MAX_CONTACT_TURN / horizon) ** 2
    w2 = 0.0
    for body, shape in ((ci[c, C_BODY_A], ci[c, C_SHAPE_A]), (ci[c, C_BODY_B], ci[c, C_SHAPE_B])):
        if is_moving(bi, body):
            spin = bf[body, OMEGA] ** 2 + bf[body, OMEGA + 1] ** 2 + bf[body, OMEGA + 2] ** 2
            if spin > max(w2, fastest) and shape_reach(sf, si, shape) > 0.0:
                w2 = spin
    return MAX_CONTACT_TURN / math.sqrt(w2) if w2 > 0.0 else math.inf


@njit
def body_pass(bf, bi, sf, si, sweep, nb, mode, stretch, horizon):
    """``(swept, spinning)``: whether some body may take part in time-of-impact ordering in ``mode``
    (:func:`_swept` can hold for a contact), and whether some moving body turns by more than
    ``MAX_CONTACT_TURN`` within ``horizon`` (s) with a shape that turning moves (:func:`turn_limit` can end
    the interval).  One pass over the bodies spares every contact those tests when neither holds, as in a
    resting pile: each would read both bodies' rows again."""
    swept = mode == TOI_ALL
    spinning = False
    fastest = (MAX_CONTACT_TURN / horizon) ** 2
    for i in range(nb):
        if not is_moving(bi, i):
            continue
        if mode == TOI_FAST and not swept and is_fast(bi, sf, si, sweep, i, stretch):
            swept = True
        if not spinning and bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2 > fastest:
            s0 = bi[i, SHAPE_START]
            for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
                spinning = spinning or shape_reach(sf, si, s) > 0.0
        if swept and spinning:
            break
    return swept, spinning


@njit
def _normal_closing(bf, bi, cf, ci, c, gravity, lead):
    """``(c, a_n)`` of contact ``c``: the closing speed (m/s) and acceleration (m/s^2) of its bodies' centres
    along its normal (module docstring; a static or sleeping body stands still; ``lead`` as in
    ``ccd.body_motion``)."""
    a = ci[c, C_BODY_A]
    b = ci[c, C_BODY_B]
    ma = is_moving(bi, a)
    mb = is_moving(bi, b)
    va = velocity_at_end(bf, bi, a, gravity, lead)
    vb = velocity_at_end(bf, bi, b, gravity, lead)
    c_lin = 0.0
    a_n = 0.0
    for k in range(3):
        n = cf[c, C_NORMAL + k]
        if mb:
            c_lin -= vb[k] * n
            a_n -= gravity[k] * n
        if ma:
            c_lin += va[k] * n
            a_n += gravity[k] * n
    return c_lin, a_n


@njit
def may_close(bf, bi, sf, si, cf, ci, c, gravity, horizon, lead):
    """True if speculative contact ``c`` can close its gap within ``horizon`` (s) at all (module docstring,
    the bound D; ``lead`` as in ``ccd.body_motion``)."""
    c_lin, a_n = _normal_closing(bf, bi, cf, ci, c, gravity, lead)
    speed = (c_lin + _turning(bf, bi, sf, si, ci[c, C_BODY_A], ci[c, C_SHAPE_A])
             + _turning(bf, bi, sf, si, ci[c, C_BODY_B], ci[c, C_SHAPE_B]))
    return speed * horizon + 0.5 * max(a_n, 0.0) * horizon * horizon > -cf[c, C_DEPTH]


@njit
def _centred(sf, s):
    """True if shape row ``s`` sits at its body's centre of mass (it turns in place)."""
    return sf[s, S_LOCAL_POS] == 0.0 and sf[s, S_LOCAL_POS + 1] == 0.0 and sf[s, S_LOCAL_POS + 2] == 0.0


@njit
def closed_form_reach(bf, bi, sf, si, cf, ci, c, gravity, horizon, lead, geom_f, geom_i, pos_t, rot_t, q):
    """1 if the pair of contact ``c`` comes within the hit tolerance in ``horizon`` (s), 0 if it does not, by
    the closed forms of ``collision/toi/closed_forms.py`` (two centred spheres with the same acceleration;
    a centred sphere and a plane), or 1 when a centred sphere touches the triangle of its contact with a mesh
    or height field that stands still at one of the times ``collision/toi/sphere_mesh_reach.py`` tries; -1
    otherwise (the search decides).  ``lead`` as in ``ccd.body_motion``; ``pos_t`` (2, 3), ``rot_t`` (2, 3, 3)
    and ``q`` (4,) scratch."""
    a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
    sa, sb = ci[c, C_SHAPE_A], ci[c, C_SHAPE_B]
    ta, tb = si[sa, S_TYPE], si[sb, S_TYPE]
    if ta == st.SPHERE and tb == st.SPHERE:
        ma = is_moving(bi, a)
        if ma != is_moving(bi, b) or not (_centred(sf, sa) and _centred(sf, sb)):
            return -1
        d0 = (bf[b, POS] - bf[a, POS], bf[b, POS + 1] - bf[a, POS + 1], bf[b, POS + 2] - bf[a, POS + 2])
        u = (0.0, 0.0, 0.0)
        if ma:
            va = velocity_at_end(bf, bi, a, gravity, lead)
            vb = velocity_at_end(bf, bi, b, gravity, lead)
            u = (vb[0] - va[0], vb[1] - va[1], vb[2] - va[2])
        return int(spheres_come_within(d0, u, sf[sa, S_PARAMS] + sf[sb, S_PARAMS], horizon, HIT_TOLERANCE))
    if (ta == st.SPHERE and tb == st.PLANE and _centred(sf, sa)) or \
            (tb == st.SPHERE and ta == st.PLANE and _centred(sf, sb)):
        c_lin, a_n = _normal_closing(bf, bi, cf, ci, c, gravity, lead)
        return int(gap_comes_within(-cf[c, C_DEPTH], c_lin, a_n, horizon, HIT_TOLERANCE))
    if made_of_pieces(ta) and tb == st.SPHERE:
        a, b, sa, sb, ta, tb = b, a, sb, sa, tb, ta
    elif not (ta == st.SPHERE and made_of_pieces(tb)):
        return -1
    if not _centred(sf, sa) or is_moving(bi, b):
        return -1
    pose_shape_at(body_motion(bf, bi, b, gravity, lead), 0.0,
                  (sf[sb, S_LOCAL_POS], sf[sb, S_LOCAL_POS + 1], sf[sb, S_LOCAL_POS + 2]),
                  (sf[sb, S_LOCAL_QUAT], sf[sb, S_LOCAL_QUAT + 1], sf[sb, S_LOCAL_QUAT + 2], sf[sb, S_LOCAL_QUAT + 3]),
                  pos_t[1], rot_t[1], q)
    if sphere_reaches_triangle(body_motion(bf, bi, a, gravity, lead), sf[sa, S_PARAMS],
                               (pos_t[1, 0], pos_t[1, 1], pos_t[1, 2]), matrix(rot_t[1]), tb == st.HEIGHTFIELD,
                               sf[sb, S_PARAMS:S_PARAMS + st.N_SHAPE_PARAMS], geom_f, geom_i, si[sb, S_OFF_F],
                               si[sb, S_OFF_I], ci[c, C_FEATURE] // 16, horizon):
        return 1
    return -1


@njit_inline
def _pair_time_of_impact(coverage, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                         pos_t, rot_t, q, touch):
    """:func:`pair_time_of_impact` with the pair tests of ``coverage``."""
    a, b = ci[c, C_BODY_A], ci[c, C_BODY_B]
    sa, sb = ci[c, C_SHAPE_A], ci[c, C_SHAPE_B]
    return time_of_impact(
        coverage,
        si[sa, S_TYPE], sf[sa, S_PARAMS:S_PARAMS + st.N_SHAPE_PARAMS], si[sa, S_OFF_F], si[sa, S_OFF_I],
        body_motion(bf, bi, a, gravity, lead), (sf[sa, S_LOCAL_POS], sf[sa, S_LOCAL_POS + 1], sf[sa, S_LOCAL_POS + 2]),
        (sf[sa, S_LOCAL_QUAT], sf[sa, S_LOCAL_QUAT + 1], sf[sa, S_LOCAL_QUAT + 2], sf[sa, S_LOCAL_QUAT + 3]),
        shape_reach(sf, si, sa),
        si[sb, S_TYPE], sf[sb, S_PARAMS:S_PARAMS + st.N_SHAPE_PARAMS], si[sb, S_OFF_F], si[sb, S_OFF_I],
        body_motion(bf, bi, b, gravity, lead), (sf[sb, S_LOCAL_POS], sf[sb, S_LOCAL_POS + 1], sf[sb, S_LOCAL_POS + 2]),
        (sf[sb, S_LOCAL_QUAT], sf[sb, S_LOCAL_QUAT + 1], sf[sb, S_LOCAL_QUAT + 2], sf[sb, S_LOCAL_QUAT + 3]),
        shape_reach(sf, si, sb),
        geom_f, geom_i, horizon, TOUCH_TOLERANCE, HIT_TOLERANCE, speed, out_f, out_i, pos_t, rot_t, q, touch)


@njit
def pair_time_of_impact_spheres(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                                pos_t, rot_t, q, touch):
    """:func:`pair_time_of_impact` in a world of coverage ``COVER_SPHERES``."""
    return _pair_time_of_impact(COVER_SPHERES, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed,
                                out_f, out_i, pos_t, rot_t, q, touch)


@njit
def pair_time_of_impact_meshes(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                               pos_t, rot_t, q, touch):
    """:func:`pair_time_of_impact` in a world of coverage ``COVER_MESHES``."""
    return _pair_time_of_impact(COVER_MESHES, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed,
                                out_f, out_i, pos_t, rot_t, q, touch)


@njit
def pair_time_of_impact_ground(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                               pos_t, rot_t, q, touch):
    """:func:`pair_time_of_impact` in a world of coverage ``COVER_GROUND``."""
    return _pair_time_of_impact(COVER_GROUND, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed,
                                out_f, out_i, pos_t, rot_t, q, touch)


@njit
def pair_time_of_impact_all(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                            pos_t, rot_t, q, touch):
    """:func:`pair_time_of_impact` with every pair test."""
    return _pair_time_of_impact(COVER_ALL, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed,
                                out_f, out_i, pos_t, rot_t, q, touch)


@njit_inline
def pair_time_of_impact(coverage, bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                        pos_t, rot_t, q, touch):
    """``(outcome, t)`` of the time-of-impact search for the shape pair of contact ``c`` within ``horizon``
    (s), impacts closing faster than ``speed`` (m/s); ``touch`` receives a mesh's touching triangles.
    ``coverage`` (``shape_types.COVER_*``, a constant where this is inlined) picks the compiled search
    with the pair tests the world can meet."""
    if coverage == COVER_SPHERES:
        return pair_time_of_impact_spheres(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f,
                                           out_i, pos_t, rot_t, q, touch)
    if coverage == COVER_MESHES:
        return pair_time_of_impact_meshes(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f,
                                          out_i, pos_t, rot_t, q, touch)
    if coverage == COVER_GROUND:
        return pair_time_of_impact_ground(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f,
                                          out_i, pos_t, rot_t, q, touch)
    return pair_time_of_impact_all(bf, bi, sf, si, geom_f, geom_i, ci, c, gravity, lead, horizon, speed, out_f, out_i,
                                   pos_t, rot_t, q, touch)


@njit
def touching_piece(si, ci, c, touch):
    """True if contact ``c`` lies on a triangle that ``touch`` lists (contacts with meshes and height fields;
    a convex pair is one piece and lists none)."""
    if not (made_of_pieces(si[ci[c, C_SHAPE_A], S_TYPE]) or made_of_pieces(si[ci[c, C_SHAPE_B], S_TYPE])):
        return False
    piece = ci[c, C_FEATURE] // 16
    for k in range(1, touch[0] + 1):
        if touch[k] == piece:
            return True
    return False


@njit
def unseen_bound(bf, bi, sf, si, sweep, nb, speculative, gravity_mag, horizon):
    """Earliest time (s) a pair the narrow phase did not report can touch, when some moving body has no
    motion in its box: ``d_s / (2 max s_i)`` over those bodies (module docstring); inf when there is none."""
    fastest = 0.0
    for i in range(nb):
        if sweep[i] == 0.0 and is_moving(bi, i):
            fastest = max(fastest, speed_bound(bf, bi, sf, si, i, gravity_mag, horizon))
    return speculative / (2.0 * fastest) if fastest > 0.0 else math.inf


@njit_inline
def _keep_row(cf, ci, impact_f, c, kept):
    """Move contact row ``c`` (the narrow phase's columns and its body-pair cache's, its ids, its impact
    impulses) to row ``kept``."""
    for k in range(7):
        cf[kept, k] = cf[c, k]
    for k in range(C_KEEP_POSE, C_KEEP_REACH + 1):
        cf[kept, k] = cf[c, k]
    for k in range(CI_COLS):
        ci[kept, k] = ci[c, k]
    for k in range(IMPACT_COLS):
        impact_f[kept, k] = impact_f[c, k]


@njit_inline
def stage_time_of_impact(ctx, coverage):
    """Stage "time of impact" (module docstring), with the pair tests of ``coverage``
    (``shape_types.COVER_*``): returns OK, SPLIT or DETECTED."""
    params_i, params_f = ctx.params_i, ctx.params_f
    if params_i[PI_DETECT] != 0:
        return DETECTED
    mode = params_i[PI_TOI_MODE]
    horizon = params_f[PF_DT]
    acting = horizon + horizon / params_i[PI_SUBSTEPS]     # T + h: how long a speculative contact acts
    stretch = params_f[PF_STEP_DT] / horizon
    time_f = ctx.time_f
    time_f[T_RESOLVED] = 0.0
    limit = math.inf
    nc = ctx.nc
    if nc > 0:
        bf, bi, sf, si, cf, ci, impact_f = ctx.bf, ctx.bi, ctx.sf, ctx.si, ctx.cf, ctx.ci, ctx.impact_f
        sweep = ctx.sweep
        speed = impact_speed(params_f)
        swept_any, spinning = False, False
        if mode != TOI_NONE:
            swept_any, spinning = body_pass(bf, bi, sf, si, sweep, ctx.nb, mode, stretch, horizon)
        gravity = (params_f[PF_GRAVITY], params_f[PF_GRAVITY + 1], params_f[PF_GRAVITY + 2])
        # Verlet stores each body's mean velocity over the last sub-step: half a sub-step behind its end
        lead = 0.5 * ctx.ws[W_PREV_DT] if params_i[PI_INTEGRATOR] == VERLET else 0.0
        if swept_any:
            m = _list_impacts(ctx, mode, speed, stretch)
            if m > 0:
                for c in range(nc):
                    for k in range(IMPACT_COLS):
                        impact_f[c, k] = 0.0
                if lead > 0.0:
                    for k in range(m):
                        c = ctx.contact_order[k]
                        restart_at_end(bf, bi, ci[c, C_BODY_A], gravity, lead)
                        restart_at_end(bf, bi, ci[c, C_BODY_B], gravity, lead)
                resolve_impacts(bf, bi, ctx.nb, cf, ci, ctx.contact_order, m, ctx.solver_bodies, impact_f,
                                params_f[PF_TOLERANCE])
                time_f[T_RESOLVED] = m
                swept_any, spinning = body_pass(bf, bi, sf, si, sweep, ctx.nb, mode, stretch, horizon)  # new spins
        splitting = params_i[PI_TOI_SPLIT] != 0 and spinning
        kept = 0
        last_a = -1
        last_b = -1
        gone = True
        for c in range(nc):
            keep = True
            if cf[c, C_DEPTH] < -TOUCH_TOLERANCE and (ci[c, C_FLAGS] & CP_SENSOR) == 0 \
                    and may_close(bf, bi, sf, si, cf, ci, c, gravity, acting, lead):
                if ci[c, C_SHAPE_A] != last_a or ci[c, C_SHAPE_B] != last_b:
                    last_a = ci[c, C_SHAPE_A]
                    last_b = ci[c, C_SHAPE_B]
                    ctx.toi_touch[0] = 0
                    swept = swept_any and _swept(mode, bi, sf, si, sweep, ci[c, C_BODY_A], ci[c, C_BODY_B],
                                                 stretch)
                    reach = -1 if swept else closed_form_reach(bf, bi, sf, si, cf, ci, c, gravity, acting, lead,
                                                               ctx.geom_f, ctx.geom_i, ctx.toi_pos, ctx.toi_rot,
                                                               ctx.toi_q)
                    if reach >= 0:
                        gone = reach == 0
                    else:
                        outcome, t_hit = pair_time_of_impact(coverage, bf, bi, sf, si, ctx.geom_f, ctx.geom_i, ci,
                                                             c, gravity, lead, acting, speed, ctx.toi_f, ctx.toi_i,
                                                             ctx.toi_pos, ctx.toi_rot, ctx.toi_q, ctx.toi_touch)
                        gone = outcome == MISS
                        if outcome == IMPACT and swept:
                            limit = min(limit, t_hit)
                            gone = t_hit >= horizon * LATE   # the next interval takes it in time order
                keep = not gone or touching_piece(si, ci, c, ctx.toi_touch)
            if keep:
                if splitting:
                    limit = min(limit, turn_limit(bf, bi, sf, si, ci, c, horizon))
                if kept < c:
                    _keep_row(cf, ci, impact_f, c, kept)
                kept += 1
        time_f[T_DROPPED] = nc - kept
        ctx.nc = kept
        ctx.stats[STAT_CONTACTS] = kept
    if mode == TOI_ALL:
        gx, gy, gz = params_f[PF_GRAVITY], params_f[PF_GRAVITY + 1], params_f[PF_GRAVITY + 2]
        limit = min(limit, unseen_bound(ctx.bf, ctx.bi, ctx.sf, ctx.si, ctx.sweep, ctx.nb, params_f[PF_SPECULATIVE],
                                        math.sqrt(gx * gx + gy * gy + gz * gz), horizon))
    if params_i[PI_TOI_SPLIT] != 0 and limit < horizon:
        limit = max(limit, params_f[PF_MIN_INTERVAL])
        if limit < horizon * LATE:
            time_f[T_LIMIT] = limit
            return SPLIT
    return 0
