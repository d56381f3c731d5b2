"""Adjacency of a triangle soup across the whole mesh: welded vertices, edge neighbours, vertex rings.

Built once per mesh (NumPy, plus a few compiled loops), for the ghost-free contacts of
``triangle_contact`` and for ``mesh_check``:

- weld: vertices closer than ``weld_tolerance`` (m) share one welded id, so duplicated vertices of
  separate triangles (split normals/UVs, separate objects) are joined;
- edge neighbours: edges with the same welded end points are neighbours; edges left open are then
  matched against collinear, overlapping open edges (T-junctions, where one long edge meets two
  short ones), taking the one that overlaps most;
- for each triangle edge, ``m2``: the neighbour's unit in-plane direction pointing away from the
  edge into the neighbour (0 for an open edge);
- vertex rings: for each welded vertex, the welded vertices joined to it by an edge (CSR).

Degenerate triangles (zero area, or two corners welded together) take no part.
"""
import numpy as np

from ..._numba.jit import njit

#: A triangle is degenerate when ``|(B - A) x (C - A)| <= DEGENERATE_SIN * (longest edge)^2``
#: (the sine of its smallest angle is at rounding level).
DEGENERATE_SIN = 1e-12


class Adjacency:
    """Result of :func:`build_adjacency` (arrays over triangles ``T`` and vertices ``V``).

    ``normals`` (T, 3) unit face normals (0 for degenerate); ``degenerate`` (T,) bool;
    ``weld`` (V,) welded id; ``representative`` (W,) a vertex index of each welded id;
    ``partner`` (T, 3) neighbour triangle across each edge (-1 open); ``partner_edge`` (T, 3) its
    edge number; ``exact`` (T, 3) bool, neighbour shares both welded end points;
    ``group_size`` (T, 3) triangles on that welded edge; ``m2`` (T, 3, 3); ``ring_start`` (W + 1,)
    and ``ring`` (vertex indices of neighbours).
    """

    def __init__(self, **arrays):
        self.__dict__.update(arrays)


def face_normals(vertices, triangles):
    """Unit normals (T, 3) by the right-hand rule ``(B - A) x (C - A)``, and the degenerate mask."""
    a = vertices[triangles[:, 0]]
    b = vertices[triangles[:, 1]]
    c = vertices[triangles[:, 2]]
    cr = np.cross(b - a, c - a)
    area2 = np.sqrt(np.einsum("ij,ij->i", cr, cr))
    longest2 = np.maximum(np.maximum(np.einsum("ij,ij->i", b - a, b - a), np.einsum("ij,ij->i", c - b, c - b)),
                          np.einsum("ij,ij->i", a - c, a - c))
    degenerate = ~(area2 > DEGENERATE_SIN * longest2)
    normals = np.zeros_like(cr)
    ok = ~degenerate
    normals[ok] = cr[ok] / area2[ok, None]
    return normals, degenerate


def unique_rows(keys):
    """Group equal rows of the int64 array ``keys`` (n, k): ``(first, inverse)`` with ``first`` the
    smallest row index of each group (groups in lexicographic order) and ``inverse`` each row's
    group.  (A lexicographic sort: much faster than ``np.unique(axis=0)``.)"""
    order = np.lexsort(keys.T[::-1])
    sk = keys[order]
    new = np.ones(len(order), bool)
    new[1:] = np.any(sk[1:] != sk[:-1], axis=1)
    group = np.cumsum(new) - 1
    inverse = np.empty(len(order), np.int64)
    inverse[order] = group
    first = np.full(int(group[-1]) + 1 if len(order) else 0, len(order), np.int64)
    np.minimum.at(first, group, order)
    return first, inverse


def weld_vertices(vertices, tolerance):
    """Welded id of every vertex (quantised to ``tolerance`` metres) and a representative of each."""
    lo = vertices.min(axis=0)
    keys = np.floor((vertices - lo) / tolerance + 0.5).astype(np.int64)
    first, inverse = unique_rows(keys)
    return inverse, first


@njit
def _match_collinear(order, group, lo, hi, tri, partner, partner_edge, best_overlap, min_overlap):
    """Sweep open edges sorted by (line, start): each pair on one line overlapping by more than
    ``min_overlap`` is a candidate; every edge keeps the partner with the largest overlap."""
    m = order.shape[0]
    for ii in range(m):
        i = order[ii]
        for jj in range(ii + 1, m):
            j = order[jj]
            if group[j] != group[i] or lo[j] >= hi[i]:
                break
            if tri[i] // 3 == tri[j] // 3:
                continue
            ov = min(hi[i], hi[j]) - lo[j]
            if ov > min_overlap:
                if ov > best_overlap[i]:
                    best_overlap[i] = ov
                    partner[i] = tri[j]
                if ov > best_overlap[j]:
                    best_overlap[j] = ov
                    partner[j] = tri[i]
    for i in range(m):
        if partner[i] >= 0:
            partner_edge[i] = partner[i] % 3
            partner[i] = partner[i] // 3


