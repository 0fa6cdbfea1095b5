"""Model of :func:`eyestereo.hdl.video.tmds_serializer.tmds_serializer`: 10-bit characters to DDR bit pairs.

Every pixel clock the block takes one character per data channel (and the clock channel's fixed
:data:`CLOCK_WORD`) and sends it in five fast clocks (5x the pixel clock), two bits per fast clock per
channel for a DDR output cell: bit 0 of a character first. Pair ``k`` of a character (k = 0..4) is
``(bit 2k, bit 2k + 1)``; the block's 2-bit output holds ``bit 2k`` in its bit 0 (the DDR cell's D0, driven
on the rising edge) and ``bit 2k + 1`` in its bit 1 (D1, the falling edge).

When: the character a pixel-clock edge at time ``t`` captures is on the outputs from the third fast-clock
edge after ``t`` (:func:`load_edge`; the toggle's two synchroniser flops and the load) for five fast clocks.
This holds for any phase of the fast clock whose edges do not coincide with the pixel clock's; with
coincident edges (one PLL, no phase shift) the first synchroniser flop may see the toggle at that edge
or one later, so the latency is 2 or 3 fast clocks, fixed once the clocks run.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["CLOCK_WORD", "LOAD_EDGES", "ddr_pairs", "serial_bits", "load_edge", "pairs_to_bits"]

#: The clock channel's character: five ones then five zeros (bit 0 first), one pixel clock period.
CLOCK_WORD = 0b0000011111
#: The fast-clock edge (counted from 1 after the pixel edge that captured the character) that loads it.
LOAD_EDGES = 3


def ddr_pairs(words) -> np.ndarray:
    """The 2-bit outputs of a sequence of characters (any int array shape ``(n, ...)``): shape
    ``(5 n, ...)``, output ``5 i + k`` = pair k of character i."""
    w = np.asarray(words, dtype=np.int64)
    pairs = np.stack([(w >> (2 * k)) & 3 for k in range(5)], axis=1)
    return pairs.reshape((5 * w.shape[0],) + w.shape[1:])


def pairs_to_bits(pairs) -> np.ndarray:
    """The serial bit stream of a channel's 2-bit outputs (bit 0 of each, then bit 1): one bit per bit time."""
    p = np.asarray(pairs, dtype=np.int64).ravel()
    return np.stack([p & 1, (p >> 1) & 1], axis=1).ravel()


def serial_bits(words) -> np.ndarray:
    """One channel's bit stream: every character's bits 0..9 in turn."""
    return pairs_to_bits(ddr_pairs(np.asarray(words, dtype=np.int64).ravel()))


def load_edge(t: int, fast_phase: int, fast_period: int) -> int:
    """Index of the fast-clock edge (edge j at ``fast_phase + j * fast_period``) from which a character
    captured by a pixel-clock edge at ``t`` is on the outputs; ValueError when an edge coincides with ``t``
    (the latency is then 2 or 3: the simulator's or the flip-flop's choice)."""
    first = math.floor((t - fast_phase) / fast_period) + 1  # the first fast edge after t
    if fast_phase + (first - 1) * fast_period == t:
        raise ValueError(f"a fast-clock edge coincides with the pixel-clock edge at {t}: the latency is 2 or 3")
    return first + LOAD_EDGES - 1
