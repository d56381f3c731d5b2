"""The goal's cloth flag: placed from the goal box on every level, pinned along its pole, flying downwind and
fluttering; the wind's push is a flat plate's pressure drag; the marble's game is the same with or without
it, bit for bit; the game's renderer draws it (both faces lit) on its pole."""
import math

import numpy as np
import pytest

from marbellous.game import flag as F
from marbellous.game.autopilot import Autopilot
from marbellous.game.goal import BestTimes
from marbellous.game.level import load_level
from marbellous.game.session import Game
from marbellous.render.renderer import Renderer
from marbellous.render.sun import SUN
from marbellous.render.transforms import look_at, perspective
from marbellous.render.view import CameraView

SIZE = (320, 180)


def game(name, **kw):
    return Game(load_level(name), best_times=BestTimes(persistent=False), **kw)


@pytest.mark.parametrize("name", ["course", "hills", "blocks"])
def test_the_flag_stands_beside_the_goal_box_on_the_ground_pinned_along_its_pole(name):
    g = game(name)
    f, lvl = g.flag, g.level
    c, h = lvl.goal_center, lvl.goal_half_extents
    # beside a corner of the box, GAP outside it both ways, the wind blowing away from the box along a side or
    # the diagonal, the one that turns the flag's face most to the sun (at least 27 degrees up from edge-on)
    assert np.allclose(np.abs(f.foot[[0, 2]] - c[[0, 2]]), h[[0, 2]] + F.GAP)
    corner = np.sign(f.foot - c) * [1.0, 0.0, 1.0]
    ways = [corner * [1.0, 0.0, 0.0], corner * [0.0, 0.0, 1.0], corner / math.sqrt(2.0)]
    assert any(np.array_equal(f.direction, d) for d in ways)
    assert abs(f.across @ SUN) == max(abs(np.cross((0.0, 1.0, 0.0), d) @ SUN) for d in ways) > math.sin(0.47)
    if name == "blocks":                                # (the marble comes along +x: the pole stands on the near side)
        assert f.foot[0] < c[0] - h[0]
    # its foot on the level's ground there; of the corners whose ground is nearest the box's bottom (within
    # GROUND_TOLERANCE), the one nearest the course's last point before the box (where the marble comes from)
    bottom = c[1] - h[1]
    assert f.foot[1] == pytest.approx(g.ground_height(f.foot[0], f.foot[2], c[1] + h[1], 2 * h[1] + 1.0))
    corners = {(sx, sz): g.ground_height(c[0] + sx * (h[0] + F.GAP), c[2] + sz * (h[2] + F.GAP), c[1] + h[1],
                                         2 * h[1] + 1.0) for sx in (1, -1) for sz in (1, -1)}
    corners = {k: abs((bottom if y is None else y) - bottom) for k, y in corners.items()}
    good = [k for k, dy in corners.items() if dy <= min(corners.values()) + F.GROUND_TOLERANCE]
    inside = np.all(np.abs(lvl.path - c) <= h, axis=1)
    came_from = lvl.path[np.argmax(inside) - 1]
    far = {k: np.hypot(c[0] + k[0] * (h[0] + F.GAP) - came_from[0], c[2] + k[1] * (h[2] + F.GAP) - came_from[2])
           for k in good}
    assert far.get(tuple(np.sign(f.foot - c)[[0, 2]])) == min(far.values())
    assert f.top[1] == pytest.approx(c[1] + h[1] + F.RISE) and np.array_equal(f.top[[0, 2]], f.foot[[0, 2]])
    # the cloth: COLUMNS x ROWS vertices, its first column pinned on the pole's surface, from its top down
    cloth = f.cloth
    assert g.world.cloths == [cloth] and len(cloth) == F.COLUMNS * F.ROWS
    assert np.array_equal(np.flatnonzero(cloth.pinned), np.arange(F.ROWS))
    edge = cloth.positions[:F.ROWS]
    assert np.allclose(np.linalg.norm((edge - f.top)[:, [0, 2]], axis=1), F.POLE_RADIUS)
    assert np.allclose(edge[:, 1], f.top[1] - np.linspace(0.0, F.HEIGHT, F.ROWS))
    assert game(name, flag=False).flag is None and game(name, flag=False).world.cloths == []


