"""A fluid in a world: bodies as moving obstacles, and the fluid's buoyancy and drag on bodies, particles and
cloth.

*Obstacles.*  Each step, every cell whose centre lies inside a shape of a body (spheres, boxes, capsules,
convex hulls; planes as half-spaces) becomes solid, moving with the body: the faces of solid cells carry the
body's velocity ``v + omega x (x - c)`` at the face, so the fluid flows around the body and is pushed aside
by it.  Triangle meshes and height fields are not obstacles (they bound no volume).  A body that crosses the
box's walls would push fluid into a closed box; the net flow through its faces is taken off them evenly, so
the projection always has a solution.

*Buoyancy.*  Below the fluid's ``surface`` (a height in y), a body displaces ``V`` m^3 of fluid and feels
Archimedes' force ``F = -rho V g`` at the centroid of the displaced volume (exact for spheres; a 16^3
quadrature of each shape otherwise).  The grid's pressure leaves out the hydrostatic part (it changes no
flow), so this is the whole of it.

*Drag.*  Relative to the flow around it (the fluid's velocity averaged over a shell just outside the body),
an object of cross-section ``A`` and diameter ``d`` feels

    F = (rho C_d A |u_rel| / 2 + 3 pi rho nu d) u_rel

(Newton's quadratic drag plus Stokes' viscous drag), taken implicitly over the step with the rate
``k = |F| / (m |u_rel|)`` held: under a steady acceleration ``a`` (gravity, buoyancy) the exact solution of
``dv/dt = a + k (u - v)`` is

    v(dt) = u + (v - u) e^(-k dt) + (a / k) (1 - e^(-k dt))

so drag adds ``(u - v) (1 - e^(-k dt)) + a ((1 - e^(-k dt)) / k - dt)`` to what the step's own ``a dt`` does:
no step overshoots, however light the object, and a falling object reaches ``u + a / k`` (Stokes' settling
velocity, for a small one) at any step.  Rotation is damped at the same rate.  Particles feel drag with their
radius, cloth vertices with their share of the cloth's area; only the part of a body below the surface feels it.
"""
import math

import numpy as np

from ..deformables import particle_layout as P
from ..math3d import quat_to_matrix_np
from ..shapes.hull import ConvexHull
from ..shapes.primitives import Box, Capsule, Plane, Sphere

#: Newton's drag coefficient of a sphere at moderate Reynolds numbers
DRAG_COEFFICIENT = 0.47
#: quadrature points along each axis of a shape's box for its submerged volume
VOLUME_SAMPLES = 16
#: directions of the shell on which the flow around a body is sampled (the 6 faces and 8 corners of a cube)
SHELL = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
                 + [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float64)
SHELL /= np.linalg.norm(SHELL, axis=1)[:, None]


#: the shapes that bound a volume (and so displace fluid)
SOLID_SHAPES = (Sphere, Box, Capsule, ConvexHull)


def inside(shape, local):
    """Which of the points ``local`` (N, 3), in the shape's own frame (m), lie inside ``shape``; None for a
    shape that bounds no volume."""
    if isinstance(shape, Sphere):
        return np.einsum("ij,ij->i", local, local) <= shape.radius ** 2
    if isinstance(shape, Box):
        return np.all(np.abs(local) <= shape.half_extents, axis=1)
    if isinstance(shape, Capsule):
        along = np.clip(local[:, 1], -shape.half_height, shape.half_height)
        away = local.copy()
        away[:, 1] -= along
        return np.einsum("ij,ij->i", away, away) <= shape.radius ** 2
    if isinstance(shape, ConvexHull):
        geom_f, geom_i = shape._geometry()
        corners, faces = int(geom_i[0]), int(geom_i[1])
        planes = geom_f[3 * corners:3 * corners + 4 * faces].reshape(faces, 4)
        return np.all(local @ planes[:, :3].T <= planes[:, 3], axis=1)
    if isinstance(shape, Plane):
        return local @ shape.normal <= shape.offset
    return None


def volume_of(shape):
    """The volume (m^3) of a shape in ``SOLID_SHAPES``."""
    if isinstance(shape, Sphere):
        return 4.0 / 3.0 * math.pi * shape.radius ** 3
    if isinstance(shape, Box):
        return 8.0 * float(np.prod(shape.half_extents))
    if isinstance(shape, Capsule):
        return math.pi * shape.radius ** 2 * (2.0 * shape.half_height + 4.0 / 3.0 * shape.radius)
    return shape.volume()


