"""The moderngl renderer of Marbellous: a lit level with shadows, the patterned marble, the goal flag
(a y-axis billboard), the game's cloth flag on its pole beside the goal, the HUD and a debug overlay.

The renderer draws into any framebuffer: an offscreen one for headless video (``render_to_array``) or
a window's screen.  One directional light (the sun) casts shadows through a shadow map rendered from
its orthographic view around the camera's focus.  Edges are smoothed by an FXAA pass (``render/fxaa.py``) before
the debug overlay and the HUD are drawn, or by 4x multisampling offscreen.
"""
from dataclasses import dataclass, field

import moderngl
import numpy as np

from .antialiasing import check_antialiasing, offscreen_samples
from .billboard import billboard_y_matrix
from .context import in_own_context
from .cloth_drawing import vertex_normals
from .geometry import capsule_triangles, collider_triangles, flat, grid_cells, indexed, uv_sphere
from .fxaa import Fxaa
from .hud import HudText
from .offscreen import Offscreen
from .shadow_map import SHADOW_GLSL, shadow_map
from .sun import SUN
from .transforms import look_at, model_matrix, orthographic, perspective
from .world_shaders import SHEET_THROUGH_GLSL

_SCENE_VS = """
#version 330
uniform mat4 u_view_proj;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
in vec3 in_pos;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_local;
out vec3 v_normal;
out vec4 v_light;
void main() {
    vec4 world = u_model * vec4(in_pos, 1.0);
    v_world = world.xyz;
    v_local = in_pos;
    v_normal = mat3(u_model) * in_normal;
    v_light = u_light_view_proj * world;
    gl_Position = u_view_proj * world;
}
"""

# compiled once per pattern (``#define PATTERN``): llvmpipe runs every side of a branch for every fragment, so a
# uniform choosing the pattern cost each fragment all patterns' code (0.8 ms of a 640 x 360 frame)
_SCENE_FS = """
""" + SHEET_THROUGH_GLSL + """
uniform vec3 u_color;
uniform vec3 u_color2;
uniform float u_alpha;
// PATTERN: 0 plain with a 1 m grid, 1 marble octants and stripes, 2 unlit, 3 a thin sheet
uniform vec3 u_sun;             // unit vector towards the sun
uniform vec3 u_eye;
""" + SHADOW_GLSL + """
in vec3 v_world;
in vec3 v_local;
in vec3 v_normal;
in vec4 v_light;
out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec3 base = u_color;
#if PATTERN == 1
    vec3 d = normalize(v_local);
    float octant = sign(d.x) * sign(d.y) * sign(d.z);
    base = octant > 0.0 ? u_color : u_color2;
    if (abs(d.y) < 0.12) base = vec3(0.97, 0.97, 0.92);
#elif PATTERN == 0
    vec2 g = abs(fract(v_world.xz + 0.5) - 0.5);
    float line = 1.0 - smoothstep(0.0, 0.03, min(g.x, g.y));
    base *= 1.0 - 0.18 * line;
#endif
#if PATTERN == 2
    f_color = vec4(base, u_alpha);
#else
    // the map's depth runs over 159 m: a bias of 0.6 m (edge-on) to 0.13 m (facing the sun)
    float sun = shadow_factor(v_light, n, 0.004, 0.0);
    float lit = max(dot(n, u_sun), 0.0) * sun;
    // a thin sheet (the cloth flag) lets part of the sun on its other face through
    float diffuse = lit + (PATTERN == 3 ? SHEET_THROUGH * max(-dot(n, u_sun), 0.0) * sun : 0.0);
    float sky = 0.5 + 0.5 * n.y;
    vec3 v = normalize(u_eye - v_world);
    float spec = pow(max(dot(reflect(-u_sun, n), v), 0.0), PATTERN == 1 ? 60.0 : 16.0)
                 * (PATTERN == 1 ? 0.9 : 0.12) * lit;
    vec3 c = base * (0.32 * sky + 0.12 + 0.78 * diffuse) + vec3(spec);
    float fog = clamp((length(u_eye - v_world) - 40.0) / 120.0, 0.0, 0.7);
    c = mix(c, vec3(0.70, 0.80, 0.92), fog);
    f_color = vec4(pow(c, vec3(1.0 / 1.1)), u_alpha);
#endif
}
"""

