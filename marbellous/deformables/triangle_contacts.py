"""Points against cloth triangles: a cloth's vertices against its own triangles (``self_collision``) and
against other cloths', and colliding particles (``collide_particles``) against every cloth.

A triangle is a slab of the cloth's thickness ``t``: a point of radius ``r`` stays at least ``r + t / 2`` from
its plane, on the side it came from. Once per step (``triangle_candidates``), a grid of the points' swept boxes
(swept_boxes.py) lists the (point, triangle) pairs whose swept boxes overlap and whose boxes, grown by what the
two can close in the step, meet, leaving out a triangle's own corners, the points an edge joins to them
(neighbours lie in the triangle's plane by design) and,
within a cloth, the vertices within twice its thickness of the triangle's corners in the cloth's rest shape (to
reach the triangle from behind they would have to fold sharper than the thickness), and records the
side ``s = +-1`` of the triangle each point is on then. In each sub-step, a pair whose point lies over the
triangle (its foot inside it, barycentric weights ``b_i >= 0``) closer than ``r + t / 2`` on side ``s``, or
behind it by less than that (it passed through in this sub-step), is pushed apart along the unit normal ``n``
(Mueller et al. 2007), with Coulomb friction across it (``_friction``):

    C = s n . (x_p - sum_i b_i x_i) - (r + t / 2) >= 0
    grad_p = s n,   grad_i = -b_i s n,   dlambda = -C / (w_p + sum_i b_i^2 w_i)

A corner that the ground holds (``particle_contacts.held_inverse_mass``) takes no part of a push into the ground
in the sub-step's second pass: its ``w`` counts as 0, unless every corner's would.

An overlap already there at the sub-step's start (``C_start < 0``, on the positions the sub-step began with)
is only reduced by ``PUSH_SPEED h``; overlap made within the sub-step is removed whole, so a point is not
pushed through.  Pushed out at once, a crumpled sheet's overlaps became velocities ``C / h`` (10 m/s for a
centimetre at 16 sub-steps of 1/60 s): a 128 x 128 sheet dropped on a sphere reached 150 m/s and its candidate
table 23 GB; pushed out gradually, it stays below 15 m/s (what still shakes it is its stretch, which 16
sub-steps do not converge at that resolution: without self-collision it shakes alike).

The side recorded at the step's start is what keeps a point that a sub-step carried through the triangle on
its first side: the constraint pulls it back rather than pushing it on.  (A point farther behind is left
alone: pulling points from far behind a triangle they were never over blows a draped cloth up.)  Not handled:
an edge of one triangle passing through another edge with both ends clear of the other's triangles (edge
against edge), which the points' thickness makes rare on a mesh finer than the fold.
"""
import math

import numpy as np

from .._numba.jit import njit, njit_inline
from ..collision.adjacency import joined
from .layer_contacts import record_push
from .particle_contacts import append_pair, held_inverse_mass
from .particle_layout import (CL_SELF, CL_THICKNESS, P_CLOTH, P_FLAGS, P_FRICTION, P_INV_MASS, P_POS, P_PREV,
                              P_RADIUS, P_REST, P_STATIC_FRICTION, PP_COLLIDE, T_A, T_CLOTH)
from .swept_boxes import (bin_boxes, box_table, closing_reach, empty_boxes, grow_box, overlapping, sweep_point,
                          typical_extent)

#: how fast (m/s) a point and a triangle that overlap at the start of a sub-step are pushed apart
PUSH_SPEED = 1.0


@njit
def _is_point(pi, p):
    """Whether particle row ``p`` meets cloth triangles: a cloth vertex or a colliding particle."""
    return pi[p, P_CLOTH] >= 0 or (pi[p, P_FLAGS] & PP_COLLIDE) != 0


