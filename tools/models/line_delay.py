"""Bit-true model of :func:`eyestereo.hdl.streaming.line_delay.line_delay`."""

import numpy as np


def line_delay(frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Output frame and the mask of its specified pixels: out[y] = frame[y - 1]; line 0 unspecified."""
    frame = np.asarray(frame, dtype=np.int64)
    out = np.zeros_like(frame)
    out[1:] = frame[:-1]
    mask = np.ones(frame.shape, dtype=bool)
    mask[0] = False
    return out, mask
