"""OpenGL contexts: headless through EGL (no display, no GPU needed with Mesa's llvmpipe); renderers that
make their own context current."""
import functools

import moderngl


def headless_context():
    """A standalone moderngl context through EGL, falling back to the platform default (GLX/WGL)."""
    try:
        return moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as egl_error:  # EGL missing or without a usable device
        try:
            return moderngl.create_standalone_context(require=330)
        except Exception:
            raise RuntimeError(f"no OpenGL 3.3 context: EGL failed with {egl_error}; install libegl1, "
                               "libegl-mesa0 and libgl1-mesa-dri") from None


def in_own_context(method):
    """Decorate a renderer's method (or ``__init__(self, ctx, ...)``) to make the renderer's context current
    first, and leave it current.  Making a context (another renderer's, an environment's) makes that one
    current, and releasing it leaves none: without this, a renderer made earlier would then fail to build
    its shaders, or draw nothing and read back stale or undefined pixels.  (moderngl's ``with ctx:`` is no
    help: leaving it makes no context current at all.)"""
    @functools.wraps(method)
    def call(self, *args, **kwargs):
        (self.ctx if hasattr(self, "ctx") else args[0]).__enter__()
        return method(self, *args, **kwargs)
    return call