@njit
def _triangle_box(pf, tri, t, grow):
    """``(lo, hi)`` of triangle ``t``'s box grown by ``grow`` (m)."""
    a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
    lo = (min(pf[a, P_POS], pf[b, P_POS], pf[c, P_POS]) - grow,
          min(pf[a, P_POS + 1], pf[b, P_POS + 1], pf[c, P_POS + 1]) - grow,
          min(pf[a, P_POS + 2], pf[b, P_POS + 2], pf[c, P_POS + 2]) - grow)
    hi = (max(pf[a, P_POS], pf[b, P_POS], pf[c, P_POS]) + grow,
          max(pf[a, P_POS + 1], pf[b, P_POS + 1], pf[c, P_POS + 1]) + grow,
          max(pf[a, P_POS + 2], pf[b, P_POS + 2], pf[c, P_POS + 2]) + grow)
    return lo, hi


@njit
def _side(pf, tri, t, p):
    """``+1`` if point row ``p`` is on the front of triangle ``t`` (its corners counter-clockwise), else
    ``-1``."""
    a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
    u = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
    v = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    d = ((pf[p, P_POS] - pf[a, P_POS]) * n[0] + (pf[p, P_POS + 1] - pf[a, P_POS + 1]) * n[1]
         + (pf[p, P_POS + 2] - pf[a, P_POS + 2]) * n[2])
    return 1 if d >= 0.0 else -1


@njit_inline
def foot_weights(u, v, w):
    """The barycentric weights ``(b0, b1, b2)`` of the foot of the point ``a + w`` on the plane of the triangle
    ``a, a + u, a + v`` (3-tuples, m): all ``>= 0`` where the foot lies in the triangle; ``-1`` each for a triangle
    without area."""
    uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    wu = w[0] * u[0] + w[1] * u[1] + w[2] * u[2]
    wv = w[0] * v[0] + w[1] * v[1] + w[2] * v[2]
    det = uu * vv - uv * uv
    if det <= 0.0:
        return -1.0, -1.0, -1.0
    b1 = (vv * wu - uv * wv) / det
    b2 = (uu * wv - uv * wu) / det
    return 1.0 - b1 - b2, b1, b2


@njit
def _near_at_rest(pf, p, a, b, c, reach):
    """Whether the cloth's vertex ``p`` is within ``reach`` (m) of a corner of its triangle ``a b c`` in the
    cloth's rest shape."""
    for q in (a, b, c):
        d = ((pf[p, P_REST] - pf[q, P_REST]) ** 2 + (pf[p, P_REST + 1] - pf[q, P_REST + 1]) ** 2
             + (pf[p, P_REST + 2] - pf[q, P_REST + 2]) ** 2)
        if d < reach * reach:
            return True
    return False


