"""Mass properties of a rigid body made of several shapes: total mass, centre of mass, inertia about it.

    m = sum m_i,   c = sum m_i p_i / m
    I = sum R_i I_i R_i^T + m_i (|d_i|^2 E - d_i d_i^T),   d_i = p_i - c   (parallel-axis theorem)

``I_i`` is shape i's inertia about its own centre in its own frame, ``R_i`` its orientation in the body.

The inertia a body is simulated with is then *conditioned* (:func:`conditioned_inertia`): no principal
moment below ``1 / MAX_MOMENT_RATIO`` of the largest.
"""
import numpy as np

from ..math3d import quat_to_matrix_np


def compound_mass_properties(parts, density, mass=None):
    """Mass (kg), centre of mass (m, in the parts' frame) and inertia tensor about it (kg m^2, 3x3) of
    ``parts`` ((shape, position, orientation) tuples) of uniform ``density`` (kg/m^3).  With ``mass``
    given, the density is scaled so that the total is ``mass``."""
    props = [(s.mass_properties(density), p, q) for s, p, q in parts]
    total = sum(mp[0] for mp, _, _ in props)
    com = sum(mp[0] * p for mp, p, _ in props) / total
    inertia = np.zeros((3, 3))
    for (m_i, i_i), p, q in props:
        r = quat_to_matrix_np(q)
        d = p - com
        inertia += r @ i_i @ r.T + m_i * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    if mass is not None:
        inertia *= mass / total
        total = mass
    return total, com, inertia


#: The largest ratio of a body's principal moments of inertia that it is simulated with.  A needle 20 m
#: long and 2 mm thick has moments 5e7 apart: the impulses at its end's four corners, 2 mm apart and solved
#: one after another, left a twist about the long axis that its tiny moment turned into hundreds of rad/s
#: per step, far past what a sub-step's linearised contact velocities describe, and the needle went through
#: the floor and gained energy without bound (30 of 120 random needles dropped on a plane, every integrator,
#: sequential impulses and the LCP alike; with moments conditioned to 1e4, 1e5 or 1e6: none).
MAX_MOMENT_RATIO = 1e4


def conditioned_inertia(inertia, max_ratio=MAX_MOMENT_RATIO):
    """``inertia`` (kg m^2, 3x3 symmetric) with every principal moment raised to at least ``1 / max_ratio`` of
    the largest, about the same principal axes:

        I' = Q diag(max(lambda_k, lambda_max / max_ratio)) Q^T,   I = Q diag(lambda_k) Q^T

    A body whose moments are within the ratio is returned unchanged (the same array).  Raising a moment only
    slows spin about that axis; the body's mass, centre and shape are untouched.  (A 2 m rod 2 cm thick, at
    5,000, keeps its exact tensor.)"""
    moments, axes = np.linalg.eigh(inertia)
    floor = moments[2] / max_ratio
    if moments[0] >= floor:
        return inertia
    conditioned = (axes * np.maximum(moments, floor)) @ axes.T
    return 0.5 * (conditioned + conditioned.T)
