"""What the renderer needs to know about the camera (plain data, no OpenGL)."""
import math
from dataclasses import dataclass

import numpy as np


@dataclass
class CameraView:
    """Where the camera is: ``eye`` and ``target`` (m) and the vertical field of view ``fov`` (rad)."""

    eye: np.ndarray
    target: np.ndarray
    fov: float = math.radians(60.0)
