"""The orbit camera: it circles a target point, framing the world's bodies to start with.

The eye sits at ``distance`` from ``target`` in the direction given by ``yaw`` (about +y, from +z
towards +x) and ``pitch`` (above the horizontal):

    eye = target + distance (cos pitch sin yaw, sin pitch, cos pitch cos yaw)

Dragging turns it (:meth:`OrbitCamera.rotate`), scrolling moves it closer or further
(:meth:`OrbitCamera.zoom`), and panning slides the target across the view (:meth:`OrbitCamera.pan`) so
the world follows the mouse.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from .transforms import look_at
from .view import CameraView

#: Turn per pixel dragged (rad).
ROTATE_PER_PIXEL = 0.008
#: Distance factor per scroll step towards the target.
ZOOM_PER_STEP = 0.88
#: Steepest pitch the camera is turned to (rad): just short of straight above or below.
MAX_PITCH = math.radians(89.0)
#: The direction a framing camera looks from, yaw and pitch (rad), and the vertical field of view (rad).
YAW, PITCH, FOV = math.radians(35.0), math.radians(25.0), math.radians(50.0)


@dataclass
class OrbitCamera:
    """A camera looking at ``target`` (m) from ``distance`` (m), at ``yaw`` and ``pitch`` (rad), with a
    vertical field of view ``fov`` (rad)."""

    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    distance: float = 10.0
    yaw: float = YAW
    pitch: float = PITCH
    fov: float = FOV

    @classmethod
    def framing(cls, points, aspect, *, yaw=YAW, pitch=PITCH, fov=FOV, margin=1.08):
        """A camera at ``yaw`` and ``pitch`` (rad) looking at the centre of the bounding box of ``points``
        (K, 3) (m; none: the cube -1..1) from the least distance at which they are all in a view of
        ``aspect`` = width / height, times ``margin``."""
        pts = np.asarray(points, np.float64).reshape(-1, 3)
        if not len(pts):
            pts = np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]])
        cam = cls(0.5 * (pts.min(axis=0) + pts.max(axis=0)), 1.0, yaw, pitch, fov)
        local = (pts - cam.target) @ look_at(cam.eye, cam.target)[:3, :3].T     # right, up, backward
        tan = np.array([math.tan(fov / 2.0) * aspect, math.tan(fov / 2.0)])
        # a point at (x, y, z) is in view once d - z >= |x| / tan_x and |y| / tan_y
        need = local[:, 2] + np.max(np.abs(local[:, :2]) / tan, axis=1)
        cam.distance = margin * max(float(need.max()), 0.5 * float(np.ptp(pts, axis=0).max()), 1e-3)
        return cam

    @classmethod
    def looking(cls, eye, target, fov=FOV):
        """The camera whose eye is at ``eye`` (m) looking at ``target`` (m); they must differ."""
        eye, target = np.asarray(eye, np.float64), np.asarray(target, np.float64)
        offset = eye - target
        d = float(np.linalg.norm(offset))
        if d == 0.0:
            raise ValueError("camera eye and target must differ")
        u = offset / d
        return cls(target.copy(), d, math.atan2(u[0], u[2]), math.asin(max(-1.0, min(1.0, u[1]))), fov)

    @property
    def eye(self):
        """Where the camera is (m)."""
        cp = math.cos(self.pitch)
        return self.target + self.distance * np.array([cp * math.sin(self.yaw), math.sin(self.pitch),
                                                       cp * math.cos(self.yaw)])

    def view(self):
        """The :class:`CameraView` the renderer takes."""
        return CameraView(eye=self.eye, target=np.array(self.target, np.float64), fov=self.fov)

    def rotate(self, dx, dy):
        """Turn by a drag of ``dx`` pixels right and ``dy`` pixels up: the world turns with the mouse."""
        self.yaw -= ROTATE_PER_PIXEL * dx
        self.pitch = max(-MAX_PITCH, min(MAX_PITCH, self.pitch - ROTATE_PER_PIXEL * dy))

    def zoom(self, steps):
        """Move ``steps`` scroll steps towards the target (negative: away)."""
        self.distance *= ZOOM_PER_STEP ** steps

    def pan(self, dx, dy, viewport_height):
        """Slide the target so the point under the mouse follows a drag of ``dx`` pixels right and ``dy``
        pixels up, in a view ``viewport_height`` pixels tall (at the target's depth)."""
        rows = look_at(self.eye, self.target)
        per_pixel = 2.0 * self.distance * math.tan(self.fov / 2.0) / viewport_height
        self.target = self.target - per_pixel * (dx * rows[0, :3] + dy * rows[1, :3])