@njit
def triangle_candidates(pf, pi, n_particles, tri, n_tri, cloth_f, mean, dt, slack, adjacent_start, adjacent,
                        out):
    """List the candidate ``(point, triangle, side)`` rows into ``out`` (module docstring); returns how many
    there are (rows past ``out``'s end are not written).  A point and a triangle are looked at when their
    swept boxes overlap (swept_boxes.py; ``mean`` the velocity they sweep relative to, m/s, each grown by its
    half of the gap kept and half of ``slack``, m), and kept when the point lies within the triangle's box
    grown by the gap, ``slack`` and what the two can close in the step (``swept_boxes.closing_reach``)."""
    if n_tri == 0:
        return 0
    point_lo, point_hi = empty_boxes(n_particles)
    for p in range(n_particles):
        if _is_point(pi, p):
            sweep_point(pf, p, mean, dt, point_lo, point_hi, p)
            grow_box(point_lo, point_hi, p, pf[p, P_RADIUS] + 0.5 * slack)
    tri_lo, tri_hi = empty_boxes(n_tri)
    for t in range(n_tri):
        for q in range(3):
            sweep_point(pf, tri[t, T_A + q], mean, dt, tri_lo, tri_hi, t)
        grow_box(tri_lo, tri_hi, t, 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS] + 0.5 * slack)
    cell = typical_extent(tri_lo, tri_hi, n_tri)
    cell_start = box_table(n_particles)
    grid = bin_boxes(point_lo, point_hi, n_particles, cell, cell_start)
    found = np.empty(n_particles, np.int64)
    n = 0
    for t in range(n_tri):
        a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
        own = tri[t, T_CLOTH]
        for f in range(overlapping(point_lo, point_hi, n_particles, cell, cell_start, grid, tri_lo, tri_hi, t, -1,
                                   found)):
            p = found[f]
            if p == a or p == b or p == c:
                continue
            if pi[p, P_CLOTH] == own and cloth_f[own, CL_SELF] == 0.0:
                continue
            # (the cheap tests first: on a sheet finer than its thickness most of the points found are its own
            # vertices near the triangle at rest; tested last, a 128 x 128 sheet falling flat spent 200 ms a step
            # finding that no pair is a candidate)
            if pi[p, P_CLOTH] == own and _near_at_rest(pf, p, a, b, c, 2.0 * cloth_f[own, CL_THICKNESS]):
                continue
            if joined(adjacent_start, adjacent, p, a) or joined(adjacent_start, adjacent, p, b) \
                    or joined(adjacent_start, adjacent, p, c):
                continue
            # the triangle's box grown by what this point and triangle can close in the step
            closing = max(closing_reach(pf, p, a, dt), closing_reach(pf, p, b, dt), closing_reach(pf, p, c, dt))
            lo, hi = _triangle_box(pf, tri, t, pf[p, P_RADIUS] + 0.5 * cloth_f[own, CL_THICKNESS] + closing + slack)
            if pf[p, P_POS] < lo[0] or pf[p, P_POS] > hi[0] or pf[p, P_POS + 1] < lo[1] or pf[p, P_POS + 1] > hi[1] \
                    or pf[p, P_POS + 2] < lo[2] or pf[p, P_POS + 2] > hi[2]:
                continue
            if n < out.shape[0]:
                out[n, 2] = _side(pf, tri, t, p)
            n = append_pair(out, n, p, t)
    return n


@njit
def triangle_contacts(pf, tri, cloth_f, pairs, n_pairs, h, ground, lf, li, n_rec):
    """The position pass over the candidate pairs (module docstring) in a sub-step of ``h`` seconds, with the
    particles that the ground holds (``ground``, ``particle_contacts.ground_normals``; all zero: none); each push
    is recorded into ``lf``/``li`` after the ``n_rec`` there (``layer_contacts.record_push``); returns their new
    count."""
    push = PUSH_SPEED * h
    for k in range(n_pairs):
        p, t, s = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        a, b, c = tri[t, T_A], tri[t, T_A + 1], tri[t, T_A + 2]
        u = (pf[b, P_POS] - pf[a, P_POS], pf[b, P_POS + 1] - pf[a, P_POS + 1], pf[b, P_POS + 2] - pf[a, P_POS + 2])
        v = (pf[c, P_POS] - pf[a, P_POS], pf[c, P_POS + 1] - pf[a, P_POS + 1], pf[c, P_POS + 2] - pf[a, P_POS + 2])
        w = (pf[p, P_POS] - pf[a, P_POS], pf[p, P_POS + 1] - pf[a, P_POS + 1], pf[p, P_POS + 2] - pf[a, P_POS + 2])
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        size = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        if size < 1e-20:
            continue
        n = (s * n[0] / size, s * n[1] / size, s * n[2] / size)
        gap = pf[p, P_RADIUS] + 0.5 * cloth_f[tri[t, T_CLOTH], CL_THICKNESS]
        d = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
        if d >= gap or d < -gap:
            continue
        b0, b1, b2 = foot_weights(u, v, w)
        if b0 < 0.0 or b1 < 0.0 or b2 < 0.0:
            continue
        # the same distance at the sub-step's start: an overlap already there is pushed out gradually
        d_start = 0.0
        for j in range(3):
            d_start += n[j] * (pf[p, P_PREV + j] - b0 * pf[a, P_PREV + j] - b1 * pf[b, P_PREV + j]
                               - b2 * pf[c, P_PREV + j])
        target = gap if d_start >= gap else min(gap, d_start + push)
        if d >= target:
            continue
        # (a corner held by the ground against the push takes none of it, unless every corner is held)
        back_n = (-n[0], -n[1], -n[2])
        wa, wb = held_inverse_mass(pf, ground, a, back_n), held_inverse_mass(pf, ground, b, back_n)
        wc, wp = held_inverse_mass(pf, ground, c, back_n), held_inverse_mass(pf, ground, p, n)
        denominator = wp + b0 * b0 * wa + b1 * b1 * wb + b2 * b2 * wc
        if denominator <= 0.0:
            wa, wb, wc, wp = pf[a, P_INV_MASS], pf[b, P_INV_MASS], pf[c, P_INV_MASS], pf[p, P_INV_MASS]
            denominator = wp + b0 * b0 * wa + b1 * b1 * wb + b2 * b2 * wc
        if denominator <= 0.0:
            continue
        dlambda = (target - d) / denominator
        for j in range(3):
            pf[p, P_POS + j] += wp * dlambda * n[j]
            pf[a, P_POS + j] -= wa * b0 * dlambda * n[j]
            pf[b, P_POS + j] -= wb * b1 * dlambda * n[j]
            pf[c, P_POS + j] -= wc * b2 * dlambda * n[j]
        n_rec = record_push(lf, li, n_rec, (p, a, b, c), (1.0, -b0, -b1, -b2), n, dlambda, target)
        _friction(pf, p, a, b, c, b0, b1, b2, n, target - d, (wp, wa, wb, wc), denominator)
    return n_rec


