"""Bit-true model of :func:`eyestereo.hdl.harris.prethreshold.prethreshold` (thesis 6.2.4).

The block takes mono and stereo streams; on a stereo stream each camera has its own thresholds and its
output is :func:`prethreshold` of that camera's frame with them (as
:func:`eyestereo.tools.models.harris_stereo.harris_stereo` computes it). :func:`block_index` is also the
model of :func:`eyestereo.hdl.harris.block_position.block_position`'s block output.
"""

from __future__ import annotations

import numbers

import numpy as np


def check_blocks(width: int, height: int, blocks) -> tuple[int, int]:
    """``blocks`` as a pair of Python ints (BX, BY); ValueError unless it is a pair of integers (numpy
    integers too, not floats or bools), each 1..16 and at most the frame's width / height."""
    if (not isinstance(blocks, (tuple, list, np.ndarray)) or len(blocks) != 2
            or not all(isinstance(b, numbers.Integral) and not isinstance(b, (bool, np.bool_)) for b in blocks)):
        raise ValueError(f"parameter blocks must be a pair of ints (BX, BY), got {blocks!r}")
    bx, by = (int(b) for b in blocks)
    if not (1 <= bx <= min(16, width) and 1 <= by <= min(16, height)):
        raise ValueError(f"parameter blocks={(bx, by)}: BX and BY must be 1..16 and at most the frame's "
                         f"width/height ({width}x{height})")
    return bx, by


def block_edges(size: int, blocks: int) -> np.ndarray:
    """Start of each block along one axis: block i covers [edges[i], edges[i+1]); edges[i] = i*size//blocks."""
    return np.array([i * size // blocks for i in range(blocks + 1)], dtype=np.int64)


def block_index(height: int, width: int, blocks: tuple[int, int]) -> np.ndarray:
    """Block index by * BX + bx of every pixel."""
    bxn, byn = blocks
    bx = np.searchsorted(block_edges(width, bxn), np.arange(width), side="right") - 1
    by = np.searchsorted(block_edges(height, byn), np.arange(height), side="right") - 1
    return by[:, None] * bxn + bx[None, :]


def prethreshold(values: np.ndarray, thresholds, blocks: tuple[int, int]) -> np.ndarray:
    """values where value > its block's threshold, else 0 (thresholds listed by block index)."""
    values = np.asarray(values, np.int64)
    thr = np.asarray(thresholds, np.int64)
    if thr.shape != (blocks[0] * blocks[1],):
        raise ValueError(f"need {blocks[0] * blocks[1]} thresholds, got {thr.shape}")
    t = thr[block_index(*values.shape, blocks)]
    return np.where(values > t, values, 0)