def test_the_flag_flies_downwind_and_flutters():
    g = game("blocks")
    f = g.flag
    rest = f.cloth.positions
    t = f.triangles
    edges = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
    length = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)
    free = np.arange((F.COLUMNS - 1) * F.ROWS, F.COLUMNS * F.ROWS)          # the flying edge
    track = []
    for k in range(round(4.0 / g.dt)):
        g.step()
        x = g.flag.cloth.positions
        assert np.all(np.isfinite(x))
        if k * g.dt >= 1.0:
            track.append(x[free].mean(axis=0))
            strain = np.linalg.norm(x[edges[:, 0]] - x[edges[:, 1]], axis=1) / length - 1.0
            assert strain.max() < 0.1
    track = np.array(track)
    downwind = (track - f.top) @ f.direction
    across = (track - f.top) @ f.across
    # it flies: its free edge stays well downwind of the pole (half a flag's length or more), never hangs
    assert downwind.min() > 0.5 * F.LENGTH and track[:, 1].min() > f.top[1] - F.HEIGHT - 0.2
    # and flutters: the free edge swings across the wind by centimetres, to and fro many times in 3 s
    assert np.ptp(across) > 0.05
    assert np.count_nonzero(np.diff(np.sign(across - across.mean()))) > 6


def test_the_wind_pushes_a_plate_across_it_with_its_pressure_drag():
    """A steady wind U straight at the flat flag changes its momentum in one step by 1/2 rho C_D A U^2 dt, less
    the pinned edge's share; a wind along it, not at all."""
    f = game("blocks").flag
    x, v = f.cloth.positions, np.zeros((len(f.cloth), 3))
    inverse_mass = np.where(f.cloth.pinned, 0.0, 1.0 / f.cloth.mass)
    for wind in (4.0 * f.across, 4.0 * f.direction):
        after = F.plate_push(x, v, f.triangles, np.tile(wind, (len(f.triangles), 1)),
                             0.5 * F.AIR_DENSITY * F.DRAG, inverse_mass, 0.01)
        momentum = f.cloth.mass @ after
        share = np.zeros(len(f.cloth))                   # each vertex's third of its triangles' area
        area = 0.5 * np.linalg.norm(np.cross(x[f.triangles[:, 1]] - x[f.triangles[:, 0]],
                                             x[f.triangles[:, 2]] - x[f.triangles[:, 0]]), axis=1)
        np.add.at(share, f.triangles.reshape(-1), np.repeat(area / 3.0, 3))
        free_area = share[~f.cloth.pinned].sum()
        expected = 0.5 * F.AIR_DENSITY * F.DRAG * free_area * np.linalg.norm(wind) ** 2 * 0.01
        assert free_area == pytest.approx(F.LENGTH * F.HEIGHT * (1 - 0.5 / (F.COLUMNS - 1)), rel=1e-9)
        if wind @ f.across:
            assert np.allclose(momentum, expected * f.across, rtol=1e-9, atol=1e-15)
        else:
            assert np.allclose(momentum, 0.0, atol=1e-15)
        assert np.all(after[f.cloth.pinned] == 0.0)


def test_the_flag_is_blown_by_the_gusts_at_its_triangles_centres():
    """``blow`` gives the velocities of :func:`plate_push` under the wind of the module's formula (written out
    here with NumPy) at each triangle's centre."""
    g = game("blocks")
    for _ in range(30):
        g.step()
    f, t = g.flag, 0.7
    x, v = f.cloth.positions, f.cloth.velocities
    centres = x[f.triangles].mean(axis=1)
    s = (centres - f.top) @ f.direction
    strength = F.WIND * (1.0 + F.GUST * math.sin(F.GUST_OMEGA * t))
    wind = strength * (f.direction + (F.ACROSS * np.sin(F.WAVE_OMEGA * t - F.WAVE_NUMBER * s))[:, None] * f.across
                       + (F.UP * np.sin(F.UP_OMEGA * t - F.WAVE_NUMBER * s))[:, None] * [0.0, 1.0, 0.0])
    assert np.allclose(f.wind(centres, t), wind, rtol=1e-12, atol=1e-12)
    expected = F.plate_push(x, v, f.triangles, wind, 0.5 * F.AIR_DENSITY * F.DRAG,
                            np.where(f.cloth.pinned, 0.0, 1.0 / f.cloth.mass), g.dt)
    f.blow(t, g.dt)
    assert np.allclose(f.cloth.velocities, expected, rtol=1e-12, atol=1e-12)
    assert not np.allclose(expected, v)


