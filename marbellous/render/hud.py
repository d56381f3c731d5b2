"""The head-up display: lines of text drawn with Pillow into a texture and blended over the frame.

Pillow draws each character once (its outline and its fill, as two coverage masks); a line is composed from
those with NumPy.  Drawing the lines with Pillow every time they change took ~1.3 ms, a tenth of a frame,
and the game's timer changes them every frame or two.
"""
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


#: The panel's colour and the text's outline and fill colours (RGBA, 0-255).
PANEL, OUTLINE, FILL = (10, 14, 24, 120), (0, 0, 0, 255), (255, 255, 255, 255)


def _inked():
    """(256, 256, 4) uint8: the colour of a pixel of outline coverage ``o`` and fill coverage ``f`` (0-255) at
    ``[o, f]``: the outline over the panel, then the fill over both, each weighted by its coverage (as Pillow
    draws outlined text)."""
    c = np.arange(256, dtype=np.float64)[:, None, None] / 255.0
    under = np.asarray(PANEL) + c * (np.asarray(OUTLINE) - np.asarray(PANEL))      # by o, (256, 1, 4)
    return (under + c.reshape(1, 256, 1) * (np.asarray(FILL) - under) + 0.5).astype(np.uint8)


_INKED = _inked()


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
            self.stroke = max(1, size // 9)
            self._glyphs = {}
            self._text = None

    def _glyph(self, char):
        """``(masks, (left, top), advance)`` of ``char``: ``masks`` (h, w, 2) uint8 the coverage (0-255) of
        the outlined and the plain glyph on one box, its corner (pixels) from the pen at the line's ascender,
        and how far (pixels) the pen moves on."""
        glyph = self._glyphs.get(char)
        if glyph is None:
            left, top, right, bottom = self.font.getbbox(char, stroke_width=self.stroke)
            masks = []
            for stroke in (self.stroke, 0):
                img = Image.new("L", (max(right - left, 1), max(bottom - top, 1)))
                ImageDraw.Draw(img).text((-left, -top), char, font=self.font, fill=255, stroke_width=stroke,
                                         stroke_fill=255)
                masks.append(np.asarray(img))
            glyph = self._glyphs[char] = (np.stack(masks, axis=-1), (left, top), self.font.getlength(char))
        return glyph

    def image(self, lines):
        """The HUD as an RGBA Pillow image: white text with a dark outline on a translucent panel."""
        widths = [sum(self._glyph(c)[2] for c in t) for t in lines]
        width, height = int(max(widths)) + 20, self.line_height * len(lines) + 12
        masks = np.zeros((height, width, 2), np.uint8)     # outline, fill
        for k, t in enumerate(lines):
            x, y = 10.0, 6 + k * self.line_height
            for c in t:
                glyph, (left, top), advance = self._glyph(c)
                i, j = y + top, int(round(x)) + left
                box = masks[i:i + glyph.shape[0], j:j + glyph.shape[1]]
                np.maximum(box, glyph[:box.shape[0], :box.shape[1]], out=box)
                x += advance
        return Image.fromarray(_INKED[masks[..., 0], masks[..., 1]], "RGBA")

    def draw(self, lines, frame_size):
        """Blend ``lines`` over the current framebuffer of ``frame_size`` (width, height) pixels."""
        w, h = frame_size
        self.set_font_size(max(10, min(26, h // 22)))
        text = "\n".join(lines)
        if text != self._text:
            img = self.image(lines)
            if self._tex is not None and self._tex.size == img.size:
                self._tex.write(img.tobytes())
            else:
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
