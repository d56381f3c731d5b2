"""The viewer on a small scene: a ball rolls down a ramp of triangles into a stack of boxes, past a
pendulum hanging from a rod.

Run:  python examples/viewer.py                      a window (drag, scroll, space, N, C, B, R, Esc)
      python examples/viewer.py --record out.mp4     a 5 s video instead (or .gif), headless
      python examples/viewer.py --png out.png --at 2.9 --contacts --boxes --camera 2.5,3.8,6.5,-1.6,0.7,0
                                                     one picture 2.9 s in, with the debug overlays,
                                                     from (2.5, 3.8, 6.5) looking at (-1.6, 0.7, 0)
"""
import argparse

import numpy as np

import marbellous as mb


SLOPE = np.radians(20.0)


def ramp_height(x):
    """Height (m) of the ramp at ``x`` (m): flat for x < 1, rising at :data:`SLOPE` beyond."""
    return np.tan(SLOPE) * np.maximum(x - 1.0, 0.0)


def ramp_mesh(half=6.0, cells=24):
    """The ramp as a square of triangles ``2 half`` metres across, ``cells`` cells per side."""
    n = cells + 1
    xs, zs = np.meshgrid(np.linspace(-half, half, n), np.linspace(-half, half, n), indexing="ij")
    ys = ramp_height(xs)
    vertices = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    return mb.TriangleMesh(vertices, np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)]))


def scene():
    """The world: the ramp with a kerb, a stack of six boxes, the ball on the ramp, a pendulum on a rod."""
    w = mb.World()
    w.add_static(ramp_mesh())
    w.add_static(mb.Box((0.2, 0.3, 6.0)), position=(-5.8, 0.3, 0.0))      # a kerb at the far end
    for k in range(6):
        w.add_body(mb.Box((0.25, 0.25, 0.25)), position=(-2.0, 0.25 + 0.5 * k, 0.0), density=200.0)
    w.add_body(mb.Sphere(0.45), position=(5.5, ramp_height(5.5) + 0.45 / np.cos(SLOPE), 0.1))
    bob = w.add_body(mb.Sphere(0.2), position=(0.4, 1.4, -2.5))
    w.add_rod(bob, None, anchor_b=(-1.0, 3.4, -2.5))
    return w


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--record", metavar="FILE", help="write a video (.mp4 or .gif) instead of opening a window")
    p.add_argument("--png", metavar="FILE", help="write one picture instead of opening a window")
    p.add_argument("--seconds", type=float, default=5.0, help="length of the video (default: 5)")
    p.add_argument("--at", type=float, default=0.0, metavar="S", help="simulate S seconds before the picture")
    p.add_argument("--contacts", action="store_true", help="draw contact points and normals")
    p.add_argument("--boxes", action="store_true", help="draw broad-phase boxes")
    p.add_argument("--camera", metavar="EX,EY,EZ,TX,TY,TZ", help="eye and target (m) instead of framing all")
    args = p.parse_args(argv)
    w = scene()
    camera = None
    if args.camera:
        v = [float(x) for x in args.camera.split(",")]
        if len(v) != 6:
            p.error(f"--camera needs six numbers, got {args.camera!r}")
        camera = (v[:3], v[3:])
    options = dict(contacts=args.contacts, boxes=args.boxes, camera=camera)
    if args.record:
        print(mb.record(w, args.record, seconds=args.seconds, stats=True, **options))
    elif args.png:
        for _ in range(round(args.at * 60)):
            w.step(1 / 60)
        mb.render_image(w, args.png, stats=True, **options)
        print(args.png)
    else:
        mb.show(w, **options)


if __name__ == "__main__":
    main()