def test_the_flag_changes_nothing_for_the_marble():
    """The autopilot's run on blocks (to the goal) is the same bit for bit with the flag and without it."""
    runs = []
    for flag in (True, False):
        g = game("blocks", flag=flag)
        pilot = Autopilot(g.course, g.spec.push)
        xs = []
        while not g.finished and g.physics_steps < 3000:
            b = g.marble
            g.step(pilot.move(b.position, b.velocity, g.camera.heading))
            xs.append(np.concatenate([b.position, b.velocity, b.orientation]))
        runs.append((g.finished, g.finish_time, np.array(xs)))
    assert runs[0][0] and runs[0][1] == runs[1][1]
    assert np.array_equal(runs[0][2], runs[1][2])


@pytest.fixture(scope="module")
def ctx():
    from marbellous.render.context import headless_context

    c = headless_context()
    yield c
    c.release()


def pixel(view, point, size=SIZE):
    """(row, column) of the pixel where ``view`` puts a world point."""
    c = perspective(view.fov, size[0] / size[1], 0.05, 400.0) @ look_at(view.eye, view.target) @ np.append(point, 1)
    return int((1 - c[1] / c[3]) / 2 * size[1]), int((c[0] / c[3] + 1) / 2 * size[0])


def yellow(px):
    """The flag's golden yellow, lit or in shade: red and green well over blue (no level's colour, the sky's,
    the goal box's green, the marble's red and blue, the poles' grey)."""
    px = np.asarray(px, int).reshape(-1, 3)
    return (px[:, 0] > 2 * px[:, 2] + 30) & (px[:, 1] > 1.6 * px[:, 2] + 20) & (px[:, 0] >= px[:, 1])


def test_the_game_renderer_draws_the_flag_on_its_pole_from_both_sides(ctx):
    """Seen from either side, the flag is yellow where its vertices are (and not without it); its face away from
    the sun is lit by the sun through it, not much darker than the sunlit one; the pole stands below it."""
    g = game("blocks")
    for _ in range(round(1.5 / g.dt)):
        g.step()
    f = g.flag
    x = f.cloth.positions
    inner = np.array([i * F.ROWS + j for i in range(2, F.COLUMNS - 2) for j in range(2, F.ROWS - 2)])
    middle = x[inner].mean(axis=0)
    plain = Renderer(ctx, g.level, 0.3, SIZE)
    r = Renderer(ctx, g.level, 0.3, SIZE, flag=f)
    pole = 0.5 * (f.foot + f.top)
    sunny = np.sign(f.across @ SUN)
    brightness = {}
    for side in (sunny, -sunny):
        view = CameraView(eye=middle + 2.0 * side * f.across + (0.0, 0.3, 0.0), target=middle)
        img = r.render_to_array(view, g.marble.position, g.marble_rotation())
        bare = plain.render_to_array(view, g.marble.position, g.marble_rotation())
        at = np.array([pixel(view, p) for p in x[inner]])
        assert yellow(img[at[:, 0], at[:, 1]]).mean() > 0.95, side
        assert not yellow(bare[at[:, 0], at[:, 1]]).any()
        brightness[side] = np.median(img[at[:, 0], at[:, 1]].astype(int).sum(axis=1))
        # the pole, below the flag: grey (lit or in shade), where there is only level without it
        row, col = pixel(view, pole)
        assert np.ptp(img[row, col].astype(int)) < 12 and np.any(img[row, col] != bare[row, col])
    assert brightness[-sunny] > 0.5 * brightness[sunny]       # (0.65 here; 0.36 were no sun let through)


def test_the_wind_compiled_ahead_is_the_one_the_flag_then_calls():
    import numba

    f = game("blocks").flag
    kernel, arguments = F.blow_call()
    f.blow(0.5, 0.01)
    assert kernel is F.blow_flag
    assert tuple(numba.typeof(a) for a in arguments) in kernel.signatures
    assert len(kernel.signatures) == 1

