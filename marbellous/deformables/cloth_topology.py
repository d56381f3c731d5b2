"""A cloth's mesh as constraints: its edges (stretch springs), its hinges (bends), its vertices' masses, and
the splitting of its vertices where it has torn.

All in the cloth's own vertex numbering, on its rest shape ``rest`` (V, 3) and triangles (T, 3).

Stretch: every edge of the triangles is a spring of stiffness (N/m)

    k_e = (4/5) Y A_e / L_e^2

``Y`` the cloth's stretch stiffness (N/m, a membrane's force per unit width per unit strain), ``L_e`` the
edge's rest length, ``A_e`` the rest area of the (one or two) triangles that hold it.  The 4/5: a sheet of
right triangles (``cloth_grid``) stretched along its grid lines with its width held, whose springs along the
stretch (``k = 4/5 Y``) and diagonals (``2/5 Y``, at half the strain) store the energy ``Y eps^2 / 2`` per
unit area, as a membrane of stiffness ``Y`` does.

Tearing: a torn edge stops acting at once; where torn edges cut the triangles around a vertex into separate
fans (two torn edges through an inner vertex, one through a vertex on the border), the vertex becomes one
vertex per fan, so that the mesh splits along the tear.  A tear's tip (one torn edge through an inner vertex)
stays joined until the tear runs on.
"""
import numpy as np

#: the stretch springs' share of ``Y A / L^2`` (module docstring)
STRETCH_SHARE = 0.8


