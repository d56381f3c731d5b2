"""Triangles for drawing: shapes about their own origin, a level's colliders, the marble, the goal flag.

Every function returns ``(positions, normals)``: float32 arrays of shape (3 T, 3), three vertices per
triangle, counter-clockwise seen from outside, in world space for level colliders and in the local
frame for shapes and the marble.  Each face keeps its own normal; :func:`indexed` merges the corners that
triangles share (equal position and normal) so that the renderers draw each vertex once through an index buffer.
"""
import numpy as np
import trimesh

from .transforms import quat_to_matrix

#: Half side (m) of the square drawn for an infinite plane.
PLANE_HALF_SIZE = 150.0


def flat(vertices, triangles):
    """Unindexed triangles with face normals from indexed ``vertices`` (V, 3), ``triangles`` (T, 3)."""
    v = np.asarray(vertices, np.float64)[np.asarray(triangles, np.int64)]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return v.reshape(-1, 3).astype(np.float32), np.repeat(n, 3, axis=0).astype(np.float32)


def smooth(vertices, triangles, vertex_normals):
    """Unindexed triangles with interpolated per-vertex normals."""
    t = np.asarray(triangles, np.int64).ravel()
    return (np.asarray(vertices, np.float32)[t], np.asarray(vertex_normals, np.float32)[t])


def indexed(positions, normals):
    """``(vertices (V, 6) float32 rows [position, normal], indices (3 T,) uint32)`` of unindexed triangles
    ``positions``, ``normals`` (3 T, 3), with equal corners (the same position and normal) made one vertex.

    A smooth mesh's corner is shared by about six triangles, so it has about a sixth as many vertices
    as corners; GPUs (and llvmpipe) shade the vertices of an indexed draw once each, not once per corner.
    The vertices keep the order of their first corners, so that neighbouring triangles use nearby vertices
    (what a vertex cache keeps).
    """
    # (+ 0.0 turns -0.0 into 0.0: equal values, equal bytes)
    corners = np.ascontiguousarray(np.hstack([positions, normals]), np.float32) + np.float32(0.0)
    # each corner's 24 bytes as one opaque value: sorting those is a few times faster than rows of floats
    _, first, inverse = np.unique(corners.view(np.dtype((np.void, 24))).ravel(), return_index=True,
                                  return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return corners[first[order]], rank[inverse.reshape(-1)].astype(np.uint32)


def uv_sphere(radius=1.0, rings=24, segments=48):
    """A sphere of ``radius`` (m) about the origin with smooth normals."""
    m = trimesh.creation.uv_sphere(radius=radius, count=[rings, segments])
    return smooth(m.vertices, m.faces, m.vertices / radius)


def heightfield_triangles(heights, spacing, origin):
    """The surface ``y = y0 + heights[i, j]`` at ``x = x0 + i dx``, ``z = z0 + j dz``, smooth normals."""
    h = np.asarray(heights, np.float64)
    nx, nz = h.shape
    dx, dz = spacing
    x0, y0, z0 = origin
    i, j = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
    verts = np.stack([x0 + i * dx, y0 + h, z0 + j * dz], axis=-1).reshape(-1, 3)
    gx, gz = np.gradient(h, dx, dz)
    normals = np.stack([-gx, np.ones_like(h), -gz], axis=-1).reshape(-1, 3)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    a = (i[:-1, :-1] * nz + j[:-1, :-1]).ravel()
    b, c, d = a + nz, a + 1, a + nz + 1
    # split along the diagonal (i, j)-(i + 1, j + 1) like the physics' HeightField; counter-clockwise
    # seen from above (+y): (a, d, b) and (a, c, d)
    tris = np.concatenate([np.stack([a, d, b], 1), np.stack([a, c, d], 1)])
    return smooth(verts, tris, normals)


def box_triangles(half_extents):
    """A box of ``half_extents`` (m) about the origin, 12 triangles with face normals."""
    m = trimesh.creation.box(extents=2.0 * np.asarray(half_extents, np.float64))
    return flat(m.vertices, m.faces)


def capsule_triangles(radius, half_height, count=24):
    """A capsule along local y: a cylinder of ``radius`` and length ``2 half_height`` (m) with
    hemispherical caps, smooth normals, ``count`` segments around and per cap."""
    m = trimesh.creation.capsule(height=2.0 * half_height, radius=radius, count=[count, count])
    to_y = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])   # trimesh's axis is z, ours is y
    v = m.vertices @ to_y.T
    # the exact normal: from the nearest point of the axis segment to the vertex (trimesh's
    # ``vertex_normals`` would average face normals through scipy, an optional package)
    axis_point = np.zeros_like(v)
    axis_point[:, 1] = np.clip(v[:, 1], -half_height, half_height)
    n = v - axis_point
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return smooth(v, m.faces, n)


