"""Marbellous level files: the TOML format, its validation, and loading it into a world.

A level is a TOML file (read with ``tomllib``, never evaluated).  Keys, units in metres and radians::

    name = "Course"                 # shown in the HUD
    description = "..."             # optional
    fall_height = -6.0              # the marble respawns when its centre drops below this y

    [start]
    position = [x, y, z]            # marble centre at the start
    heading = 0.0                   # camera yaw about +y; 0 looks along +x, pi/2 along +z

    [goal]                          # an axis-aligned box; the goal is reached when the marble touches it
    center = [x, y, z]
    half_extents = [hx, hy, hz]

    [materials.NAME]                # any number of named materials
    friction = 0.7                  # Coulomb coefficient while sliding
    static_friction = 0.8           # optional, while sticking (default: friction)
    restitution = 0.2               # in [0, 1]
    rolling_friction = 0.01         # optional, m: lever arm of rolling resistance (0.01 = 1 cm)
    color = [r, g, b]               # optional, each in [0, 1]

    [[colliders]]                   # any number; each has a type and a material
    type = "plane" | "box" | "sphere" | "capsule" | "mesh" | "heightfield"
    material = "NAME"
    position = [x, y, z]            # optional, default origin
    orientation = [w, x, y, z]      # optional unit quaternion, or instead:
    axis = [x, y, z]                #   a rotation axis and
    angle = 0.5                     #   an angle in radians
    # plane:       normal = [nx, ny, nz], offset = d      (solid where dot(normal, x) <= d)
    # box:         half_extents = [hx, hy, hz]
    # sphere:      radius = r
    # capsule:     radius = r, half_height = h            (axis along the local y axis)
    # mesh:        file = "course.glb"                    (OBJ, STL, PLY, GLB/GLTF; relative to the level file)
    # heightfield: image = "hills.png", spacing = [dx, dz], origin = [x0, y0, z0], height_scale = s
    #              (greyscale PNG; pixel (row j, column i) is the height y0 + s * grey / 255 at
    #               x0 + i dx, z0 + j dz)

    [[soft_blocks]]                 # optional, any number: boxes of soft material (finite elements)
    half_extents = [hx, hy, hz]
    position = [x, y, z]            # its centre at rest
    cells = [nx, ny, nz]            # optional, default [4, 2, 4]: cells along each side, 6 tetrahedra each
    young_modulus = 5e4             # optional, Pa (default 5e4: a firm foam)
    poisson_ratio = 0.3             # optional, in [0, 0.49]
    density = 300.0                 # optional, kg/m^3
    damping = 0.01                  # optional, s: stiffness-proportional damping
    pinned = true                   # optional, default true: its bottom face held in place
    material = "NAME"               # its friction and colour

    [[streams]]                     # optional, any number: a box of moving water or air that carries the marble
    min = [x, y, z]                 # the box's lower corner (m)
    max = [x, y, z]                 # its upper corner (m)
    velocity = [vx, 0, vz]          # the stream's mean velocity (m/s, level), held by a pump
    surface = 0.4                   # optional, m: the water's surface height; without it the box is full (air)
    cell = 0.2                      # optional, m: the side of the grid's cells (default 0.2)
    density = 1000.0                # optional, kg/m^3 (default water; air is 1.2)
    viscosity = 1e-6                # optional, m^2/s (default water; air is 1.5e-5)

    [course]                        # optional: the way to the goal, for the autopilot and the rewards
    path = [[x, y, z], ...]         # marble-centre waypoints from start to goal
    speeds = [v, ...]               # optional target speed (m/s) at each waypoint

Every problem raises :class:`LevelError` (a ``ValueError``) naming the file and the key, including
problems found while building a collider's shape (a degenerate or truncated mesh, a height field too
big).  Numbers are bounded: coordinates within ``MAX_EXTENT`` m of the origin, sizes in
``[MIN_SIZE, MAX_EXTENT]`` m; the mesh files and height images of a level together hold at most
``MAX_LEVEL_TRIANGLES`` triangles and ``MAX_LEVEL_POINTS`` height points, so a small level file cannot
ask for gigabytes.
"""
import math
import numbers
import pathlib
import reprlib
from dataclasses import dataclass, field

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import numpy as np

