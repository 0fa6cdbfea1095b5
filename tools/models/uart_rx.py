"""Bit-level model of :func:`eyestereo.hdl.serial.uart_rx.uart_rx`: the line sampled at each clock -> bytes.

The receiver's rule, clock by clock (the VHDL's, edge for edge):

* the line goes through two flip-flops (a synchroniser: it comes from another clock domain, the
  FT231X's); the state machine sees the line as it was two edges before;
* after reset and after a framing error it waits for the line to be high (a line held low, a *break*,
  makes no bytes); then a low line starts a byte;
* the start bit is checked ``h = (clocks_per_bit + 1) // 2`` clocks after the low was first seen, near its
  middle: still low, the byte goes on; high again, it was a glitch (no byte, no error): a pulse shorter
  than half a bit covers at most ``h`` samples, so it never passes;
* the 8 data bits and the stop bit are sampled ``clocks_per_bit`` clocks apart from there (their
  middles); a stop bit of 1 delivers the byte, a stop bit of 0 is a framing error (the byte is dropped)
  and the receiver waits for the line to go high again;
* right after a stop bit's sample it looks for the next start bit, so a sender up to a few percent fast
  loses nothing (the next start edge may come half a bit early).

:func:`uart_rx` returns the events with the edge they happen at: ``(k, "byte", value)`` (``source.valid``
rises after edge k) and ``(k, "framing", None)`` (``frame_error`` high for the clock after edge k).
:func:`sample` turns a line given as transition times into per-edge samples. Pure Python.
"""

from __future__ import annotations

from eyestereo.tools.models.uart_tx import frame_bits

__all__ = ["check_offset", "sample", "uart_rx", "waveform"]


def check_offset(clocks_per_bit: int) -> int:
    """Clocks from the first low sample of a start bit to its check (and from each bit's edge to its sample)."""
    return (int(clocks_per_bit) + 1) // 2


def waveform(data, bit_time: float, *, start: float = 0.0, gap: float = 0.0, stop_bits=None):
    """Transitions ``[(time, level), ...]`` of a sender at ``bit_time`` per bit (any unit, e.g. ps): the
    bytes of ``data`` from ``start`` on, ``gap`` idle time after each stop bit. ``stop_bits``: per byte the
    level of its stop bit (default all 1; a 0 makes a framing error). Returns (transitions, end time)."""
    out: list[tuple[float, int]] = []
    level, t = 1, float(start)
    for i, b in enumerate(data):
        bits = frame_bits(b)
        if stop_bits is not None:
            bits[9] = int(stop_bits[i])
        for bit in bits:
            if bit != level:
                out.append((t, bit))
                level = bit
            t += bit_time
        if level == 0:  # a 0 stop bit: the line goes back high after it
            out.append((t, 1))
            level = 1
        t += gap
    return out, t


def sample(transitions, edge_times) -> list[int]:
    """The line at each edge: the level of the last transition strictly before the edge (1 before any)."""
    out, j, level = [], 0, 1
    trans = sorted(transitions)
    for t in edge_times:
        while j < len(trans) and trans[j][0] < t:
            level = trans[j][1]
            j += 1
        out.append(level)
    return out


def uart_rx(samples, clocks_per_bit: int) -> list[tuple[int, str, int | None]]:
    """The receiver's events for the line ``samples`` (``samples[k]``: the line at edge k, edge 0 the first
    after reset; the synchroniser's flip-flops hold 1 out of reset). See the module docstring."""
    cpb = int(clocks_per_bit)
    h = check_offset(cpb)
    s1 = s2 = 1
    state, bit, count, shreg = "break", 0, 0, 0
    events: list[tuple[int, str, int | None]] = []
    for k, v in enumerate(samples):
        seen = s2  # what the state machine sees at edge k: the line at edge k - 2
        if state == "break":
            if seen:
                state = "idle"
        elif state == "idle":
            if not seen:
                state, bit, count = "recv", 0, h - 1
        elif count:
            count -= 1
        else:
            count = cpb - 1
            if bit == 0:
                if seen:
                    state = "idle"  # a glitch: the start bit did not last to its middle
                else:
                    bit = 1
            elif bit <= 8:
                shreg = (seen << 7) | (shreg >> 1)
                bit += 1
            elif seen:
                events.append((k, "byte", shreg))
                state = "idle"
            else:
                events.append((k, "framing", None))
                state = "break"
        s1, s2 = int(v), s1
    return events
