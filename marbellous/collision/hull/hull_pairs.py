"""A convex hull against any shape: the pair test for each kind of the other shape, the hull first.

Hull and box run the polytope test (``polytope_polytope``), sphere and capsule the core test
(``round_polytope``), plane the vertex test (``hull_plane``), meshes and height fields the triangle test
(``triangle/triangle_hull``) through their acceleration.  Normals run from the hull to the other shape.
"""
from ..._numba.jit import njit
from .. import shape_types as st
from ..mesh.heightfield_collide import collide_hull_heightfield
from ..mesh.mesh_collide import collide_hull_mesh
from ..pairs.plane_pairs import world_plane
from ..vec3 import column, load, madd, matrix, scale
from .hull_plane import collide_polytope_plane
from .polytope import box_polytope, hull_polytope
from .polytope_polytope import collide_polytopes
from .round_polytope import collide_segment_polytope


@njit
def collide_hull_shape(pos_a, rot_a, params_a, off_f_a, off_i_a, type_b, pos_b, rot_b, params_b, off_f_b, off_i_b,
                       geom_f, geom_i, prediction, out_f, out_i, n):
    """Contacts of hull a (its blob slices at ``off_f_a``/``off_i_a``) with shape b of any kind; arguments
    and buffer convention as ``pairs/dispatch.collide_pair``.  Returns the new count."""
    if type_b == st.MESH:
        return collide_hull_mesh(pos_a, rot_a, params_a, off_f_a, off_i_a, pos_b, rot_b, params_b, geom_f, geom_i,
                                 off_f_b, off_i_b, prediction, out_f, out_i, n)
    if type_b == st.HEIGHTFIELD:
        return collide_hull_heightfield(pos_a, rot_a, params_a, off_f_a, off_i_a, pos_b, rot_b, params_b, geom_f,
                                        geom_i, off_f_b, off_i_b, prediction, out_f, out_i, n)
    va, pa, sa, la, ea = hull_polytope(pos_a, rot_a, geom_f, geom_i, off_f_a, off_i_a)
    if type_b == st.PLANE:
        pn, off = world_plane(load(pos_b), matrix(rot_b), (params_b[0], params_b[1], params_b[2]), params_b[3])
        return collide_polytope_plane(va, pn, off, prediction, out_f, out_i, n)
    if type_b == st.SPHERE:
        return collide_segment_polytope(False, load(pos_b), (0.0, 0.0, 0.0), params_b[0], va, pa, sa, la, ea,
                                        prediction, out_f, out_i, n)
    if type_b == st.CAPSULE:
        axis = column(rot_b, 1)
        hh = params_b[1]
        return collide_segment_polytope(False, madd(load(pos_b), -hh, axis), scale(axis, 2.0 * hh), params_b[0],
                                        va, pa, sa, la, ea, prediction, out_f, out_i, n)
    if type_b == st.BOX:
        vb, pb, sb, lb, eb = box_polytope(pos_b, rot_b, params_b)
        size_b = min(params_b[0], min(params_b[1], params_b[2]))
        return collide_polytopes(va, pa, sa, la, ea, params_a[6], vb, pb, sb, lb, eb, size_b, prediction,
                                 out_f, out_i, n)
    vb, pb, sb, lb, eb = hull_polytope(pos_b, rot_b, geom_f, geom_i, off_f_b, off_i_b)
    return collide_polytopes(va, pa, sa, la, ea, params_a[6], vb, pb, sb, lb, eb, params_b[6], prediction,
                             out_f, out_i, n)
