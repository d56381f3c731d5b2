"""OpenGL contexts: headless through EGL (no display, no GPU needed with Mesa's llvmpipe)."""
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
