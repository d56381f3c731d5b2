"""Ray casts against any shape: primitives analytically, hulls by their faces, height fields and meshes through
their acceleration."""
import numpy as np

from ..._numba.jit import njit
from .. import shape_types as st
from .raycast_hull import raycast_hull
from .raycast_primitives import raycast_primitive
from .raycast_static import raycast_static


@njit
def raycast_shape(stype, pos, rot, params, geom_f, geom_i, off_f, off_i, origin, direction, max_distance,
                  normal_out):
    """Distance (m) along the unit ``direction`` from ``origin`` to the shape's surface, or -1.0 on a miss.

    On a hit writes the unit surface normal (facing the ray for meshes and height fields, outward for
    solids) into ``normal_out``.
    """
    if stype == st.HULL:
        return raycast_hull(pos, rot, geom_f, geom_i, off_f, off_i, origin, direction, max_distance, normal_out)
    if stype <= st.PLANE:
        return raycast_primitive(stype, pos, rot, params, origin, direction, max_distance, normal_out)
    out = np.empty(8)
    if not raycast_static(stype, pos, rot, params, geom_f, geom_i, off_f, off_i, origin, direction,
                          max_distance, out):
        return -1.0
    for k in range(3):
        normal_out[k] = out[4 + k]
    return out[0]