def shape_poses(body):
    """``(shape, centre (m), rotation (3, 3))`` of each shape of ``body`` in the world."""
    position, rotation = body.position, quat_to_matrix_np(body.orientation)
    return [(shape, position + rotation @ p, rotation @ quat_to_matrix_np(q)) for shape, p, q in body.shapes]


def _cell_range(fluid, centre, radius):
    """Index ranges of the cells whose centres may lie within ``radius`` of ``centre``; None if none do."""
    lo = np.floor((centre - radius - fluid._origin) / fluid._h - 0.5).astype(np.int64)
    hi = np.ceil((centre + radius - fluid._origin) / fluid._h - 0.5).astype(np.int64) + 1
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, fluid._n)
    return None if np.any(hi <= lo) else (lo, hi)


def cell_centres(fluid, lo, hi):
    """The centres (m) of the cells ``lo .. hi - 1`` (index triples), ``(nx, ny, nz, 3)``."""
    axes = [fluid._origin[a] + (np.arange(lo[a], hi[a]) + 0.5) * fluid._h for a in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)


def mark_obstacles(fluid, bodies):
    """Solid cells (``fluid._solid``) and the velocity (m/s) of the bodies there, ``(3, nx, ny, nz)``.  The
    static bodies' cells are kept from step to step while those bodies stay where they are."""
    statics = [b for b in bodies if b.is_static]
    key = tuple((id(b), *b.position, *b.orientation) for b in statics)
    cached = fluid._static_cells
    if cached is None or cached[0] != key:
        cached = (key, *_cells_of(fluid, statics, np.zeros_like(fluid._solid), np.zeros_like(fluid._q)))
        fluid._static_cells = cached
    return _cells_of(fluid, [b for b in bodies if not b.is_static], cached[1].copy(), cached[2].copy())


def _cells_of(fluid, bodies, solid, velocity):
    """Mark the cells inside ``bodies`` in ``solid`` and their velocities in ``velocity``; returns both."""
    box_lo, box_hi = fluid._origin, fluid._origin + fluid._n * fluid._h
    for body in bodies:
        x, v, omega = body.position, body.velocity, body.angular_velocity
        for shape, centre, rotation in shape_poses(body):
            if isinstance(shape, Plane):
                cells = (np.zeros(3, np.int64), fluid._n.copy())
            else:
                reach = shape.bounding_radius()
                if np.any(centre + reach < box_lo) or np.any(centre - reach > box_hi):
                    continue
                cells = _cell_range(fluid, centre, reach)
            if cells is None:
                continue
            lo, hi = cells
            points = cell_centres(fluid, lo, hi)
            flat = points.reshape(-1, 3)
            hit = inside(shape, (flat - centre) @ rotation)
            if hit is None or not hit.any():
                continue
            hit = hit.reshape(points.shape[:3])
            window = tuple(slice(lo[a], hi[a]) for a in range(3))
            solid[window] |= hit.astype(np.uint8)
            moving = v + np.cross(omega, points - x)
            for c in range(3):
                velocity[(c,) + window] = np.where(hit, moving[..., c], velocity[(c,) + window])
    return solid, velocity


def obstacle_faces(fluid, solid, velocity):
    """The fixed faces (walls and faces of solid cells) and the velocity each fixed face of a solid cell
    takes: the mean of its solid cells' velocities."""
    fixed = np.zeros_like(fluid._fixed)
    values = fluid._q.copy()
    for c in range(3):
        if not fluid._periodic[c]:
            index = [slice(None)] * 3
            index[c] = 0
            fixed[(c,) + tuple(index)] = 1
        below = np.roll(solid, 1, axis=c)
        below_v = np.roll(velocity[c], 1, axis=c)
        if not fluid._periodic[c]:
            index = [slice(None)] * 3
            index[c] = 0
            below[tuple(index)] = 0
        count = solid.astype(np.float64) + below
        touched = count > 0
        mean = np.where(touched, (solid * velocity[c] + below * below_v) / np.maximum(count, 1.0), 0.0)
        free = fixed[c] == 0
        values[c] = np.where(touched & free, mean, values[c])
        fixed[c] |= touched.astype(np.uint8)
    return fixed, values


