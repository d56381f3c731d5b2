"""``show(world)``: a window that draws any World and steps it in real time.

Mouse: drag to turn the camera about its target, right- or middle-drag (or shift-drag) to pan, scroll
to zoom.  Keys: space pauses and resumes, N or the right arrow takes one step (pausing first), C shows
contacts and normals, B broad-phase boxes, P hides and shows the particles (their networks' edges
stay), R returns to the state the window opened with, F frames every body and particle again, Esc
closes the window.  A line at the top shows bodies, particles, contacts, the wall-clock time per step
and the simulated time.
"""
import os
import sys
import time

from ..render.bounds import world_points
from ..render.orbit_camera import OrbitCamera
from .sim_runner import SimRunner
from .stats import stats_line
from .view_options import check_flag, check_size, check_world, initial_camera, layers_for

#: The key help shown under the stats line.
KEYS_HELP = ("space pause  |  N step  |  C contacts  |  E events  |  B boxes  |  P particles  |  R reset  |  "
             "F frame  |  Esc quit")
#: Seconds of real time between two state lines when ``print_state`` is on.
PRINT_INTERVAL = 0.5


def show(world, *, dt=1.0 / 60.0, paused=False, size=(1280, 720), contacts=False, boxes=False, camera=None,
         max_steps_per_frame=4, print_state=False):
    """Open a window on ``world`` and step it by ``dt`` seconds as real time passes, until the window is
    closed.

    Mouse: drag turns the camera, right- or middle-drag (or shift-drag) pans, scrolling zooms.  Keys:
    space pauses and resumes, N or the right arrow takes one step (pausing first), C toggles contacts
    and normals, B broad-phase boxes, P the particles (their networks' edges stay), R returns to the
    state the window opened with, F frames every body and particle again, Esc closes the window.

    ``paused`` starts it paused; ``size`` = (width, height) pixels of the window; ``contacts`` and
    ``boxes`` start with those overlays on; ``camera`` is None (frame every body and particle) or
    ``(eye, target)`` (m); at most ``max_steps_per_frame`` steps are taken per drawn frame (a world slower
    than real time runs in slow motion).  With ``print_state`` a line ``viewer <event> t=... steps=... paused=...
    layers=... first=x,y,z`` is printed once the first frame is drawn, after every key, twice a second
    and when the window closes (``t`` the simulated time, s; ``first`` the first dynamic body's
    position, m), for scripts and tests.  Raises ``OSError`` when there is no display.
    """
    check_world(world)
    size = check_size(size)
    layers = list(layers_for(contacts, boxes))
    check_flag("paused", paused)
    check_flag("print_state", print_state)
    runner = SimRunner(world, dt, paused=paused, max_steps=max_steps_per_frame)
    orbit = initial_camera(world, camera, size[0] / size[1])
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise OSError("show needs a display (DISPLAY is not set); record() and render_image() run headless")
    try:
        import moderngl
        import pyglet
        from pyglet.window import key, mouse

        from ..render.world_renderer import WorldRenderer
    except ImportError as e:
        raise ImportError(f"show needs the rendering packages: pip install 'marbellous[game]' ({e})") from None

    window = _open_window(pyglet, size)
    ctx = moderngl.create_context()
    renderer = WorldRenderer(ctx, size)
    dynamic = next((b for b in world.bodies if not (b.is_static or b.is_kinematic)), None)
    last_print = [time.monotonic()]
    drawn = [False]

    def report(event):
        if not print_state:
            return
        first = "-" if dynamic is None else ",".join(f"{v:.4f}" for v in dynamic.position)
        print(f"viewer {event} t={world.time:.6f} steps={runner.steps} paused={int(runner.paused)} "
              f"layers={'+'.join(layers)} first={first}", flush=True)
        last_print[0] = time.monotonic()

    def toggle(layer):
        if layer in layers:
            layers.remove(layer)
        else:
            layers.append(layer)

    actions = {
        key.SPACE: lambda: setattr(runner, "paused", not runner.paused),
        key.N: runner.step_once,
        key.RIGHT: runner.step_once,
        key.C: lambda: toggle("contacts"),
        key.E: lambda: toggle("events"),
        key.B: lambda: toggle("boxes"),
        key.P: lambda: toggle("particles"),
        key.R: runner.reset,
        key.F: lambda: _reframe(orbit, world, window),
        key.ESCAPE: window.close,
    }

    def on_key_press(symbol, modifiers):
        action = actions.get(symbol)
        if action is None:
            return False
        action()
        report(f"key={key.symbol_string(symbol)}")
        return True

    def on_mouse_drag(x, y, dx, dy, buttons, modifiers):
        if buttons & (mouse.RIGHT | mouse.MIDDLE) or (buttons & mouse.LEFT and modifiers & key.MOD_SHIFT):
            orbit.pan(dx, dy, window.height)
        elif buttons & mouse.LEFT:
            orbit.rotate(dx, dy)

    def on_mouse_scroll(x, y, scroll_x, scroll_y):
        orbit.zoom(scroll_y)

    def on_draw():
        w, h = window.get_framebuffer_size()
        hud = [stats_line(world, contacts=len(world.contacts()), step_seconds=runner.step_seconds,
                          paused=runner.paused), KEYS_HELP]
        renderer.render(ctx.screen, world, orbit.view(), layers=layers, hud_lines=hud, viewport=(0, 0, w, h))
        if not drawn[0]:
            drawn[0] = True
            report("ready")

    def update(frame_time):
        runner.advance(frame_time)
        if print_state and time.monotonic() - last_print[0] >= PRINT_INTERVAL:
            report("tick")

    window.push_handlers(on_key_press=on_key_press, on_mouse_drag=on_mouse_drag,
                         on_mouse_scroll=on_mouse_scroll, on_draw=on_draw)
    pyglet.clock.schedule_interval(update, 1.0 / 120.0)
    try:
        pyglet.app.run(1.0 / 60.0)
    finally:
        pyglet.clock.unschedule(update)
    report("closed")


def _open_window(pyglet, size):
    """A resizable pyglet window with an OpenGL 3.3 context.

    It needs no multisampling (the renderer's FXAA pass smooths the edges) and no depth buffer of its own (the
    scene is drawn into the pass's frame, which has one; the overlays drawn on the window test no depth), but asks
    for one first, as most displays offer it, then takes any 3.3 window.
    """
    for depth_size in (24, 0):
        config = pyglet.gl.Config(double_buffer=True, depth_size=depth_size, major_version=3, minor_version=3)
        try:
            return pyglet.window.Window(size[0], size[1], caption="Marbellous viewer", resizable=True,
                                        config=config)
        except pyglet.window.NoSuchConfigException:
            continue
    raise OSError("the display offers no OpenGL 3.3 window")


def _reframe(orbit, world, window):
    """Point ``orbit`` at every body and particle of ``world`` again, from the direction it looks in now."""
    w, h = window.get_framebuffer_size()
    framed = OrbitCamera.framing(world_points(world), w / h, yaw=orbit.yaw, pitch=orbit.pitch, fov=orbit.fov)
    orbit.target, orbit.distance = framed.target, framed.distance
