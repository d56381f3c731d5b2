"""The solver's view of the bodies: one compact row per body with everything a constraint touches.

Row ``i`` of the (nb, SB_COLS) table ``sb`` holds

    SB_INV_MASS  1/m                                    (1/kg)
    SB_INV_I     R I_body^-1 R^T, row-major, 9 values   (1/(kg m^2))
    SB_V, SB_W   linear and angular velocity            (m/s, rad/s)
    SB_DP        displacement since the step began      (m)
    SB_DTHETA    rotation vector since the step began,  (rad)
                 scaled by sin(theta) / theta
    SB_ISO       s when I_w^-1 = s E, else -1: impulses then skip the matrix product

Static and sleeping bodies get zero inverse mass and inertia, so every constraint treats them as
immovable without a branch.  The sequential-impulse solver works on these rows alone (three cache lines
per body instead of the body table's nine): ``prepare_solver_bodies`` loads them, ``store_velocities``
writes the solved velocities back.

The velocity of a body is handled as a 6-tuple ``u = (v, omega)`` so that a constraint reads its two
bodies once, updates them in registers and writes them back once.
"""
import math

from .._numba.jit import njit, njit_inline
from ..math3d import cross
from ..state.layout import (DTHETA, F_ISOTROPIC, FLAGS, INV_I, INV_MASS, OMEGA, POS, POS0, QUAT, SB_DP, SB_DTHETA,
                            SB_INV_I, SB_INV_MASS, SB_ISO, SB_V, SB_W, VEL)
from .forces import is_moving
from .rigid import inverse_inertia_world



@njit_inline
def prepare_solver_bodies(bf, bi, nb, sb):
    """Fill ``sb`` from the bodies' current poses and velocities."""
    for i in range(nb):
        moving = is_moving(bi, i)
        if moving and (bi[i, FLAGS] & F_ISOTROPIC) != 0:
            # R (s E) R^T = s E: the body-frame inverse inertia is already the world one.
            sb[i, SB_INV_MASS] = bf[i, INV_MASS]
            for k in range(9):
                sb[i, SB_INV_I + k] = bf[i, INV_I + k]
            sb[i, SB_ISO] = bf[i, INV_I]
        elif moving:
            sb[i, SB_INV_MASS] = bf[i, INV_MASS]
            iw = inverse_inertia_world(bf, i, (bf[i, QUAT], bf[i, QUAT + 1], bf[i, QUAT + 2], bf[i, QUAT + 3]))
            for k in range(9):
                sb[i, SB_INV_I + k] = iw[k]
            sb[i, SB_ISO] = -1.0
        else:
            for k in range(10):
                sb[i, k] = 0.0
            sb[i, SB_ISO] = 0.0
        # the rotation vector scaled by sin(theta) / theta (1 - theta^2 / 6 below 0.01 rad, within 1e-10)
        t0, t1, t2 = bf[i, DTHETA], bf[i, DTHETA + 1], bf[i, DTHETA + 2]
        theta2 = t0 * t0 + t1 * t1 + t2 * t2
        sinc = 1.0 - theta2 / 6.0 if theta2 < 1e-4 else math.sin(math.sqrt(theta2)) / math.sqrt(theta2)
        for k in range(3):
            sb[i, SB_V + k] = bf[i, VEL + k]
            sb[i, SB_W + k] = bf[i, OMEGA + k]
            sb[i, SB_DP + k] = bf[i, POS + k] - bf[i, POS0 + k]
            sb[i, SB_DTHETA + k] = bf[i, DTHETA + k] * sinc


@njit_inline
def store_velocities(bf, bi, nb, sb):
    """Write the solved velocities of the moving bodies back to the body table."""
    for i in range(nb):
        if is_moving(bi, i):
            for k in range(3):
                bf[i, VEL + k] = sb[i, SB_V + k]
                bf[i, OMEGA + k] = sb[i, SB_W + k]


