"""The queue read port: a FIFO's read side offering image-stream words with valid/ready flow control.

The camera path's async FIFO (camera clock -> memory clock) presents its words on this port and the SRAM
arbiter's camera writers take them; the feature-list writer takes feature words the same way. Fields
(ports ``<arg>_<field>``):

``data``   the word (camera words: 16 bits, Y in 7..0, the pixel's chroma sample U (even x) or V (odd x)
           in 15..8; feature words: 16 bits)
``eol``    with the last word of a line
``eof``    with the last word of a frame (and ``eol``, as in the image stream; a feature list has no lines:
           ``eof`` alone marks its last word)
``valid``  source -> sink: a word is offered
``ready``  sink -> source: the sink takes it

A word moves on a rising edge with ``valid`` and ``ready`` both high. The source holds the word until it
moves; the sink may drive ``ready`` regardless of ``valid`` (the SRAM writers derive it from registers
only). Frames come whole: the async FIFO drops a broken frame on its write side and never presents
part of one. For image frames a word with ``eof`` high and ``eol`` low is a reset token, as in the
image stream (the camera writers abandon the frame in progress); a feature list has no lines, and the
feature writer reads ``eof`` as the end of its list whatever ``eol`` says.

Timing (``#`` high, ``_`` low, ``.`` don't care; ``^`` marks the edges words move on)::

    cycle   0    1    2    3    4    5    6
    valid   _    #    #    #    _    #    #
    ready   #    #    _    #    #    #    _
    data    .    w0   w1   w1   .    w2   w3
    moves        ^w0       ^w1       ^w2
"""

from __future__ import annotations

import numbers

from myhdl import Signal, intbv

__all__ = ["QueuePort"]


class QueuePort:
    """A queue read port bundle (see the module docstring)."""

    def __init__(self, data_width: int = 16):
        if isinstance(data_width, bool) or not isinstance(data_width, numbers.Integral) or data_width < 1:
            raise ValueError(f"QueuePort data_width must be an int >= 1, got {data_width!r}")
        self.data_width = int(data_width)
        self.data = Signal(intbv(0)[self.data_width:])
        self.valid = Signal(bool(0))
        self.ready = Signal(bool(0))
        self.eol = Signal(bool(0))
        self.eof = Signal(bool(0))

    def fields(self) -> list[str]:
        return ["data", "valid", "ready", "eol", "eof"]

    def __repr__(self) -> str:
        return f"QueuePort(data_width={self.data_width})"
