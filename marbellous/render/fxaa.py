"""Fast approximate anti-aliasing (FXAA, after Timothy Lottes' FXAA 3 "console" pass): a full-screen pass that
blurs a drawn frame along its edges only.

Where the luma of a pixel and its four diagonal neighbours spans enough, the pixel is on an edge, whose
direction is across the corners' luma gradient; the pass replaces the pixel by the mean of two bilinear samples
a sixth of that direction's span either side.  (FXAA 3 also tries a wider mean of four samples; on Mesa's
llvmpipe each bilinear sample costs about a sixth of a millisecond per 640 x 360 frame, and the near pair alone
smooths the game's edges nearly as well.)  At 640 x 360 on llvmpipe the pass costs about 2 ms, 4x multisampling
about 8 ms (four samples per pixel rasterised, then resolved).
"""
import moderngl

_FXAA_VS = """
#version 330
// one triangle over the whole viewport: (-1, -1), (3, -1), (-1, 3)
void main() { gl_Position = vec4(vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0, 0.0, 1.0); }
"""
_FXAA_FS = """
#version 330
uniform sampler2D u_frame;
out vec4 f_color;
const vec3 LUMA = vec3(0.299, 0.587, 0.114);
const float EDGE_MIN = 1.0 / 16.0;      // luma range (0-1) below which a pixel is left alone
const float EDGE_RELATIVE = 1.0 / 8.0;  // ... or below this share of its brightest neighbour's luma
const float REDUCE_MUL = 1.0 / 8.0, REDUCE_MIN = 1.0 / 128.0, SPAN_MAX = 8.0;  // texels along the edge

// the frame's texel at p, clamped to the frame (a fetch outside it is undefined)
vec3 at(ivec2 p) { return texelFetch(u_frame, clamp(p, ivec2(0), textureSize(u_frame, 0) - 1), 0).rgb; }

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 m = texelFetch(u_frame, px, 0).rgb;
    float nw = dot(at(px + ivec2(-1, 1)), LUMA);
    float ne = dot(at(px + ivec2(1, 1)), LUMA);
    float sw = dot(at(px + ivec2(-1, -1)), LUMA);
    float se = dot(at(px + ivec2(1, -1)), LUMA);
    float lm = dot(m, LUMA);
    float lo = min(lm, min(min(nw, ne), min(sw, se)));
    float hi = max(lm, max(max(nw, ne), max(sw, se)));
    // along the edge: perpendicular to the luma gradient of the four corners, scaled so that its shorter
    // component is about one texel, at most SPAN_MAX texels long
    vec2 dir = vec2(-((nw + ne) - (sw + se)), (nw + sw) - (ne + se));
    float reduce = max((nw + ne + sw + se) * 0.25 * REDUCE_MUL, REDUCE_MIN);
    vec2 texel = 1.0 / vec2(textureSize(u_frame, 0));
    dir = clamp(dir / (min(abs(dir.x), abs(dir.y)) + reduce), -SPAN_MAX, SPAN_MAX) * texel;
    vec2 uv = gl_FragCoord.xy * texel;
    vec3 along = 0.5 * (texture(u_frame, uv - dir / 6.0).rgb + texture(u_frame, uv + dir / 6.0).rgb);
    // (a select, not a branch: llvmpipe runs both sides of a branch anyway)
    f_color = vec4(hi - lo < max(EDGE_MIN, hi * EDGE_RELATIVE) ? m : along, 1.0);
}
"""


class Fxaa:
    """The FXAA pass of a moderngl ``ctx``: a frame is drawn into :meth:`frame` (a colour texture and a depth
    buffer), then :meth:`draw` draws it anti-aliased into the current framebuffer, pixel for pixel."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=_FXAA_VS, fragment_shader=_FXAA_FS)
        self.vao = ctx.vertex_array(self.program, [])
        self._frame = None

    def frame(self, size):
        """The framebuffer to draw a frame of ``size`` (width, height) pixels into (its depth attachment a texture);
        made again when the size changes."""
        if self._frame is None or self._frame.size != tuple(size):
            if self._frame is not None:
                for attachment in (*self._frame.color_attachments, self._frame.depth_attachment):
                    attachment.release()
                self._frame.release()
            color = self.ctx.texture(size, 4)
            color.filter = (moderngl.LINEAR, moderngl.LINEAR)
            color.repeat_x = color.repeat_y = False
            # (depth as a texture, read as plain values: lines drawn after the pass test it in their shader)
            depth = self.ctx.depth_texture(size)
            depth.compare_func = ""
            self._frame = self.ctx.framebuffer(color_attachments=[color], depth_attachment=depth)
        return self._frame

    def draw(self):
        """Draw :meth:`frame`'s colour anti-aliased into the current framebuffer, whose viewport must be the
        frame's size; depth test and blending are left off."""
        self._frame.color_attachments[0].use(3)
        self.program["u_frame"].value = 3
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        self.vao.render(moderngl.TRIANGLES, vertices=3)