@njit
def velocity(sb, i):
    """``u = (v, omega)`` of body ``i`` (m/s, rad/s)."""
    return (sb[i, SB_V], sb[i, SB_V + 1], sb[i, SB_V + 2], sb[i, SB_W], sb[i, SB_W + 1], sb[i, SB_W + 2])


@njit
def set_velocity(sb, i, u):
    """Write ``u = (v, omega)`` to body ``i``."""
    for k in range(3):
        sb[i, SB_V + k] = u[k]
        sb[i, SB_W + k] = u[3 + k]


@njit
def motion(sb, i):
    """``(dx, dtheta)`` of body ``i`` since the step began (m, rad), shaped like a velocity."""
    return (sb[i, SB_DP], sb[i, SB_DP + 1], sb[i, SB_DP + 2],
            sb[i, SB_DTHETA], sb[i, SB_DTHETA + 1], sb[i, SB_DTHETA + 2])


@njit
def velocity_at(u, r):
    """Velocity of the point at offset ``r`` of a body moving with ``u = (v, omega)``:  v + omega x r."""
    return (u[0] + u[4] * r[2] - u[5] * r[1],
            u[1] + u[5] * r[0] - u[3] * r[2],
            u[2] + u[3] * r[1] - u[4] * r[0])


@njit
def relative_velocity_at(ua, ra, ub, rb):
    """``(v_b + w_b x rb) - (v_a + w_a x ra)`` (m/s)."""
    pa = velocity_at(ua, ra)
    pb = velocity_at(ub, rb)
    return pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]


@njit
def push(sb, i, u, r, px, py, pz, sign):
    """``u`` of body ``i`` after the impulse ``sign p`` (N s) at offset ``r``:
    v += sign p / m,  omega += sign I_w^-1 (r x p)."""
    iso = sb[i, SB_ISO]
    if iso == 0.0:
        return u                    # static or sleeping: nothing moves it
    cx = r[1] * pz - r[2] * py
    cy = r[2] * px - r[0] * pz
    cz = r[0] * py - r[1] * px
    im = sign * sb[i, SB_INV_MASS]
    if iso > 0.0:
        si = sign * iso
        return u[0] + im * px, u[1] + im * py, u[2] + im * pz, u[3] + si * cx, u[4] + si * cy, u[5] + si * cz
    return (u[0] + im * px, u[1] + im * py, u[2] + im * pz,
            u[3] + sign * (sb[i, SB_INV_I] * cx + sb[i, SB_INV_I + 1] * cy + sb[i, SB_INV_I + 2] * cz),
            u[4] + sign * (sb[i, SB_INV_I + 3] * cx + sb[i, SB_INV_I + 4] * cy + sb[i, SB_INV_I + 5] * cz),
            u[5] + sign * (sb[i, SB_INV_I + 6] * cx + sb[i, SB_INV_I + 7] * cy + sb[i, SB_INV_I + 8] * cz))


@njit_inline
def twist(u, inv_i, impulse, sign):
    """``u`` of a body of world inverse inertia ``inv_i`` (row-major 9-tuple) after the angular impulse
    ``sign l`` (``l`` = ``impulse``, N m s):

        omega += sign I_w^-1 l

    Plain arithmetic, so the wide floats of ``contact_bundles`` take it too, lane by lane with the same
    rounding."""
    return (u[0], u[1], u[2],
            u[3] + sign * (inv_i[0] * impulse[0] + inv_i[1] * impulse[1] + inv_i[2] * impulse[2]),
            u[4] + sign * (inv_i[3] * impulse[0] + inv_i[4] * impulse[1] + inv_i[5] * impulse[2]),
            u[5] + sign * (inv_i[6] * impulse[0] + inv_i[7] * impulse[1] + inv_i[8] * impulse[2]))


@njit_inline
def _isotropic_term(iso, c):
    """``c . (iso E) c`` (1/kg) for ``c = r x d`` when ``I_w^-1 = iso E``: the products with the zero entries
    left out, so rounded as the full product."""
    return c[0] * (iso * c[0]) + c[1] * (iso * c[1]) + c[2] * (iso * c[2])