def balance_inflow(fluid, solid, values):
    """Make the bodies' faces let as much fluid in as out: an incompressible fluid in a closed box cannot make
    room for a body that enters it through a wall (or a face of the box that it crosses), so the net flow
    through the faces between solid and fluid cells is taken off them evenly, along their normals.  (A body
    wholly inside the box moves no net volume: for it this changes nothing.)"""
    faces = []
    net = 0.0
    for c in range(3):
        if fluid._n[c] == 1:
            continue
        below = np.roll(solid, 1, axis=c)
        inner = np.ones_like(solid, dtype=bool)
        if not fluid._periodic[c]:
            index = [slice(None)] * 3
            index[c] = 0
            inner[tuple(index)] = False          # (a wall face: nothing flows through it)
        into_solid = inner & (below == 0) & (solid != 0)      # fluid below, solid above: outflow +u
        out_of_solid = inner & (below != 0) & (solid == 0)    # solid below, fluid above: outflow -u
        sign = into_solid.astype(np.float64) - out_of_solid
        net += float(np.sum(sign * values[c]))
        faces.append((c, sign))
    count = sum(float(np.abs(sign).sum()) for _, sign in faces)
    if count == 0.0 or net == 0.0:
        return
    for c, sign in faces:
        values[c] -= sign * (net / count)


def place_obstacles(fluid, bodies):
    """Make the cells inside ``bodies`` solid, moving with them, before the fluid's step."""
    solid, velocity = mark_obstacles(fluid, bodies)
    if not np.array_equal(solid, fluid._solid):
        fluid._solid[:] = solid
        fluid._prepared = False
    fixed, values = obstacle_faces(fluid, solid, velocity)
    balance_inflow(fluid, solid, values)
    fluid._fixed[:], fluid._q[:] = fixed, values
    fluid._flow = None


def _quadrature(shape):
    """Points (local, m) and the volume (m^3) each stands for, filling ``shape`` (a ``VOLUME_SAMPLES``^3 grid
    over its bounding box, the points inside kept)."""
    cached = _QUADRATURE.get(shape)
    if cached is None:
        reach = shape.bounding_radius()
        ticks = (np.arange(VOLUME_SAMPLES) + 0.5) / VOLUME_SAMPLES * 2 * reach - reach
        grid = np.stack(np.meshgrid(ticks, ticks, ticks, indexing="ij"), -1).reshape(-1, 3)
        keep = inside(shape, grid)
        cached = (grid[keep], (2 * reach / VOLUME_SAMPLES) ** 3)
        _QUADRATURE[shape] = cached
    return cached


_QUADRATURE = {}


def submerged(shape, centre, rotation, surface):
    """``(volume (m^3), centroid (m))`` of the part of ``shape`` (at ``centre``, turned by ``rotation``)
    below the height ``surface`` (y)."""
    if isinstance(shape, Sphere):
        r = shape.radius
        depth = min(max(surface - (centre[1] - r), 0.0), 2 * r)
        if depth == 0.0:
            return 0.0, centre
        volume = math.pi * depth * depth * (3 * r - depth) / 3
        below = 3 * (2 * r - depth) ** 2 / (4 * (3 * r - depth))    # the cap's centroid below the centre
        return volume, centre - np.array([0.0, below, 0.0])
    points, weight = _quadrature(shape)
    world = centre + points @ rotation.T
    wet = world[world[:, 1] <= surface]
    if len(wet) == 0:
        return 0.0, centre
    return len(wet) * weight, wet.mean(axis=0)


def _shell_flow(fluid, centre, radius):
    """The fluid's mean velocity (m/s, 3) on a shell of ``radius`` about ``centre`` (the points inside the
    box)."""
    points = centre + (radius + fluid._h) * SHELL
    lo, hi = fluid._origin, fluid._origin + fluid._n * fluid._h
    points = points[np.all((points >= lo) & (points <= hi), axis=1)]
    if len(points) == 0:
        return None
    return fluid.velocity_at(points).mean(axis=0)


