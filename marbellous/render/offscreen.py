"""An offscreen target of the renderers: a framebuffer to draw into (multisampled or not) and its read-back to
a NumPy image."""
import numpy as np


class Offscreen:
    """A colour and depth target of ``size`` (width, height) pixels in the moderngl ``ctx``, with ``samples``
    per pixel (at most the context's; 1: none).  Draw into :attr:`draw`; :meth:`read` returns the picture."""

    def __init__(self, ctx, size, samples=1):
        self.ctx, self.size = ctx, tuple(int(s) for s in size)
        self.resolve = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size)],
                                       depth_attachment=ctx.depth_renderbuffer(self.size))
        samples = min(samples, ctx.max_samples)
        self.draw = self.resolve if samples <= 1 else ctx.framebuffer(
            color_attachments=[ctx.renderbuffer(self.size, samples=samples)],
            depth_attachment=ctx.depth_renderbuffer(self.size, samples=samples))
        self._pixels = np.empty((self.size[1], self.size[0], 3), np.uint8)

    def read(self):
        """What was drawn into :attr:`draw` (resolved, if multisampled) as a new (height, width, 3) uint8 array,
        top row first."""
        if self.resolve is not self.draw:
            self.ctx.copy_framebuffer(self.resolve, self.draw)
        # read into a kept array, then one flipped copy: a fresh 2.7 MB buffer per 1280 x 720 frame, and a
        # second for the copy, cost ~3 ms more in page faults
        self.resolve.read_into(self._pixels, components=3, alignment=1)
        return self._pixels[::-1].copy()