from .._validate import MAX_FRICTION, MIN_SIZE, normalized
from ..shapes import Box, Capsule, HeightField, Plane, Sphere, TriangleMesh
from ..shapes.mesh import MAX_TRIANGLES
from ..shapes.mesh_file import read_mesh_file
from .level_index import DEFAULT_LEVEL, LEVEL_DIR, level_names

#: Limits that keep a hostile or broken level file from exhausting memory.
MAX_FILE_BYTES = 64 * 1024 * 1024
#: Largest level TOML file (bytes); the files it names may each be up to ``MAX_FILE_BYTES``.
MAX_TOML_BYTES = 4 * 1024 * 1024
MAX_IMAGE_SIDE = 2049
MAX_COLLIDERS = 4096
#: Most triangles of all the level's meshes together, and most points of all its height fields.
MAX_LEVEL_TRIANGLES = 1 << 22
MAX_LEVEL_POINTS = 1 << 23
#: Every coordinate (m) of a level lies within this distance of the origin; sizes are at most this.
MAX_EXTENT = 1e5
#: Fastest course speed (m/s).
MAX_COURSE_SPEED = 1e3
#: Longest name and description (characters).
MAX_TEXT = 4096

_SHAPE_KEYS = {
    "plane": {"normal", "offset"},
    "box": {"half_extents"},
    "sphere": {"radius"},
    "capsule": {"radius", "half_height"},
    "mesh": {"file"},
    "heightfield": {"image", "spacing", "origin", "height_scale"},
}
_COMMON_KEYS = {"type", "material", "position", "orientation", "axis", "angle"}
_MATERIAL_KEYS = {"friction", "static_friction", "restitution", "rolling_friction", "color"}
_TOP_KEYS = {"name", "description", "fall_height", "start", "goal", "materials", "colliders", "soft_blocks", "streams",
             "course"}
_SOFT_KEYS = {"half_extents", "position", "cells", "young_modulus", "poisson_ratio", "density", "damping", "pinned",
              "material"}
_STREAM_KEYS = {"min", "max", "velocity", "surface", "cell", "density", "viscosity"}
#: Most streams of a level, and most grid cells of one.
MAX_STREAMS = 8
MAX_STREAM_CELLS = 1 << 18
#: Most soft blocks of a level, and most cells along a soft block's side.
MAX_SOFT_BLOCKS = 64
MAX_SOFT_CELLS = 32


class LevelError(ValueError):
    """A level file is missing, malformed or inconsistent; the message names the file and the key."""


@dataclass(frozen=True)
class Material:
    """Surface properties of a collider (see ``World.add_static``) and its colour for rendering."""

    name: str
    friction: float
    static_friction: float
    restitution: float
    rolling_friction: float
    color: tuple


@dataclass
class Collider:
    """One static collider of a level.

    ``kind`` is the collider type; ``params`` its validated shape parameters; ``position`` (m) and
    ``orientation`` (w, x, y, z) its placement.  Meshes carry ``vertices`` (V, 3) float64 and
    ``triangles`` (T, 3) int64; height fields carry ``heights`` (nx, nz) float64 (m above ``origin``).
    ``built`` caches the shape (made when the level is loaded, so that its problems name the file).
    """

    kind: str
    material: Material
    params: dict
    position: np.ndarray
    orientation: np.ndarray
    vertices: np.ndarray = None
    triangles: np.ndarray = None
    heights: np.ndarray = None
    built: object = field(default=None, repr=False, compare=False)

    def shape(self):
        """The ``marbellous`` shape of this collider (built once, when the level is loaded; shapes are
        immutable, so every world may share it)."""
        if self.built is None:
            self.built = self.make_shape()
        return self.built

    def make_shape(self):
        """A new ``marbellous`` shape of this collider."""
        p = self.params
        if self.kind == "plane":
            return Plane(normal=p["normal"], offset=p["offset"])
        if self.kind == "box":
            return Box(p["half_extents"])
        if self.kind == "sphere":
            return Sphere(p["radius"])
        if self.kind == "capsule":
            return Capsule(p["radius"], p["half_height"])
        if self.kind == "mesh":
            return TriangleMesh(self.vertices, self.triangles)
        return HeightField(self.heights, spacing=p["spacing"], origin=p["origin"])


