"""Which bodies continuous collision sweeps, and the motion the time-of-impact search gives each body.

A body is *fast for its size* when the distance its surface may travel in the interval exceeds a fraction
of its smallest dimension:

    fast  <=>  sweep > FAST_FRACTION * extent,
               sweep = (|v| + |omega| r_reach) T + (|g| + |F| / m + |I^-1 tau| r_reach) T^2  (m)

with ``extent`` the smallest of its shapes' inner sizes (a sphere's or capsule's radius, a box's smallest
half extent).  Speculative contacts already keep a body that moves less than that from passing through
anything; a fast body's impacts are also found by time of impact, taken in time order and resolved at
their time (``pipeline/impacts.py``).  ``add_body(ccd=True)`` makes a body fast whatever its speed
(``F_CCD_ALWAYS``), ``ccd=False`` never (``F_CCD_NEVER``, which also leaves its motion out of its box).

The motion of a body over an interval, as the search extrapolates it (``collision/toi/motion.py``), is
its pose and velocities at the interval's start with gravity and its user force ``F`` as its acceleration
(its user torque ``tau`` is in its sweep, not in its motion: the search turns it at a constant rate);
static and sleeping bodies stand still.
"""
import math

from .._numba.jit import njit
from ..collision import shape_types as st
from ..collision.toi.motion import rotation_reach
from ..state.layout import (F_CCD_ALWAYS, F_CCD_NEVER, FLAGS, OMEGA, POS, QUAT, S_LOCAL_POS, S_PARAMS, S_RADIUS,
                            S_TYPE, SHAPE_COUNT, SHAPE_START, VEL)
from .forces import free_acceleration, is_moving, user_acceleration, user_angular_acceleration
from .integrators import velocity_at_end

#: a body whose surface may move more than this fraction of its smallest dimension in an interval is fast.
#: Below it, speculative contacts are enough: the body stops at the surface within the step, and its impact
#: is placed at the step's end instead of its time, a travel of less than half that dimension.  (At 0.25
#: the bench's marble, 3.6 m/s with a radius of 0.25 m at 60 Hz, was cut at impacts in 1% of its steps,
#: each costing a second run of the step and the interval loop in Python.)
FAST_FRACTION = 0.5


@njit
def shape_reach(sf, si, s):
    """How far (m) shape row ``s`` reaches from its body's centre of mass as the body turns
    (``collision/toi/motion.rotation_reach``)."""
    return rotation_reach(si[s, S_TYPE], (sf[s, S_LOCAL_POS], sf[s, S_LOCAL_POS + 1], sf[s, S_LOCAL_POS + 2]),
                          sf[s, S_RADIUS])


@njit
def body_extent(bi, sf, si, i):
    """Smallest inner size (m) of body row ``i``'s shapes: radius of a sphere or capsule, smallest half
    extent of a box, inner radius of a hull; ``inf`` for a body of static-only shapes."""
    e = math.inf
    s0 = bi[i, SHAPE_START]
    for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
        t = si[s, S_TYPE]
        if t == st.SPHERE or t == st.CAPSULE:
            e = min(e, sf[s, S_PARAMS])
        elif t == st.BOX:
            e = min(e, sf[s, S_PARAMS], sf[s, S_PARAMS + 1], sf[s, S_PARAMS + 2])
        elif t == st.HULL:
            e = min(e, sf[s, S_PARAMS + 6])
    return e


@njit
def is_fast(bi, sf, si, sweep, i, stretch):
    """True if body row ``i`` is swept by time of impact in this interval: moving, and ``ccd=True`` or fast
    for its size over the whole step: ``sweep[i]`` (m, the interval's, from the bounding-box stage) times
    ``stretch``, the step's length over the interval's (a body swept when the step began stays swept in
    the short intervals it is cut into)."""
    f = bi[i, FLAGS]
    if not is_moving(bi, i) or (f & F_CCD_NEVER) != 0:
        return False
    if (f & F_CCD_ALWAYS) != 0:
        return True
    return sweep[i] * stretch > FAST_FRACTION * body_extent(bi, sf, si, i)


@njit
def body_motion(bf, bi, i, gravity, lead):
    """The motion ``(x0, v, a, q0, omega)`` of body row ``i`` over the interval (``collision/toi/motion.py``):
    its pose and velocities now (``integrators.velocity_at_end``: ``lead`` is half the last sub-step for
    Verlet, whose stored velocity is that sub-step's mean, else 0), accelerated by ``gravity`` (m/s^2) and its
    user force if it moves; a static or sleeping body stands still."""
    x = (bf[i, POS], bf[i, POS + 1], bf[i, POS + 2])
    q = (bf[i, QUAT], bf[i, QUAT + 1], bf[i, QUAT + 2], bf[i, QUAT + 3])
    if is_moving(bi, i):
        return (x, velocity_at_end(bf, bi, i, gravity, lead), free_acceleration(bf, i, gravity), q,
                (bf[i, OMEGA], bf[i, OMEGA + 1], bf[i, OMEGA + 2]))
    zero = (0.0, 0.0, 0.0)
    return x, zero, zero, q, zero


@njit
def speed_bound(bf, bi, sf, si, i, gravity_mag, horizon):
    """Fastest (m/s) any surface point of body row ``i`` may move within ``horizon`` (s):
    ``|v| + |omega| r_reach + (|g| + |F| / m + |I^-1 tau| r_reach) T`` (0 for a static or sleeping body; ``F``,
    ``tau`` its user force and torque)."""
    if not is_moving(bi, i):
        return 0.0
    v = math.sqrt(bf[i, VEL] ** 2 + bf[i, VEL + 1] ** 2 + bf[i, VEL + 2] ** 2)
    w = math.sqrt(bf[i, OMEGA] ** 2 + bf[i, OMEGA + 1] ** 2 + bf[i, OMEGA + 2] ** 2)
    reach = 0.0
    s0 = bi[i, SHAPE_START]
    for s in range(s0, s0 + bi[i, SHAPE_COUNT]):
        reach = max(reach, shape_reach(sf, si, s))
    alpha = user_angular_acceleration(bf, i)
    return (v + (w * reach if w > 0.0 else 0.0) + (gravity_mag + user_acceleration(bf, i)) * horizon
            + (alpha * reach * horizon if alpha > 0.0 else 0.0))
