"""The particles' step: small sub-steps of extended position-based dynamics, after the rigid bodies' step.

Each step of ``dt`` is taken in ``substeps`` sub-steps of ``h = dt / substeps``, one constraint pass each
("small steps", Macklin et al. 2019: many short sub-steps with one pass converge better than few with many
passes).  Before them, once per step (``find_candidates``): the shapes and the particle pairs each particle
may meet in the step.  Each sub-step, in order:

    drift           pushed bodies go on with the velocity the particles gave them, bodies in free fall
                    fall as particles do (body_motion.py)
    soft bodies     their nodes' velocities by one implicit step of their elastic forces (soft_step.py;
                    once per sub-step, so that a node stopped by a contact pushes back on its neighbours
                    before they have moved far into it)
    integrate       v0 = v;  internal motion damped;  v += h (g + F / m) (not for soft bodies' nodes: their
                    velocity for the step comes from the soft bodies' implicit step, soft_step.py);
                    x_prev = x;  x += h v;  particles pinned to the world put back on their pins
    pins            particles pinned to a body put on its point (a pinned particle is a point of its body)
    whole cloths    with ``World.cloth_stretch_passes``: the cloths' springs and flat hinges solved together
                    (stretch_solve.py)
    edges           the networks' springs, rods and cables (edge_constraints.py); an edge that ends on a
                    body-pinned particle pulls the body (two ways); the cloths' edges get a second pass
                    (with one, a 50 x 50 cloth dropped on a sphere at 16 sub-steps blew up on impact, and
                    so does a plain XPBD sheet written to check it; with two it settles)
    bends           the cloths' hinges (bend_constraints.py; with the whole-cloth solve, the hinges bent at rest,
                    before it)
    tethers         no particle farther from its world pin than its rods and cables allow (tethers.py)
    pins            again, where the edges have moved the bodies
    contacts        overlaps with other particles, with cloth triangles, of cloth edges and with the shapes
                    removed; static friction (particle_pairs.py, triangle_contacts.py, edge_contacts.py,
                    particle_contacts.py); with cloth, the triangles and shapes twice, then the corners of
                    boxes, hulls, balls and capsules against the triangles (corner_contacts.py); a body holding a
                    vertex of the whole-cloth solve gets the contact's whole force (stretch_solve.py)
    velocities      v = (x - x_prev) / h
    velocity pass   dynamic friction and restitution of the sub-step's contacts, then the restitution of the
                    bodies' corners on the triangles; the soft bodies' nodes note their contacts' normals for the
                    next sub-step's implicit step

and at the end the pushed bodies' poses and velocities are written back, the edges whose force of the step
passed their breaking force break, and the user forces are cleared.
Semi-implicit Euler in velocity and position, with the constraints as corrections of the positions: stable at
60 Hz for any stiffness, with a small numerical damping that shrinks with ``h``.

Damping: each particle's velocity relative to its set's mean velocity (mass-weighted) decays at its rate
``c`` (1/s), ``v <- v_mean + (v - v_mean) exp(-c h)``: internal motion is damped, rigid motion is not.
"""
import math

import numpy as np

from .._numba.jit import borrow, njit
from ..collision.shape_types import COVER_GROUND, COVER_MESHES, COVER_SPHERES
from .body_motion import body_pose, clear_motion, drift, start_motion, to_world, write_back
from .bend_constraints import solve_bends
from .corner_contacts import (C_COLS, C_INT_COLS, corner_candidates, corner_capacity, corner_contacts,
                              corner_velocity_pass)
from .edge_constraints import break_edges, clear_edge_forces, solve_edges
from .edge_contacts import edge_candidates, edge_contacts
from .layer_contacts import hold_layers
from .particle_contacts import forced_reach, shape_candidates, shape_contacts, velocity_pass
from .particle_layout import (P_DAMPING, P_FLAGS, P_FORCE, P_INV_MASS, P_MASS, P_PIN, P_PIN_BODY, P_POS,
                              P_PREV, P_VEL, P_VEL0, PP_PINNED, PP_SOFT, Q_DT, Q_GRAVITY, Q_LOADS, Q_STRETCH_PASSES,
                              Q_SUBSTEPS,
                              SET_COUNT, SET_START)