@dataclass(frozen=True)
class SoftBlock:
    """A box of soft material in a level (``World.add_soft_body``): its ``half_extents`` and rest ``position``
    (m), ``cells`` along each side, ``young_modulus`` (Pa), ``poisson_ratio``, ``density`` (kg/m^3),
    ``damping`` (s), whether its bottom face is ``pinned``, and its ``material`` (friction, colour)."""

    half_extents: tuple
    position: tuple
    cells: tuple
    young_modulus: float
    poisson_ratio: float
    density: float
    damping: float
    pinned: bool
    material: Material


@dataclass(frozen=True)
class Stream:
    """A box of moving water or air in a level (a :class:`~marbellous.Fluid` periodic along x and z): its
    corners ``lower`` and ``upper`` (m), ``velocity`` (m/s, level: its y component is 0), ``surface`` (m, or
    None: full), ``cell`` (m), ``density`` (kg/m^3) and ``viscosity`` (m^2/s)."""

    lower: tuple
    upper: tuple
    velocity: tuple
    surface: float | None
    cell: float
    density: float
    viscosity: float

    @property
    def resolution(self):
        """Cells along x, y and z."""
        return tuple(max(1, round((hi - lo) / self.cell)) for lo, hi in zip(self.lower, self.upper))


@dataclass
class Level:
    """A loaded, validated level.  Lengths in metres, angles in radians."""

    name: str
    description: str
    source: pathlib.Path
    start_position: np.ndarray
    start_heading: float
    goal_center: np.ndarray
    goal_half_extents: np.ndarray
    fall_height: float
    materials: dict
    colliders: list
    path: np.ndarray = field(default=None)
    speeds: np.ndarray = field(default=None)
    soft_blocks: list = field(default_factory=list)
    streams: list = field(default_factory=list)

    @property
    def key(self):
        """A short identifier for best-time records: the file's stem."""
        return self.source.stem

    @property
    def start_side(self):
        """Unit vector across the start, to the right of its heading ``h`` (rad): forward ``(cos h, 0, sin h)``
        crossed with up, ``(-sin h, 0, cos h)``; where starts are spread sideways."""
        return np.array([-math.sin(self.start_heading), 0.0, math.cos(self.start_heading)])

    def bounds(self):
        """``(lo, hi)`` corners (m) of the finite geometry, the start and the goal."""
        pts = [self.start_position, self.goal_center - self.goal_half_extents,
               self.goal_center + self.goal_half_extents]
        for c in self.colliders:
            if c.vertices is not None:
                pts.extend([c.vertices.min(axis=0), c.vertices.max(axis=0)])
            elif c.heights is not None:
                o = np.asarray(c.params["origin"])
                sx, sz = c.params["spacing"]
                pts.append(o)
                pts.append(o + [sx * (c.heights.shape[0] - 1), c.heights.max(), sz * (c.heights.shape[1] - 1)])
            elif c.kind != "plane":
                r = _bounding_radius(c)
                pts.extend([c.position - r, c.position + r])
        pts = np.array(pts)
        return pts.min(axis=0), pts.max(axis=0)


def _bounding_radius(c):
    p = c.params
    if c.kind == "box":
        return float(np.linalg.norm(p["half_extents"]))
    if c.kind == "capsule":
        return p["radius"] + p["half_height"]
    return p["radius"]


def resolve_level(name_or_path):
    """The path of a shipped level given by name, or of a user's level file given by path."""
    if name_or_path is None:
        name_or_path = DEFAULT_LEVEL
    if not isinstance(name_or_path, (str, pathlib.PurePath)):
        raise TypeError(f"level must be a level name or a path, got {name_or_path!r}")
    s = str(name_or_path)
    if s in level_names():
        return LEVEL_DIR / f"{s}.toml"
    p = pathlib.Path(s).expanduser()
    if p.is_file():
        return p.resolve()
    raise LevelError(f"level {s!r} is neither a shipped level ({', '.join(level_names())}) nor an existing file")


