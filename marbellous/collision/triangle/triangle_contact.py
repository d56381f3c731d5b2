"""Contacts of one convex shape with one triangle of a static mesh or height field, without ghosts.

The pair tests (``triangle_sphere``, ``triangle_capsule``, ``triangle_box``) write candidate
contacts as rows of a small ``scratch`` array (layout below).  A row is a contact on a triangle
*feature*: its face, one of its edges or one of its vertices.

Ghost collisions (a ball that hops where two triangles meet) come from edge and vertex contacts on
internal edges: on a flat or concave edge the closest point of one triangle lies on the shared edge
while the ball really rests on the neighbour's face, and the contact normal ``P - Q`` points
sideways.  A contact on a feature is only true if the query point ``P`` lies in the Voronoi region
of that feature on the *whole* surface, not just on its own triangle:

- edge ``e`` shared with a neighbour whose in-plane direction away from ``e`` is ``m2``: the
  neighbour's closest point to ``P`` is also ``Q`` iff ``(P - Q).m2 <= 0``.  For a flat edge
  ``m2 = -m1`` and only ``P - Q`` along the normal passes; for a concave edge nothing in front of
  the surface passes; for a convex edge exactly the wedge between the two face normals passes.
  An open edge has ``m2 = 0`` and always passes.
- vertex ``V`` with one-ring (welded) neighbours ``W``: ``P``'s closest point on every incident
  triangle is ``V`` iff ``(P - V).(W - V) <= 0`` for every ``W``.

A contact that fails is dropped: ``P`` then lies in the region of a neighbouring feature that is
at least as close, and that feature reports the true contact.  Neighbours come from welded vertex
positions and collinear overlapping edges (T-junctions), across the whole mesh.
"""
import math

from ..._numba.jit import njit
from ..vec3 import dot, sub

#: Columns of a scratch row (see ``write_row``): 0-2 point on the triangle, 3-5 unit normal from
#: the convex shape to the triangle, 6 depth (m, > 0 overlap), 7 feature code, 8-10 the query
#: point ``P`` (the sphere's centre, the capsule axis point) whose Voronoi region is tested.
N_COLS = 11
#: Rows of the scratch array: the most contacts one convex shape makes with one triangle.
MAX_ROWS = 8
#: Emitted contacts a query remembers to drop exact repeats.
SEEN_ROWS = 16
#: A contact's feature id is ``triangle * FEATURE_STRIDE + feature code`` (codes 0..15).
FEATURE_STRIDE = 16
#: Relative rounding allowance of the Voronoi tests: ``(P - Q).m2 <= GHOST_ROUNDING |P - Q|``.
GHOST_ROUNDING = 1e-12


@njit
def write_row(scratch, k, q, normal, depth, feature, centre):
    """Store one candidate contact in row ``k`` of ``scratch``; return ``k + 1``."""
    scratch[k, 0] = q[0]
    scratch[k, 1] = q[1]
    scratch[k, 2] = q[2]
    scratch[k, 3] = normal[0]
    scratch[k, 4] = normal[1]
    scratch[k, 5] = normal[2]
    scratch[k, 6] = depth
    scratch[k, 7] = feature
    scratch[k, 8] = centre[0]
    scratch[k, 9] = centre[1]
    scratch[k, 10] = centre[2]
    return k + 1


@njit
def edge_is_true(p, q, m2):
    """Voronoi test of an edge contact: ``(P - Q).m2 <= 0`` (``m2`` the neighbour's unit in-plane
    direction away from the edge, 0 for an open edge)."""
    pq = sub(p, q)
    return dot(pq, m2) <= GHOST_ROUNDING * math.sqrt(dot(pq, pq))


@njit
def vertex_ring_passes(p, v, w):
    """One term of the vertex Voronoi test: ``(P - V).(W - V) <= 0`` for a ring neighbour ``W``."""
    pv = sub(p, v)
    wv = sub(w, v)
    return dot(pv, wv) <= GHOST_ROUNDING * math.sqrt(dot(pv, pv) * dot(wv, wv))
