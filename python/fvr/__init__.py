"""Frequency-domain volume rendering (Totsuka & Levoy, SIGGRAPH 1993).

Parallel-beam X-ray projections of a volume from its Hartley spectrum: the
volume is transformed once (``Renderer(...)``), then each view is one 2D
slice through the origin and one inverse 2D transform (``Renderer.project``).

    >>> import fvr
    >>> vol, spacing = fvr.load("brainsmall")
    >>> r = fvr.Renderer(vol, spacing)
    >>> imgs = r.project([[1, 0.3, 0.2], [0, 1, 0]])   # (2, H, W) float32

See docs/python.md for the rotation convention, the exceptions and the
examples.
"""

from ._fvr import Renderer, __version__, load, memory_limit, set_max_memory

__all__ = ["Renderer", "load", "memory_limit", "set_max_memory", "__version__"]
