"""Billboards that keep the world's y-axis in place (the lecture's exercise 8, 2.3).

A cylindrical billboard turns about its own vertical axis to face the camera but never tilts: a flag or
a label stays upright however the camera looks down on it.  The lecture builds it from the view
matrix's rotation part, whose columns hold the camera's ``right``, ``up`` and ``lookat`` axes, by
replacing everything but the ``up`` column with the identity's:

    (right up lookat)        (1  up  0)
    (right up lookat)  --->  (0  up  0)
    (right up lookat)        (0  up  1)

Knowing the object's position makes it easier: the billboard's local z axis points horizontally from
the object to the camera, its y axis is the world's y, and x completes a right-handed frame.
"""
import numpy as np


def billboard_y_matrix(position, camera_position):
    """Model rotation (3, 3) of an upright billboard at ``position`` facing ``camera_position`` (m).

    Columns are the billboard's local x, y and z axes in world space: ``y = (0, 1, 0)`` always, ``z``
    is the horizontal direction to the camera, ``x = y x z``.  When the camera is straight above,
    the billboard keeps facing +z.
    """
    to_cam = np.asarray(camera_position, np.float64) - np.asarray(position, np.float64)
    to_cam[1] = 0.0
    n = np.linalg.norm(to_cam)
    z = to_cam / n if n > 1e-9 else np.array([0.0, 0.0, 1.0])
    y = np.array([0.0, 1.0, 0.0])
    return np.column_stack([np.cross(y, z), y, z])

