"""Checking a triangle mesh: degenerate, duplicate and flipped triangles, open and non-manifold edges.

Uses the welded adjacency of ``triangle_adjacency``:

- degenerate: zero area (or two corners welded together); they never collide;
- duplicate: a later triangle over the same three welded vertices as an earlier one;
- open edges: triangle edges with no neighbour at all (the rim of a terrain is open, which is
  normal for a level, so open edges alone do not warn); T-junctions (edges matched only to
  collinear overlapping edges) are counted separately;
- non-manifold edges: welded edges shared by three or more triangles;
- flipped: two triangles sharing an edge agree in winding when they run along it in opposite
  directions.  Orientation classes are propagated over shared manifold edges (union-find over
  ``(triangle, orientation)`` pairs); in every connected patch the triangles in the smaller class
  are reported as flipped.
"""
import numpy as np

from ..._numba.jit import njit
from ..triangle.triangle_adjacency import unique_rows


class MeshReport:
    """What :func:`check_mesh` found.  Counts are ints, index lists are int64 arrays.

    ``degenerate``, ``duplicate``, ``flipped``: triangle indices; ``open_edges``,
    ``non_manifold_edges``, ``t_junction_edges``: ``(triangle, edge)`` pairs, shape (k, 2), with
    edge ``k`` running from corner ``k`` to corner ``k + 1``.
    """

    def __init__(self, n_triangles, degenerate, duplicate, flipped, open_edges, non_manifold_edges,
                 t_junction_edges):
        self.n_triangles = n_triangles
        self.degenerate = degenerate
        self.duplicate = duplicate
        self.flipped = flipped
        self.open_edges = open_edges
        self.non_manifold_edges = non_manifold_edges
        self.t_junction_edges = t_junction_edges

    @property
    def has_problems(self):
        """True if any triangle is degenerate, duplicate or flipped or any edge non-manifold."""
        return bool(len(self.degenerate) or len(self.duplicate) or len(self.flipped)
                    or len(self.non_manifold_edges))

    def counts(self):
        """A dict of the number of each kind of finding."""
        return {"triangles": self.n_triangles, "degenerate": len(self.degenerate),
                "duplicate": len(self.duplicate), "flipped": len(self.flipped),
                "open_edges": len(self.open_edges), "non_manifold_edges": len(self.non_manifold_edges),
                "t_junction_edges": len(self.t_junction_edges)}

    def summary(self):
        """One line: the counts, e.g. ``'3 degenerate, 0 duplicate, ... of 200 triangles'``."""
        c = self.counts()
        return (f"{c['degenerate']} degenerate, {c['duplicate']} duplicate, {c['flipped']} flipped "
                f"triangles, {c['non_manifold_edges']} non-manifold edges, {c['open_edges']} open "
                f"edges, {c['t_junction_edges']} T-junction edges, of {c['triangles']} triangles")

    def __repr__(self):
        return f"MeshReport({self.summary()})"


@njit
def _find(parent, x):
    root = x
    while parent[root] != root:
        root = parent[root]
    while parent[x] != root:
        nxt = parent[x]
        parent[x] = root
        x = nxt
    return root


@njit
def _orientation_classes(n_tri, t1, t2, consistent):
    """Union-find over nodes ``2 t`` (as wound) and ``2 t + 1`` (flipped): returns the root of each
    triangle's as-wound node and of its flipped node."""
    parent = np.arange(2 * n_tri)
    for i in range(t1.shape[0]):
        a, b = 2 * t1[i], 2 * t2[i]
        if consistent[i]:
            pairs = ((a, b), (a + 1, b + 1))
        else:
            pairs = ((a, b + 1), (a + 1, b))
        for x, y in pairs:
            rx, ry = _find(parent, x), _find(parent, y)
            if rx != ry:
                parent[max(rx, ry)] = min(rx, ry)
    plus = np.empty(n_tri, np.int64)
    minus = np.empty(n_tri, np.int64)
    for t in range(n_tri):
        plus[t] = _find(parent, 2 * t)
        minus[t] = _find(parent, 2 * t + 1)
    return plus, minus


def check_mesh(vertices, triangles, adj):
    """A :class:`MeshReport` for ``triangles`` over ``vertices`` with adjacency ``adj``."""
    n_tri = triangles.shape[0]
    live = ~adj.degenerate
    degenerate = np.nonzero(adj.degenerate)[0]

    wt = adj.weld[triangles]
    srt = np.sort(wt, axis=1)
    live_idx = np.nonzero(live)[0]
    is_first = np.zeros(n_tri, bool)
    if live_idx.shape[0]:
        first, _ = unique_rows(srt[live_idx])
        is_first[live_idx[first]] = True
    duplicate = np.nonzero(live & ~is_first)[0]

    edge_live = np.repeat(live[:, None], 3, axis=1)
    open_edges = np.argwhere(edge_live & (adj.partner < 0))
    t_junction = np.argwhere(edge_live & (adj.partner >= 0) & ~adj.exact)
    non_manifold = np.argwhere(edge_live & (adj.group_size > 2))

    # Winding agreement over manifold edges (each pair once: t < partner).
    pairs = np.argwhere(edge_live & adj.exact & (adj.group_size == 2))
    t1, k1 = pairs[:, 0], pairs[:, 1]
    t2, k2 = adj.partner[t1, k1], adj.partner_edge[t1, k1]
    once = t1 < t2
    t1, k1, t2, k2 = t1[once], k1[once], t2[once], k2[once]
    same_start = wt[t1, k1] == wt[t2, k2]
    consistent = ~same_start             # opposite directions along the shared edge
    plus, minus = _orientation_classes(n_tri, t1.astype(np.int64), t2.astype(np.int64), consistent)
    patch = np.minimum(plus, minus)
    as_wound = plus <= minus
    flipped_mask = np.zeros(n_tri, bool)
    if live.any():
        ids, inv = np.unique(patch[live], return_inverse=True)
        n_wound = np.bincount(inv, weights=as_wound[live], minlength=ids.shape[0])
        n_all = np.bincount(inv, minlength=ids.shape[0])
        majority_wound = n_wound * 2 >= n_all
        flipped_mask[live_idx] = as_wound[live] != majority_wound[inv.reshape(-1)]
    flipped = np.nonzero(flipped_mask)[0]
    return MeshReport(n_tri, degenerate, duplicate, flipped, open_edges, non_manifold, t_junction)
