"""The bodies of a world as instanced solids: every shape of every body, coloured by what the body is.

Each body's shapes are placed by the body's pose and their local poses; all instances of one mesh with
one opacity go into one :class:`Solids`, so a thousand boxes are one draw call.  Static bodies carry
the grid pattern, round dynamic shapes the octant pattern (their spin shows), the rest are plain.
An infinite plane is drawn as a square of half side :data:`PLANE_SCALE` times the camera's distance,
centred under the camera's focus, so it reaches the horizon from any view.
"""
from collections import defaultdict

import numpy as np

from ..shapes.primitives import Plane
from . import palette
from .draw_lists import GRID, OCTANTS, PLAIN, Solids
from .shape_meshes import plane_frame, shape_mesh
from .transforms import quat_to_matrix, quats_to_matrices

#: Half side of a drawn plane, in camera distances from the focus.
PLANE_SCALE = 12.0


def body_solids(frame):
    """:class:`Solids` of every body of ``frame.world`` (a :class:`WorldFrame`)."""
    bodies = frame.bodies
    n = len(bodies)
    positions = np.empty((n, 3))
    quats = np.empty((n, 4))
    # (mesh key, alpha) -> instance rows: body row, local position, local quaternion, scale, colour, pattern
    batches = defaultdict(list)
    meshes = {}
    planes = []
    for i, b in enumerate(bodies):
        positions[i] = b.position
        quats[i] = b.orientation
        static = b.is_static
        kinematic = b.is_kinematic
        sensor = b.is_sensor
        color = palette.body_color(i, static=static, sleeping=not static and b.is_sleeping, sensor=sensor,
                                   kinematic=kinematic)
        alpha = palette.SENSOR_ALPHA if sensor else 1.0
        for shape, local_pos, local_quat in b.shapes:
            if isinstance(shape, Plane):
                planes.append((i, shape, local_pos, local_quat, color, alpha))
                continue
            mesh = shape_mesh(shape)
            pattern = GRID if static or kinematic else (OCTANTS if mesh.round else PLAIN)
            key = (mesh.key, alpha)
            meshes[key] = mesh
            batches[key].append((i, local_pos, local_quat, mesh.scale, color, pattern))
    rotations = quats_to_matrices(quats)
    out = []
    for key, rows in batches.items():
        idx = np.array([r[0] for r in rows])
        local_pos = np.array([r[1] for r in rows], np.float64)
        local_rot = quats_to_matrices(np.array([r[2] for r in rows], np.float64))
        scale = np.array([r[3] for r in rows], np.float64)
        rot = rotations[idx]
        models = np.zeros((len(rows), 4, 4))
        models[:, :3, :3] = rot @ local_rot * scale[:, None, :]
        models[:, :3, 3] = positions[idx] + np.einsum("nij,nj->ni", rot, local_pos)
        models[:, 3, 3] = 1.0
        out.append(Solids(meshes[key], models, np.array([r[4] for r in rows]), np.array([r[5] for r in rows]),
                          key[1]))
    for i, shape, local_pos, local_quat, color, alpha in planes:
        out.append(_plane_solids(frame, shape, rotations[i] @ quat_to_matrix(local_quat),
                                 positions[i] + rotations[i] @ local_pos, color, alpha))
    return out


def _plane_solids(frame, plane, rotation, origin, color, alpha):
    """The drawn square of ``plane`` whose shape frame has ``rotation`` (3, 3) and ``origin`` (m)."""
    frame_rot, point = plane_frame(plane)
    rot = rotation @ frame_rot
    normal = rot[:, 1]
    on_plane = origin + rotation @ point
    centre = frame.focus - (normal @ (frame.focus - on_plane)) * normal
    half = PLANE_SCALE * frame.distance
    model = np.eye(4)
    model[:3, :3] = rot * np.array([half, 1.0, half])
    model[:3, 3] = centre
    return Solids(shape_mesh(plane), model[None], np.asarray(color, np.float64)[None], np.array([GRID]), alpha)
