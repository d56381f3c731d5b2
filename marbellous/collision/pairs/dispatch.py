"""The narrow-phase dispatcher: any two shapes to the right pair test, normals from a to b.

Pair tests exist for the canonical order only (sphere < capsule < box < plane < height field <
mesh; a convex hull's pair tests take the hull first, whatever the other shape).  When the caller's a
comes second in that order the shapes are swapped, the pair test runs, and the rows it added get their
normals negated; points, depths and feature ids stay as they are
(the point is the midpoint between the surfaces, the same seen from either side).

The dispatchers are inlined into their callers (``njit_inline``): each level of calls would pass, and
reference-count, every array again (a box pair in a stack: 780 -> 550 ns in the narrow phase).  Their
``coverage`` (``shape_types.COVER_*``, a constant where they are inlined) leaves out the pair tests a world
cannot meet, so that they are not compiled for it.
"""
from ..._numba.jit import njit, njit_inline
from .. import shape_types as st
from ..shape_types import COVER_ALL, COVER_GROUND, COVER_MESHES, COVER_SPHERES
from ..hull.hull_pairs import collide_hull_shape
from ..hull.polytope import hull_polytope
from ..hull.round_polytope import collide_segment_polytope
from ..mesh.heightfield_collide import collide_convex_heightfield, collide_sphere_heightfield
from ..mesh.mesh_collide import collide_convex_mesh, collide_sphere_mesh
from ..vec3 import load, mat_column, matrix
from .box_box import collide_box_box
from .capsule_box import collide_capsule_box
from .capsule_capsule import collide_capsule_capsule
from .contact_output import add_contact
from .plane_pairs import collide_box_plane, collide_capsule_plane, sphere_plane, world_plane
from .sphere_box import sphere_box
from .sphere_capsule import sphere_capsule
from .sphere_sphere import sphere_sphere


@njit
def sphere_primitive(c, r, type_b, pos_b, m_b, params_b, prediction):
    """The contact of the sphere ``(c, r)`` with a sphere, capsule, box or plane b, all in registers.

    ``c``, ``pos_b`` 3-tuples (m), ``r`` (m), ``m_b`` b's rotation as a row-major 9-tuple
    (``vec3.matrix``; not read for a sphere), ``params_b`` the first four of b's parameters.
    Returns ``(hit, p_on_a, normal, depth)`` (``sphere_sphere.ball_ball``), normal from the sphere
    to b, feature id 0.  The fast path of the narrow phase: no array argument, so no reference
    counting (which costs more than the pair test itself).
    """
    if type_b == st.SPHERE:
        return sphere_sphere(c, r, pos_b, params_b[0], prediction)
    if type_b == st.CAPSULE:
        return sphere_capsule(c, r, pos_b, mat_column(m_b, 1), params_b[0], params_b[1], prediction)
    if type_b == st.BOX:
        return sphere_box(c, r, pos_b, m_b, (params_b[0], params_b[1], params_b[2]), prediction)
    pn, off = world_plane(pos_b, m_b, (params_b[0], params_b[1], params_b[2]), params_b[3])
    return sphere_plane(c, r, pn, off, prediction)


@njit_inline
def _ordered_convex_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, prediction,
                         out_f, out_i, n):
    """Pair test for ``type_a <= type_b``, both primitives; plane-plane has no contacts."""
    if type_a == st.SPHERE:
        hit, p, normal, depth = sphere_primitive(load(pos_a), params_a[0], type_b, load(pos_b), matrix(rot_b),
                                                 (params_b[0], params_b[1], params_b[2], params_b[3]), prediction)
        return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n
    if type_a == st.CAPSULE:
        if type_b == st.CAPSULE:
            return collide_capsule_capsule(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n)
        if type_b == st.BOX:
            return collide_capsule_box(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n)
        return collide_capsule_plane(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n)
    if type_a == st.BOX:
        if type_b == st.BOX:
            return collide_box_box(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n)
        return collide_box_plane(pos_a, rot_a, params_a, pos_b, rot_b, params_b, prediction, out_f, out_i, n)
    return n


