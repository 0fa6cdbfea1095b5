"""Rectify images by backward maps with bilinear interpolation (thesis 3.6), in numpy.

For each rectified pixel the map gives a source position ``(x, y)`` in the camera image; with
``x0 = floor(x)``, ``dx = x - x0`` (likewise y) the value is

    I_rect = (1-dx)(1-dy) I(x0, y0) + dx (1-dy) I(x0+1, y0) + (1-dx) dy I(x0, y0+1) + dx dy I(x0+1, y0+1)

(the thesis's ``[1-dx, dx] [[I(x,y), I(x,y+1)], [I(x+1,y), I(x+1,y+1)]] [1-dy, dy]^T``). A pixel whose
source lies outside ``[0, W-1] x [0, H-1]`` (or is not finite) becomes 0 -- black, like the hardware's
out-of-range case. Integer images are rounded to nearest and clipped to their type.

Agreement with ``cv2.remap(INTER_LINEAR, BORDER_CONSTANT)`` on 8-bit images: OpenCV 4 quantises the
sub-pixel position to 1/32 pixel, so the two can differ by up to ``ceil(255/64) = 4`` grey levels at
the sharpest edges (position error <= 1/64 px times a gradient of <= 255 per px), and by at most 1
level (rounding) once the positions are put on the 1/32 grid beforehand; the OpenCV 5 used here
agrees to 1 grey level everywhere (mean 5e-5 on a real image). Inside the one-pixel band just
outside the image OpenCV blends with the border colour, while imwarp gives 0.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.rectify.polyfit import Fit, poly_from_dict, read_poly_json
from eyestereo.tools.rectify.maps import Maps

__all__ = ["imwarp", "maps_from_poly", "warp_side"]


def imwarp(img: np.ndarray, map_x: np.ndarray, map_y: np.ndarray) -> np.ndarray:
    """Backward-warp ``img`` (H, W) or (H, W, C) by ``map_x``/``map_y`` (h, w): result (h, w[, C])."""
    img = np.asarray(img)
    if img.ndim not in (2, 3) or img.shape[0] < 1 or img.shape[1] < 1:
        raise ValueError(f"image must be (H, W) or (H, W, C), got shape {img.shape}")
    if not (np.issubdtype(img.dtype, np.integer) or np.issubdtype(img.dtype, np.floating)):
        raise ValueError(f"image must hold numbers, got {img.dtype}")
    mx = np.asarray(map_x, dtype=np.float64)
    my = np.asarray(map_y, dtype=np.float64)
    if mx.ndim != 2 or mx.shape != my.shape:
        raise ValueError(f"map_x and map_y must be 2-D and of equal shape, got {mx.shape} and {my.shape}")
    h0, w0 = img.shape[:2]
    with np.errstate(invalid="ignore"):
        valid = (np.isfinite(mx) & np.isfinite(my) & (mx >= 0) & (mx <= w0 - 1) & (my >= 0)
                 & (my <= h0 - 1))
    x = np.where(valid, mx, 0.0)
    y = np.where(valid, my, 0.0)
    x0 = np.floor(x).astype(np.intp)
    y0 = np.floor(y).astype(np.intp)
    dx = x - x0
    dy = y - y0
    x1 = np.minimum(x0 + 1, w0 - 1)  # at x == W-1 the weight of x0+1 is 0
    y1 = np.minimum(y0 + 1, h0 - 1)
    src = img.astype(np.float64)
    if img.ndim == 3:
        dx, dy, valid_b = dx[..., None], dy[..., None], valid[..., None]
    else:
        valid_b = valid
    out = ((1 - dx) * (1 - dy) * src[y0, x0] + dx * (1 - dy) * src[y0, x1]
           + (1 - dx) * dy * src[y1, x0] + dx * dy * src[y1, x1])
    out = np.where(valid_b, out, 0.0)
    if np.issubdtype(img.dtype, np.integer):
        info = np.iinfo(img.dtype)
        return np.clip(np.floor(out + 0.5), info.min, info.max).astype(img.dtype)
    return out.astype(img.dtype)


def maps_from_poly(poly: Fit | dict[str, Any] | str | os.PathLike[str]) -> Maps:
    """Evaluate the four polynomials of a :class:`Fit`, a parsed ``poly.json`` dict or a file path."""
    if isinstance(poly, (str, os.PathLike)):
        f = read_poly_json(Path(poly))
    elif isinstance(poly, dict):
        f = poly_from_dict(poly)
    elif isinstance(poly, Fit):
        f = poly
    else:
        raise ValueError(f"maps_from_poly wants a Fit, a poly.json dict or a path, got {type(poly).__name__}")
    sw, sh = f.report.get("source_width"), f.report.get("source_height")
    known = all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in (sw, sh))
    return Maps(f.evaluate("left_x"), f.evaluate("left_y"), f.evaluate("right_x"), f.evaluate("right_y"),
                image_width=sw if known else None, image_height=sh if known else None,
                method=f"poly{f.degree}")


def warp_side(img: np.ndarray, maps: Maps, side: str) -> np.ndarray:
    """Rectify one camera's image with its maps; ValueError if the image size does not fit the maps.

    The camera image must have the size the maps were made for (``maps.source_size``; when unknown,
    the maps' own size).
    """
    mx, my = maps.side(side)
    want = maps.source_size or (maps.width, maps.height)
    got = (np.asarray(img).shape[1], np.asarray(img).shape[0])
    if got != want:
        raise ValueError(f"image is {got[0]}x{got[1]} but the maps were made for {want[0]}x{want[1]} images")
    return imwarp(img, mx, my)