@njit_inline
def _slip_along(pf, p, a, b, c, b0, b1, b2, j):
    """Point ``p``'s motion (m) along axis ``j`` in the sub-step relative to the triangle ``a b c``'s point of
    barycentric weights ``b0 b1 b2``."""
    return (pf[p, P_POS + j] - pf[p, P_PREV + j]) - (b0 * (pf[a, P_POS + j] - pf[a, P_PREV + j])
                                                     + b1 * (pf[b, P_POS + j] - pf[b, P_PREV + j])
                                                     + b2 * (pf[c, P_POS + j] - pf[c, P_PREV + j]))


@njit
def _friction(pf, p, a, b, c, b0, b1, b2, n, depth, inverse_masses, denominator):
    """Coulomb friction between point ``p`` and the triangle ``a b c`` (barycentric weights ``b0 b1 b2``) whose
    overlap ``depth`` (m) along ``n`` was just removed, on positions (Macklin et al. 2014): their relative
    motion across ``n`` in this sub-step, ``dx_t``, is undone if it is shorter than ``mu_s depth`` (static),
    else shortened by ``mu_d depth`` (sliding), split by the ``inverse_masses`` (of ``p a b c``) as the overlap
    was.  The coefficients: the geometric means of the point's and the triangle's."""
    dx = (_slip_along(pf, p, a, b, c, b0, b1, b2, 0), _slip_along(pf, p, a, b, c, b0, b1, b2, 1),
          _slip_along(pf, p, a, b, c, b0, b1, b2, 2))
    along = dx[0] * n[0] + dx[1] * n[1] + dx[2] * n[2]
    t = (dx[0] - along * n[0], dx[1] - along * n[1], dx[2] - along * n[2])
    slip = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    if slip <= 0.0:
        return
    mu_s = math.sqrt(pf[p, P_STATIC_FRICTION] * pf[a, P_STATIC_FRICTION])
    mu_d = math.sqrt(pf[p, P_FRICTION] * pf[a, P_FRICTION])
    undo = slip if slip < mu_s * depth else min(slip, mu_d * depth)
    dlambda = undo / (slip * denominator)
    wp, wa, wb, wc = inverse_masses
    for j in range(3):
        pf[p, P_POS + j] -= wp * dlambda * t[j]
        pf[a, P_POS + j] += wa * b0 * dlambda * t[j]
        pf[b, P_POS + j] += wb * b1 * dlambda * t[j]
        pf[c, P_POS + j] += wc * b2 * dlambda * t[j]