def build_adjacency(vertices, triangles, weld_tolerance):
    """Adjacency of ``triangles`` (T, 3) int64 over ``vertices`` (V, 3) float64; see :class:`Adjacency`."""
    n_tri = triangles.shape[0]
    normals, degenerate = face_normals(vertices, triangles)
    weld, representative = weld_vertices(vertices, weld_tolerance)
    wt = weld[triangles]
    degenerate |= (wt[:, 0] == wt[:, 1]) | (wt[:, 1] == wt[:, 2]) | (wt[:, 2] == wt[:, 0])
    normals[degenerate] = 0.0
    live = np.nonzero(~degenerate)[0]

    # Edges (t, k) from corner k to corner k+1, over live triangles only.
    e_tri = np.repeat(live, 3)
    e_k = np.tile(np.arange(3), live.shape[0])
    wi = wt[e_tri, e_k]
    wj = wt[e_tri, (e_k + 1) % 3]
    n_weld = representative.shape[0]
    key = np.minimum(wi, wj) * n_weld + np.maximum(wi, wj)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.r_[0, np.nonzero(np.diff(skey))[0] + 1]
    sizes = np.diff(np.r_[starts, skey.shape[0]])
    size_of = np.repeat(sizes, sizes)
    first_of = np.repeat(starts, sizes)
    pos = np.arange(skey.shape[0])
    nxt = np.where(pos + 1 < first_of + size_of, pos + 1, first_of)     # cyclic next in the group
    partner = np.full((n_tri, 3), -1, np.int64)
    partner_edge = np.full((n_tri, 3), -1, np.int64)
    group_size = np.zeros((n_tri, 3), np.int64)
    exact = np.zeros((n_tri, 3), bool)
    st, sk = e_tri[order], e_k[order]
    group_size[st, sk] = size_of
    shared = size_of > 1
    partner[st[shared], sk[shared]] = st[nxt[shared]]
    partner_edge[st[shared], sk[shared]] = sk[nxt[shared]]
    exact[st[shared], sk[shared]] = True

    # T-junctions: open edges that lie on one line and overlap.
    open_t, open_k = st[~shared], sk[~shared]
    if open_t.shape[0] > 1:
        u = vertices[triangles[open_t, open_k]]
        w = vertices[triangles[open_t, (open_k + 1) % 3]]
        d = w - u
        length = np.sqrt(np.einsum("ij,ij->i", d, d))
        d = d / length[:, None]
        big = np.argmax(np.abs(d), axis=1)
        d *= np.sign(d[np.arange(d.shape[0]), big])[:, None]
        s_u = np.einsum("ij,ij->i", u, d)
        s_w = np.einsum("ij,ij->i", w, d)
        foot = u - s_u[:, None] * d
        line = np.concatenate([np.floor(d * 1e6 + 0.5), np.floor((foot - vertices.min(axis=0)) /
                                                                 (1e3 * weld_tolerance) + 0.5)], axis=1)
        _, group = unique_rows(line.astype(np.int64))
        lo = np.minimum(s_u, s_w)
        hi = np.maximum(s_u, s_w)
        srt = np.lexsort((lo, group)).astype(np.int64)
        tp = np.full(open_t.shape[0], -1, np.int64)
        te = np.full(open_t.shape[0], -1, np.int64)
        _match_collinear(srt, group, lo, hi, open_t * 3 + open_k, tp, te,
                         np.zeros(open_t.shape[0]), 10.0 * weld_tolerance)
        partner[open_t, open_k] = tp
        partner_edge[open_t, open_k] = te

    # m2: the neighbour's in-plane direction away from the edge, towards its opposite corner.
    m2 = np.zeros((n_tri, 3, 3))
    has = partner >= 0
    pt, pe = partner[has], partner_edge[has]
    pu = vertices[triangles[pt, pe]]
    pw = vertices[triangles[pt, (pe + 1) % 3]]
    po = vertices[triangles[pt, (pe + 2) % 3]]
    d = pw - pu
    d /= np.sqrt(np.einsum("ij,ij->i", d, d))[:, None]
    v = po - pu
    v -= np.einsum("ij,ij->i", v, d)[:, None] * d
    v /= np.sqrt(np.einsum("ij,ij->i", v, v))[:, None]
    m2[has] = v

    # Vertex rings over welded ids (both directions of every live edge, without repeats).
    pair_key = np.sort(np.r_[wi * n_weld + wj, wj * n_weld + wi])
    if pair_key.size:        # (none when every triangle is degenerate)
        pair_key = pair_key[np.r_[True, pair_key[1:] != pair_key[:-1]]]
    owner, member = pair_key // n_weld, pair_key % n_weld
    ring_start = np.zeros(n_weld + 1, np.int64)
    np.add.at(ring_start, owner + 1, 1)
    ring_start = np.cumsum(ring_start)
    ring = representative[member]
    return Adjacency(normals=normals, degenerate=degenerate, weld=weld, representative=representative,
                     partner=partner, partner_edge=partner_edge, exact=exact, group_size=group_size,
                     m2=m2, ring_start=ring_start, ring=ring.astype(np.int64))
