"""Generate the shipped Marbellous levels that are made of data: the course mesh and the height map.

    python tools/make_levels.py            # writes marbellous/levels/course.glb, course.toml,
                                           #        hills.png, hills.toml

The course is an "artist-style" triangle mesh: a road slab swept along a centre line built by a
turtle from pieces (ramps, a banked turn, speed bumps, a narrow bridge, a goal platform), with walls or
low curbs at its edges.  The hills level is a greyscale PNG (0 = low, 255 = high) turned into a
``HeightField`` by the level loader.  The generator is deterministic: running it twice gives the same
files.  The hand-placed collider level (``blocks.toml``) is written by hand.
"""
import math
import pathlib

import numpy as np
import trimesh
from PIL import Image

LEVELS = pathlib.Path(__file__).resolve().parent.parent / "marbellous" / "levels"

#: Marble radius (m) the levels are designed for (the default in ``marbellous.game.marble``).
MARBLE_RADIUS = 0.3
#: Sampling step (m) along the course centre line.
DS = 0.5
#: Slab thickness, wall thickness, wall and curb heights (m).
THICKNESS, WALL_T, WALL_H, CURB_H = 0.4, 0.25, 0.7, 0.12

# Course pieces: (length m, turn deg (+ = right), rise m, width m, bank deg, bump amplitude m, walls,
#                 autopilot speed m/s)
PIECES = [
    (6.0, 0, 0.0, 4.0, 0, 0.0, True, 3.0),       # start platform
    (10.0, 0, -3.0, 3.0, 0, 0.0, True, 4.0),     # ramp down
    (14.0, 180, -0.5, 3.4, 18, 0.0, True, 3.5),  # banked U-turn
    (10.0, 0, -0.5, 3.0, 0, 0.12, True, 3.0),    # speed bumps
    (3.0, 0, 0.0, 1.6, 0, 0.0, False, 2.0),      # narrowing
    (8.0, 0, 0.0, 1.6, 0, 0.0, False, 2.0),      # narrow bridge, no walls
    (3.0, 0, 0.0, 3.0, 0, 0.0, True, 2.5),       # widening
    (9.0, -90, -0.4, 3.2, -15, 0.0, True, 3.0),  # banked left turn
    (5.0, 0, 0.8, 3.0, 0, 0.0, True, 3.5),       # ramp up
    (6.0, 0, 0.0, 5.0, 0, 0.0, True, 1.5),       # goal platform
]
START = np.array([0.0, 5.0, 0.0])


def course_samples():
    """Sample the centre line: positions, headings, widths, banks, bumps, wall heights, speeds."""
    pos, psi = START.copy(), 0.0
    width, wall, bank = PIECES[0][3], WALL_H, 0.0
    rows = [(pos.copy(), psi, width, bank, 0.0, wall, PIECES[0][7], 0.0)]
    s_total = 0.0
    for length, turn, rise, w_end, bank_end, bump, walls, speed in PIECES:
        n = max(1, int(round(length / DS)))
        ds = length / n
        w0, h0, b0 = width, wall, bank
        h1, b1 = (WALL_H if walls else CURB_H), math.radians(bank_end)
        for k in range(1, n + 1):
            f = k / n
            psi += math.radians(turn) / n
            pos = pos + np.array([math.cos(psi) * ds, rise / n, math.sin(psi) * ds])
            s_total += ds
            # bank ramps in and out over the first and last fifth of a turning piece
            ramp = min(1.0, f / 0.2, (1.0 - f) / 0.2) if turn else 0.0
            bnk = b0 + (b1 - b0) * f if not turn else b1 * max(0.0, ramp)
            bump_h = bump * math.sin(math.pi * s_total / 1.25) ** 2 if bump else 0.0
            rows.append((pos.copy(), psi, w0 + (w_end - w0) * f, bnk, bump_h,
                         h0 + (h1 - h0) * f, speed, s_total))
        width, wall, bank = w_end, h1, (bnk if not turn else 0.0)
    return rows


def section(width, wall_h, n_top=7):
    """The road's cross-section in (lateral u, up v) coordinates, a closed loop of 13 points."""
    half = width / 2
    top = [(u, 0.0) for u in np.linspace(-half, half, n_top)]
    return top + [(half, wall_h), (half + WALL_T, wall_h), (half + WALL_T, -THICKNESS),
                  (-half - WALL_T, -THICKNESS), (-half - WALL_T, wall_h), (-half, wall_h)]


