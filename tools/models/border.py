"""Border bookkeeping shared by the bit-true models of window filters (pure numpy)."""

import numpy as np


def interior_mask(height: int, width: int, radius: int) -> np.ndarray:
    """True where a (2r+1)x(2r+1) window centred on the pixel lies inside a height x width image.

    Window filters (border treatment option 3, thesis 6.2.1) give unspecified data elsewhere, so bit-true
    comparisons look at these pixels only.
    """
    m = np.zeros((height, width), dtype=bool)
    if 2 * radius < height and 2 * radius < width:
        m[radius:height - radius, radius:width - radius] = True
    return m


def correlate_int(img: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """Exact integer correlation: out[y, x] = sum k[i, j] * img[y - r + i, x - r + j] (interior only).

    Border pixels are 0. int64 throughout, so any 8..36-bit input with small kernels is exact.
    """
    img = np.asarray(img, dtype=np.int64)
    kernel = np.asarray(kernel, dtype=np.int64)
    n = kernel.shape[0]
    if kernel.ndim != 2 or kernel.shape[1] != n or n % 2 == 0:
        raise ValueError(f"kernel must be square with odd size, got shape {kernel.shape}")
    r = n // 2
    h, w = img.shape
    out = np.zeros((h, w), dtype=np.int64)
    if h <= 2 * r or w <= 2 * r:
        return out
    acc = np.zeros((h - 2 * r, w - 2 * r), dtype=np.int64)
    for i in range(n):
        for j in range(n):
            if kernel[i, j]:
                acc += kernel[i, j] * img[i:h - 2 * r + i, j:w - 2 * r + j]
    out[r:h - r, r:w - r] = acc
    return out
