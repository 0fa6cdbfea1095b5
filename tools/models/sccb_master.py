"""Model of :func:`eyestereo.hdl.camera.sccb_master.sccb_master`: a register table -> the exact SIO_C / SIO_D
levels per quarter bit and per clock, and the register writes they carry.

The master works in *quarters* of an SCCB bit, each :func:`quarter_clocks` clocks long. A level is
``(c, d)``: SIO_C and the master's SIO_D (1 = released, pulled up; 0 = driven low). The symbols
(one column per quarter)::

    idle   c 1       start  c 1 1 1 0     bit b  c 0 1 1 0     stop  c 0 1 1 1
           d 1              d 1 0 0 0            d b b b b           d 0 0 1 1

SIO_D changes only a quarter after SIO_C fell (hold one quarter, set-up one quarter before SIO_C rises),
except in the start (falls while SIO_C is high) and the stop (rises while SIO_C is high). Transactions
[SCCB]: a write is start, ID 0x42, sub-address, data, stop (3 phases of 9 bits, the 9th released: the
slave's "don't care"); a read is start, 0x42, sub-address, stop, start, 0x43, 8 bits the slave drives
and the 9th ("NA") released, stop. Each table entry is preceded by one idle quarter (the ROM fetch); a
delay entry of ``ms`` milliseconds is ``ms * quarters_per_ms`` idle quarters. After the table come the
ID reads (PID, VER), then one more idle quarter, at whose end ``done`` pulses.

Clock numbering (:func:`changes`): edge 1 is the first rising edge with the reset low; quarter 0 is
the reset level (1, 1) until edge ``q``; quarter ``k`` >= 1 is on the pins from edge ``k q + 1`` (the
state moves at edge ``k q``, the pins are registers one clock behind), ``done`` is high after edge
``len(quarters) * q`` for one clock.
"""

from __future__ import annotations

import math
from fractions import Fraction

from eyestereo.tools.ov7670 import DELAY, ID_READ, ID_WRITE, PID, PID_VALUE, VER, VER_VALUE, check_table

__all__ = ["WRITE", "READ", "WAIT", "END", "T_LOW_S", "quarter_clocks", "quarters_per_ms", "rom", "quarters",
           "changes", "writes", "decode", "check_rates"]

#: ROM entry kinds.
WRITE, READ, WAIT, END = 0, 1, 2, 3
#: SIO_C low time the sensor needs ([DS] Table 6, tLOW); a quarter is at least half of it (SIO_C is low
#: for two quarters), which caps the rate at 384.6 kHz below the SCCB's 400 kHz.
T_LOW_S = Fraction(13, 10_000_000)
#: The identity reads after the table: (register, expected value).
ID_READS = ((PID, PID_VALUE), (VER, VER_VALUE))


def check_rates(clk_hz, sccb_hz) -> tuple[Fraction, Fraction]:
    """clk_hz and sccb_hz as exact numbers; ValueError for a rate out of range."""
    for name, v in (("clk_hz", clk_hz), ("sccb_hz", sccb_hz)):
        if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)) or not v > 0 or math.isinf(v):
            raise ValueError(f"parameter {name} must be a positive number of Hz, got {v!r}")
    clk, sccb = Fraction(clk_hz), Fraction(sccb_hz)
    if sccb > 400_000:
        raise ValueError(f"parameter sccb_hz={float(sccb):g} is above the SCCB's 400 kHz")
    if clk < 8 * sccb:
        raise ValueError(f"parameter clk_hz={float(clk):g} is too slow for sccb_hz={float(sccb):g}: a quarter bit "
                         f"needs at least 2 clocks (clk_hz >= 8 x sccb_hz)")
    return clk, sccb


def quarter_clocks(clk_hz, sccb_hz) -> int:
    """Clocks per quarter bit: at least a quarter of 1/sccb_hz and half the SIO_C low time, whole clocks."""
    clk, sccb = check_rates(clk_hz, sccb_hz)
    return max(math.ceil(clk / (4 * sccb)), math.ceil(clk * T_LOW_S / 2), 2)


def quarters_per_ms(clk_hz, sccb_hz) -> int:
    """Quarters in a delay entry's millisecond (rounded up: a delay is never shorter than asked)."""
    q = quarter_clocks(clk_hz, sccb_hz)
    return math.ceil(Fraction(clk_hz) / 1000 / q)