@njit
def flip_normals(out_f, start, stop):
    """Negate the normals of rows ``start <= row < stop`` that fit in the buffer."""
    for row in range(start, min(stop, out_f.shape[0])):
        out_f[row, 3] = -out_f[row, 3]
        out_f[row, 4] = -out_f[row, 4]
        out_f[row, 5] = -out_f[row, 5]


@njit_inline
def collide_convex_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, prediction,
                        out_f, out_i, n):
    """Contacts of two primitives (sphere, capsule, box, plane) in any order; returns the new count.

    Type codes from ``shape_types``; ``pos_*`` (3,) m, ``rot_*`` (3, 3), ``params_*`` the shape
    records; ``prediction`` (m) the largest gap still reported; rows appended to ``out_f`` /
    ``out_i`` from row ``n`` (docs/architecture.md), normals from a to b.
    """
    if type_a <= type_b:
        return _ordered_convex_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b,
                                    prediction, out_f, out_i, n)
    m = _ordered_convex_pair(type_b, pos_b, rot_b, params_b, type_a, pos_a, rot_a, params_a,
                             prediction, out_f, out_i, n)
    flip_normals(out_f, n, m)
    return m


@njit_inline
def collide_pair_covering(coverage, type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i,
                          off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n):
    """:func:`collide_pair` with the pair tests of ``coverage`` (``shape_types.COVER_*``) only: pairs that a
    world of that coverage cannot meet report no contact.  Below ``COVER_ALL`` every moving shape is a
    sphere, so every pair has one: the sphere's own tests (:func:`collide_sphere_shape`)."""
    if coverage != COVER_ALL:
        if type_a == st.SPHERE:
            return collide_sphere_shape(coverage, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f,
                                        geom_i, off_f_b, off_i_b, prediction, out_f, out_i, n)
        if type_b != st.SPHERE:
            return n
        m = collide_sphere_shape(coverage, pos_b, rot_b, params_b, type_a, pos_a, rot_a, params_a, geom_f, geom_i,
                                 off_f_a, off_i_a, prediction, out_f, out_i, n)
        flip_normals(out_f, n, m)
        return m
    if type_a == st.HULL or type_b == st.HULL:
        if type_a == st.HULL:
            return collide_hull_shape(pos_a, rot_a, params_a, off_f_a, off_i_a, type_b, pos_b, rot_b, params_b,
                                      off_f_b, off_i_b, geom_f, geom_i, prediction, out_f, out_i, n)
        m = collide_hull_shape(pos_b, rot_b, params_b, off_f_b, off_i_b, type_a, pos_a, rot_a, params_a, off_f_a,
                               off_i_a, geom_f, geom_i, prediction, out_f, out_i, n)
        flip_normals(out_f, n, m)
        return m
    if type_a <= st.PLANE and type_b <= st.PLANE:
        return collide_convex_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, prediction,
                                   out_f, out_i, n)
    if type_a <= st.BOX and type_b == st.MESH:
        return collide_convex_mesh(type_a, pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, geom_i,
                                   off_f_b, off_i_b, prediction, out_f, out_i, n)
    if type_a <= st.BOX and type_b == st.HEIGHTFIELD:
        return collide_convex_heightfield(type_a, pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f,
                                          geom_i, off_f_b, off_i_b, prediction, out_f, out_i, n)
    if type_b <= st.BOX and type_a == st.MESH:
        m = collide_convex_mesh(type_b, pos_b, rot_b, params_b, pos_a, rot_a, params_a, geom_f, geom_i,
                                off_f_a, off_i_a, prediction, out_f, out_i, n)
    elif type_b <= st.BOX and type_a == st.HEIGHTFIELD:
        m = collide_convex_heightfield(type_b, pos_b, rot_b, params_b, pos_a, rot_a, params_a, geom_f,
                                       geom_i, off_f_a, off_i_a, prediction, out_f, out_i, n)
    else:
        return n
    flip_normals(out_f, n, m)
    return m