from .particle_pairs import edge_adjacency, particle_candidates, particle_contacts
from .soft_step import record_contact_normals, step_soft_bodies
from .stretch_solve import hold_bodies, solve_stretch
from .tethers import solve_tethers
from .triangle_contacts import triangle_candidates, triangle_contacts


@njit
def _integrate(params, pf, pi, n_particles, sets, n_sets, h):
    """Stage "integrate" (module docstring)."""
    gx, gy, gz = params[Q_GRAVITY], params[Q_GRAVITY + 1], params[Q_GRAVITY + 2]
    for p in range(n_particles):
        for k in range(3):
            pf[p, P_VEL0 + k] = pf[p, P_VEL + k]
    # (damped before the forces act: damped after, a force on one particle is damped as if it were its motion,
    # and a 19.6 N load on the middle vertex of a damped sheet (2 1/s) rested 0.5 % short of its equilibrium sag at
    # 16 sub-steps, 69 % at 4)
    for s in range(n_sets):
        _damp(pf, sets[s, SET_START], sets[s, SET_COUNT], h)
    for p in range(n_particles):
        if pf[p, P_INV_MASS] > 0.0 and (pi[p, P_FLAGS] & PP_SOFT) == 0:
            inv_m = pf[p, P_INV_MASS]
            pf[p, P_VEL] += h * (gx + pf[p, P_FORCE] * inv_m)
            pf[p, P_VEL + 1] += h * (gy + pf[p, P_FORCE + 1] * inv_m)
            pf[p, P_VEL + 2] += h * (gz + pf[p, P_FORCE + 2] * inv_m)
    for p in range(n_particles):
        for k in range(3):
            pf[p, P_PREV + k] = pf[p, P_POS + k]
        if pf[p, P_INV_MASS] > 0.0:
            for k in range(3):
                pf[p, P_POS + k] += h * pf[p, P_VEL + k]
        elif (pi[p, P_FLAGS] & PP_PINNED) != 0 and pi[p, P_PIN_BODY] < 0:
            for k in range(3):
                pf[p, P_POS + k] = pf[p, P_PIN + k]
                pf[p, P_VEL + k] = 0.0


@njit
def _damp(pf, start, count, h):
    """Damp the internal motion of the particles ``start .. start + count - 1`` over ``h`` seconds."""
    mass = 0.0
    mean = [0.0, 0.0, 0.0]
    damped = False
    for p in range(start, start + count):
        if pf[p, P_INV_MASS] > 0.0:
            mass += pf[p, P_MASS]
            for k in range(3):
                mean[k] += pf[p, P_MASS] * pf[p, P_VEL + k]
            damped = damped or pf[p, P_DAMPING] > 0.0
    if not damped or mass <= 0.0:
        return
    for p in range(start, start + count):
        if pf[p, P_INV_MASS] > 0.0 and pf[p, P_DAMPING] > 0.0:
            keep = math.exp(-pf[p, P_DAMPING] * h)
            for k in range(3):
                m = mean[k] / mass
                pf[p, P_VEL + k] = m + (pf[p, P_VEL + k] - m) * keep


@njit
def _pins(pf, pi, n_particles, bf, bi, bx, back):
    """Stage "pins": the particles pinned to a body put on its point, where the body is now (a pinned
    particle is a point of its body: the edges move the body through it, edge_constraints.py)."""
    pf, pi, bf, bi, bx = borrow(pf), borrow(pi), borrow(bf), borrow(bi), borrow(bx)
    for p in range(n_particles):
        b = pi[p, P_PIN_BODY]
        if (pi[p, P_FLAGS] & PP_PINNED) == 0 or b < 0:
            continue
        x_b, q_b = body_pose(bf, bi, bx, b, back)
        target = to_world(x_b, q_b, (pf[p, P_PIN], pf[p, P_PIN + 1], pf[p, P_PIN + 2]))
        for k in range(3):
            pf[p, P_POS + k] = target[k]


@njit
def _velocities(pf, n_particles, h):
    """Stage "velocities": ``v = (x - x_prev) / h`` for the particles that move."""
    for p in range(n_particles):
        if pf[p, P_INV_MASS] > 0.0:
            for k in range(3):
                pf[p, P_VEL + k] = (pf[p, P_POS + k] - pf[p, P_PREV + k]) / h


