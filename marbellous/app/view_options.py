"""Checks of the arguments shared by ``show``, ``record`` and ``render_image``: each names the argument
and the rule it broke."""
import numbers
import pathlib

from .._validate import as_vec3
from ..render.bounds import world_points
from ..render.orbit_camera import OrbitCamera
from ..world import World

#: Smallest and largest image side (pixels).
MIN_SIDE, MAX_SIDE = 16, 4096


def check_world(world):
    """``world`` if it is a :class:`~marbellous.World`, else ``TypeError``."""
    if not isinstance(world, World):
        raise TypeError(f"world must be a marbellous.World, got {world!r}")
    return world


def check_size(size):
    """``size`` as ``(width, height)``: two integers from :data:`MIN_SIDE` to :data:`MAX_SIDE` pixels."""
    try:
        width, height = size
    except (TypeError, ValueError):
        raise TypeError(f"size must be two integers (width, height), got {size!r}") from None
    for v in (width, height):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral):
            raise TypeError(f"size must be two integers (width, height), got {size!r}")
        if not MIN_SIDE <= v <= MAX_SIDE:
            raise ValueError(f"size must be {MIN_SIDE} to {MAX_SIDE} pixels per side, got {size!r}")
    return int(width), int(height)


def check_suffix(path, suffixes):
    """``path`` as a ``pathlib.Path`` if it ends in one of ``suffixes`` (e.g. ``(".mp4", ".gif")``)."""
    try:
        p = pathlib.Path(path)
    except TypeError:
        raise TypeError(f"path must be a file path (str or os.PathLike), got {path!r}") from None
    if p.suffix.lower() not in suffixes:
        raise ValueError(f"path must end in {' or '.join(suffixes)}, got {str(path)!r}")
    return p


def check_flag(name, value):
    """``value`` if it is True or False, else ``TypeError`` naming ``name``."""
    if not isinstance(value, bool):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return value


def layers_for(contacts, boxes):
    """The drawable layers to draw: those shown by default (bodies, particles, cloth, soft bodies and
    constraints with particle networks), with ``contacts`` and ``boxes`` if asked."""
    from ..render.drawables import default_layers     # (the drawing modules load when a world is drawn)

    names = list(default_layers())
    if check_flag("contacts", contacts):
        names.append("contacts")
    if check_flag("boxes", boxes):
        names.append("boxes")
    return tuple(names)


def initial_camera(world, camera, aspect):
    """The :class:`OrbitCamera` to start with: framing every body and particle of ``world`` for a view of
    ``aspect`` (width / height) when ``camera`` is None, else looking from ``camera = (eye, target)`` (m)."""
    if camera is None:
        return OrbitCamera.framing(world_points(world), aspect)
    try:
        eye, target = camera
    except (TypeError, ValueError):
        raise TypeError(f"camera must be None or a pair (eye, target) of 3-vectors, got {camera!r}") from None
    return OrbitCamera.looking(as_vec3("camera eye", eye), as_vec3("camera target", target))
