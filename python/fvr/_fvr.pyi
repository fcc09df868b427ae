"""Type stubs of the extension module ``fvr._fvr`` (re-exported by ``fvr``)."""

from os import PathLike
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

Colour = Union[float, Sequence[float], str]
Light = Union[str, Tuple[Sequence[float], Colour]]

def load(spec: str) -> Tuple[npt.NDArray[np.float32], Tuple[float, float, float]]:
    """Load whatever the CLI's VOLUME takes: a file (NRRD, NIfTI, DICOM
    folder, ...), a data set name (``brainsmall``, ``ct-head``,
    ``mri-head``) or a phantom (``gaussians@64``, ``sphere@64``,
    ``teapot@64``).

    Returns ``(volume, spacing)``: a C-contiguous float32 array of shape
    ``(z, y, x)`` that owns the loaded samples (no copy), and the voxel
    spacing ``(dz, dy, dx)`` in mm, in the array's axis order.

    Raises FileNotFoundError (no such file or name), OSError (a file that
    cannot be read or decoded), MemoryError (beyond the memory limit),
    ValueError (a bad phantom parameter).
    """

def set_max_memory(limit: Union[int, str]) -> None:
    """The CLI's ``--max-memory``: bytes, or text such as ``"4G"``. Raises
    or lowers the default ceiling of 2.75 GiB, never above the machine's
    limits."""

def memory_limit() -> Tuple[int, str]:
    """The bytes a job may hold now and where that limit comes from."""

class Renderer:
    """A volume prepared for rendering: premultiplied, 3D Hartley
    transformed and stored once; each view is then a 2D slice and an
    inverse 2D transform.

    ``volume`` is a 3-D array ``(z, y, x)`` of real numbers (any real
    dtype and memory order: converted to C-contiguous float32 when it is
    not already; complex or object arrays raise TypeError; NaN or infinity
    raises ValueError), or a VOLUME string as ``load`` takes it.
    ``spacing`` is ``(dz, dy, dx)`` in mm (or one number), default 1 mm;
    with a VOLUME string the file's spacing is used unless given.

    Settings left None are the accuracy planner's to choose, exactly as
    ``fvr render`` chooses them without the flags: the cheapest filter,
    grid and precision predicted to reach ``accuracy_db`` (50 dB when not
    given). ``filter`` (nearest, linear, cubic, kb3..kb6), ``oversample``
    (1, 1.25, 1.5, 2) and ``precision`` (f16, f32, f64) fix a choice.

    The scene is part of the preparation (lights need a second spectrum,
    of ``|grad f|``): ``depth_cue`` takes the CLI's text
    (``"linear:1,0.3"``, ``"sine:1,0.3"``, ``"profile:..."``), ``lights``
    a list of ``"X,Y,Z:R,G,B"`` texts or ``((x, y, z), colour)`` pairs,
    ``ambient`` a grey value, ``(r, g, b)`` or ``"R,G,B"`` (default 1
    without lights, 0.2 with). ``ignore_spacing`` renders in voxel units,
    ``pixel_size`` (mm) sets the image's pixel, ``preview_level`` and
    ``adaptive`` (a tolerance in dB) are the CLI's ``--preview-level`` and
    ``--adaptive``.

    Raises ValueError for bad settings, MemoryError when the spectrum would
    not fit the memory limit, and what ``load`` raises for a VOLUME string.
    """

    def __init__(
        self,
        volume: Union[npt.ArrayLike, str],
        spacing: Optional[Union[float, Sequence[float]]] = None,
        *,
        accuracy_db: Optional[float] = None,
        filter: Optional[str] = None,
        oversample: Optional[float] = None,
        precision: Optional[str] = None,
        depth_cue: Optional[str] = None,
        ambient: Optional[Colour] = None,
        lights: Optional[Sequence[Light]] = None,
        ignore_spacing: bool = False,
        pixel_size: Optional[float] = None,
        preview_level: int = 0,
        adaptive: Optional[float] = None,
    ) -> None: ...
    def project(
        self,
        views: npt.ArrayLike,
        up: Optional[npt.ArrayLike] = None,
        size: Optional[Union[int, Tuple[int, int]]] = None,
        out: Optional[npt.NDArray[np.float32]] = None,
    ) -> npt.NDArray[np.float32]:
        """Render views on all cores with the GIL released.

        ``views``: directions ``(B, 3)`` (from the eye into the volume,
        ``(x, y, z)`` with x the volume's last array axis: the CLI's
        ``--dir``), one direction ``(3,)``, or rotations ``(B, 3, 3)``
        whose columns are the camera's right, up and backward axes (the
        view direction is ``-R[:, 2]``; see docs/python.md). ``up``: the
        up hint for directions, one ``(3,)`` or ``(B, 3)``; default
        ``(0, 0, 1)`` as the CLI's. ``size``: ``(height, width)`` or one
        side; default the CLI's, ``default_size`` (the power of two at or
        above the volume's longest side, within the grid).

        Returns float32 ``(B, H, W)`` (``(B, H, W, 3)`` for coloured scenes;
        ``(H, W)`` for one ``(3,)`` direction), row 0 at the top, each image
        bit for bit ``fvr render``'s NRRD of the same view. With ``out``
        (a C-contiguous float32 array of exactly that shape) the images are
        written there and ``out`` is returned.

        Raises ValueError (bad shapes, a zero or parallel direction, a
        size beyond the grid), TypeError (non-numeric input) and
        MemoryError (a batch beyond the memory limit).
        """
    @property
    def report(self) -> dict[str, Any]:
        """The choices, predicted dB, bytes and times: the keys of
        ``fvr render --stats-json`` that describe the preparation, plus
        ``warnings``."""
    @property
    def default_size(self) -> Tuple[int, int]:
        """The default image shape ``(height, width)``."""
    def spectrum(self) -> Tuple[npt.NDArray[Any], float]:
        """A read-only copy of the stored density spectrum, shape
        ``(n, n, n)`` in its storage dtype (float16, float32 or float64),
        ``kx`` fastest in natural Hartley order, and the scale images are
        divided by."""
