"""Bit-true model of :func:`eyestereo.hdl.prethreshold.prethreshold` (thesis 6.2.4)."""

from __future__ import annotations

import numpy as np


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
