"""Bit-true model of :func:`eyestereo.hdl.streaming.convolve.convolve`: integer kernels, floor scaling."""

from __future__ import annotations

import numpy as np

from eyestereo.tools.fixed import Fmt, fit_format
from eyestereo.tools.models.border import correlate_int, interior_mask


def check_kernel(kernel=None, col=None, row=None) -> tuple[np.ndarray, bool]:
    """The NxN integer kernel (N = 3 or 5) and whether it is given in separable form (col x row)."""
    if kernel is not None and (col is not None or row is not None):
        raise ValueError("give either kernel= (inseparable) or col= and row= (separable), not both")
    if kernel is None:
        if col is None or row is None:
            raise ValueError("a separable kernel needs both col= and row=")
        col = _int_coeffs(col, "col")
        row = _int_coeffs(row, "row")
        if col.ndim != 1 or row.ndim != 1 or len(col) != len(row):
            raise ValueError(f"col and row must be 1-D of equal length, got {col.shape} and {row.shape}")
        kernel = np.outer(col, row)
        separable = True
    else:
        kernel = _int_coeffs(kernel, "kernel")
        separable = False
    if kernel.ndim != 2 or kernel.shape[0] != kernel.shape[1] or kernel.shape[0] not in (3, 5):
        raise ValueError(f"kernel must be 3x3 or 5x5, got shape {kernel.shape}")
    if np.abs(kernel).max() >= 1 << 16:
        raise ValueError("kernel coefficients must be below 2**16 in magnitude")
    return kernel, separable


def _int_coeffs(values, name: str) -> np.ndarray:
    """Coefficients as int64, refusing anything that is not an integer (each factor on its own)."""
    a = np.asarray(values)
    if a.dtype == bool or not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise ValueError(f"{name} coefficients must be integers, got dtype {a.dtype}")
    if not np.all(np.isfinite(a)) or not np.all(a == np.round(a)):
        raise ValueError(f"{name} coefficients must be integers (scale them and use shift=), got {a.tolist()}")
    return a.astype(np.int64)


def sum_range(kernel: np.ndarray, data_width: int) -> tuple[int, int]:
    """Exact range of the window sum for unsigned data_width-bit input."""
    top = (1 << data_width) - 1
    k = np.asarray(kernel, dtype=np.int64)
    return int(k[k < 0].sum()) * top, int(k[k > 0].sum()) * top


def output_range(kernel: np.ndarray, data_width: int, shift: int) -> tuple[int, int]:
    """Range of floor(sum / 2**shift); the output word is that many bits, two's complement if signed."""
    lo, hi = sum_range(kernel, data_width)
    return lo >> shift, hi >> shift


def output_format(kernel: np.ndarray, data_width: int, shift: int) -> Fmt:
    """Smallest fixed-point format of the output codes (fraction length 0: integer codes)."""
    return fit_format(*output_range(kernel, data_width, shift))


def output_width(kernel: np.ndarray, data_width: int, shift: int) -> tuple[int, bool]:
    """(bits, signed) of the output word."""
    f = output_format(kernel, data_width, shift)
    return f.wl, f.signed


def convolve(frame: np.ndarray, kernel: np.ndarray, shift: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(values, interior mask): floor(correlation / 2**shift) as signed integers."""
    frame = np.asarray(frame, dtype=np.int64)
    r = np.asarray(kernel).shape[0] // 2
    return correlate_int(frame, kernel) >> shift, interior_mask(*frame.shape, r)


def to_word(values: np.ndarray, bits: int) -> np.ndarray:
    """Signed values as unsigned two's complement words of `bits` bits (the stream's data)."""
    return np.asarray(values, dtype=np.int64) & ((1 << bits) - 1)


def from_word(words: np.ndarray, bits: int, signed: bool) -> np.ndarray:
    """Inverse of :func:`to_word`."""
    w = np.asarray(words, dtype=np.int64) & ((1 << bits) - 1)
    if signed:
        w = np.where(w >= 1 << (bits - 1), w - (1 << bits), w)
    return w
