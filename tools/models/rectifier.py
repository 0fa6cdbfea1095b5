"""Bit-true model of :func:`eyestereo.hdl.rectify.rectifier.rectifier`: coordinate warper + fetch and interpolation.

One definition of the arithmetic: the coordinates and flags are the coordinate warper's model
(:func:`eyestereo.tools.models.coordinate_warper.coordinate_warper`, itself the toolbox's fixed-point
evaluator of the calibration), the pixels the fetch/interpolate model
(:mod:`eyestereo.tools.models.fetch_interpolate`) applied to them. The rectified pair has the
calibration's rectified size; the camera images its source size.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from eyestereo.tools.models import coordinate_warper as warper
from eyestereo.tools.models import fetch_interpolate as fi
from eyestereo.tools.models.poly_unit import DEFAULT_FRAC, Calibration, resolve_frac

__all__ = ["check_images", "rectifier", "requests", "stream"]


def check_images(cal: Calibration, left: npt.ArrayLike, right: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The camera images as uint8 arrays of the calibration's source size, else a ValueError saying why."""
    out = []
    for name, img in (("left", left), ("right", right)):
        a = np.asarray(img)
        if a.ndim != 2 or a.dtype != np.uint8:
            raise ValueError(f"{name} image must be a 2-D uint8 (grey) array, got {a.dtype} {a.shape}")
        if a.shape != (cal.source_height, cal.source_width):
            raise ValueError(f"{name} image is {a.shape[1]}x{a.shape[0]}; the calibration was made for "
                             f"{cal.source_width}x{cal.source_height} camera images")
        out.append(a)
    return out[0], out[1]


def rectifier(cal: Calibration, left: npt.ArrayLike, right: npt.ArrayLike,
              frac: int | None = DEFAULT_FRAC) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """The rectified (left, right) images, ``(cal.height, cal.width)`` uint8 each."""
    lf, rt = check_images(cal, left, right)
    frac = resolve_frac(cal, frac)
    return fi.fetch_interpolate(lf, rt, warper.coordinate_warper(cal, frac), frac)


def requests(cal: Calibration, frac: int | None = DEFAULT_FRAC, frames: int = 1) -> dict[str, npt.NDArray[np.int64]]:
    """The fetch-port requests of ``frames`` frames (:func:`eyestereo.tools.models.fetch_interpolate.requests`)."""
    frac = resolve_frac(cal, frac)
    return fi.requests(warper.pairs(cal, frac, frames), frac)


def stream(cal: Calibration, left: npt.ArrayLike, right: npt.ArrayLike,
           frac: int | None = DEFAULT_FRAC) -> dict[str, npt.NDArray[np.int64]]:
    """The rectifier's stereo output stream of one frame (flat ``data, cam, eol, eof``)."""
    return fi.stereo_stream(*rectifier(cal, left, right, frac))
