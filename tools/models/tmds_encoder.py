"""Bit-true model of :func:`eyestereo.hdl.video.tmds_encoder.tmds_encoder`: DVI 1.0 TMDS encoding and decoding.

DVI 1.0 section 3.2.2 (the encoder's flow chart, figure 3-5): while DE is high a byte becomes a 10-bit
character in two steps. Transition minimising: ``q_m[0] = D[0]``, ``q_m[i] = q_m[i-1] XOR D[i]`` (``q_m[8] =
1``), or XNOR (``q_m[8] = 0``) when D has more than four ones, or exactly four with ``D[0] = 0``. DC
balancing: ``q_out[7:0]`` is ``q_m[7:0]`` or its complement (``q_out[9]`` says which, ``q_out[8] = q_m[8]``),
chosen by the running disparity ``cnt`` (ones minus zeros sent so far) so that it tends back to 0. While DE
is low the character is one of the four control codes for (C1, C0) and ``cnt`` restarts at 0. Characters
are sent ``q_out[0]`` first; ints here hold ``q_out[9]`` as their bit 9.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CONTROL", "CONTROL_OF", "encode", "encode_stream", "decode", "transition_minimise",
           "DATA_SYMBOLS", "DISPARITY_BOUND"]

#: The control characters for (C1, C0) = (0, 0), (0, 1), (1, 0), (1, 1) (DVI 1.0 3.2.2).
CONTROL = (0b1101010100, 0b0010101011, 0b0101010100, 0b1010101011)
#: character -> (c0, c1)
CONTROL_OF = {q: (i & 1, i >> 1) for i, q in enumerate(CONTROL)}
#: The largest |cnt| the encoder reaches from cnt = 0: the reachable states are the even numbers -8 .. 8
#: (tests/models/test_tmds.py visits them all); the hardware's counter is sized with room above it.
DISPARITY_BOUND = 8


def _ones(x: int, bits: int = 8) -> int:
    return bin(x & ((1 << bits) - 1)).count("1")


def transition_minimise(d: int) -> int:
    """``q_m[8:0]`` of a byte (DVI 1.0 figure 3-5, first half)."""
    n1 = _ones(d)
    xnor = n1 > 4 or (n1 == 4 and not d & 1)
    qm = d & 1
    for i in range(1, 8):
        b = ((qm >> (i - 1)) ^ (d >> i)) & 1
        qm |= (b ^ xnor) << i
    return qm | (0 if xnor else 1) << 8


def encode(d: int, cnt: int) -> tuple[int, int]:
    """(character, next cnt) of data byte ``d`` at running disparity ``cnt`` (DE high)."""
    qm = transition_minimise(d)
    q8 = qm >> 8
    n1 = _ones(qm)
    n0 = 8 - n1
    low = qm & 0xFF
    if cnt == 0 or n1 == n0:
        inv = not q8
        cnt += (n1 - n0) if q8 else (n0 - n1)
    elif (cnt > 0 and n1 > n0) or (cnt < 0 and n0 > n1):
        inv = True
        cnt += 2 * q8 + (n0 - n1)
    else:
        inv = False
        cnt += -2 * (1 - q8) + (n1 - n0)
    q = (int(inv) << 9) | (q8 << 8) | (low ^ 0xFF if inv else low)
    return q, cnt


def encode_stream(data, c0, c1, de, cnt: int = 0) -> np.ndarray:
    """Characters of a sequence of inputs (arrays of equal length, or scalars), from running disparity ``cnt``."""
    data, c0, c1, de = np.broadcast_arrays(*(np.asarray(a, dtype=np.int64).ravel() for a in (data, c0, c1, de)))
    out = np.empty(len(data), dtype=np.int64)
    for i in range(len(data)):
        if de[i]:
            out[i], cnt = encode(int(data[i]), cnt)
        else:
            out[i], cnt = CONTROL[(int(c1[i]) & 1) << 1 | (int(c0[i]) & 1)], 0
    return out


def decode(q: int) -> tuple[bool, int]:
    """(de, value) of a character: (False, c1 << 1 | c0) for a control code, else (True, the byte) (DVI 1.0
    figure 3-6: undo the complement that ``q[9]`` says, then the XOR / XNOR chain that ``q[8]`` says)."""
    if q in CONTROL_OF:
        c0, c1 = CONTROL_OF[q]
        return False, c1 << 1 | c0
    low = (q ^ 0xFF) & 0xFF if q >> 9 & 1 else q & 0xFF
    xnor = not q >> 8 & 1
    d = low & 1
    for i in range(1, 8):
        b = ((low >> i) ^ (low >> (i - 1))) & 1
        d |= (b ^ xnor) << i
    return True, d


def _data_symbols() -> frozenset:
    """Every character the encoder can send while DE is high (over all bytes and reachable disparities)."""
    out = set()
    for d in range(256):
        for cnt in range(-DISPARITY_BOUND, DISPARITY_BOUND + 1, 2):
            out.add(encode(d, cnt)[0])
    return frozenset(out)


#: The set of valid data characters (460 of the 1024 10-bit words).
DATA_SYMBOLS = _data_symbols()
