"""AXI4-Stream video: the interface of Xilinx's video IP, for the bridges to and from the image stream.

The convention is AMBA AXI4-Stream with the video usage of Xilinx UG934 ("AXI4-Stream Video IP and
System Design Guide"): one pixel per transfer, raster order, and the frame structure carried by two
sideband signals. All signals are active high and sampled on the rising edge of the clock; VHDL/Verilog
ports come out as ``<arg>_<field>`` (``source_tdata``, ``sink_tready``, ...), the names Vivado's
interface inference and cocotbext-axi's ``AxiStreamBus.from_prefix`` look for.

Fields:

``tdata``
    The pixel, ``8 * ceil(data_width / 8)`` bits: the image stream's data in the low ``data_width``
    bits, zeros above (UG934 pads every component to whole bytes).
``tvalid``
    Master -> slave: a transfer is offered. Once high it stays high, with ``tdata/tlast/tuser``
    unchanged, until the slave takes it (AXI4-Stream rule; it must not wait for ``tready``).
``tready``
    Slave -> master: the slave takes the offered transfer. A transfer happens on a rising edge with
    ``tvalid`` and ``tready`` both high. ``tready`` may be low for as long as the slave likes.
``tlast``
    End of line (UG934's EOL): high on the last pixel of every line.
``tuser``
    Start of frame (UG934's SOF, ``tuser(0)``): high on the first pixel of every frame, pixel (0, 0).

There is no end-of-frame signal: a frame ends where the next one starts. A frame whose SOF comes before
its last line is complete ("early SOF" in UG934's terms) is a **cut frame**: the eyestereo bridges send
one when their FIFO overflows (:func:`eyestereo.hdl.axi.stream_to_axis.stream_to_axis`) and turn one into a
reset token of the image stream (:func:`eyestereo.hdl.axi.axis_to_stream.axis_to_stream`).

Timing of a 3x2 frame with back-pressure (``tready`` low in cycles 3 and 6: the offered beat waits),
an idle cycle, and the next frame's first pixel (``#`` high, ``_`` low, ``.`` don't care; data shows
the pixel's (x,y); ``^`` marks the transfers)::

    cycle    0    1    2    3    4    5    6    7    8    9    10
    tvalid   _    #    #    #    #    #    #    #    _    #    #
    tready   #    #    #    _    #    #    _    #    #    #    #
    tuser    .    #    _    _    _    _    _    _    .    _    #
    tlast    .    _    _    #    #    _    _    _    .    #    _
    tdata    .   0,0  1,0  2,0  2,0  0,1  1,1  1,1   .   2,1  0,0
    moves         ^    ^         ^    ^         ^         ^    ^

The WaveDrom form of this diagram is ``docs/wavedrom/axis_video.json`` (``make timing`` renders it).
"""

from __future__ import annotations

from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member, word_width
from eyestereo.tools.packed import PackedWord


def tdata_width(data_width: int) -> int:
    """Bits of ``tdata`` for a pixel of ``data_width`` bits: whole bytes (UG934)."""
    return 8 * ((int(data_width) + 7) // 8)


class AxiStream(Bundle):
    """A MyHDL interface bundle for an AXI4-Stream video port (see the module docstring for the protocol).

    Parameters:
        data_width: bits of the pixel it carries (the image stream's ``data_width``), or a
            :class:`~eyestereo.tools.packed.PackedWord`; ``tdata`` has that many bits rounded up to
            whole bytes (``tdata_bits``).
    """

    MEMBERS = (Member("tdata", "tdata_bits", OUT), Member("tvalid", bool, OUT), Member("tready", bool, IN),
               Member("tlast", bool, OUT), Member("tuser", bool, OUT))

    def __init__(self, data_width: int | PackedWord = 8):
        self.data_width, _ = word_width("AxiStream", data_width)
        self.tdata_bits = tdata_width(self.data_width)
        self.make()

    def __repr__(self) -> str:
        return f"AxiStream(data_width={self.data_width}, tdata={len(self.tdata)} bits)"
