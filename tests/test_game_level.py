"""Level files: the shipped levels load, and malformed files fail with errors that name the key."""
import pathlib

import numpy as np
import pytest

from marbellous.game.level import LevelError, level_names, load_level

SHIPPED = ["blocks", "course", "hills"]


def test_shipped_levels_are_listed_and_small():
    assert set(SHIPPED) <= set(level_names())
    total = sum(p.stat().st_size for p in (pathlib.Path(load_level("course").source).parent).iterdir())
    assert total < 3_000_000


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_level_loads(name):
    level = load_level(name)
    assert level.key == name
    assert level.path is not None and len(level.path) >= 2
    assert np.all(level.goal_half_extents > 0)
    kinds = {c.kind for c in level.colliders}
    expected = {"course": {"mesh"}, "hills": {"heightfield"}, "blocks": {"plane", "box", "capsule"}}[name]
    assert kinds == expected
    # the start is above the fall height and the goal lies within the level's bounds
    lo, hi = level.bounds()
    assert level.fall_height < level.start_position[1]
    assert np.all(level.goal_center >= lo) and np.all(level.goal_center <= hi)


def test_course_mesh_is_closed_and_faces_outward():
    level = load_level("course")
    (mesh,) = level.colliders
    v, t = mesh.vertices, mesh.triangles
    # signed volume of a closed, outward-wound surface is positive (divergence theorem)
    vol = np.einsum("ij,ij->i", v[t[:, 0]], np.cross(v[t[:, 1]], v[t[:, 2]])).sum() / 6.0
    assert vol > 10.0
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)


def test_heightfield_image_maps_rows_to_z():
    level = load_level("hills")
    (hf,) = level.colliders
    from PIL import Image

    grey = np.asarray(Image.open(hf.params["image"]).convert("L"), float)
    i, j = 5, 17   # x index, z index
    assert hf.heights[i, j] == pytest.approx(grey[j, i] * hf.params["height_scale"] / 255.0)


GOOD = """
name = "T"
[start]
position = [0.0, 1.0, 0.0]
[goal]
center = [5.0, 1.0, 0.0]
half_extents = [1.0, 1.0, 1.0]
[materials.m]
friction = 0.5
[[colliders]]
type = "box"
half_extents = [10.0, 0.5, 10.0]
position = [0.0, -0.5, 0.0]
material = "m"
"""