def load_level(name_or_path=None):
    """Load and validate a level: a shipped level's name (``"course"``) or a path to a TOML file.

    Every problem raises :class:`LevelError` naming the file and the key (see the module docstring)."""
    path = resolve_level(name_or_path)
    try:
        size = path.stat().st_size
        if size > MAX_TOML_BYTES:
            raise LevelError(f"{path.name}: file is larger than {MAX_TOML_BYTES} bytes")
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as e:
        raise LevelError(f"{path.name}: not a valid TOML file (not UTF-8 text: {e})") from None
    except OSError as e:
        raise LevelError(f"{path.name}: cannot read the file: {e.strerror or e}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise LevelError(f"{path.name}: not a valid TOML file: {e}") from None
    except RecursionError:
        raise LevelError(f"{path.name}: not a valid level file: arrays or tables nested too deeply") from None
    return _Parser(path).level(data)


_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict, _SHORT.maxstring, _SHORT.maxother = 3, 6, 6, 60, 60


class _Parser:
    """Validates a level's TOML table; every error names the file and the dotted key."""

    def __init__(self, path):
        self.path = path
        self.triangles = 0      # triangles of the meshes read so far
        self.points = 0         # points of the height fields read so far

    def fail(self, key, rule, value):
        raise LevelError(f"{self.path.name}: {key} {rule}, got {_SHORT.repr(value)}")

    def table(self, data, key, required=True):
        if key.split(".")[-1] not in data:
            if required:
                raise LevelError(f"{self.path.name}: missing required key {key!r}")
            return None
        v = data[key.split(".")[-1]]
        if not isinstance(v, dict):
            self.fail(key, "must be a table", v)
        return v

    def unknown(self, table, allowed, where):
        extra = sorted(set(table) - set(allowed))
        if extra:
            raise LevelError(f"{self.path.name}: unknown key {where + '.' if where else ''}{_SHORT.repr(extra[0])} "
                             f"(allowed: {', '.join(sorted(allowed))})")

    def number(self, table, key, where, *, default=None, positive=False, lo=None, hi=None):
        """A finite number within ``[lo, hi]`` (and ``+-MAX_EXTENT`` unless other bounds are given)."""
        name = f"{where}.{key}" if where else key
        if key not in table:
            if default is None:
                raise LevelError(f"{self.path.name}: missing required key {name!r}")
            return float(default)
        v = table[key]
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            self.fail(name, "must be a finite number", v)
        if lo is None:
            lo = MIN_SIZE if positive else -MAX_EXTENT
        if hi is None:
            hi = MAX_EXTENT
        if positive and not v > 0:
            self.fail(name, "must be > 0", v)
        if lo is not None and v < lo:
            self.fail(name, f"must be >= {lo}", v)
        if hi is not None and v > hi:
            self.fail(name, f"must be <= {hi}", v)
        return float(v)

    def vector(self, table, key, where, n=3, *, default=None, positive=False):
        name = f"{where}.{key}" if where else key
        if key not in table:
            if default is None:
                raise LevelError(f"{self.path.name}: missing required key {name!r}")
            return np.array(default, dtype=np.float64)
        return self.vector_value(table[key], name, n, positive=positive)

    def vector_value(self, v, name, n=3, *, positive=False):
        """A list of ``n`` finite numbers within ``+-MAX_EXTENT`` (``positive``: sizes, each in
        ``[MIN_SIZE, MAX_EXTENT]``)."""
        ok = (isinstance(v, list) and len(v) == n
              and all(isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x) for x in v))
        if not ok:
            self.fail(name, f"must be a list of {n} finite numbers", v)
        if positive and min(v) <= 0:
            self.fail(name, "must have every component > 0", v)
        if positive and min(v) < MIN_SIZE:
            self.fail(name, f"must have every component >= {MIN_SIZE:g} m", v)
        if max(abs(x) for x in v) > MAX_EXTENT:
            self.fail(name, f"must have every component within +-{MAX_EXTENT:g}", v)
        return np.array(v, dtype=np.float64)

    def string(self, table, key, where, default=None):
        name = f"{where}.{key}" if where else key
        if key not in table:
            if default is None:
                raise LevelError(f"{self.path.name}: missing required key {name!r}")
            return default
        if not isinstance(table[key], str):
            self.fail(name, "must be a string", table[key])
        if len(table[key]) > MAX_TEXT:
            self.fail(name, f"must be at most {MAX_TEXT} characters", table[key])
        return table[key]

    def file(self, table, key, where):
        name = f"{where}.{key}"
        rel = self.string(table, key, where)
        try:
            p = (self.path.parent / rel).resolve()
            if not p.is_file():
                self.fail(name, f"must name an existing file (relative to {self.path.parent})", rel)
            if p.stat().st_size > MAX_FILE_BYTES:
                self.fail(name, f"must be at most {MAX_FILE_BYTES} bytes", rel)
        except (OSError, ValueError) as e:     # (a name with NUL bytes, a file we may not read, ...)
            if isinstance(e, LevelError):
                raise
            self.fail(name, f"must name a readable file ({e})", rel)
        return p

    def level(self, data):
        self.unknown(data, _TOP_KEYS, "")
        start = self.table(data, "start")
        self.unknown(start, {"position", "heading"}, "start")
        goal = self.table(data, "goal")
        self.unknown(goal, {"center", "half_extents"}, "goal")
        materials = self.materials(self.table(data, "materials"))
        cols = data.get("colliders")
        if not isinstance(cols, list) or not cols or not all(isinstance(c, dict) for c in cols):
            self.fail("colliders", "must be a non-empty array of tables ([[colliders]])", cols)
        if len(cols) > MAX_COLLIDERS:
            self.fail("colliders", f"must have at most {MAX_COLLIDERS} entries", len(cols))
        colliders = [self.collider(c, f"colliders[{i}]", materials) for i, c in enumerate(cols)]
        level = Level(
            name=self.string(data, "name", "", default=self.path.stem),
            description=self.string(data, "description", "", default=""),
            source=self.path,
            start_position=self.vector(start, "position", "start"),
            start_heading=self.number(start, "heading", "start", default=0.0),
            goal_center=self.vector(goal, "center", "goal"),
            goal_half_extents=self.vector(goal, "half_extents", "goal", positive=True),
            fall_height=self.number(data, "fall_height", "", default=-10.0),
            materials=materials,
            colliders=colliders,
        )
        if level.fall_height >= level.start_position[1]:
            self.fail("fall_height", "must be below start.position's height", level.fall_height)
        blocks = data.get("soft_blocks", [])
        if not isinstance(blocks, list) or not all(isinstance(b, dict) for b in blocks):
            self.fail("soft_blocks", "must be an array of tables ([[soft_blocks]])", blocks)
        if len(blocks) > MAX_SOFT_BLOCKS:
            self.fail("soft_blocks", f"must have at most {MAX_SOFT_BLOCKS} entries", len(blocks))
        level.soft_blocks = [self.soft_block(b, f"soft_blocks[{i}]", materials) for i, b in enumerate(blocks)]
        streams = data.get("streams", [])
        if not isinstance(streams, list) or not all(isinstance(b, dict) for b in streams):
            self.fail("streams", "must be an array of tables ([[streams]])", streams)
        if len(streams) > MAX_STREAMS:
            self.fail("streams", f"must have at most {MAX_STREAMS} entries", len(streams))
        level.streams = [self.stream(b, f"streams[{i}]") for i, b in enumerate(streams)]
        course = self.table(data, "course", required=False)
        if course is not None:
            self.course(course, level)
        return level

    def stream(self, b, where):
        self.unknown(b, _STREAM_KEYS, where)
        lower, upper = self.vector(b, "min", where), self.vector(b, "max", where)
        if not np.all(upper - lower >= MIN_SIZE):
            self.fail(f"{where}.max", "must lie above min along every axis", b["max"])
        velocity = self.vector(b, "velocity", where)
        if velocity[1] != 0.0 or np.abs(velocity).max() > 100.0:
            self.fail(f"{where}.velocity", "must be level (y = 0) and at most 100 m/s", b["velocity"])
        cell = self.number(b, "cell", where, default=0.2, lo=0.01, hi=100.0)
        surface = None if "surface" not in b else self.number(b, "surface", where)
        stream = Stream(lower=tuple(float(x) for x in lower), upper=tuple(float(x) for x in upper),
                        velocity=tuple(float(x) for x in velocity), surface=surface, cell=cell,
                        density=self.number(b, "density", where, default=1000.0, lo=0.01, hi=1e5),
                        viscosity=self.number(b, "viscosity", where, default=1e-6, lo=0.0, hi=10.0))
        if math.prod(stream.resolution) > MAX_STREAM_CELLS:
            self.fail(f"{where}.cell", f"makes {math.prod(stream.resolution)} cells; at most {MAX_STREAM_CELLS} "
                      "are allowed", cell)
        return stream

    def soft_block(self, b, where, materials):
        self.unknown(b, _SOFT_KEYS, where)
        mat = self.string(b, "material", where)
        if mat not in materials:
            self.fail(f"{where}.material", f"must name a material in [materials] ({', '.join(materials)})", mat)
        cells = b.get("cells", [4, 2, 4])
        if not isinstance(cells, list) or len(cells) != 3 or not all(
                isinstance(c, int) and not isinstance(c, bool) and 1 <= c <= MAX_SOFT_CELLS for c in cells):
            self.fail(f"{where}.cells", f"must be three whole numbers in [1, {MAX_SOFT_CELLS}]", cells)
        pinned = b.get("pinned", True)
        if not isinstance(pinned, bool):
            self.fail(f"{where}.pinned", "must be true or false", pinned)
        return SoftBlock(
            half_extents=tuple(float(x) for x in self.vector(b, "half_extents", where, positive=True)),
            position=tuple(float(x) for x in self.vector(b, "position", where)), cells=tuple(cells),
            young_modulus=self.number(b, "young_modulus", where, default=5e4, lo=1.0, hi=1e12),
            poisson_ratio=self.number(b, "poisson_ratio", where, default=0.3, lo=0.0, hi=0.49),
            density=self.number(b, "density", where, default=300.0, lo=1.0, hi=1e5),
            damping=self.number(b, "damping", where, default=0.01, lo=0.0, hi=10.0),
            pinned=pinned, material=materials[mat])

    def materials(self, table):
        if not table:
            self.fail("materials", "must define at least one material", table)
        out = {}
        for name, m in table.items():
            where = f"materials.{name}"
            if not isinstance(m, dict):
                self.fail(where, "must be a table", m)
            self.unknown(m, _MATERIAL_KEYS, where)
            friction = self.number(m, "friction", where, lo=0.0, hi=MAX_FRICTION)
            color = self.vector(m, "color", where, default=(0.7, 0.7, 0.7))
            if color.min() < 0 or color.max() > 1:
                self.fail(f"{where}.color", "must have components in [0, 1]", m["color"])
            out[name] = Material(
                name=name, friction=friction,
                static_friction=self.number(m, "static_friction", where, default=friction, lo=0.0, hi=MAX_FRICTION),
                restitution=self.number(m, "restitution", where, default=0.0, lo=0.0, hi=1.0),
                rolling_friction=self.number(m, "rolling_friction", where, default=0.0, lo=0.0, hi=MAX_EXTENT),
                color=tuple(float(x) for x in color))
        return out

    def collider(self, c, where, materials):
        kind = self.string(c, "type", where)
        if kind not in _SHAPE_KEYS:
            self.fail(f"{where}.type", f"must be one of {', '.join(sorted(_SHAPE_KEYS))}", kind)
        self.unknown(c, _COMMON_KEYS | _SHAPE_KEYS[kind], where)
        mat = self.string(c, "material", where)
        if mat not in materials:
            self.fail(f"{where}.material", f"must name a material in [materials] ({', '.join(materials)})", mat)
        position = self.vector(c, "position", where, default=(0.0, 0.0, 0.0))
        orientation = self.orientation(c, where)
        col = Collider(kind=kind, material=materials[mat], params={}, position=position, orientation=orientation)
        p = col.params
        if kind == "plane":
            n = self.vector(c, "normal", where, default=(0.0, 1.0, 0.0))
            if not np.any(n):
                self.fail(f"{where}.normal", "must be non-zero", c.get("normal"))
            p["normal"], p["offset"] = normalized("normal", n), self.number(c, "offset", where, default=0.0)
            if "position" in c or "orientation" in c or "axis" in c:
                raise LevelError(f"{self.path.name}: {where}: a plane is placed by normal and offset only")
        elif kind == "box":
            p["half_extents"] = self.vector(c, "half_extents", where, positive=True)
        elif kind == "sphere":
            p["radius"] = self.number(c, "radius", where, lo=MIN_SIZE)
        elif kind == "capsule":
            p["radius"] = self.number(c, "radius", where, lo=MIN_SIZE)
            p["half_height"] = self.number(c, "half_height", where, lo=MIN_SIZE)
        elif kind == "mesh":
            self.mesh(c, where, col)
        else:
            self.heightfield(c, where, col)
        try:
            col.shape()
        except (ValueError, TypeError) as e:
            key = f"{where}.file" if kind == "mesh" else f"{where}.image" if kind == "heightfield" else where
            source = f" ({pathlib.Path(col.params.get('file') or col.params.get('image')).name})" \
                if kind in ("mesh", "heightfield") else ""
            raise LevelError(f"{self.path.name}: {key}{source}: {e}") from None
        return col

    def orientation(self, c, where):
        if "orientation" in c:
            if "axis" in c or "angle" in c:
                raise LevelError(f"{self.path.name}: {where}: give either orientation or axis and angle, not both")
            q = self.vector(c, "orientation", where, n=4)
            if not np.any(q):
                self.fail(f"{where}.orientation", "must be a non-zero quaternion (w, x, y, z)", c["orientation"])
            return normalized("orientation", q)
        if "axis" in c or "angle" in c:
            axis = self.vector(c, "axis", where)
            if not np.any(axis):
                self.fail(f"{where}.axis", "must be non-zero", c["axis"])
            angle = self.number(c, "angle", where)
            axis = normalized("axis", axis)
            return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])
        return np.array([1.0, 0.0, 0.0, 0.0])

    def mesh(self, c, where, col):
        p = self.file(c, "file", where)
        try:
            v, t = read_mesh_file(p, MAX_TRIANGLES, MAX_FILE_BYTES)
        except (ValueError, TypeError) as e:
            raise LevelError(f"{self.path.name}: {where}.file: cannot read mesh {p.name}: {e}") from None
        self.triangles += t.shape[0]
        if self.triangles > MAX_LEVEL_TRIANGLES:
            self.fail(f"{where}.file", f"brings the level's meshes over {MAX_LEVEL_TRIANGLES} triangles in all",
                      p.name)
        if not np.all(np.isfinite(v)):
            self.fail(f"{where}.file", "must hold a mesh with triangles and finite vertices", p.name)
        col.params["file"] = str(p)
        col.vertices, col.triangles = v, t

    def heightfield(self, c, where, col):
        from PIL import Image

        p = self.file(c, "image", where)
        scale = self.number(c, "height_scale", where, positive=True)
        spacing = self.vector(c, "spacing", where, n=2, positive=True)
        origin = tuple(self.vector(c, "origin", where, default=(0.0, 0.0, 0.0)))
        try:
            with Image.open(p) as img:
                if max(img.size) > MAX_IMAGE_SIDE:
                    self.fail(f"{where}.image", f"must be at most {MAX_IMAGE_SIDE} pixels on a side", img.size)
                if img.size[0] * img.size[1] + self.points > MAX_LEVEL_POINTS:
                    self.fail(f"{where}.image", f"brings the level's height fields over {MAX_LEVEL_POINTS} "
                                                "points in all", img.size)
                grey = np.asarray(img.convert("L"), dtype=np.float64)
        except LevelError:
            raise
        except Exception as e:   # noqa: BLE001  (Pillow raises many kinds of errors on malformed images)
            raise LevelError(f"{self.path.name}: {where}.image: cannot read image {p.name}: "
                             f"{type(e).__name__}: {e}") from None
        if grey.ndim != 2 or min(grey.shape) < 2:
            self.fail(f"{where}.image", "must be at least 2 x 2 pixels", grey.shape)
        self.points += grey.size
        col.params.update(image=str(p), spacing=tuple(spacing), height_scale=scale, origin=origin)
        col.heights = grey.T * (scale / 255.0)

    def course(self, course, level):
        self.unknown(course, {"path", "speeds"}, "course")
        pts = course.get("path")
        if (not isinstance(pts, list) or len(pts) < 2
                or not all(isinstance(q, list) and len(q) == 3 for q in pts)):
            self.fail("course.path", "must be a list of at least 2 points [x, y, z]", pts)
        level.path = np.array([self.vector_value(q, f"course.path[{i}]") for i, q in enumerate(pts)])
        if "speeds" in course:
            s = course["speeds"]
            if not isinstance(s, list) or len(s) != len(pts):
                self.fail("course.speeds", "must be a list with one speed per path point", s)
            level.speeds = np.array([self.number({f"speeds[{i}]": v}, f"speeds[{i}]", "course", positive=True,
                                                 hi=MAX_COURSE_SPEED) for i, v in enumerate(s)])