def course_mesh(rows):
    """Sweep the cross-section along the sampled centre line; returns a ``trimesh.Trimesh``."""
    verts, faces = [], []
    n_sec = len(section(1.0, 1.0))
    up = np.array([0.0, 1.0, 0.0])
    for i, (p, psi, width, bank, bump_h, wall_h, _speed, _s) in enumerate(rows):
        right = np.array([-math.sin(psi), 0.0, math.cos(psi)])
        r_b = right * math.cos(bank) - up * math.sin(bank)
        u_b = up * math.cos(bank) + right * math.sin(bank)
        for k, (u, v) in enumerate(section(width, wall_h)):
            lift = bump_h if k < 7 else 0.0
            verts.append(p + u * r_b + (v + lift) * u_b)
        if i:
            a, b = (i - 1) * n_sec, i * n_sec
            for k in range(n_sec):
                k1 = (k + 1) % n_sec
                faces.append((a + k, a + k1, b + k1))
                faces.append((a + k, b + k1, b + k))
    # end caps: the slab (a fan over the top points and the two bottom corners) and the two walls
    for base, flip in ((0, True), ((len(rows) - 1) * n_sec, False)):
        cap = [(10, i, i + 1) for i in range(6)] + [(10, 6, 9), (6, 7, 8), (6, 8, 9),
                                                    (10, 11, 12), (10, 12, 0)]
        for t in cap:
            t = tuple(base + c for c in t)
            faces.append(t[::-1] if flip else t)
    return trimesh.Trimesh(np.array(verts), np.array(faces), process=False)


def write_course():
    """Write course.glb and course.toml."""
    rows = course_samples()
    mesh = course_mesh(rows)
    mesh.export(LEVELS / "course.glb")
    # autopilot path: every second sample, at marble-centre height above the top surface
    path = [(p + np.array([0.0, MARBLE_RADIUS + bump, 0.0]), speed)
            for p, _psi, _w, _b, bump, _h, speed, _s in rows[::2]]
    end = rows[-1]
    goal_c = end[0] - 2.0 * np.array([math.cos(end[1]), 0.0, math.sin(end[1])])
    start = rows[1][0] + np.array([0.0, MARBLE_RADIUS + 0.02, 0.0])
    fmt = lambda v: "[" + ", ".join(f"{x:.3f}" for x in v) + "]"
    lines = [
        '# Generated by tools/make_levels.py: an artist-style triangle-mesh course.',
        'name = "Course"',
        'description = "Ramps, a banked U-turn, speed bumps, a narrow bridge and a goal platform."',
        'fall_height = -6.0',
        '',
        '[start]',
        f'position = {fmt(start)}',
        f'heading = {rows[1][1]:.4f}',
        '',
        '[goal]',
        f'center = {fmt(goal_c + np.array([0.0, 0.8, 0.0]))}',
        'half_extents = [1.2, 0.8, 1.2]',
        '',
        '[materials.track]',
        'friction = 0.7',
        'restitution = 0.2',
        'rolling_friction = 0.01',
        'color = [0.55, 0.62, 0.72]',
        '',
        '[[colliders]]',
        'type = "mesh"',
        'file = "course.glb"',
        'material = "track"',
        '',
        '[course]',
        'path = [',
        *[f'  {fmt(p)},' for p, _ in path],
        ']',
        'speeds = [' + ", ".join(f"{s:.1f}" for _, s in path) + ']',
    ]
    (LEVELS / "course.toml").write_text("\n".join(lines) + "\n")
    return mesh


# Hills: a 65 x 65 height map, 0.75 m between samples, up to 6 m high, with a valley carved from the
# start corner to the goal and a rim that keeps the marble in.
HILLS_N, HILLS_DX, HILLS_H = 65, 0.75, 6.0
HILLS_VALLEY = [(6.0, 6.0), (20.0, 10.0), (30.0, 24.0), (22.0, 36.0), (38.0, 42.0)]


