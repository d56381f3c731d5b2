"""Headless pictures of any World: :func:`record` steps it and writes an MP4 or GIF, :func:`render_image`
draws one frame to an array or a PNG.

Both render offscreen through EGL (Mesa's llvmpipe needs no display and no GPU).  The camera frames
every body and particle at the start unless ``camera = (eye, target)`` places it, and then stays put.
"""
import math

from .._validate import as_float, as_int
from ..render.video import FORMATS, VideoWriter
from .sim_runner import SimRunner
from .stats import stats_line
from .view_options import check_flag, check_size, check_suffix, check_world, initial_camera, layers_for


def _headless_renderer(size, caller):
    """An EGL context and a :class:`WorldRenderer` of ``size``, or ``ImportError`` naming ``caller`` when
    the rendering packages (the "game" extra) are missing."""
    try:
        from ..render.context import headless_context
        from ..render.world_renderer import WorldRenderer
    except ImportError as e:
        raise ImportError(f"{caller} needs the rendering packages: pip install 'marbellous[game]' ({e})") from None
    ctx = headless_context()
    return ctx, WorldRenderer(ctx, size)


def record(world, path, *, seconds, dt=1.0 / 60.0, fps=30, size=(640, 360), camera=None, contacts=False,
           boxes=False, stats=False):
    """Step ``world`` for ``seconds`` of simulated time in steps of ``dt`` seconds and write what it does
    to ``path`` (``.mp4`` or ``.gif``) at ``fps`` frames per second, ``size`` = (width, height) pixels.

    Frame ``k`` shows the world at ``k / fps`` seconds after the call; there are ``n = round(seconds *
    fps)`` frames (at least one) and the world is left ``n / fps`` seconds on (in whole steps).
    ``camera`` is None (frame every body and particle as they are at the start) or ``(eye, target)`` (m).
    ``contacts`` and ``boxes`` draw contact points and normals and broad-phase boxes; ``stats`` adds the
    stats line.  Returns ``path`` as a ``pathlib.Path``.
    """
    check_world(world)
    out = check_suffix(path, FORMATS)
    seconds = as_float("seconds", seconds, positive=True)
    dt = as_float("dt", dt, positive=True)
    fps = as_int("fps", fps, lo=1, hi=1000)
    size = check_size(size)
    layers = layers_for(contacts, boxes)
    check_flag("stats", stats)
    frames = max(1, round(seconds * fps))
    cam = initial_camera(world, camera, size[0] / size[1]).view()
    # every step a frame's time holds, however many (the runner's cap is never reached)
    runner = SimRunner(world, dt, max_steps=math.ceil(1.0 / (fps * dt)) + 1)
    ctx, renderer = _headless_renderer(size, "record")
    try:
        with VideoWriter(out, fps) as writer:
            for _ in range(frames):
                hud = ([stats_line(world, contacts=len(world.contacts()), step_seconds=runner.step_seconds)]
                       if stats else ())
                writer.write(renderer.render_to_array(world, cam, layers=layers, hud_lines=hud))
                runner.advance(1.0 / fps)
    finally:
        ctx.release()
    return out


def render_image(world, path=None, *, size=(640, 360), camera=None, contacts=False, boxes=False, stats=False):
    """Draw ``world`` as it is now: an RGB image (height, width, 3) uint8, also saved as a PNG to ``path``
    unless it is None.  ``size`` = (width, height) pixels; ``camera``, ``contacts``, ``boxes`` and
    ``stats`` as for :func:`record`.
    """
    check_world(world)
    out = None if path is None else check_suffix(path, (".png",))
    size = check_size(size)
    layers = layers_for(contacts, boxes)
    check_flag("stats", stats)
    cam = initial_camera(world, camera, size[0] / size[1]).view()
    ctx, renderer = _headless_renderer(size, "render_image")
    try:
        hud = [stats_line(world, contacts=len(world.contacts()))] if stats else ()
        img = renderer.render_to_array(world, cam, layers=layers, hud_lines=hud)
    finally:
        ctx.release()
    if out is not None:
        from PIL import Image

        Image.fromarray(img).save(out, optimize=True)
    return img
