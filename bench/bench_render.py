"""Time of a frame of the game's headless renderer (``marbellous.render.renderer.Renderer``, as ``marbellous demo``
draws): the course level, the camera following the autopilot.

The autopilot plays the level first (at the demo's 30 frames per second), and ``--frames`` camera views spread
evenly over its first ``--seconds`` are kept with the marble's place and the HUD's lines; then each size draws
``--warmup`` of them untimed and all of them timed, one at a time:
- submit: ``Renderer.draw_offscreen`` returns (Python, and the vertex work llvmpipe does in the calling thread);
- raster: ``ctx.finish()`` returns (the rest of the drawing);
- read: ``Renderer.read_offscreen`` returns (multisample resolve, if any, and the read-back to NumPy);
- total: the three together.
Reported: the median of each over the frames (ms).  No GPU is needed: Mesa's llvmpipe draws through EGL.

With ``--viewer`` it times the viewer's renderer instead (``marbellous.render.world_renderer.WorldRenderer``, as
``mb.record`` and ``mb.render_image`` draw): a world of a stack of boxes on a triangle-mesh floor, a ball on a hinge,
a heap of particles and a cloth, stepped ``--seconds`` (at most 1 s), seen from ``--frames`` cameras around it, with
its contacts and a stats line.

    python bench/bench_render.py                          640 x 360 and 1280 x 720, 60 frames
    python bench/bench_render.py --frames 5 --warmup 1    a check of the script
    python bench/bench_render.py --json                   also write bench/results/<date>-<host>-render.json
    python bench/bench_render.py --viewer                 the viewer's frames
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.machine import describe, write_results  # noqa: E402
from marbellous.render.antialiasing import ANTIALIASING  # noqa: E402

#: the demo's video frame rate (frames per second)
FPS = 30
#: what each frame's time is split into, in order
PARTS = ("submit", "raster", "read", "total")


def course_views(frames, seconds, level="course"):
    """``(level, game, [(view, marble position, marble rotation, HUD lines)] * frames)``: the autopilot's run of
    ``level`` at :data:`FPS` frames per second, ``frames`` of its first ``seconds`` (s) kept, evenly spread."""
    from marbellous.game.autopilot import Autopilot
    from marbellous.game.goal import BestTimes
    from marbellous.game.level import load_level
    from marbellous.game.session import Game

    lvl = load_level(level)
    game = Game(lvl, best_times=BestTimes(persistent=False))
    pilot = Autopilot(game.course, game.spec.push)
    steps_per_frame = max(1, int(round(1.0 / (FPS * game.dt))))
    total = max(frames, int(seconds * FPS))
    keep = set(np.linspace(0, total - 1, frames).round().astype(int).tolist())
    views = []
    for k in range(total):
        for _ in range(steps_per_frame):
            pilot.step(game)
        view = game.update_camera(steps_per_frame * game.dt)
        if k in keep:
            views.append((view, game.marble.position.copy(), game.marble_rotation().copy(), game.hud_lines()))
    return lvl, game, views


def viewer_views(frames, seconds):
    """``(world, [camera view] * frames)``: the viewer's world (see the module's docstring) stepped ``seconds``
    (s, at most 1) at 60 steps a second, and ``frames`` views of it from all round, 30 degrees above it."""
    import marbellous as mb
    from marbellous.render.orbit_camera import OrbitCamera

    w = mb.World()
    n = 9
    xs, zs = np.meshgrid(np.linspace(-4.0, 4.0, n), np.linspace(-4.0, 4.0, n), indexing="ij")
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    w.add_static(mb.TriangleMesh(np.stack([xs.ravel(), np.zeros(n * n), zs.ravel()], axis=1),
                                 np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])))
    for k in range(4):
        w.add_body(mb.Box((0.4, 0.3, 0.4)), position=(-1.5, 0.3 + 0.6 * k, 0.0))
    bar = w.add_body(mb.Box((0.5, 0.05, 0.05)), position=(0.0, 3.0, -1.0))
    w.add_hinge(bar, None, anchor=(-0.5, 3.0, -1.0), axis=(0.0, 0.0, 1.0))
    heap = np.stack(np.meshgrid(*[np.arange(6)] * 3, indexing="ij"), -1).reshape(-1, 3)
    w.add_particles(heap * 0.2 + (1.0, 0.2, -2.0), radius=0.1, collide_particles=True)
    v, t = mb.cloth_grid(1.5, 1.5, 16, 16)
    w.add_cloth(v, t, mass=0.2, position=(0.5, 1.5, 1.5))
    for _ in range(int(60 * min(seconds, 1.0))):
        w.step(1.0 / 60.0)
    return w, [OrbitCamera.looking((9.0 * np.sin(yaw), 6.0, 9.0 * np.cos(yaw)), (0.0, 1.0, 0.0)).view()
               for yaw in np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)]


def time_frames(renderer, views, warmup, **options):
    """``{part: median ms}`` over ``views`` (each the renderer's positional arguments) drawn by ``renderer`` with
    keyword arguments ``options`` after ``warmup`` of them untimed."""
    for v in views[:warmup]:
        renderer.render_to_array(*v, **options)
    times = []
    for v in views:
        t0 = time.perf_counter()
        renderer.draw_offscreen(*v, **options)
        t1 = time.perf_counter()
        renderer.ctx.finish()
        t2 = time.perf_counter()
        renderer.read_offscreen()
        t3 = time.perf_counter()
        times.append((t1 - t0, t2 - t1, t3 - t2, t3 - t0))
    return {part: 1e3 * float(np.median(column)) for part, column in zip(PARTS, np.array(times).T)}


def run(sizes, frames, warmup, seconds, antialiasing=None, shadow_size=None, viewer=False):
    """``{"settings": {...}, "results": {"WxH": {part: median ms}}}`` of the course (``viewer``: the viewer's world)
    at each (width, height) in ``sizes``; ``antialiasing`` and ``shadow_size`` (None: the renderer's defaults) are
    passed to ``Renderer`` (``WorldRenderer``)."""
    from marbellous.app.stats import stats_line
    from marbellous.render.context import headless_context
    from marbellous.render.drawables import default_layers
    from marbellous.render.renderer import Renderer
    from marbellous.render.world_renderer import WorldRenderer

    options = {k: v for k, v in (("antialiasing", antialiasing), ("shadow_size", shadow_size)) if v is not None}
    if viewer:
        world, cameras = viewer_views(frames, seconds)
        views = [(world, view) for view in cameras]
        draw = {"layers": list(default_layers()) + ["contacts"],
                "hud_lines": [stats_line(world, contacts=len(world.contacts()), step_seconds=0.003)]}
    else:
        lvl, game, views = course_views(frames, seconds)
        draw = {}
    ctx = headless_context()
    results, settings = {}, {}
    try:
        for size in sizes:
            r = (WorldRenderer(ctx, size, **options) if viewer else
                 Renderer(ctx, lvl, game.spec.radius, size, flag=game.flag, soft_bodies=game.soft_blocks, **options))
            settings = {"antialiasing": r.antialiasing, "shadow_size": r.shadow_size}
            results[f"{size[0]}x{size[1]}"] = time_frames(r, views, warmup, **draw)
    finally:
        ctx.release()
    return {"settings": settings, "frames": frames, "warmup": warmup, "seconds": seconds, "viewer": viewer,
            "results": results}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="640x360,1280x720", help="comma-separated WIDTHxHEIGHT (pixels)")
    parser.add_argument("--frames", type=int, default=60, help="timed frames per size")
    parser.add_argument("--warmup", type=int, default=5, help="untimed frames first")
    parser.add_argument("--seconds", type=float, default=20.0, help="the frames are spread over this much play (s)")
    parser.add_argument("--antialiasing", choices=ANTIALIASING, help="(default: the renderer's)")
    parser.add_argument("--shadow-size", type=int, help="shadow map side in texels (default: the renderer's)")
    parser.add_argument("--json", nargs="?", const="", metavar="FILE",
                        help="write the results to FILE (no FILE: bench/results/<date>-<host>-render.json)")
    parser.add_argument("--viewer", action="store_true", help="time the viewer's renderer (WorldRenderer)")
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in s.split("x")) for s in args.sizes.split(",")]
    out = run(sizes, args.frames, args.warmup, args.seconds, args.antialiasing, args.shadow_size, args.viewer)
    print(f"{'viewer' if args.viewer else 'course'}, {args.frames} frames after {args.warmup} untimed; "
          f"{out['settings']}; median ms per frame")
    print(f"{'size':>10s} " + " ".join(f"{p:>7s}" for p in PARTS))
    for size, r in out["results"].items():
        print(f"{size:>10s} " + " ".join(f"{r[p]:7.2f}" for p in PARTS))
    if args.json is not None:
        path = write_results(os.path.join(HERE, "results"), "render",
                             {"benchmark": "render", "machine": describe(os.path.dirname(HERE), {}), **out}, args.json)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main()
