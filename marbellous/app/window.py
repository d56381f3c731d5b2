"""``marbellous play``: the game in a pyglet window.

Controls: arrows or WASD push the marble relative to the camera, space jumps, R restarts, F1 toggles the
debug overlay (contacts, normals, the level's 2D grid), Esc quits.  The physics runs at the game's
fixed step, driven by the frame time; the HUD shows the timer and the best time.
"""
import os
import sys

from ..game.controls import move_from_keys
from ..game.level import load_level
from ..game.session import Game


def play(level=None, size=(1280, 720), debug=False, print_state=False):
    """Open a window and play ``level`` (a name or a path) until it is closed; returns 0.

    Raises ``OSError`` when there is no display to open a window on.
    """
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise OSError("marbellous play needs a display (DISPLAY is not set); "
                      "`marbellous demo` runs headless and writes a video")
    import moderngl
    import pyglet
    from pyglet.window import key

    from ..render.renderer import DebugOverlay, Renderer

    lvl = load_level(level)
    game = Game(lvl)
    config = pyglet.gl.Config(double_buffer=True, depth_size=24, major_version=3, minor_version=3)
    window = pyglet.window.Window(size[0], size[1], caption=f"Marbellous - {lvl.name}", resizable=True,
                                  config=config)
    ctx = moderngl.create_context()
    renderer = Renderer(ctx, lvl, game.spec.radius, size, flag=game.flag,
                        soft_bodies=game.soft_blocks)
    keys = key.KeyStateHandler()
    window.push_handlers(keys)
    state = {"jump": False, "debug": debug, "view": game.update_camera(0.0), "report": 0.0}

    def on_key_press(symbol, modifiers):
        if symbol == key.SPACE:
            state["jump"] = True
        elif symbol == key.R:
            game.restart()
        elif symbol == key.F1:
            state["debug"] = not state["debug"]
        elif symbol == key.ESCAPE:
            window.close()

    # a separate handler frame, so the KeyStateHandler below still sees every key
    window.push_handlers(on_key_press=on_key_press)

    def update(frame_time):
        pressed = {name for name in ("W", "A", "S", "D", "UP", "DOWN", "LEFT", "RIGHT")
                   if keys[getattr(key, name)]}
        if game.advance(frame_time, move_from_keys(pressed), state["jump"]):
            state["jump"] = False
        state["view"] = game.update_camera(frame_time)
        if print_state and game.elapsed >= state["report"]:
            state["report"] += 0.5
            x, y, z = game.marble.position
            print(f"t={game.elapsed:.2f} position={x:.3f},{y:.3f},{z:.3f}", flush=True)

    @window.event
    def on_draw():
        w, h = window.get_framebuffer_size()
        dbg = None
        if state["debug"]:
            pts, nrm = game.contact_points()
            dbg = DebugOverlay(points=pts, normals=nrm)
        hud = game.hud_lines() + ["arrows/WASD move, space jumps, R restarts, F1 debug"]
        renderer.render(ctx.screen, state["view"], game.marble.position, game.marble_rotation(), hud, dbg,
                        viewport=(0, 0, w, h))

    pyglet.clock.schedule_interval(update, 1.0 / 120.0)
    pyglet.app.run()
    sys.stdout.flush()
    return 0