@njit
def _angular_term(sb, i, r, d):
    """``(r x d) . I_w^-1 (r x d)`` of body ``i`` (1/kg)."""
    c = cross(r, d)
    iso = sb[i, SB_ISO]
    if iso >= 0.0:
        return _isotropic_term(iso, c)
    cx, cy, cz = c
    return (cx * (sb[i, SB_INV_I] * cx + sb[i, SB_INV_I + 1] * cy + sb[i, SB_INV_I + 2] * cz)
            + cy * (sb[i, SB_INV_I + 3] * cx + sb[i, SB_INV_I + 4] * cy + sb[i, SB_INV_I + 5] * cz)
            + cz * (sb[i, SB_INV_I + 6] * cx + sb[i, SB_INV_I + 7] * cy + sb[i, SB_INV_I + 8] * cz))


@njit
def effective_mass_along(sb, a, ra, b, rb, d):
    """``1 / (m_a^-1 + m_b^-1 + (ra x d) I_a^-1 (ra x d) + (rb x d) I_b^-1 (rb x d))`` along unit ``d`` (kg):
    the impulse that changes the relative velocity of the two points along ``d`` by 1 m/s.  ``b < 0`` is the
    fixed world.  Returns 0 if nothing can move."""
    k = sb[a, SB_INV_MASS] + _angular_term(sb, a, ra, d)
    if b >= 0:
        k += sb[b, SB_INV_MASS] + _angular_term(sb, b, rb, d)
    return 1.0 / k if k > 0.0 else 0.0


@njit_inline
def _isotropic_mass(inv_mass_a, iso_a, ra, inv_mass_b, iso_b, rb, d):
    """:func:`effective_mass_along` of two bodies whose world inverse inertias are ``iso_a E`` and ``iso_b E``
    (same rounding)."""
    k = (inv_mass_a + _isotropic_term(iso_a, cross(ra, d))) + (inv_mass_b + _isotropic_term(iso_b, cross(rb, d)))
    return 1.0 / k if k > 0.0 else 0.0


@njit_inline
def effective_masses(sb, a, ra, b, rb, n, t1, t2):
    """:func:`effective_mass_along` along a contact's normal ``n`` and tangents ``t1``, ``t2`` (kg), bit for bit.
    When both bodies' world inverse inertias are multiples of the identity (spheres, cubes, and whatever cannot
    move) the three are written out here, with no call: a third of the time per contact."""
    iso_a, iso_b = sb[a, SB_ISO], sb[b, SB_ISO]
    if iso_a >= 0.0 and iso_b >= 0.0:
        inv_a, inv_b = sb[a, SB_INV_MASS], sb[b, SB_INV_MASS]
        return (_isotropic_mass(inv_a, iso_a, ra, inv_b, iso_b, rb, n),
                _isotropic_mass(inv_a, iso_a, ra, inv_b, iso_b, rb, t1),
                _isotropic_mass(inv_a, iso_a, ra, inv_b, iso_b, rb, t2))
    return (effective_mass_along(sb, a, ra, b, rb, n), effective_mass_along(sb, a, ra, b, rb, t1),
            effective_mass_along(sb, a, ra, b, rb, t2))


@njit
def lighter(mass, old_mass):
    """``min(1, mass / old_mass)``: the factor on an accumulated impulse whose effective mass changed from
    ``old_mass`` to ``mass`` (kg).  Re-applied at the next warm start, ``lambda`` then changes the velocity
    along its direction by no more than it did (``lambda K`` with ``K = 1 / m``), and its energy
    ``lambda^2 K / 2`` by no more than before; it is never raised (the relax pass may take an impulse
    back only down to zero, so it must not count more impulse than was applied)."""
    if mass < old_mass and old_mass > 0.0:
        return mass / old_mass
    return 1.0