def write(tmp_path, text, name="lvl.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("heading", [0.0, 0.3, 1.5707963267948966, -2.0, 3.0])
def test_the_start_side_is_level_unit_and_to_the_right_of_the_heading(heading):
    level = load_level("course")
    level.start_heading = heading
    forward = np.array([np.cos(heading), 0.0, np.sin(heading)])
    side = level.start_side
    assert side[1] == 0.0
    assert np.linalg.norm(side) == pytest.approx(1.0, abs=1e-15)
    assert forward @ side == pytest.approx(0.0, abs=1e-15)
    # forward x up: the right of a heading with y up
    np.testing.assert_allclose(side, np.cross(forward, [0.0, 1.0, 0.0]), atol=1e-15)


def test_user_level_loads_by_path(tmp_path):
    level = load_level(write(tmp_path, GOOD))
    assert level.name == "T" and level.colliders[0].kind == "box"
    assert level.path is None


@pytest.mark.parametrize("edit, key", [
    (("half_extents = [1.0, 1.0, 1.0]", "half_extents = [1.0, -1.0, 1.0]"), "goal.half_extents"),
    (("center = [5.0, 1.0, 0.0]", "center = [5.0, 1.0]"), "goal.center"),
    (("friction = 0.5", "friction = -0.5"), "materials.m.friction"),
    (("friction = 0.5", "friction = 0.5\nrestitution = 2.0"), "materials.m.restitution"),
    (('material = "m"', 'material = "gold"'), "colliders[0].material"),
    (('type = "box"', 'type = "cone"'), "colliders[0].type"),
    (("half_extents = [10.0, 0.5, 10.0]", "half_extents = [10.0, 0.5, 10.0]\ncolour = 3"), "colours"),
    (("[start]\nposition = [0.0, 1.0, 0.0]", "[start]"), "start.position"),
    (("[goal]", "fall_height = 5.0\n[goal]"), "fall_height"),
    (('type = "box"', 'type = "mesh"\nfile = "missing.obj"'), "colliders[0]"),
])
def test_bad_level_names_the_key(tmp_path, edit, key):
    text = GOOD.replace(*edit)
    assert text != GOOD
    with pytest.raises(LevelError) as err:
        load_level(write(tmp_path, text))
    msg = str(err.value)
    assert "lvl.toml" in msg
    assert key.rstrip("s") in msg


def test_not_toml_and_unknown_level(tmp_path):
    with pytest.raises(LevelError, match="not a valid TOML"):
        load_level(write(tmp_path, "name = = 3"))
    with pytest.raises(LevelError, match="neither a shipped level"):
        load_level("no-such-level")
    with pytest.raises(TypeError, match="level"):
        load_level(3.5)


def test_heightfield_and_mesh_files_are_checked(tmp_path):
    (tmp_path / "bad.png").write_bytes(b"not an image")
    text = GOOD.replace('type = "box"\nhalf_extents = [10.0, 0.5, 10.0]\nposition = [0.0, -0.5, 0.0]',
                        'type = "heightfield"\nimage = "bad.png"\nspacing = [1.0, 1.0]\nheight_scale = 2.0')
    with pytest.raises(LevelError, match=r"colliders\[0\].image"):
        load_level(write(tmp_path, text))
    (tmp_path / "bad.obj").write_text("v 0 0 0\n")
    text = GOOD.replace('type = "box"\nhalf_extents = [10.0, 0.5, 10.0]\nposition = [0.0, -0.5, 0.0]',
                        'type = "mesh"\nfile = "bad.obj"')
    with pytest.raises(LevelError, match=r"colliders\[0\].file"):
        load_level(write(tmp_path, text))


SOFT = GOOD + """
[[soft_blocks]]
half_extents = [0.5, 0.3, 0.5]
position = [2.0, 0.3, 2.0]
material = "m"
"""


def test_soft_blocks_load_with_defaults(tmp_path):
    block, = load_level(write(tmp_path, SOFT)).soft_blocks
    assert block.half_extents == (0.5, 0.3, 0.5) and block.cells == (4, 2, 4) and block.pinned
    assert (block.young_modulus, block.poisson_ratio, block.density) == (5e4, 0.3, 300.0)
    assert load_level(write(tmp_path, GOOD)).soft_blocks == []


@pytest.mark.parametrize("edit, key", [
    (("half_extents = [0.5, 0.3, 0.5]", "half_extents = [0.5, 0.0, 0.5]"), "soft_blocks[0].half_extents"),
    (('position = [2.0, 0.3, 2.0]\nmaterial = "m"', 'position = [2.0, 0.3, 2.0]\nmaterial = "x"'),
     "soft_blocks[0].material"),
    (('material = "m"\n', 'material = "m"\ncells = [4, 0, 4]\n'), "soft_blocks[0].cells"),
    (('material = "m"\n', 'material = "m"\npoisson_ratio = 0.5\n'), "soft_blocks[0].poisson_ratio"),
    (('material = "m"\n', 'material = "m"\npinned = 1\n'), "soft_blocks[0].pinned"),
    (('material = "m"\n', 'material = "m"\nshape = "ball"\n'), "soft_blocks[0]"),
])
def test_bad_soft_blocks_name_the_key(tmp_path, edit, key):
    head, tail = SOFT.rsplit("[[soft_blocks]]", 1)           # (the soft block's keys, not the collider's)
    text = head + "[[soft_blocks]]" + tail.replace(*edit)
    assert text != SOFT
    with pytest.raises(LevelError) as err:
        load_level(write(tmp_path, text))
    assert key in str(err.value) and "lvl.toml" in str(err.value)


STREAM = GOOD + """
[[streams]]
min = [-1.0, 0.0, -2.0]
max = [1.0, 0.6, 2.0]
velocity = [0.0, 0.0, 1.0]
surface = 0.4
"""


def test_streams_load_with_defaults(tmp_path):
    stream, = load_level(write(tmp_path, STREAM)).streams
    assert stream.lower == (-1.0, 0.0, -2.0) and stream.upper == (1.0, 0.6, 2.0) and stream.surface == 0.4
    assert (stream.cell, stream.density, stream.viscosity) == (0.2, 1000.0, 1e-6)
    assert stream.resolution == (10, 3, 20)
    assert load_level(write(tmp_path, GOOD)).streams == []


@pytest.mark.parametrize("edit, key", [
    (("max = [1.0, 0.6, 2.0]", "max = [1.0, 0.0, 2.0]"), "streams[0].max"),
    (("velocity = [0.0, 0.0, 1.0]", "velocity = [0.0, 1.0, 1.0]"), "streams[0].velocity"),
    (("velocity = [0.0, 0.0, 1.0]", "velocity = [0.0, 0.0]"), "streams[0].velocity"),
    (("surface = 0.4", "surface = \"high\""), "streams[0].surface"),
    (("surface = 0.4", "surface = 0.4\ncell = 0.001"), "streams[0].cell"),
    (("surface = 0.4", "surface = 0.4\ndensity = -1.0"), "streams[0].density"),
    (("surface = 0.4", "surface = 0.4\nwind = true"), "streams[0]"),
])
def test_bad_streams_name_the_key(tmp_path, edit, key):
    text = STREAM.replace(*edit)
    assert text != STREAM
    with pytest.raises(LevelError) as err:
        load_level(write(tmp_path, text))
    assert key in str(err.value) and "lvl.toml" in str(err.value)
