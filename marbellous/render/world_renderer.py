"""Drawing any World with moderngl: lit, shadowed bodies, debug overlays and a text line, into a window
or offscreen.

A frame asks each layer of the drawable registry (``drawables.py``) for its draw lists, then draws:
a shadow map from the sun over the region the camera looks at; the opaque solids, the surfaces (cloth) and
the spheres (particles), lit and shadowed; lines in the scene (particle networks); translucent solids
(sensors); lines and dots over everything; the HUD text.  By default an FXAA pass (``fxaa.py``) smooths the edges
before the lines, the dots and the text are drawn, which stay sharp (the lines in the scene still hidden by what
is in front of them).  Distances that depend on the scale of the world (the drawn extent of planes, fog, the grid
cell, the clip planes, the shadow region) follow the camera's distance to its target, so a 5 cm marble and a
500 m terrain both read.
"""
import math
from collections import defaultdict

import moderngl
import numpy as np

from . import palette
from . import world_shaders as glsl
from .antialiasing import check_antialiasing, offscreen_samples
from .context import in_own_context
from .draw_lists import Lines, Points, Solids, Spheres, Surface, WorldFrame
from .drawables import DRAWABLES, check_layers, default_layers
from .fxaa import Fxaa
from .hud import HudText
from .offscreen import Offscreen
from .mesh_cache import MeshCache
from .shadow_map import shadow_map
from .transforms import look_at, orthographic, perspective

#: Unit vector towards the sun.
SUN = np.array([0.45, 0.85, 0.30]) / np.linalg.norm([0.45, 0.85, 0.30])
#: Fog starts at this many camera distances from the eye and is complete this many further on.
FOG_START, FOG_LENGTH = 3.0, 6.0
#: The far clip plane, in camera distances; the near one is this many times closer.
FAR, NEAR_RATIO = 10.0, 5000.0
#: Floats per vertex of the overlay buffers: position, colour, width or size.
_OVERLAY_FLOATS = 7
#: Floats per sphere of the sphere buffer: centre, radius, colour.
_SPHERE_FLOATS = 7
#: Floats per vertex of the surface buffer: position, normal, colour, pattern code.
_SURFACE_FLOATS = 10


def _f32(m):
    """A (4, 4) matrix as column-major float32 bytes for a GLSL ``mat4``."""
    return np.ascontiguousarray(np.asarray(m, np.float64).T, dtype=np.float32).tobytes()


def _write(buffer, raw):
    """Write the bytes ``raw`` to the start of the moderngl ``buffer``, growing it (at least twice) first
    if they do not fit."""
    if len(raw) > buffer.size:
        buffer.orphan(max(len(raw), 2 * buffer.size))
    buffer.write(raw)


def grid_cell(distance):
    """The grid cell (m) drawn on static bodies seen from ``distance`` (m): a power of ten near a
    tenth of it."""
    return 10.0 ** round(math.log10(distance / 8.0))