def drag_change(relative, acceleration, k, dt):
    """The velocity change (m/s) that drag at the rate ``k`` (1/s, array or number) makes over ``dt`` from
    the relative velocity ``relative`` = u - v, under the steady ``acceleration`` (see the module docstring);
    ``relative`` and ``acceleration`` broadcast against ``k[..., None]``."""
    k = np.asarray(k, np.float64)
    share = -np.expm1(-k * dt)
    lag = np.where(k * dt > 1e-8, share / np.maximum(k, 1e-300) - dt, -0.5 * k * dt * dt)
    return share[..., None] * relative + lag[..., None] * acceleration


def push_bodies(fluid, bodies, gravity, dt):
    """Apply buoyancy and drag to each dynamic body touching the fluid, for the coming step of ``dt``."""
    box_lo, box_hi = fluid._origin, fluid._origin + fluid._n * fluid._h
    rho, nu = fluid._density, fluid._viscosity
    gravity = np.asarray(gravity, np.float64)
    for body in bodies:
        if body.is_static or body.is_kinematic:
            continue
        x = body.position
        poses = [(s, c, r) for s, c, r in shape_poses(body) if isinstance(s, SOLID_SHAPES)]
        if not poses:
            continue
        reach = max(float(np.linalg.norm(c - x)) + s.bounding_radius() for s, c, r in poses)
        if np.any(x + reach < box_lo) or np.any(x - reach > box_hi):
            continue
        total = sum(volume_of(s) for s, c, r in poses)
        mass = body.mass
        wet_share = 1.0
        acceleration = gravity.copy()
        if fluid._surface is not None:
            volume, moment = 0.0, np.zeros(3)
            for shape, centre, rotation in poses:
                v, at = submerged(shape, centre, rotation, fluid._surface)
                volume += v
                moment += v * at
            if volume <= 0.0:
                continue
            buoyancy = -rho * volume * gravity
            body.apply_force(buoyancy, moment / volume)
            acceleration += buoyancy / mass
            wet_share = min(volume / total, 1.0)
        flow = _shell_flow(fluid, x, reach)
        if flow is None:
            continue
        relative = flow - body.velocity
        speed = float(np.linalg.norm(relative))
        area = math.pi * reach * reach * wet_share
        k = (0.5 * rho * DRAG_COEFFICIENT * area * speed + 3 * math.pi * rho * nu * 2 * reach * wet_share) / mass
        body.apply_force(mass / dt * drag_change(relative, acceleration, k, dt))
        body.apply_torque(math.expm1(-k * dt) / dt * (body.inertia @ body.angular_velocity))


def drag_particles(fluid, particles, gravity, dt):
    """Drag on the free particles and cloth vertices inside the fluid's box (into their force accumulators),
    for the coming step of ``dt``.  Soft bodies' nodes are left alone."""
    n = particles.n
    if n == 0:
        return
    pf, pi = particles.pf[:n], particles.pi[:n]
    lo, hi = fluid._origin, fluid._origin + fluid._n * fluid._h
    position = pf[:, P.P_POS:P.P_POS + 3]
    chosen = np.all((position >= lo) & (position <= hi), axis=1) & ((pi[:, P.P_FLAGS] & P.PP_SOFT) == 0) \
        & (pf[:, P.P_INV_MASS] > 0.0)
    if fluid._surface is not None:
        chosen &= position[:, 1] <= fluid._surface
    rows = np.flatnonzero(chosen)
    if len(rows) == 0:
        return
    relative = fluid.velocity_at(position[rows]) - pf[rows, P.P_VEL:P.P_VEL + 3]
    speed = np.linalg.norm(relative, axis=1)
    radius = pf[rows, P.P_RADIUS]
    mass = pf[rows, P.P_MASS]
    area = math.pi * radius * radius
    cloth = pi[rows, P.P_CLOTH]
    for c in np.unique(cloth[cloth >= 0]):
        mine = cloth == c
        area[mine] = mass[mine] / particles.cloths[c].density
    rho, nu = fluid._density, fluid._viscosity
    k = (0.5 * rho * DRAG_COEFFICIENT * area * speed + 6 * math.pi * rho * nu * radius) / mass
    acceleration = np.asarray(gravity, np.float64) + pf[rows, P.P_FORCE:P.P_FORCE + 3] / mass[:, None]
    pf[rows, P.P_FORCE:P.P_FORCE + 3] += (mass / dt)[:, None] * drag_change(relative, acceleration, k, dt)

