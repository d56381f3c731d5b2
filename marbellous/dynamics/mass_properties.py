"""Mass properties of a rigid body made of several shapes: total mass, centre of mass, inertia about it.

    m = sum m_i,   c = sum m_i p_i / m
    I = sum R_i I_i R_i^T + m_i (|d_i|^2 E - d_i d_i^T),   d_i = p_i - c   (parallel-axis theorem)

``I_i`` is shape i's inertia about its own centre in its own frame, ``R_i`` its orientation in the body.
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
