"""A convex hull against a plane: its vertices within ``prediction`` of the plane, reduced to four.

Vertex ``k`` at height ``h_k = n . v_k - offset`` above the plane is a contact of depth ``-h_k`` (feature id
``k``) when ``h_k <= prediction``; of more than ``MOST_CONTACTS`` such vertices, those touching come first
(four at most) and then the nearest (``pairs/manifold``): a hull resting on a small face keeps the corners
it rests on, not far corners above, and a falling hull the corners it meets first.
"""
from ..._numba.jit import njit
from ..pairs.contact_output import add_contact
from ..pairs.manifold import reduce_on_plane
from ..vec3 import scale
from .polytope import vertex

#: most contacts of a hull with a plane: four touching corners and the nearest speculative ones (a random hull
#: dropped from 2.9 m with four in all went 47 mm into the ground as a corner left out hit; with eight, 0.5 mm)
MOST_CONTACTS = 8


@njit
def collide_polytope_plane(verts, pn, off, prediction, out_f, out_i, n):
    """Contacts of the placed polytope ``verts`` (shape a) with the plane ``pn . x = off`` (shape b, unit
    ``pn``, solid below); normals from a to b (``-pn``).  Returns the new count."""
    heights, chosen, m = reduce_on_plane(verts, verts.shape[0], pn, off, prediction, MOST_CONTACTS)
    normal = scale(pn, -1.0)
    for q in range(m):
        k = chosen[q]
        n = add_contact(out_f, out_i, n, vertex(verts, k), normal, -heights[k], k)
    return n
