"""Soft constraints (Box2D v3's "soft step"): a constraint as a damped spring of given frequency.

For a constraint error C and stiffness expressed as a frequency ``hertz`` with damping ratio ``zeta``,
over a sub-step h (``omega = 2 pi hertz``):

    a1 = 2 zeta + h omega,  a2 = h omega a1,  a3 = 1 / (1 + a2)
    bias_rate = omega / a1,  mass_scale = a2 a3,  impulse_scale = a3

and the impulse is ``-m_eff mass_scale (J v + bias_rate C) - impulse_scale lambda``.  Position errors
are removed at a bounded rate, and the "relax" pass that follows (bias 0, mass_scale 1,
impulse_scale 0) takes the correction velocity out again, so position correction adds no energy.
"""
import math

from .._numba.jit import njit_inline

#: The deepest overlap (m) that a contact's soft solve passes open through the velocities.  Deeper overlap
#: is pushed out by split impulses (``contact_solver.push_contacts``), which move poses and are never kept
#: as velocity.  A resting contact sinks a fraction of a millimetre (``g / omega^2`` per body of load, 0.07 mm
#: at 60 Hz), far less than this; bodies spawned into one another are centimetres to metres deep, and
#: opened through the velocities the bias of every contact of a heap added up along its chains (100
#: spheres spawned at one point flew apart at 27 m/s in the first step, 1,000 at 215 m/s).
SOFT_DEPTH = 0.01


@njit_inline
def soft_depth(rate, max_push):
    """``D`` (m): the overlap the soft solve passes open through the velocities, at ``rate d`` (1/s times m)
    up to ``D = min(max_push / rate, SOFT_DEPTH)``; 0 when ``rate`` is 0 (rigid passes, the LCP's rows)."""
    if rate <= 0.0:
        return 0.0
    return min(max_push / rate, SOFT_DEPTH)


@njit_inline
def soft_coefficients(hertz, zeta, h, out):
    """Write ``(bias_rate (1/s), mass_scale, impulse_scale)`` of a soft constraint into ``out``."""
    if hertz <= 0.0:
        out[0] = 0.0
        out[1] = 1.0
        out[2] = 0.0
        return
    omega = 2.0 * math.pi * hertz
    a1 = 2.0 * zeta + h * omega
    a2 = h * omega * a1
    a3 = 1.0 / (1.0 + a2)
    out[0] = omega / a1
    out[1] = a2 * a3
    out[2] = a3
