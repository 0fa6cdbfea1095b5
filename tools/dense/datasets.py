"""The stereo pairs with ground truth the project has, at their own size and at the cameras' (352 x 288).

* ``tsukuba``: Middlebury Tsukuba (Scharstein & Szeliski 2002), 384 x 288, ``im3``/``im4``, ground truth
  ``disp3.pgm`` = disparity x 16, 0 = unknown (its 18-pixel frame).
* ``venus``: Middlebury Venus, 434 x 383, ``im2``/``im6``, ``disp2.pgm`` = disparity x 8, 0 = unknown.
* ``motorcycle``: Middlebury 2014 Motorcycle from scikit-image (``skimage.data.stereo_motorcycle()``),
  741 x 500, float disparities, +inf = unknown.

The Middlebury files are read from the shared data folder (``$EYESTEREO_SHARED_DATA`` or
``../shared/data``, see its README). Images are made grey (OpenCV's luma). Ground truth is float64 px
of the left view, NaN = unknown.

Resizing to the cameras' frame (:func:`resize`): the images by area averaging, the ground truth by the
nearest sample (no blending across depth edges, unknown stays unknown) with every disparity multiplied
by the width factor (the pairs are rectified: rows stay rows, a horizontal scale scales the shifts). A
height factor other than the width's (Venus, Motorcycle) changes the aspect only.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

__all__ = ["PAIRS", "Pair", "data_dir", "load", "resize", "disparity_range"]

#: The pairs' names.
PAIRS = ("tsukuba", "venus", "motorcycle")
#: Middlebury files: left, right, ground truth, its scale.
FILES = {"tsukuba": ("im3.png", "im4.png", "disp3.pgm", 16.0), "venus": ("im2.png", "im6.png", "disp2.pgm", 8.0)}


@dataclass(frozen=True)
class Pair:
    """A rectified grey pair and the ground truth of its left view."""

    name: str
    left: np.ndarray    # uint8 (h, w)
    right: np.ndarray   # uint8 (h, w)
    gt: np.ndarray      # float64 px, NaN = unknown

    @property
    def size(self) -> str:
        return f"{self.left.shape[1]}x{self.left.shape[0]}"

    @property
    def max_disparity(self) -> float:
        return float(np.nanmax(self.gt))


def data_dir() -> Path:
    """The shared data folder."""
    env = os.environ.get("EYESTEREO_SHARED_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2].parent / "shared" / "data"


def _grey(img: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(img, cv2.COLOR_RGB2GRAY) if img.ndim == 3 else img


def _read(path: Path, flags: int) -> np.ndarray:
    img = cv2.imread(str(path), flags)
    if img is None:
        raise ValueError(f"cannot read {path} (see {data_dir() / 'README.md'})")
    return img


def load(name: str) -> Pair:
    """A pair at its own size by name (one of :data:`PAIRS`)."""
    if name not in PAIRS:
        raise ValueError(f"unknown pair {name!r}; the pairs are {', '.join(PAIRS)}")
    if name == "motorcycle":
        from skimage.data import stereo_motorcycle  # the wheel holds the pair (fetched once, then cached)

        left, right, disp = stereo_motorcycle()
        gt = np.where(np.isfinite(disp), disp, np.nan).astype(np.float64)
        return Pair(name, _grey(left), _grey(right), gt)
    lf, rf, gf, scale = FILES[name]
    folder = data_dir() / "middlebury" / name
    raw = _read(folder / gf, cv2.IMREAD_UNCHANGED).astype(np.float64)
    return Pair(name, _read(folder / lf, cv2.IMREAD_GRAYSCALE), _read(folder / rf, cv2.IMREAD_GRAYSCALE),
                np.where(raw > 0, raw / scale, np.nan))


def resize(pair: Pair, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT) -> Pair:
    """The pair and its ground truth at ``width`` x ``height`` (disparities times the width factor)."""
    if not (isinstance(width, int) and isinstance(height, int) and width >= 8 and height >= 8):
        raise ValueError(f"size must be at least 8x8 pixels, got {width}x{height}")
    h, w = pair.left.shape
    fx = width / w
    gt = cv2.resize(pair.gt, (width, height), interpolation=cv2.INTER_NEAREST) * fx

    def img(a: np.ndarray) -> np.ndarray:
        return cv2.resize(a, (width, height), interpolation=cv2.INTER_AREA)

    return Pair(pair.name, img(pair.left), img(pair.right), gt)


def disparity_range(pair: Pair, minimum: int = 64) -> int:
    """D for a pair: ``minimum`` (64, the hardware's default) or more when the ground truth needs it
    (its maximum + 1 rounded up to 16, the granularity OpenCV's matchers need), at most 128."""
    need = 16 * -(-(int(np.floor(pair.max_disparity)) + 2) // 16)
    return min(128, max(minimum, need))
