"""Every cloth and every soft body of a world as a shaded surface: its triangles as they are now, with smooth
normals (a soft body's triangles are the boundary of its tetrahedra).

A cloth is drawn from its vertices' positions and its current triangles (``Cloth.triangles``, which change as
it tears: the vertices along a tear are split in two, so a tear opens as a gap).  Each vertex's normal is
recomputed every frame from the positions, as the area-weighted mean of the normals of its triangles::

    n_v = normalize( sum over the triangles (a, b, c) around v of (x_b - x_a) x (x_c - x_a) )

(a triangle's edge cross product is its normal times twice its area), so the shading runs smoothly over the
folds of the sheet and breaks along a tear.  Both faces are lit (the renderer turns the normal of a face seen
from behind towards the eye, and ``draw_lists.SHEET`` lets the sun show through).  The cloth's vertices are
not drawn again as particles, nor its edges as springs (``world_internals.particle_table``,
``network_edges``).
"""
import numpy as np

from . import palette
from .draw_lists import PLAIN, SHEET, Points, Surface

#: The normal (+y) of a vertex whose triangles have no area (a sheet crushed to a line or a point).
_UP = np.array([0.0, 1.0, 0.0])


def vertex_normals(positions, triangles):
    """Unit normals (V, 3) at the vertices ``positions`` (V, 3) (m) of the mesh ``triangles`` (T, 3) (vertex
    indices, counter-clockwise seen from the front): each the area-weighted mean of the normals of the
    triangles it is a corner of, +y where those have no area (or there are none)."""
    x = np.asarray(positions, np.float64)
    t = np.asarray(triangles, np.int64).reshape(-1, 3)
    face = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])      # (T, 3): normal times 2 area
    corners = t.reshape(-1)
    n = np.column_stack([np.bincount(corners, weights=np.repeat(face[:, k], 3), minlength=len(x))
                         for k in range(3)])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0.0, n / np.maximum(length, 1e-300), _UP)


def soft_body_surfaces(frame):
    """A :class:`Surface` of the boundary of every soft body of ``frame.world`` (its surface triangles at the
    nodes' positions now), in the soft-body colour, smooth-shaded like a cloth, and a raspberry dot on each
    pinned node."""
    out = []
    pinned = []
    for body in frame.world.soft_bodies:
        x, t = body.positions, body.surface_triangles
        out.append(Surface(x, vertex_normals(x, t), t, np.asarray(palette.SOFT_BODY), PLAIN))
        pinned.append(x[body.pinned])
    held = np.concatenate(pinned) if pinned else np.zeros((0, 3))
    if held.shape[0]:
        out.append(Points(held, np.tile(palette.PINNED_PARTICLE, (held.shape[0], 1)), 8.0))
    return out


def cloth_surfaces(frame):
    """A :class:`Surface` of every cloth of ``frame.world``, in the cloth colour, its normals from its
    positions now."""
    out = []
    for cloth in frame.world.cloths:
        x, t = cloth.positions, cloth.triangles
        out.append(Surface(x, vertex_normals(x, t), t, np.asarray(palette.CLOTH), SHEET))
    return out
