"""How the renderers smooth edges: the modes both take (``antialiasing=``) and what each asks of the offscreen
target."""

#: ``"fxaa"`` a post-process pass over each frame (:class:`~marbellous.render.fxaa.Fxaa`), ``"msaa"``
#: :data:`MSAA_SAMPLES` samples per pixel offscreen (about twice the frame's cost on llvmpipe), ``"none"``.
ANTIALIASING = ("fxaa", "msaa", "none")
#: Samples per pixel of ``"msaa"`` (llvmpipe takes as long over 2 as over 4).
MSAA_SAMPLES = 4


def check_antialiasing(mode):
    """``ValueError`` unless ``mode`` is one of :data:`ANTIALIASING`."""
    if mode not in ANTIALIASING:
        raise ValueError(f"antialiasing must be one of {', '.join(ANTIALIASING)}, got {mode!r}")


def offscreen_samples(mode):
    """Samples per pixel of the offscreen target for antialiasing ``mode``."""
    return MSAA_SAMPLES if mode == "msaa" else 1