def triangle_areas(rest, triangles):
    """Each triangle's area (m^2) in the rest shape."""
    a, b, c = rest[triangles[:, 0]], rest[triangles[:, 1]], rest[triangles[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def vertex_masses(rest, triangles, n_vertices, density):
    """Each vertex's mass (kg): a third of the rest area of each triangle it is a corner of, times
    ``density`` (kg/m^2)."""
    share = np.repeat(triangle_areas(rest, triangles) / 3.0, 3)
    return density * np.bincount(triangles.reshape(-1), weights=share, minlength=n_vertices)


def _edge_occurrences(triangles):
    """For the 3 T directed edges of the triangles (``(0, 1), (1, 2), (2, 0)`` of each): their vertices
    ``(3 T, 2)``, their corners ``(3 T, 2)`` (corner ``3 t + k``), and their undirected keys sorted, with the
    order that sorts them."""
    t = triangles.shape[0]
    local = np.array([[0, 1], [1, 2], [2, 0]])
    corners = (3 * np.arange(t)[:, None, None] + local[None]).reshape(-1, 2)
    vertices = triangles.reshape(-1)[corners]
    keys = np.sort(vertices, axis=1)
    order = np.lexsort((keys[:, 1], keys[:, 0]))
    return vertices, corners, keys, order


def border_edges(triangles):
    """Per triangle, the bits ``1 << k`` of its edges on the border of the mesh (held by no other triangle), edge
    ``k`` the one opposite its corner ``k``."""
    _, corners, keys, order = _edge_occurrences(triangles)
    k = keys[order]
    same = np.all(k[1:] == k[:-1], axis=1)
    alone = np.ones(k.shape[0], dtype=bool)
    alone[1:] &= ~same
    alone[:-1] &= ~same
    border = np.zeros(triangles.shape[0], dtype=np.int64)
    occurrence = order[alone]              # directed edge 3 t + j runs from corner j to corner j + 1: opposite j + 2
    np.bitwise_or.at(border, occurrence // 3, 1 << ((occurrence % 3 + 2) % 3))
    return border


def _shared(keys, order):
    """Pairs ``(i, j)`` of occurrences of the same undirected edge, for edges held by exactly two triangles."""
    k = keys[order]
    same = np.all(k[1:] == k[:-1], axis=1)
    starts = np.flatnonzero(np.concatenate([[True], ~same]))
    counts = np.diff(np.concatenate([starts, [k.shape[0]]]))
    two = starts[counts == 2]
    return order[two], order[two + 1]


def _in_pairs(keys, pairs):
    """Whether each row of ``keys`` (sorted vertex pairs) is one of ``pairs`` (sorted pairs)."""
    if pairs.shape[0] == 0 or keys.shape[0] == 0:
        return np.zeros(keys.shape[0], dtype=bool)
    big = max(int(keys.max()), int(pairs.max())) + 1
    return np.isin(keys[:, 0] * big + keys[:, 1], pairs[:, 0] * big + pairs[:, 1])


def split_torn(triangles, torn, n_vertices):
    """Split the vertices whose fans the torn edges ``torn`` (sorted pairs) cut apart (module docstring).
    Returns ``(triangles, source)``: the new triangles, and for each vertex of the new numbering the vertex it
    came from (the first ``n_vertices`` keep their numbers)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    vertices, corners, keys, order = _edge_occurrences(triangles)
    i, j = _shared(keys, order)
    joined = ~_in_pairs(keys[i], torn)
    i, j = i[joined], j[joined]
    same = vertices[i, 0] == vertices[j, 0]
    a = np.concatenate([corners[i, 0], corners[i, 1]])
    b = np.concatenate([np.where(same, corners[j, 0], corners[j, 1]), np.where(same, corners[j, 1], corners[j, 0])])
    n_corners = 3 * triangles.shape[0]
    graph = coo_matrix((np.ones(a.shape[0]), (a, b)), shape=(n_corners, n_corners))
    _, fan = connected_components(graph, directed=False)
    vertex = triangles.reshape(-1)
    # each (vertex, fan) one vertex: the fan holding the vertex's first corner keeps the vertex's number
    first_corner = np.full(fan.max() + 1, n_corners)
    np.minimum.at(first_corner, fan, np.arange(n_corners))
    pairs, inverse = np.unique(np.stack([vertex, first_corner[fan]], axis=1), axis=0, return_inverse=True)
    keeps = np.concatenate([[True], pairs[1:, 0] != pairs[:-1, 0]])
    number = pairs[:, 0].copy()
    number[~keeps] = n_vertices + np.arange(np.count_nonzero(~keeps))
    new = number[inverse.reshape(-1)].astype(np.int64)
    source = np.concatenate([np.arange(n_vertices), pairs[~keeps, 0]]).astype(np.int64)
    return new.reshape(-1, 3), source


def edges_and_hinges(triangles, torn):
    """The cloth's edges and hinges: ``(edges (E, 2), torn (E,) bool, hinges (H, 4))``.  Edges: each
    undirected edge of the triangles once (sorted pairs); those in ``torn`` and still held by two triangles
    marked torn.  Hinges ``(x0, x1, x2, x3)``: each edge held by exactly two triangles and not torn, then each
    triangle's third corner."""
    vertices, corners, keys, order = _edge_occurrences(triangles)
    edges = np.unique(keys, axis=0)
    i, j = _shared(keys, order)
    shared = keys[i]
    still = _in_pairs(shared, torn)
    edge_torn = _in_pairs(edges, shared[still])
    i, j = i[~still], j[~still]
    flat = triangles.reshape(-1)
    far_i = flat[3 * (corners[i, 0] // 3) + (corners[i, 1] % 3 + 1) % 3]
    far_j = flat[3 * (corners[j, 0] // 3) + (corners[j, 1] % 3 + 1) % 3]
    hinges = np.stack([vertices[i, 0], vertices[i, 1], far_i, far_j], axis=1).astype(np.int64)
    return edges.astype(np.int64), edge_torn, hinges.reshape(-1, 4)


def edge_stiffness(rest, triangles, edges, stretch_stiffness):
    """Each edge's spring stiffness (N/m) and rest length (m) (module docstring)."""
    _, _, keys, _ = _edge_occurrences(triangles)
    area = np.repeat(triangle_areas(rest, triangles), 3)
    big = int(max(edges.max(), keys.max())) + 1
    slot = np.searchsorted(edges[:, 0] * big + edges[:, 1], keys[:, 0] * big + keys[:, 1])
    held = np.bincount(slot, weights=area, minlength=edges.shape[0])
    length = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)
    return STRETCH_SHARE * stretch_stiffness * held / np.maximum(length, 1e-12) ** 2, length


def hinge_stiffness(rest, hinges, bend_stiffness):
    """Each hinge's stiffness ``kappa = D |e|^2 / A`` (N m per rad^2; bend_constraints.py)."""
    x0, x1, x2, x3 = (rest[hinges[:, k]] for k in range(4))
    area = 0.5 * (np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1) + np.linalg.norm(np.cross(x1 - x0, x3 - x0),
                                                                                     axis=1))
    return bend_stiffness * np.sum((x1 - x0) ** 2, axis=1) / np.maximum(area, 1e-24)