@njit_inline
def collide_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i,
                 off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n):
    """Contacts of any two shapes, normals from a to b; returns the new count.

    As :func:`collide_convex_pair`, plus height fields and meshes, whose bulk geometry lies in the
    blobs ``geom_f`` (float64) and ``geom_i`` (int64) at each shape's offsets.  Two static-only
    shapes (plane, height field, mesh) have no contacts.  Each pair test is called from here directly:
    every level of calls between passes (and reference counts) all the arrays again.
    """
    return collide_pair_covering(COVER_ALL, type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f,
                                 geom_i, off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n)


@njit_inline
def collide_sphere_shape(coverage, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i, off_f_b,
                         off_i_b, prediction, out_f, out_i, n):
    """:func:`collide_pair` of a sphere a (radius ``params_a[0]``, m) with shape b of any kind, normals from the
    sphere to b, with the sphere's pair tests only (a particle's, or any pair of a world whose moving shapes
    are spheres: no box, capsule or hull test against other shapes is compiled for it); with ``coverage``
    ``COVER_SPHERES``, not against meshes, height fields or hulls either, with ``COVER_MESHES`` not against height
    fields or hulls."""
    if type_b <= st.PLANE:
        hit, p, normal, depth = sphere_primitive(load(pos_a), params_a[0], type_b, load(pos_b), matrix(rot_b),
                                                 (params_b[0], params_b[1], params_b[2], params_b[3]), prediction)
        return add_contact(out_f, out_i, n, p, normal, depth, 0) if hit else n
    if coverage == COVER_SPHERES:
        return n                    # no mesh, height field or hull in this world
    if type_b == st.MESH:
        return collide_sphere_mesh(load(pos_a), params_a[0], load(pos_b), matrix(rot_b), params_b, geom_f, geom_i,
                                   off_f_b, off_i_b, prediction, out_f, out_i, n)
    if coverage == COVER_MESHES:
        return n                    # no height field or hull in this world
    if type_b == st.HEIGHTFIELD:
        return collide_sphere_heightfield(pos_a, rot_a, params_a, pos_b, rot_b, params_b, geom_f, off_f_b, prediction,
                                          out_f, out_i, n)
    if type_b == st.HULL:
        verts, planes, starts, loops, edges = hull_polytope(pos_b, rot_b, geom_f, geom_i, off_f_b, off_i_b)
        return collide_segment_polytope(True, load(pos_a), (0.0, 0.0, 0.0), params_a[0], verts, planes, starts,
                                        loops, edges, prediction, out_f, out_i, n)
    return n


@njit
def collide_sphere_primitive_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i,
                                  off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n):
    """:func:`collide_pair` of a sphere and a sphere, capsule, box or plane, compiled with the sphere-primitive
    tests alone (the game's goal test, a sphere against a box, compiles in a second)."""
    return collide_pair_covering(COVER_SPHERES, type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b,
                                 geom_f, geom_i, off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n)


@njit
def collide_sphere_mesh_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i,
                             off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n):
    """:func:`collide_pair` of a sphere and a primitive or a triangle mesh, compiled with those tests alone."""
    return collide_pair_covering(COVER_MESHES, type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b,
                                 geom_f, geom_i, off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n)


@njit
def collide_sphere_pair(type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b, geom_f, geom_i, off_f_a,
                        off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n):
    """:func:`collide_pair` where a or b is a sphere, compiled with the sphere's pair tests only (a query of a
    sphere need not wait for every pair test to compile)."""
    return collide_pair_covering(COVER_GROUND, type_a, pos_a, rot_a, params_a, type_b, pos_b, rot_b, params_b,
                                 geom_f, geom_i, off_f_a, off_i_a, off_f_b, off_i_b, prediction, out_f, out_i, n)


#: a sphere's pair test by its coverage (``shape_types.COVER_*`` below ``COVER_ALL``: the other shape's kind),
#: ``SPHERE_PAIR[coverage]``
SPHERE_PAIR = (collide_sphere_primitive_pair, collide_sphere_mesh_pair, collide_sphere_pair)
