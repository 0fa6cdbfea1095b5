"""Bit-level model of :func:`eyestereo.hdl.serial.uart_tx.uart_tx`: bytes offered at given clocks -> the line.

The UART frame (8N1): a start bit (0), the 8 data bits LSB first, a stop bit (1); the line idles high.
Each bit lasts ``clocks_per_bit`` clocks. The transmitter takes a byte at a rising edge where its
``sink.valid`` and ``sink.ready`` are both high; ``ready`` is high while it is idle and in the last clock
of a stop bit, so bytes offered without pause follow each other with no idle time on the line. The line
is a register: after the edge that takes a byte it shows the start bit.

:func:`uart_tx` runs that rule clock by clock and returns the edges at which bytes were taken and the
line's transitions (edge index, new level), what a bench records from the VHDL. Pure Python.
"""

from __future__ import annotations

__all__ = ["frame_bits", "line", "uart_tx"]


def frame_bits(byte: int) -> list[int]:
    """The 10 bits of one 8N1 frame, first on the line first: start 0, data LSB first, stop 1."""
    if not 0 <= int(byte) <= 0xFF:
        raise ValueError(f"a UART byte is 0..255, got {byte!r}")
    return [0] + [(int(byte) >> i) & 1 for i in range(8)] + [1]


def line(data, clocks_per_bit: int, *, idle_before: int = 0) -> list[int]:
    """The line, one sample per clock, for ``data`` sent back to back after ``idle_before`` idle clocks."""
    out = [1] * idle_before
    for b in data:
        for bit in frame_bits(b):
            out += [bit] * clocks_per_bit
    return out


def uart_tx(offers, clocks_per_bit: int) -> tuple[list[int], list[tuple[int, int]]]:
    """The transmitter, clock by clock. ``offers``: ``[(gap, byte), ...]`` in order; byte i's ``valid`` is
    raised ``gap`` clocks after the edge that took byte i - 1 (before edge ``take[i-1] + 1 + gap``; byte 0:
    before edge ``gap``) and held until taken. Edge 0 is the first edge after reset.

    Returns ``(takes, transitions)``: the edge that took each byte; ``(k, level)`` for every change of the
    line at edge k (the line is 1 before the first), up to the end of the last stop bit.
    """
    cpb = int(clocks_per_bit)
    offers = list(offers)
    takes: list[int] = []
    transitions: list[tuple[int, int]] = []
    tx, busy, bit, count, shreg = 1, False, 0, 0, 0
    i = 0
    offered_at = offers[0][0] if offers else None
    k = 0
    while i < len(offers) or busy:
        ready = not busy or (bit == 9 and count == cpb - 1)
        valid = i < len(offers) and k >= offered_at
        new_tx = tx
        if valid and ready:
            shreg = (int(offers[i][1]) << 1) | 0x200
            new_tx, busy, bit, count = 0, True, 0, 0
            takes.append(k)
            i += 1
            if i < len(offers):
                offered_at = k + 1 + offers[i][0]
        elif busy:
            if count == cpb - 1:
                count = 0
                if bit == 9:
                    busy = False
                else:
                    bit += 1
                    new_tx = (shreg >> 1) & 1
                    shreg >>= 1
            else:
                count += 1
        if new_tx != tx:
            transitions.append((k, new_tx))
            tx = new_tx
        k += 1
    return takes, transitions