def _kernels(meeting, coverage):
    """``(find_candidates, step_particles)``: the particles' step kernels, with (``meeting``) or without the
    paths of particles that meet each other (colliding particles, cloth on cloth or on itself, soft bodies:
    their candidates, contacts and the soft bodies' sub-step), with the sphere pair tests of ``coverage``
    (``COVER_SPHERES``, ``COVER_MESHES`` or ``COVER_GROUND``: the kinds of shape the world has).  Without the
    meeting paths, a scene that needs none (a single cloth that does not collide with itself, a net of
    particles) compiles about a third less; the results are the same, since those paths do nothing when there
    is nothing to meet (Numba compiles the variants apart: ``meeting`` and ``coverage`` are constants of
    each)."""
    @njit
    def find_candidates(params, pf, pi, n_particles, ei, ne, tri, n_tri, cloth_f, bf, bi, sf, si, geom_f, geom_i, nb,
                        aabbs, bx, shape_pairs, particle_pairs, triangle_pairs, edge_pairs, corner_pairs,
                        adjacent_start, adjacent, cell_start, cell_entries, scratch_f, scratch_i, sphere, pos_a, rot_a,
                        pos_s, rot_s, q_s):
        """Once per step: the ``(particle, shape)`` candidates into ``shape_pairs``, the ``(particle, particle)``
        candidates into ``particle_pairs``, the ``(point, triangle, side)`` candidates into ``triangle_pairs``, the
        ``(edge, edge, side)`` candidates into ``edge_pairs`` and the ``(shape, triangle, side)`` candidates of the
        bodies' corners into ``corner_pairs``; returns the five counts (a count past an array's length: grow it and
        call again).  The reach: how far a
        particle can fall in the step, ``|g| dt^2``, beyond its velocity's sweep (and, where particles meet, how
        far the fastest one may push it); how far two points may close: twice the fastest one's sweep (relative to
        the points' mean velocity) and reach."""
        dt = params[Q_DT]
        g = math.sqrt(params[Q_GRAVITY] ** 2 + params[Q_GRAVITY + 1] ** 2 + params[Q_GRAVITY + 2] ** 2)
        reach = g * dt * dt
        clear_motion(bx, nb)
        # particles that meet each other push each other: a slow one struck by the fastest may go as far as it
        # within the step (a layer of cloth slammed onto another lying just above the ground drove it 7 cm under
        # the plane in one step, the ground out of its reach)
        pushed = 0.0
        if meeting:
            for p in range(n_particles):
                pushed = max(pushed, math.sqrt(pf[p, P_VEL] ** 2 + pf[p, P_VEL + 1] ** 2 + pf[p, P_VEL + 2] ** 2) * dt
                             + forced_reach(pf, p, dt))
        # (up: against gravity, for the candidates that hold a body up; only while the sub-steps follow the loads)
        up = (-params[Q_GRAVITY] / g, -params[Q_GRAVITY + 1] / g, -params[Q_GRAVITY + 2] / g) \
            if g > 0.0 and params[Q_LOADS] != 0.0 else (0.0, 0.0, 0.0)
        n_shape = shape_candidates(coverage, pf, pi, n_particles, bf, bi, bx, sf, si, geom_f, geom_i, nb, aabbs, dt,
                                   reach + pushed, up, shape_pairs, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s,
                                   rot_s, q_s)
        n_corner = corner_candidates(pf, pi, tri, n_tri, cloth_f, bf, bi, sf, si, geom_f, geom_i, nb, dt, reach,
                                     corner_pairs)
        if not meeting:
            return n_shape, 0, 0, 0, n_corner
        # two points close no faster than twice the fastest one's speed relative to any common velocity: the mean
        # (a sheet falling as a whole then needs no wider cells than one at rest)
        mean = [0.0, 0.0, 0.0]
        for p in range(n_particles):
            for k in range(3):
                mean[k] += pf[p, P_VEL + k] / n_particles
        fastest = 0.0
        for p in range(n_particles):
            fastest = max(fastest, math.sqrt((pf[p, P_VEL] - mean[0]) ** 2 + (pf[p, P_VEL + 1] - mean[1]) ** 2
                                             + (pf[p, P_VEL + 2] - mean[2]) ** 2))
        edge_adjacency(ei, ne, n_particles, adjacent_start, adjacent)
        margin = 2.0 * (fastest * dt + reach)
        n_pair = particle_candidates(pf, pi, n_particles, margin, cell_start, cell_entries, adjacent_start, adjacent,
                                     particle_pairs)
        n_triangle = triangle_candidates(pf, pi, n_particles, tri, n_tri, cloth_f, mean, dt, reach, adjacent_start,
                                         adjacent, triangle_pairs)
        n_edge = edge_candidates(pf, pi, ei, ne, cloth_f, mean, dt, reach, edge_pairs)
        return n_shape, n_pair, n_triangle, n_edge, n_corner

    @njit
    def step_particles(params, pf, pi, n_particles, sets, n_sets, ef, ei, ne, bend_f, bend_i, n_bends, tri, cloth_f,
                       tether_p, tether_q, tether_length, bf, bi, nb, sf, si, geom_f, geom_i, bx, shape_pairs, n_shape,
                       particle_pairs, n_pair, triangle_pairs, n_triangle, edge_pairs, n_edge, corner_pairs, n_corner,
                       kf, ki, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, body_start, soft_bodies,
                       n_soft, tf, ti, soft_tolerance, soft_iterations, soft_rot, soft_work, solved, stretch_edges,
                       flat, hinges, weights, slot, rows, mass_h2, perm_r, perm_c, l_start, l_row, l_value, u_start,
                       u_row, u_value, u_diagonal, y, b, x, columns, column_of, column_unknown, column_used, lf, li):
        """The particles' step (module docstring) over the candidates of :func:`find_candidates` (``body_start``
        (nb, 9): the bodies' positions, m, velocities, m/s, and user forces, N, before their step;
        ``soft_bodies`` .. ``soft_work`` the soft bodies' rows, elements, solver settings and scratch,
        ``step_soft_bodies``; ``solved`` .. ``column_used`` the factored stretch of the cloths,
        ``stretch_solve.StretchSystem``; ``lf``, ``li`` scratch for the pushes of cloth on cloth, layer_contacts.py);
        returns ``(edges broken, most contacts of a sub-step, most soft-body solver
        iterations of a sub-step, its largest residual ratio)``
        (contacts past ``kf``'s length had no velocity pass)."""
        dt = params[Q_DT]
        substeps = int(params[Q_SUBSTEPS])
        passes = int(params[Q_STRETCH_PASSES])
        h = dt / substeps
        g = math.sqrt(params[Q_GRAVITY] ** 2 + params[Q_GRAVITY + 1] ** 2 + params[Q_GRAVITY + 2] ** 2)
        start_motion(bf, bi, bx, nb, body_start, dt, (params[Q_GRAVITY], params[Q_GRAVITY + 1], params[Q_GRAVITY + 2]))
        clear_edge_forces(ef, ei, ne)
        most = soft_most = 0
        soft_residual = 0.0
        ground = np.zeros((n_particles, 5))
        n_corner_rows = corner_capacity(sf, si, geom_i, tri, corner_pairs, n_corner)
        cf, ci = np.empty((n_corner_rows, C_COLS)), np.empty((n_corner_rows, C_INT_COLS), np.int64)
        for step in range(substeps):
            back = dt - (step + 1) * h
            drift(bf, bx, nb, h)
            if meeting and n_soft > 0:
                used, residual = step_soft_bodies(params, pf, pi, soft_bodies, n_soft, tf, ti, h, soft_tolerance,
                                                  soft_iterations, soft_rot, soft_work, bf, bi, bx, back)
                soft_most = max(soft_most, used)
                soft_residual = max(soft_residual, residual)
            _integrate(params, pf, pi, n_particles, sets, n_sets, h)
            _pins(pf, pi, n_particles, bf, bi, bx, back)
            # (the hinges left to the local pass before the whole-cloth solve, which takes their moves as part of the
            # prediction, stretch_solve.py; without it, after the edges as they always were)
            if passes > 0:
                solve_bends(pf, bend_f, bend_i, n_bends, flat, h)
            solve_stretch(pf, ef, ei, solved, stretch_edges, flat, hinges, weights, slot, rows, mass_h2, perm_r, perm_c,
                          l_start, l_row, l_value, u_start, u_row, u_value, u_diagonal, y, b, x, passes, h,
                          (params[Q_GRAVITY], params[Q_GRAVITY + 1], params[Q_GRAVITY + 2]), 1.0 / substeps)
            solve_edges(pf, pi, ef, ei, ne, solved, bf, bi, bx, back, h, 1.0 / substeps, True)
            solve_edges(pf, pi, ef, ei, ne, solved, bf, bi, bx, back, h, 1.0 / substeps, False)
            if passes == 0:
                solve_bends(pf, bend_f, bend_i, n_bends, flat, h)
            solve_tethers(pf, pi, bf, bi, bx, tether_p, tether_q, tether_length, slot, back, h)
            _pins(pf, pi, n_particles, bf, bi, bx, back)
            # (particles against particles first: the shapes' static friction then holds what a particle's load
            # pushes sideways in the same sub-step; the other way round a grain in the groove of two on the floor
            # spread them apart by 5 cm in 10 s)
            nk = n_rec = 0
            # (the first pass of cloth on cloth with nothing held by the ground: the whole-cloth solve takes its
            # pushes back by the particles' own inverse masses, layer_contacts.py; the shapes' contacts then find
            # what the ground holds, particle_contacts.ground_normals)
            ground[:] = 0.0
            if meeting:
                nk = particle_contacts(pf, bf, bi, bx, particle_pairs, n_pair, h, kf, ki, 0)
                n_rec = triangle_contacts(pf, tri, cloth_f, triangle_pairs, n_triangle, h, ground, lf, li, 0)
                n_rec = edge_contacts(pf, ei, edge_pairs, n_edge, h, lf, li, n_rec)
            nk = shape_contacts(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, shape_pairs, n_shape, back, h,
                                kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)
            if meeting and passes > 0:
                hold_layers(pf, slot, rows, perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value,
                            u_diagonal, x, columns, column_of, column_unknown, column_used, lf, li, n_rec, ground)
            if meeting and n_triangle > 0:
                # a second pass over the triangles and the shapes (the shapes' contacts of this one not kept for the
                # velocity pass): a layer of cloth pressed onto another on the ground, once the ground pushed the
                # lower layer back up into the upper, passed through it at 10 g with one pass; with two it holds (its
                # pushes are not solved with the whole-cloth solve's step).  In it the ground holds what lies on it:
                # split by the inverse masses, a point pressed onto a layer on the ground moved its share of each
                # overlap, the ground took the layer's share back, and a folded strip's upper layer pressed at 300 g
                # went 1.7 cm through the lower
                triangle_contacts(pf, tri, cloth_f, triangle_pairs, n_triangle, h, ground, lf, li, 0)
                shape_contacts(coverage, pf, pi, bf, bi, bx, sf, si, geom_f, geom_i, shape_pairs, n_shape, back, h,
                               kf, ki, nk, scratch_f, scratch_i, sphere, pos_a, rot_a, pos_s, rot_s, q_s, ground)
            n_corners = corner_contacts(pf, tri, cloth_f, bf, bi, bx, sf, si, geom_f, geom_i, corner_pairs, n_corner,
                                        back, h, ground, slot, cf, ci)
            most = max(most, nk)
            if passes > 0:
                hold_bodies(pf, slot, rows, perm_r, perm_c, l_start, l_row, l_value, u_start, u_row, u_value,
                            u_diagonal, x, columns, column_of, column_unknown, column_used, kf, ki, nk, bf, bi, bx,
                            back, h, ground)
            _velocities(pf, n_particles, h)
            velocity_pass(pf, pi, bf, bi, bx, kf, ki, nk, back, h, g * h, ground)
            corner_velocity_pass(pf, bf, bi, bx, cf, ci, n_corners, back, h, g * h)
            if meeting and n_soft > 0:
                record_contact_normals(pf, pi, n_particles, bf, kf, ki, nk)
        write_back(bf, bi, bx, nb)
        broke = break_edges(pf, ef, ei, ne)
        for p in range(n_particles):
            for k in range(3):
                pf[p, P_FORCE + k] = 0.0
        return broke, most, soft_most, soft_residual

    return find_candidates, step_particles


#: the particles' step kernels ``(find_candidates, step_particles)`` of each kind of scene,
#: ``KERNELS[meeting][coverage]``: ``meeting`` whether its particles meet each other (``ParticleState.meeting``),
#: ``coverage`` the kinds of shape it has (``COVER_SPHERES``, ``COVER_MESHES`` or ``COVER_GROUND``,
#: ``world_state.shape_coverage``)
KERNELS = tuple(tuple(_kernels(meeting, coverage) for coverage in (COVER_SPHERES, COVER_MESHES, COVER_GROUND))
                for meeting in (False, True))