class WorldRenderer:
    """Draws worlds with moderngl into any framebuffer.

    ``ctx`` is a moderngl context (headless EGL or a window's); ``size`` (width, height) in pixels of
    the offscreen target of :meth:`render_to_array`; ``antialiasing`` one of
    :data:`~marbellous.render.antialiasing.ANTIALIASING` (``"fxaa"`` a pass over each frame, ``"msaa"`` multisampling,
    offscreen only, ``"none"``); ``shadow_size`` the side of the shadow map in texels.
    """

    @in_own_context
    def __init__(self, ctx, size=(640, 360), *, antialiasing="fxaa", shadow_size=1024):
        check_antialiasing(antialiasing)
        self.ctx = ctx
        self.size = tuple(int(s) for s in size)
        self.solid = ctx.program(vertex_shader=glsl.SOLID_VS, fragment_shader=glsl.SOLID_FS)
        self.depth = ctx.program(vertex_shader=glsl.DEPTH_VS, fragment_shader=glsl.DEPTH_FS)
        self.lines = ctx.program(vertex_shader=glsl.LINES_VS, geometry_shader=glsl.LINES_GS,
                                 fragment_shader=glsl.LINES_FS)
        self.points = ctx.program(vertex_shader=glsl.POINTS_VS, geometry_shader=glsl.POINTS_GS,
                                  fragment_shader=glsl.POINTS_FS)
        self.spheres = ctx.program(vertex_shader=glsl.SPHERES_VS, geometry_shader=glsl.SPHERES_GS,
                                   fragment_shader=glsl.SPHERES_FS)
        self.spheres_depth = ctx.program(vertex_shader=glsl.SPHERES_DEPTH_VS, geometry_shader=glsl.SPHERES_DEPTH_GS,
                                         fragment_shader=glsl.SPHERES_DEPTH_FS)
        self.meshes = MeshCache(ctx, self.solid, self.depth)
        self.shadow_tex, self.shadow_fbo = shadow_map(ctx, shadow_size)
        self.overlay_vbo = ctx.buffer(reserve=1024 * _OVERLAY_FLOATS * 4, dynamic=True)
        layout = (self.overlay_vbo, "3f 3f 1f", "in_pos", "in_color")
        self.lines_vao = ctx.vertex_array(self.lines, [layout + ("in_width",)])
        self.points_vao = ctx.vertex_array(self.points, [layout + ("in_size",)])
        self.sphere_vbo = ctx.buffer(reserve=1024 * _SPHERE_FLOATS * 4, dynamic=True)
        self.spheres_vao, self.spheres_depth_vao = self._sphere_arrays()
        self.sphere_count = 0
        self.surface_vbo = ctx.buffer(reserve=1024 * _SURFACE_FLOATS * 4, dynamic=True)
        self.surface_ibo = ctx.buffer(reserve=1024 * 3 * 4, dynamic=True)
        self.surface_vao, self.surface_depth_vao = self._surface_arrays()
        self.surface_count = 0
        self.hud = HudText(ctx)
        self.antialiasing, self.shadow_size = antialiasing, shadow_size
        self.fxaa = Fxaa(ctx) if antialiasing == "fxaa" else None
        self._offscreen = None

    # ------------------------------------------------------------------ drawing
    def render(self, fbo, world, view, *, layers=None, hud_lines=(), viewport=None):
        """Draw ``world`` seen from ``view`` (a :class:`~marbellous.render.view.CameraView`) into ``fbo``
        (a moderngl framebuffer, e.g. ``ctx.screen``), within ``viewport`` (x, y, width, height pixels;
        None: all of ``fbo``).

        ``layers`` names the drawables to draw (None: those shown by default, see ``drawables.py``);
        ``hud_lines`` are text lines for the top-left corner.  With :attr:`antialiasing` ``"fxaa"`` the scene is
        drawn into the FXAA pass's frame first and anti-aliased into ``fbo``; the lines (in the scene and over
        everything: contacts, normals, boxes), the dots and the HUD are drawn after it, sharp.
        """
        layers = default_layers() if layers is None else check_layers(layers)
        ctx = self.ctx
        w, h = viewport[2:] if viewport else fbo.size
        eye = np.asarray(view.eye, np.float64)
        target = np.asarray(view.target, np.float64)
        distance = max(float(np.linalg.norm(eye - target)), 1e-6)
        frame = WorldFrame(world, target, distance)
        solids, spheres, surfaces, lines, points = [], [], [], [], []
        kinds = {Solids: solids, Spheres: spheres, Surface: surfaces, Lines: lines, Points: points}
        for name, drawable in DRAWABLES.items():
            if name in layers:
                for item in drawable.draw(frame):
                    kinds[type(item)].append(item)
        opaque, translucent = self._upload(solids)
        self._upload_spheres(spheres, eye)
        self._upload_surfaces(surfaces)
        scene_lines = [x for x in lines if x.in_scene]
        lines = [x for x in lines if not x.in_scene]

        vp = perspective(view.fov, w / h, FAR * distance / NEAR_RATIO, FAR * distance) @ look_at(eye, target)
        half = 1.5 * distance * math.tan(view.fov / 2.0) * max(w / h, 1.0)
        light_view = look_at(target + 4.0 * half * SUN, target, (0.0, 0.0, 1.0))
        light_vp = orthographic(half, half, 0.0, 8.0 * half) @ light_view
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        self.shadow_fbo.use()
        self.shadow_fbo.clear(depth=1.0)
        self.depth["u_light_view_proj"].write(_f32(light_vp))
        for m in opaque:
            m.depth.render(instances=m.count)
        if self.surface_count:
            self.surface_depth_vao.render(vertices=self.surface_count, instances=1)
        if self.sphere_count:
            d = self.spheres_depth
            d["u_light_view_proj"].write(_f32(light_vp))
            d["u_light_right"].value = tuple(light_view[0, :3])
            d["u_light_up"].value = tuple(light_view[1, :3])
            self.spheres_depth_vao.render(moderngl.POINTS, vertices=self.sphere_count)

        scene, scene_viewport = (fbo, viewport) if self.fxaa is None else (self.fxaa.frame((w, h)), None)
        scene.use()
        if scene_viewport:
            ctx.viewport = scene_viewport
        scene.clear(*palette.BACKGROUND, 1.0, depth=1.0)
        s = self.solid
        s["u_view_proj"].write(_f32(vp))
        s["u_light_view_proj"].write(_f32(light_vp))
        s["u_sun"].value = tuple(SUN)
        s["u_eye"].value = tuple(eye)
        s["u_grid"].value = grid_cell(distance)
        s["u_fog"].value = (FOG_START * distance, FOG_LENGTH * distance)
        s["u_background"].value = palette.BACKGROUND
        self.shadow_tex.use(0)
        s["u_shadow"].value = 0
        s["u_alpha"].value = 1.0
        for m in opaque:
            m.solid.render(instances=m.count)
        if self.surface_count:
            self.surface_vao.render(vertices=self.surface_count, instances=1)
        if self.sphere_count:
            p = self.spheres
            p["u_view_proj"].write(_f32(vp))
            p["u_light_view_proj"].write(_f32(light_vp))
            p["u_pixel"].value = 2.0 * math.tan(view.fov / 2.0) / h
            p["u_sun"].value = tuple(SUN)
            p["u_eye"].value = tuple(eye)
            p["u_fog"].value = (FOG_START * distance, FOG_LENGTH * distance)
            p["u_background"].value = palette.BACKGROUND
            p["u_shadow"].value = 0
            p["u_alpha"].value = 1.0
            self.spheres_vao.render(moderngl.POINTS, vertices=self.sphere_count)
        line_parts = [[(x.segments.reshape(-1, 3), np.repeat(x.colors, 2, axis=0), x.width) for x in group]
                      for group in (scene_lines, lines)]
        self.lines["u_behind"].value = False
        if self.fxaa is None:
            self._overlay(self.lines, self.lines_vao, moderngl.LINES, vp, (w, h), line_parts[0])
        if translucent:
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            scene.depth_mask = False
            for alpha, m in translucent:
                s["u_alpha"].value = alpha
                m.solid.render(instances=m.count)
            scene.depth_mask = True
            ctx.disable(moderngl.BLEND)
        if self.fxaa is not None:
            fbo.use()
            if viewport:
                ctx.viewport = viewport
            self.fxaa.draw()
            # the lines in the scene (a net's edges) are a pixel or two wide: FXAA would smear them into what they
            # cross (a net's particles, as thin) and both would lose their colour, so they come after it, hidden
            # where the scene's depth is nearer (over translucent solids, then, not blended under them)
            scene.depth_attachment.use(4)
            self.lines["u_depth"].value = 4
            self.lines["u_behind"].value = True
            self._overlay(self.lines, self.lines_vao, moderngl.LINES, vp, (w, h), line_parts[0])
            self.lines["u_behind"].value = False

        ctx.disable(moderngl.DEPTH_TEST)
        self._overlay(self.lines, self.lines_vao, moderngl.LINES, vp, (w, h), line_parts[1])
        self._overlay(self.points, self.points_vao, moderngl.POINTS, vp, (w, h),
                      [(x.positions, x.colors, x.size) for x in points])
        if hud_lines:
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            self.hud.draw(list(hud_lines), (w, h))
            ctx.disable(moderngl.BLEND)

    def _upload(self, solids):
        """Write the instances of ``solids`` (merged by mesh and opacity) to their GPU meshes; returns
        the opaque meshes and the translucent ``(alpha, mesh)`` pairs."""
        groups = defaultdict(list)
        for item in solids:
            groups[(item.mesh.key, item.alpha)].append(item)
        opaque, translucent = [], []
        for (_key, alpha), items in groups.items():
            m = self.meshes.get(items[0].mesh, alpha)
            m.write(np.concatenate([x.models for x in items]), np.concatenate([x.colors for x in items]),
                    np.concatenate([x.patterns for x in items]))
            if alpha >= 1.0:
                opaque.append(m)
            else:
                translucent.append((alpha, m))
        self.meshes.keep_only(set(groups))
        return opaque, translucent

    def _sphere_arrays(self):
        """The vertex arrays of the sphere buffer for the lit and the shadow programs."""
        lit = self.ctx.vertex_array(self.spheres, [(self.sphere_vbo, "3f 1f 3f", "in_center", "in_radius",
                                                    "in_color")])
        depth = self.ctx.vertex_array(self.spheres_depth, [(self.sphere_vbo, "3f 1f 12x", "in_center", "in_radius")])
        return lit, depth

    def _upload_spheres(self, spheres, eye):
        """Write the centres, radii and colours of every :class:`Spheres` to the sphere buffer, nearest to
        ``eye`` (m) first (so the early depth test skips shading the hidden ones)."""
        n = sum(len(x.centers) for x in spheres)
        self.sphere_count = n
        if not n:
            return
        rows = np.empty((n, _SPHERE_FLOATS), np.float32)
        k = 0
        for x in spheres:
            m = len(x.centers)
            rows[k:k + m, 0:3] = x.centers
            rows[k:k + m, 3] = x.radii
            rows[k:k + m, 4:7] = x.colors
            k += m
        offset = rows[:, 0:3] - eye.astype(np.float32)
        _write(self.sphere_vbo, rows[np.argsort(np.einsum("ij,ij->i", offset, offset))].tobytes())

    def _surface_arrays(self):
        """The indexed vertex arrays of the surface buffers for the solids' lit and shadow programs: the
        vertices carry their colour and pattern, and one instance of the identity places them (they are in
        world space already)."""
        identity = self.ctx.buffer(np.eye(4, dtype=np.float32).tobytes())
        lit = self.ctx.vertex_array(self.solid, [(self.surface_vbo, "3f 3f 4f", "in_pos", "in_normal", "in_color"),
                                                 (identity, "16f/i", "in_model")],
                                    index_buffer=self.surface_ibo, index_element_size=4)
        depth = self.ctx.vertex_array(self.depth, [(self.surface_vbo, "3f 28x", "in_pos"),
                                                   (identity, "16f/i", "in_model")],
                                      index_buffer=self.surface_ibo, index_element_size=4)
        return lit, depth

    def _upload_surfaces(self, surfaces):
        """Write the vertices (position, normal, colour, pattern) and the triangles of every :class:`Surface`
        to the surface buffers, as one mesh."""
        n = sum(len(x.positions) for x in surfaces)
        self.surface_count = 3 * sum(len(x.triangles) for x in surfaces)
        if not self.surface_count:
            return
        rows = np.empty((n, _SURFACE_FLOATS), np.float32)
        indices = []
        k = 0
        for x in surfaces:
            m = len(x.positions)
            rows[k:k + m, 0:3] = x.positions
            rows[k:k + m, 3:6] = x.normals
            rows[k:k + m, 6:9] = x.color
            rows[k:k + m, 9] = x.pattern
            indices.append(np.asarray(x.triangles, np.int64).reshape(-1) + k)
            k += m
        _write(self.surface_vbo, rows.tobytes())
        _write(self.surface_ibo, np.concatenate(indices).astype(np.uint32).tobytes())

    def _overlay(self, program, vao, mode, vp, size, parts):
        """Draw ``parts`` ((K, 3) positions, (K, 3) colours, pixels) with ``program`` as ``mode`` primitives."""
        if not parts:
            return
        rows = np.concatenate([np.column_stack([p, c, np.full(len(p), px)]) for p, c, px in parts])
        _write(self.overlay_vbo, rows.astype(np.float32).tobytes())
        program["u_view_proj"].write(_f32(vp))
        program["u_viewport"].value = tuple(float(v) for v in size)
        vao.render(mode, vertices=len(rows))

    # ------------------------------------------------------------------ offscreen
    @in_own_context
    def render_to_array(self, world, view, *, layers=None, hud_lines=()):
        """Render offscreen at :attr:`size` (see :meth:`render`) and return the image as a
        (height, width, 3) uint8 array, top row first."""
        self.draw_offscreen(world, view, layers=layers, hud_lines=hud_lines)
        return self.read_offscreen()

    @in_own_context
    def draw_offscreen(self, world, view, *, layers=None, hud_lines=()):
        """Submit one frame (as :meth:`render`) to the offscreen target of :attr:`size`; the GPU may still be
        drawing it when this returns.  :meth:`read_offscreen` reads it."""
        if self._offscreen is None:
            self._offscreen = Offscreen(self.ctx, self.size, offscreen_samples(self.antialiasing))
        self.render(self._offscreen.draw, world, view, layers=layers, hud_lines=hud_lines)

    @in_own_context
    def read_offscreen(self):
        """The frame last drawn by :meth:`draw_offscreen` as a (height, width, 3) uint8 array, top row first."""
        return self._offscreen.read()
