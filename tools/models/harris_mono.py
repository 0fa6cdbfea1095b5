"""Bit-true model of :func:`eyestereo.hdl.harris.harris_mono.harris_mono`, the float reference, and helpers.

The chain: Sobel -> harris_window -> cornerness -> prethreshold -> nms, one model per block. The float
reference :func:`harris_float` uses the same kernels without any quantization and defines the units of
``c`` (and so of thresholds): with raw Sobel gradients g ([1 2 1] x [-1 0 1]) and
M = sum_w w g g^T / 128 over the 5x5 window w = [1 2 4 2 1] x [1 2 4 2 1],
c = det(M) - k trace(M)^2. The hardware's cornerness code is c / 2**21 up to quantization, so
:func:`threshold_code` is floor(c / 2**21).
"""

from __future__ import annotations

import numbers

import numpy as np

from eyestereo.tools.constants import NMS_DEFAULT, NMS_SIZES, THRESHOLD_BLOCKS
from eyestereo.tools.models import cornerness as _corner
from eyestereo.tools.models import harris_window as _window
from eyestereo.tools.models import nms as _nms
from eyestereo.tools.models import prethreshold as _pre
from eyestereo.tools.models import sobel as _sobel
from eyestereo.tools.models.border import interior_mask

#: cornerness code = c / 2**CODE_SHIFT (c in harris_float's units)
CODE_SHIFT = 21
SOBEL_RADIUS = 1


def k_code(k: float) -> int:
    """The k port code (ufix[8,8]): round(k * 256); k must lie in [0, 255/256]."""
    code = int(round(float(k) * 256))
    if not 0 <= code <= 255:
        raise ValueError(f"k = {k} is outside what the 8-bit k port holds (0 .. 0.996)")
    return code


def threshold_code(c: float) -> int:
    """Threshold port code for a cornerness threshold ``c`` in :func:`harris_float` units."""
    code = int(np.floor(float(c) / 2 ** CODE_SHIFT))
    return int(np.clip(code, _corner.OUT.lo, _corner.OUT.hi))


def radius(nms: int) -> int:
    """Border width (pixels) outside of which the feature flags are specified."""
    return SOBEL_RADIUS + _window.RADIUS + nms // 2


def check_params(width: int, height: int, blocks: tuple[int, int], nms: int) -> None:
    if isinstance(nms, bool) or not isinstance(nms, numbers.Integral) or nms not in NMS_SIZES:
        raise ValueError(f"parameter nms must be {', '.join(map(str, NMS_SIZES[:-1]))} or {NMS_SIZES[-1]}, got {nms!r}")
    _pre.check_blocks(width, height, blocks)


def harris_stages(frame: np.ndarray, k: int, thresholds, *, blocks=THRESHOLD_BLOCKS, nms: int = NMS_DEFAULT) -> dict:
    """Every block's output for one 8-bit frame (integer codes)."""
    frame = np.asarray(frame, np.int64)
    h, w = frame.shape
    check_params(w, h, tuple(blocks), nms)
    sob = _sobel.pack(*_sobel.sobel(frame)[:2])
    win, _ = _window.harris_window(sob)
    corner = _corner.cornerness(win, k)
    pre = _pre.prethreshold(corner, thresholds, tuple(blocks))
    flags, _ = _nms.nms(pre, nms)
    return dict(sobel=sob, window=win, cornerness=corner, prethreshold=pre, flags=flags,
                mask=interior_mask(h, w, radius(nms)))


def harris_mono(frame: np.ndarray, k: int, thresholds, *, blocks=THRESHOLD_BLOCKS, nms: int = NMS_DEFAULT):
    """(feature flags, mask of specified pixels) as the hardware computes them."""
    s = harris_stages(frame, k, thresholds, blocks=blocks, nms=nms)
    return s["flags"], s["mask"]


def features(flags: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """(x, y) coordinates of the set flags, raster order, shape (n, 2)."""
    f = np.asarray(flags).astype(bool)
    if mask is not None:
        f = f & mask
    return np.argwhere(f)[:, ::-1].astype(np.int64)


def harris_float(img: np.ndarray, k: float) -> np.ndarray:
    """Float64 cornerness with the hardware's kernels and no quantization (border: 0)."""
    det, trace = harris_float_terms(img)
    return det - k * trace ** 2


def harris_float_terms(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(det M, trace M) of the float64 structure tensor (border: 0), M as in the module doc."""
    import cv2

    img = np.asarray(img, np.float64)
    gx = cv2.Sobel(img, cv2.CV_64F, 1, 0, ksize=3, borderType=cv2.BORDER_REPLICATE)
    gy = cv2.Sobel(img, cv2.CV_64F, 0, 1, ksize=3, borderType=cv2.BORDER_REPLICATE)
    kern = _window.KERNEL.astype(np.float64) / 128.0
    mxx = cv2.filter2D(gx * gx, -1, kern, borderType=cv2.BORDER_REPLICATE)
    myy = cv2.filter2D(gy * gy, -1, kern, borderType=cv2.BORDER_REPLICATE)
    mxy = cv2.filter2D(gx * gy, -1, kern, borderType=cv2.BORDER_REPLICATE)
    r = SOBEL_RADIUS + _window.RADIUS
    det = np.zeros_like(mxx)
    trace = np.zeros_like(mxx)
    det[r:-r, r:-r] = (mxx * myy - mxy * mxy)[r:-r, r:-r]
    trace[r:-r, r:-r] = (mxx + myy)[r:-r, r:-r]
    return det, trace


def float_features(img: np.ndarray, k: float, threshold: float | np.ndarray, *, blocks=(1, 1),
                   nms: int = NMS_DEFAULT) -> tuple[np.ndarray, np.ndarray]:
    """(flags, mask): the float pipeline with the same pre-threshold and NMS rules as the hardware."""
    c = harris_float(img, k)
    thr = np.broadcast_to(np.asarray(threshold, np.float64), (blocks[0] * blocks[1],))
    idx = _pre.block_index(*c.shape, tuple(blocks))
    pre = np.where(c > thr[idx], c, 0.0)
    h, w = c.shape
    r = nms // 2
    flags = pre > 0
    if r:
        pad = np.full((h + 2 * r, w + 2 * r), -np.inf)
        pad[r:r + h, r:r + w] = pre
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                if dy or dx:
                    n = pad[r + dy:r + dy + h, r + dx:r + dx + w]
                    flags &= (pre > n) if (dy < 0 or (dy == 0 and dx < 0)) else (pre >= n)
    return flags.astype(np.int64), interior_mask(h, w, radius(nms))
