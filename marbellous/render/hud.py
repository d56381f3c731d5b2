"""The head-up display: lines of text drawn with Pillow into a texture and blended over the frame."""
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .transforms import orthographic

_HUD_VS = """
#version 330
uniform mat4 u_mvp;
in vec3 in_pos;
in vec2 in_uv;
out vec2 v_uv;
void main() { v_uv = in_uv; gl_Position = u_mvp * vec4(in_pos, 1.0); }
"""
_HUD_FS = """
#version 330
uniform sampler2D u_tex;
in vec2 v_uv;
out vec4 f_color;
void main() { f_color = texture(u_tex, v_uv); }
"""


class HudText:
    """Draws lines of text in the top-left corner of a frame.

    ``ctx`` is the moderngl context; the HUD compiles its own textured-quad program.  The texture is
    rebuilt only when the text changes.
    """

    def __init__(self, ctx):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=_HUD_VS, fragment_shader=_HUD_FS)
        self._text, self._tex, self._tex_size = None, None, (1, 1)
        self.font_size = None
        self.vbo = ctx.buffer(reserve=6 * 5 * 4)
        self.vao = ctx.vertex_array(self.program, [(self.vbo, "3f 2f", "in_pos", "in_uv")])

    def set_font_size(self, size):
        """Use Pillow's scalable default font at ``size`` pixels."""
        if size != self.font_size:
            self.font_size = size
            self.font = ImageFont.load_default(size=size)
            self.line_height = size + size // 3
            self._text = None

    def image(self, lines):
        """The HUD as an RGBA Pillow image: white text with a dark outline on a translucent panel."""
        width = max(int(self.font.getlength(t)) for t in lines) + 20
        height = self.line_height * len(lines) + 12
        img = Image.new("RGBA", (width, height), (10, 14, 24, 120))
        draw = ImageDraw.Draw(img)
        for k, t in enumerate(lines):
            draw.text((10, 6 + k * self.line_height), t, font=self.font, fill=(255, 255, 255, 255),
                      stroke_width=max(1, self.font_size // 9), stroke_fill=(0, 0, 0, 255))
        return img

    def draw(self, lines, frame_size):
        """Blend ``lines`` over the current framebuffer of ``frame_size`` (width, height) pixels."""
        w, h = frame_size
        self.set_font_size(max(10, min(26, h // 22)))
        text = "\n".join(lines)
        if text != self._text:
            img = self.image(lines)
            if self._tex is not None:
                self._tex.release()
            self._tex = self.ctx.texture(img.size, 4, img.tobytes())
            self._text, self._tex_size = text, img.size
        tw, th = self._tex_size
        x0, y0 = 8.0, h - 8.0 - th
        quad = np.array([[x0, y0, 0, 0, 1], [x0 + tw, y0, 0, 1, 1], [x0 + tw, y0 + th, 0, 1, 0],
                         [x0, y0, 0, 0, 1], [x0 + tw, y0 + th, 0, 1, 0], [x0, y0 + th, 0, 0, 0]], np.float32)
        self.vbo.write(quad.tobytes())
        pixels = orthographic(w / 2, h / 2, -1.0, 1.0)
        pixels[:2, 3] = -1.0
        self.program["u_mvp"].write(np.ascontiguousarray(pixels.T, np.float32).tobytes())
        self._tex.use(2)
        self.program["u_tex"].value = 2
        self.vao.render()