_DEPTH_VS = """
#version 330
uniform mat4 u_light_view_proj;
uniform mat4 u_model;
in vec3 in_pos;
void main() { gl_Position = u_light_view_proj * u_model * vec4(in_pos, 1.0); }
"""
_DEPTH_FS = """
#version 330
void main() {}
"""

_LINES_VS = """
#version 330
uniform mat4 u_view_proj;
in vec3 in_pos;
in vec3 in_color;
out vec3 v_color;
void main() { v_color = in_color; gl_Position = u_view_proj * vec4(in_pos, 1.0); }
"""
_LINES_FS = """
#version 330
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
"""

_TEXTURED_VS = """
#version 330
uniform mat4 u_mvp;
in vec3 in_pos;
in vec2 in_uv;
out vec2 v_uv;
void main() { v_uv = in_uv; gl_Position = u_mvp * vec4(in_pos, 1.0); }
"""
_TEXTURED_FS = """
#version 330
uniform sampler2D u_tex;
uniform float u_wave;
in vec2 v_uv;
out vec4 f_color;
void main() {
    vec4 c = texture(u_tex, v_uv);
    if (c.a < 0.02) discard;
    f_color = vec4(c.rgb * (1.0 - u_wave * 0.15 * sin(v_uv.x * 9.0)), c.a);
}
"""

SKY = (0.70, 0.80, 0.92)
#: The cloth flag's colour (golden yellow: not the marble's red and blue, the goal's green, a level's greys).
FLAG_COLOR = (0.98, 0.78, 0.10)
#: The poles' colour.
POLE_COLOR = (0.9, 0.9, 0.9)
#: The scene programs' patterns: the ``PATTERN`` each is compiled with.
PATTERNS = {"plain": 0, "marble": 1, "unlit": 2, "sheet": 3}
#: The marble's second colour (its first is its draw item's).
MARBLE_COLOR2 = (0.12, 0.28, 0.85)
#: The marble's sphere: rings and segments.  Its outline is a polygon of 32 sides: off the circle by at most
#: ``r (1 - cos(pi / 32)) = 0.005 r``, under a pixel while the marble is under 200 pixels across.
MARBLE_RINGS_SEGMENTS = (16, 32)
#: Sides of a pole: 5 cm thin, a few pixels across from the game's camera, whose outline 8 sides keep round.
POLE_SEGMENTS = 8
#: a level's streams: translucent water blue
WATER_COLOR = (0.15, 0.45, 0.90)


@dataclass
class DebugOverlay:
    """What the debug overlay shows: contact ``points`` and ``normals`` ((K, 3) arrays, m) and
    whether to draw the level's 2D grid cells."""

    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    grid: bool = True


def _f32(m):
    """The bytes of a (4, 4) matrix ``m`` (column vectors) as a GLSL ``mat4`` uniform: float32, column-major."""
    return np.ascontiguousarray(np.asarray(m, np.float64).T, dtype=np.float32).tobytes()


#: the identity model matrix of meshes already in world space, as uniform bytes
_IDENTITY = _f32(np.eye(4))