def rom(table, *, ids=ID_READS) -> list[tuple[int, int, int]]:
    """(kind, reg, value) entries: the table's writes and waits, the ID reads, END."""
    out = [(WAIT, 0, v) if r == DELAY else (WRITE, r, v) for r, v in check_table(table)]
    out += [(READ, r, v) for r, v in ids]
    return out + [(END, 0, 0)]


def _start():
    return [(1, 1), (1, 0), (1, 0), (0, 0)]


def _stop():
    return [(0, 0), (1, 0), (1, 1), (1, 1)]


def _byte(value: int):
    word = (value << 1) | 1  # the 9th bit released: "don't care" after a write phase, "NA" after a read
    out = []
    for i in range(8, -1, -1):
        b = (word >> i) & 1
        out += [(0, b), (1, b), (1, b), (0, b)]
    return out


def transaction(kind: int, reg: int, value: int) -> list[tuple[int, int]]:
    """The quarters of one write or read (the slave's read bits are released by the master: 0xFF)."""
    if kind == WRITE:
        return _start() + _byte(ID_WRITE) + _byte(reg) + _byte(value) + _stop()
    return _start() + _byte(ID_WRITE) + _byte(reg) + _stop() + _start() + _byte(ID_READ) + _byte(0xFF) + _stop()


def quarters(table, *, clk_hz=100e6, sccb_hz=100e3) -> list[tuple[int, int]]:
    """The (c, d) level of every quarter of one run, from quarter 0 (after reset, or the first quarter
    after ``start`` was taken) to the last idle quarter at whose end ``done`` pulses."""
    qpm = quarters_per_ms(clk_hz, sccb_hz)
    out = []
    for kind, reg, value in rom(table):
        out.append((1, 1))  # the fetch quarter
        if kind == WAIT:
            out += [(1, 1)] * (value * qpm)
        elif kind != END:
            out += transaction(kind, reg, value)
    return out


def changes(table, *, clk_hz=100e6, sccb_hz=100e3) -> tuple[list[tuple[int, int, int]], int]:
    """(level changes as (edge, c, d), the edge after which ``done`` is high) of the run after reset."""
    q = quarter_clocks(clk_hz, sccb_hz)
    seq = quarters(table, clk_hz=clk_hz, sccb_hz=sccb_hz)
    out, prev = [], (1, 1)
    for k, lv in enumerate(seq):
        if lv != prev:
            out.append((k * q + 1, *lv))
            prev = lv
    return out, len(seq) * q


def writes(table) -> list[tuple[int, int]]:
    """The register writes a run carries: the table without its delays."""
    return [(r, v) for r, v in check_table(table) if r != DELAY]


def decode(levels) -> list[tuple]:
    """Transactions of a (c, d) level sequence (one entry per quarter, or per clock), read as a slave
    does: a start is d falling while c is high, a stop d rising while c is high, a bit is d at c's
    rising edge. Returns ``("w", reg, value)`` for 3-phase writes and ``("r", reg)`` for 2-phase write +
    2-phase read pairs; raises ValueError on anything else (a phase of other than 9 bits, another ID)."""
    out, bits, phases, pending = [], None, [], None
    pc, pd = 1, 1
    for c, d in levels:
        if pc and c and pd != d:
            if not d:  # start
                bits, phases = [], []
            else:  # stop
                # the stop's own SIO_C rise clocked one more bit
                if bits is None or len(bits) % 9 != 1:
                    raise ValueError(f"stop after {0 if bits is None else len(bits) - 1} bits: not whole 9-bit "
                                     f"phases")
                bits = bits[:-1]
                phases = [int("".join(map(str, bits[i:i + 8])), 2) for i in range(0, len(bits), 9)]
                if phases[0] == ID_WRITE and len(phases) == 3:
                    out.append(("w", phases[1], phases[2]))
                elif phases[0] == ID_WRITE and len(phases) == 2:
                    pending = phases[1]
                elif phases[0] == ID_READ and len(phases) == 2 and pending is not None:
                    out.append(("r", pending))
                    pending = None
                else:
                    raise ValueError(f"transaction {[hex(p) for p in phases]} is no SCCB write or read")
                bits = None
        elif c and not pc and bits is not None:
            bits.append(d)
        pc, pd = c, d
    if bits is not None:
        raise ValueError("the sequence ends inside a transaction")
    return out