def _dist_to_polyline(x, z, pts):
    d = np.full_like(x, np.inf)
    for (ax, az), (bx, bz) in zip(pts[:-1], pts[1:]):
        ex, ez = bx - ax, bz - az
        t = np.clip(((x - ax) * ex + (z - az) * ez) / (ex * ex + ez * ez), 0.0, 1.0)
        d = np.minimum(d, np.hypot(x - ax - t * ex, z - az - t * ez))
    return d


def hills_heights():
    """Heights (m) on the grid, ``h[i, j]`` at ``x = i dx``, ``z = j dx``."""
    c = np.arange(HILLS_N) * HILLS_DX
    x, z = np.meshgrid(c, c, indexing="ij")
    rng = np.random.default_rng(7)
    h = np.zeros_like(x)
    for _ in range(14):
        cx, cz = rng.uniform(0, c[-1], 2)
        h += rng.uniform(2.0, 4.5) * np.exp(-((x - cx) ** 2 + (z - cz) ** 2) / (2 * rng.uniform(3, 6) ** 2))
    # the valley: a smooth trough 2.5 m wide that descends gently from start to goal
    d = _dist_to_polyline(x, z, HILLS_VALLEY)
    valley = np.exp(-(d / 2.5) ** 2)
    slope = 1.2 * (1.0 - (x + z) / (2 * c[-1]))
    h = h * (1.0 - valley) + slope * valley + 0.6
    # rim
    edge = np.minimum.reduce([x, z, c[-1] - x, c[-1] - z])
    h += 3.0 * np.clip(1.0 - edge / 3.0, 0.0, 1.0) ** 2
    return np.clip(h, 0.0, HILLS_H)


def write_hills():
    """Write hills.png (greyscale, row = z, column = x) and hills.toml."""
    h = hills_heights()
    img = np.round(h / HILLS_H * 255.0).astype(np.uint8)
    Image.fromarray(img.T, mode="L").save(LEVELS / "hills.png", optimize=True)
    hq = img.astype(float) / 255.0 * HILLS_H

    def at(px, pz):
        return float(hq[int(round(px / HILLS_DX)), int(round(pz / HILLS_DX))])

    path = []
    for (ax, az), (bx, bz) in zip(HILLS_VALLEY[:-1], HILLS_VALLEY[1:]):
        n = max(1, int(math.hypot(bx - ax, bz - az) / 2.0))
        for k in range(n):
            px, pz = ax + (bx - ax) * k / n, az + (bz - az) * k / n
            path.append((px, at(px, pz) + MARBLE_RADIUS, pz))
    gx, gz = HILLS_VALLEY[-1]
    path.append((gx, at(gx, gz) + MARBLE_RADIUS, gz))
    fmt = lambda v: "[" + ", ".join(f"{x:.3f}" for x in v) + "]"
    sx, sz = HILLS_VALLEY[0]
    lines = [
        '# Generated by tools/make_levels.py: a height-map level (greyscale PNG -> HeightField).',
        'name = "Hills"',
        'description = "Roll down a winding valley between grassy hills."',
        'fall_height = -5.0',
        '',
        '[start]',
        f'position = {fmt((sx, at(sx, sz) + MARBLE_RADIUS + 0.05, sz))}',
        f'heading = {math.atan2(10.0 - 6.0, 20.0 - 6.0):.4f}',
        '',
        '[goal]',
        f'center = {fmt((gx, at(gx, gz) + 0.8, gz))}',
        'half_extents = [1.5, 1.0, 1.5]',
        '',
        '[materials.grass]',
        'friction = 0.8',
        'restitution = 0.1',
        'rolling_friction = 0.03',
        'color = [0.42, 0.66, 0.36]',
        '',
        '[[colliders]]',
        'type = "heightfield"',
        'image = "hills.png"',
        f'spacing = [{HILLS_DX}, {HILLS_DX}]',
        'origin = [0.0, 0.0, 0.0]',
        f'height_scale = {HILLS_H}',
        'material = "grass"',
        '',
        '[course]',
        'path = [',
        *[f'  {fmt(p)},' for p in path],
        ']',
    ]
    (LEVELS / "hills.toml").write_text("\n".join(lines) + "\n")


def main():
    """Write all generated levels."""
    LEVELS.mkdir(parents=True, exist_ok=True)
    mesh = write_course()
    write_hills()
    print(f"course.glb: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles")
    print(f"levels written to {LEVELS}")


if __name__ == "__main__":
    main()