def _checker_texture(ctx, n=64, squares=8):
    """RGBA chequered flag texture."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    black = ((i * squares // n + j * squares // n) % 2).astype(bool)
    img = np.where(black[..., None], [20, 20, 20, 255], [250, 250, 250, 255]).astype(np.uint8)
    tex = ctx.texture((n, n), 4, img.tobytes())
    # mipmapped: a few pixels high far away, the squares blend to grey instead of flickering (which an edge
    # smoothing pass would then smear)
    tex.build_mipmaps()
    tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.NEAREST)
    return tex


class Renderer:
    """Draws a level and its marble with moderngl.

    ``ctx`` is a moderngl context (headless EGL or a window's), ``level`` a loaded
    ``marbellous.game.level.Level``, ``marble_radius`` in metres, ``size`` the (width, height) in
    pixels of the offscreen target used by :meth:`render_to_array`.  ``flag`` (None: none) is a cloth flag
    on a pole, drawn as it is at each frame: an object with ``cloth`` (its positions, m, and triangles
    are read every frame; its triangles must not change), ``foot`` and ``top`` (the pole's ends, m) and
    ``radius`` (the pole's, m), such as the game's ``GoalFlag``.  ``soft_bodies`` are the level's soft blocks
    as ``SoftBody`` handles (``Game.soft_blocks``, in the order of ``level.soft_blocks``), drawn in their
    materials' colours as their surfaces are at each frame.  The level's streams are drawn as translucent
    water (or air) up to their surfaces.  ``antialiasing`` is one of ``antialiasing.ANTIALIASING`` and
    ``shadow_size`` the side of the sun's shadow map (texels, over 60 m around the camera's focus).
    """

    @in_own_context
    def __init__(self, ctx, level, marble_radius, size=(640, 360), *, antialiasing="fxaa", shadow_size=1024,
                 grid_cell=2.0, flag=None, soft_bodies=()):
        check_antialiasing(antialiasing)
        self.ctx, self.level, self.marble_radius = ctx, level, float(marble_radius)
        self.size = tuple(int(s) for s in size)
        self.scenes = {pattern: ctx.program(vertex_shader=_SCENE_VS,
                                            fragment_shader=f"#version 330\n#define PATTERN {pattern}\n{_SCENE_FS}")
                       for pattern in PATTERNS.values()}
        self.depth = ctx.program(vertex_shader=_DEPTH_VS, fragment_shader=_DEPTH_FS)
        self.lines = ctx.program(vertex_shader=_LINES_VS, fragment_shader=_LINES_FS)
        self.textured = ctx.program(vertex_shader=_TEXTURED_VS, fragment_shader=_TEXTURED_FS)
        lo, hi = level.bounds()
        center = 0.5 * (lo + hi)
        self.items = []  # draw items (:meth:`_item`)
        for c in level.colliders:
            pos, nrm = collider_triangles(c, center)
            self.items.append(self._mesh(pos, nrm, c.material.color))
        self.marble = self._mesh(*uv_sphere(1.0, *MARBLE_RINGS_SEGMENTS), (0.85, 0.15, 0.12), "marble")
        center, half = np.asarray(level.goal_center), np.asarray(level.goal_half_extents)
        self.poles = [self._mesh(*_pole_triangles(center - [0.0, half[1], 0.0], center + [0.0, half[1] + 1.2, 0.0],
                                                  0.05), POLE_COLOR)]
        self.flag = flag
        if flag is not None:
            self.poles.append(self._mesh(*_pole_triangles(flag.foot, flag.top, flag.radius), POLE_COLOR))
            self.flag_item, self.flag_vertices = self._moving_mesh(len(flag.cloth.positions), flag.cloth.triangles,
                                                                   FLAG_COLOR, "sheet")
        # each soft block: (body, its surface triangles, its draw item, its vertex buffer)
        self.soft = []
        for body, block in zip(soft_bodies, level.soft_blocks):
            triangles = body.surface_triangles
            self.soft.append((body, triangles, *self._moving_mesh(len(body), triangles, block.material.color)))
        box = _goal_box_triangles(level.goal_center, level.goal_half_extents)
        self.goal_box = self._mesh(*flat(*box), (0.3, 0.95, 0.4), "unlit")
        self.water = []
        for stream in level.streams:
            lower, upper = np.array(stream.lower), np.array(stream.upper)
            if stream.surface is not None:
                upper[1] = min(max(stream.surface, lower[1]), upper[1])
            if upper[1] > lower[1]:
                self.water.append(self._mesh(*flat(*_goal_box_triangles(0.5 * (lower + upper), 0.5 * (upper - lower))),
                                             WATER_COLOR))
        quad = np.array([[0, 0, 0, 0, 1], [1.6, 0, 0, 1, 1], [1.6, 1.0, 0, 1, 0],
                         [0, 0, 0, 0, 1], [1.6, 1.0, 0, 1, 0], [0, 1.0, 0, 0, 0]], np.float32)
        self.flag_vbo = ctx.buffer(quad.tobytes())
        self.flag_vao = ctx.vertex_array(self.textured, [(self.flag_vbo, "3f 2f", "in_pos", "in_uv")])
        self.flag_tex = _checker_texture(ctx)
        self.flag_top = np.array(level.goal_center) + [0.0, level.goal_half_extents[1] + 1.2, 0.0]
        self.shadow_tex, self.shadow_fbo = shadow_map(ctx, shadow_size)
        self.hud = HudText(ctx)
        self.grid_cell = grid_cell
        self._grid_lines = None
        self.line_vbo = ctx.buffer(reserve=6 * 4 * 2 * 1024)
        self.line_vao = ctx.vertex_array(self.lines, [(self.line_vbo, "3f 3f", "in_pos", "in_color")])
        self._offscreen = None
        self.antialiasing, self.shadow_size = antialiasing, shadow_size
        self.fxaa = Fxaa(ctx) if antialiasing == "fxaa" else None

    def _mesh(self, pos, nrm, color, pattern="plain"):
        """The draw item of the unindexed triangles ``pos``, ``nrm`` (3 T, 3) in ``color`` and ``pattern`` (a
        key of :data:`PATTERNS`), drawn indexed (:func:`indexed`)."""
        vertices, indices = indexed(pos, nrm)
        return self._item(self.ctx.buffer(vertices.tobytes()), self.ctx.buffer(indices.tobytes()), color, pattern)

    def _item(self, vbo, ibo, color, pattern):
        """A draw item: ``(scene vertex array, depth vertex array, colour, scene program)`` of the vertices in
        ``vbo`` (rows [position, normal], float32) indexed by ``ibo`` (uint32)."""
        program = self.scenes[PATTERNS[pattern]]
        # (the unlit pattern's program has no normals)
        layout = [(vbo, "3f 3f", "in_pos", "in_normal") if program.get("in_normal", None) is not None
                  else (vbo, "3f 12x", "in_pos")]
        return (self.ctx.vertex_array(program, layout, index_buffer=ibo, index_element_size=4),
                self.ctx.vertex_array(self.depth, [(vbo, "3f 12x", "in_pos")], index_buffer=ibo,
                                      index_element_size=4), tuple(color), program)

    def _moving_mesh(self, n_vertices, triangles, color, pattern="plain"):
        """``(draw item, vertex buffer)`` of a mesh of ``n_vertices`` vertices whose places change every frame
        (the flag, a soft block): indexed by ``triangles``, its vertices written by :meth:`_write_vertices`."""
        vbo = self.ctx.buffer(reserve=n_vertices * 6 * 4, dynamic=True)
        ibo = self.ctx.buffer(np.asarray(triangles).astype(np.uint32).tobytes())
        return self._item(vbo, ibo, color, pattern), vbo

    @staticmethod
    def _write_vertices(vbo, positions, triangles):
        """Write a moving mesh's vertices as they are now, with smooth normals from its triangles."""
        vbo.write(np.hstack([positions, vertex_normals(positions, triangles)]).astype(np.float32).tobytes())

    # ------------------------------------------------------------------ drawing
    def render(self, fbo, view, marble_position, marble_rotation, hud_lines=(), debug=None, viewport=None):
        """Draw one frame into ``fbo`` (a moderngl framebuffer, e.g. ``ctx.screen``).

        ``view`` is a :class:`CameraView`; ``marble_position`` (m) and ``marble_rotation`` (3, 3) place
        the marble; ``hud_lines`` are text lines for the top-left corner; ``debug`` an optional
        :class:`DebugOverlay`.  With :attr:`antialiasing` ``"fxaa"`` the world is drawn into a texture first and
        anti-aliased into ``fbo`` (:class:`~marbellous.render.fxaa.Fxaa`); the debug overlay and the HUD are
        drawn last, sharp.
        """
        ctx = self.ctx
        w, h = viewport[2:] if viewport else fbo.size
        if self.fxaa is None:
            vp = self._draw_world(fbo, viewport, (w, h), view, marble_position, marble_rotation)
        else:
            vp = self._draw_world(self.fxaa.frame((w, h)), None, (w, h), view, marble_position, marble_rotation)
            fbo.use()
            if viewport:
                ctx.viewport = viewport
            self.fxaa.draw()
        if debug is not None:
            self._draw_debug(vp, debug)
        if hud_lines:
            ctx.disable(moderngl.DEPTH_TEST)
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            self.hud.draw(list(hud_lines), (w, h))
        ctx.disable(moderngl.BLEND)

    def _draw_world(self, fbo, viewport, size, view, marble_position, marble_rotation):
        """Everything but the overlays into ``fbo`` (in ``viewport``, None: all of it) of ``size`` (width, height)
        pixels; leaves blending on.  Returns the camera's view-projection matrix."""
        ctx = self.ctx
        w, h = size
        focus = np.asarray(view.target, np.float64)
        marble_model = _f32(model_matrix(marble_position, marble_rotation, self.marble_radius))
        statics = self.items + self.poles
        if self.flag is not None:
            self._write_vertices(self.flag_vertices, self.flag.cloth.positions, self.flag.cloth.triangles)
            statics = statics + [self.flag_item]
        for body, triangles, item, vbo in self.soft:
            self._write_vertices(vbo, body.positions, triangles)
            statics = statics + [item]

        # shadow pass: an orthographic sun camera 60 m across around the focus
        light_view = look_at(focus + SUN * 60.0, focus, (0.0, 0.0, 1.0) if abs(SUN[1]) > 0.99 else (0, 1, 0))
        light_vp = orthographic(30.0, 30.0, 1.0, 160.0) @ light_view
        self.shadow_fbo.use()
        self.shadow_fbo.clear(depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        self.depth["u_light_view_proj"].write(_f32(light_vp))
        self.depth["u_model"].write(_IDENTITY)
        for _vao, dvao, _c, _p in statics:
            dvao.render()
        self.depth["u_model"].write(marble_model)
        self.marble[1].render()

        # main pass
        fbo.use()
        if viewport:
            ctx.viewport = viewport
        fbo.clear(*SKY, 1.0, depth=1.0)
        proj = perspective(view.fov, w / h, 0.05, 400.0)
        view_m = look_at(view.eye, view.target)
        vp = proj @ view_m
        frame_uniforms = {"u_view_proj": _f32(vp), "u_light_view_proj": _f32(light_vp),
                          "u_sun": np.asarray(SUN, np.float32).tobytes(),
                          "u_eye": np.asarray(view.eye, np.float32).tobytes(),
                          "u_color2": np.asarray(MARBLE_COLOR2, np.float32).tobytes(),
                          "u_shadow": np.int32(0).tobytes()}
        for program in self.scenes.values():
            for name, value in frame_uniforms.items():
                uniform = program.get(name, None)   # (a pattern's program may not use it)
                if uniform is not None:
                    uniform.write(value)
        self.shadow_tex.use(0)
        self._draw(self.items + self.poles + [item for _, _, item, _ in self.soft], _IDENTITY)
        if self.flag is not None:
            self._draw([self.flag_item], _IDENTITY)
        self._draw([self.marble], marble_model)

        # the flag: an upright billboard above the goal
        rot = billboard_y_matrix(self.flag_top, view.eye)
        flag_model = model_matrix(self.flag_top - [0.0, 1.0, 0.0], rot)
        self.textured["u_mvp"].write(_f32(vp @ flag_model))
        self.textured["u_wave"].value = 1.0
        self.flag_tex.use(1)
        self.textured["u_tex"].value = 1
        self.flag_vao.render()

        # translucent goal box
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self._draw([self.goal_box], _IDENTITY, alpha=0.25)
        self._draw(self.water, _IDENTITY, alpha=0.35)
        return vp

    def _draw(self, items, model, alpha=1.0):
        """Draw ``items`` (draw items) placed by ``model`` (uniform bytes, :func:`_f32`) with opacity ``alpha``."""
        for vao, _d, color, program in items:
            program["u_model"].write(model)
            program["u_alpha"].value = alpha
            program["u_color"].value = color
            vao.render()

    def _draw_debug(self, vp, debug):
        rows = []
        if debug.grid:
            if self._grid_lines is None:
                self._grid_lines = _grid_line_rows(self.level, self.grid_cell)
            rows.append(self._grid_lines)
        pts = np.asarray(debug.points, np.float64).reshape(-1, 3)
        nrm = np.asarray(debug.normals, np.float64).reshape(-1, 3)
        if len(pts):
            seg = np.empty((2 * len(pts), 6))
            seg[0::2, :3], seg[1::2, :3] = pts, pts + 1.0 * nrm
            seg[:, 3:] = (1.0, 0.9, 0.1)
            rows.append(seg)
        if not rows:
            return
        data = np.concatenate(rows).astype(np.float32).tobytes()
        if len(data) > self.line_vbo.size:
            self.line_vbo.orphan(len(data))
        self.line_vbo.write(data)
        self.lines["u_view_proj"].write(_f32(vp))
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.line_vao.render(moderngl.LINES, vertices=len(data) // 24)
        self.ctx.enable(moderngl.DEPTH_TEST)

    # ------------------------------------------------------------------ offscreen
    @in_own_context
    def render_to_array(self, view, marble_position, marble_rotation, hud_lines=(), debug=None):
        """Render offscreen at :attr:`size` and return the image as a (height, width, 3) uint8 array
        (top row first)."""
        self.draw_offscreen(view, marble_position, marble_rotation, hud_lines, debug)
        return self.read_offscreen()

    @in_own_context
    def draw_offscreen(self, view, marble_position, marble_rotation, hud_lines=(), debug=None):
        """Submit one frame (as :meth:`render`) to the offscreen target of :attr:`size`; the GPU may still be
        drawing it when this returns.  :meth:`read_offscreen` reads it."""
        if self._offscreen is None:
            self._offscreen = Offscreen(self.ctx, self.size, offscreen_samples(self.antialiasing))
        self.render(self._offscreen.draw, view, marble_position, marble_rotation, hud_lines, debug)

    @in_own_context
    def read_offscreen(self):
        """The frame last drawn by :meth:`draw_offscreen` as a (height, width, 3) uint8 array (top row first)."""
        return self._offscreen.read()


def _pole_triangles(foot, top, radius):
    """``(positions, normals)`` of an upright pole from ``foot`` to ``top`` (m, straight above it) of ``radius``
    (m): a capsule of :data:`POLE_SEGMENTS` sides."""
    foot, top = np.asarray(foot, np.float64), np.asarray(top, np.float64)
    pos, nrm = capsule_triangles(float(radius), 0.5 * float(top[1] - foot[1]), POLE_SEGMENTS)
    return (pos + 0.5 * (foot + top)).astype(np.float32), nrm


def _goal_box_triangles(center, half_extents):
    import trimesh

    m = trimesh.creation.box(extents=2.0 * np.asarray(half_extents))
    return m.vertices + center, m.faces


def _grid_line_rows(level, cell):
    """Line segments (rows ``[x, y, z, r, g, b]``) outlining the level's occupied 2D grid cells."""
    cells, tops, origin, size = grid_cells(level, cell)
    rows = np.empty((8 * len(cells), 6))
    for k, ((i, j), y) in enumerate(zip(cells, tops)):
        x0, z0 = origin + np.array([i, j]) * size
        c = [[x0, z0], [x0 + size, z0], [x0 + size, z0 + size], [x0, z0 + size]]
        for e in range(4):
            a, b = c[e], c[(e + 1) % 4]
            rows[8 * k + 2 * e] = (a[0], y + 0.02, a[1], 0.1, 0.9, 1.0)
            rows[8 * k + 2 * e + 1] = (b[0], y + 0.02, b[1], 0.1, 0.9, 1.0)
    return rows
