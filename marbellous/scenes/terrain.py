"""A marble rolling across a hilly terrain given as a triangle mesh (131,072 triangles by default), and a bowl
of triangles to pour things into (``bowl``).

The terrain is a regular grid of ``n x n`` cells over x-z, two triangles per cell split along the
diagonal from (i, j) to (i+1, j+1), with heights

    y(x, z) = -slope x + a sin(2 pi x / L) sin(2 pi z / L) + (a / 2) sin(2 pi (x + 2z) / (L / 2))

(gentle hills on an incline down towards +x, so the marble keeps rolling).  ``terrain_height`` gives
the mesh's own piecewise-linear height, the exact surface the marble rolls on.
"""
import math

import numpy as np

from ..shapes.mesh import TriangleMesh
from ..shapes.primitives import Sphere
from ..world import World

#: default grid: 256 x 256 cells, 2 triangles each = 131,072 triangles
CELLS = 256
SPACING = 0.5         # m between grid lines
SLOPE = 0.05          # fall per metre along +x
AMPLITUDE = 0.4       # m, height of the hills
WAVELENGTH = 16.0     # m, size of the hills


def _heights(x, z):
    """Analytic heights (m) at grid points."""
    k = 2.0 * math.pi / WAVELENGTH
    return (-SLOPE * x + AMPLITUDE * np.sin(k * x) * np.sin(k * z)
            + 0.5 * AMPLITUDE * np.sin(2.0 * k * (x + 2.0 * z)))


def terrain_grid(cells=CELLS, spacing=SPACING):
    """Grid of the terrain: ``(origin_x, origin_z, spacing, heights)`` with ``heights`` of shape
    ``(cells + 1, cells + 1)`` indexed ``[i, j]`` at ``x = origin_x + i spacing``, ``z = origin_z + j spacing``.
    The grid is centred on the origin."""
    half = cells * spacing / 2.0
    coords = -half + spacing * np.arange(cells + 1)
    x, z = np.meshgrid(coords, coords, indexing="ij")
    return -half, -half, spacing, _heights(x, z)


def terrain_arrays(cells=CELLS, spacing=SPACING):
    """Vertices (V, 3) and counter-clockwise-from-above triangles (2 cells^2, 3) of the terrain."""
    x0, z0, d, h = terrain_grid(cells, spacing)
    n = cells + 1
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    vertices = np.column_stack([(x0 + d * i).ravel(), h.ravel(), (z0 + d * j).ravel()])
    v00 = (np.arange(cells)[:, None] * n + np.arange(cells)[None, :]).ravel()
    v01, v10, v11 = v00 + 1, v00 + n, v00 + n + 1
    # (B - A) x (C - A) points along +y for both halves of a cell.
    triangles = np.concatenate([np.column_stack([v00, v01, v11]), np.column_stack([v00, v11, v10])])
    return vertices, triangles


def terrain_mesh(cells=CELLS, spacing=SPACING, accel="grid2d"):
    """The terrain as a :class:`marbellous.TriangleMesh` (``2 cells^2`` triangles)."""
    vertices, triangles = terrain_arrays(cells, spacing)
    return TriangleMesh(vertices, triangles, accel=accel)


def terrain_height(x, z, cells=CELLS, spacing=SPACING):
    """Height (m) of the terrain mesh's surface at ``(x, z)`` (linear on each triangle).

    In a cell with fractions (u, v) along x and z:  y = h00 + v (h01 - h00) + u (h11 - h01) when v >= u,
    else y = h00 + u (h10 - h00) + v (h11 - h10)."""
    x0, z0, d, h = terrain_grid(cells, spacing)
    fx = min(max((x - x0) / d, 0.0), cells - 1e-9)
    fz = min(max((z - z0) / d, 0.0), cells - 1e-9)
    i, j = int(fx), int(fz)
    u, v = fx - i, fz - j
    h00, h01, h10, h11 = h[i, j], h[i, j + 1], h[i + 1, j], h[i + 1, j + 1]
    if v >= u:
        return float(h00 + v * (h01 - h00) + u * (h11 - h01))
    return float(h00 + u * (h10 - h00) + v * (h11 - h10))


def marble_on_terrain(world=None, *, cells=CELLS, spacing=SPACING, radius=0.25, velocity=(3.0, 0.0, 1.0),
                      friction=0.5, accel="grid2d", mesh=None):
    """A marble of ``radius`` (m) resting on the terrain near its -x edge, launched with ``velocity`` (m/s).

    ``mesh``: a ``terrain_mesh(cells, spacing, accel)`` built before, to reuse (None: build one).
    Returns ``(world, [terrain, marble])``; the marble starts touching the surface at x = -L/3, z = 0
    where L = cells * spacing is the terrain's side."""
    w = World() if world is None else world
    mesh = terrain_mesh(cells, spacing, accel) if mesh is None else mesh
    terrain = w.add_static(mesh, friction=friction)
    x = -cells * spacing / 3.0
    y = terrain_height(x, 0.0, cells, spacing) + radius
    marble = w.add_body(Sphere(radius), position=(x, y, 0.0), velocity=velocity, friction=friction)
    return w, [terrain, marble]


def bowl(radius=2.0, depth=1.0, rings=6, sectors=16):
    """A bowl ``y = depth (r / radius)^2`` (m) of triangles facing up, centred on the origin: ``rings`` rings of
    ``sectors`` vertices around a centre vertex."""
    verts = [(0.0, 0.0, 0.0)]
    for i in range(1, rings + 1):
        r = radius * i / rings
        verts += [(r * math.cos(a), depth * (r / radius) ** 2, r * math.sin(a))
                  for a in 2.0 * math.pi * np.arange(sectors) / sectors]
    tris = [(0, 1 + (j + 1) % sectors, 1 + j) for j in range(sectors)]
    for i in range(rings - 1):
        inner, outer = 1 + i * sectors, 1 + (i + 1) * sectors
        for j in range(sectors):
            k = (j + 1) % sectors
            tris += [(inner + j, inner + k, outer + j), (inner + k, outer + k, outer + j)]
    return TriangleMesh(np.array(verts), np.array(tris))