def collider_triangles(collider, center=(0.0, 0.0, 0.0)):
    """World-space triangles of a level collider (``marbellous.game.level.Collider``).

    An infinite plane is drawn as a square of half side :data:`PLANE_HALF_SIZE` around the point of
    the plane nearest to ``center``.
    """
    p = collider.params
    if collider.kind == "mesh":
        return flat(collider.vertices, collider.triangles)
    if collider.kind == "heightfield":
        return heightfield_triangles(collider.heights, p["spacing"], p["origin"])
    if collider.kind == "plane":
        n = np.asarray(p["normal"], np.float64)
        c = np.asarray(center, np.float64)
        c = c - (n @ c - p["offset"]) * n
        u = np.cross(n, (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 0.0, 1.0))
        u /= np.linalg.norm(u)
        w = np.cross(u, n)
        s = PLANE_HALF_SIZE
        quad = np.array([c - s * u - s * w, c + s * u - s * w, c + s * u + s * w, c - s * u + s * w])
        pos, nrm = flat(quad, [[0, 1, 2], [0, 2, 3]])
        if nrm[0] @ n < 0:
            pos, nrm = flat(quad, [[0, 2, 1], [0, 3, 2]])
        return pos, nrm
    if collider.kind == "box":
        local = box_triangles(p["half_extents"])
    elif collider.kind == "sphere":
        local = uv_sphere(p["radius"], 16, 32)
    else:
        local = capsule_triangles(p["radius"], p["half_height"])
    r = quat_to_matrix(collider.orientation)
    return ((local[0] @ r.T + collider.position).astype(np.float32), (local[1] @ r.T).astype(np.float32))


def grid_cells(level, cell_size):
    """Occupied cells of a 2D grid over the level's x-z plane: the lecture's 2D grid for the level mesh.

    A cell is occupied when the x-z bounding rectangle of one of the level's finite triangles overlaps
    it.  Returns ``(cells (K, 2) int64, tops (K,) float64, origin (2,), cell_size)`` with cell ``(i, k)``
    spanning ``origin + (i, k) * cell_size`` to ``origin + (i + 1, k + 1) * cell_size`` and ``tops`` the
    highest y (m) of the triangles over it.
    """
    tris = [collider_triangles(c)[0].reshape(-1, 3, 3) for c in level.colliders if c.kind != "plane"]
    if not tris:
        return np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(2), cell_size
    t = np.concatenate(tris).astype(np.float64)
    lo_xz = t[:, :, [0, 2]].min(axis=1)
    hi_xz = t[:, :, [0, 2]].max(axis=1)
    origin = lo_xz.min(axis=0)
    i0 = np.floor((lo_xz - origin) / cell_size).astype(np.int64)
    i1 = np.floor((hi_xz - origin) / cell_size).astype(np.int64)
    top = t[:, :, 1].max(axis=1)
    shape = i1.max(axis=0) + 1
    tops = np.full(shape, -np.inf)
    for (a0, b0), (a1, b1), y in zip(i0, i1, top):
        np.maximum(tops[a0:a1 + 1, b0:b1 + 1], y, out=tops[a0:a1 + 1, b0:b1 + 1])
    cells = np.argwhere(np.isfinite(tops))
    return cells, tops[cells[:, 0], cells[:, 1]], origin, cell_size
