"""The queue read port: an image stream with back-pressure, as the async FIFO's read side presents it.

The image stream (:mod:`eyestereo.hdl.interfaces.stream`) has no back-pressure: a block takes every beat. A queue
read port adds ``ready`` so that a consumer that must sometimes wait (an SRAM writer sharing the memory
with other masters) can hold the words back; the queue behind it absorbs them.

Fields (ports come out as ``<arg>_<field>``: ``source_data``, ``source_valid``, ``source_ready``, ...):

``data``, ``eol``, ``eof``
    As in the image stream: one pixel per word, raster order, ``eol`` on each line's last pixel,
    ``eof`` with ``eol`` on the frame's last pixel; a word with ``eof`` high and ``eol`` low is a reset
    token (below).
``valid`` (queue -> consumer)
    A word is offered. Once high, ``valid`` and the word stay until taken.
``ready`` (consumer -> queue)
    The consumer takes the offered word. ``ready`` may be high with ``valid`` low, and may depend on
    ``valid`` (a consumer may wait for ``valid`` before raising ``ready``).

A word moves on a rising edge of the read clock at which ``valid`` and ``ready`` are both high.

Frames: a frame that comes out whole, ending with ``eof``, is good: every word of it, in order, nothing
missing and nothing extra. A frame the queue could not deliver whole (a word was lost because the queue
overflowed, the camera's frame was broken, the writing side was reset) ends, after whatever part of it
already came out, with a **reset token** instead of its remaining words: the consumer discards the partial
frame and expects the next word to be pixel (0, 0) of a new frame. A frame of which nothing had come out
is dropped without a token. So a consumer never sees a short or long frame end with ``eof``: it keeps
(or publishes) a frame only on ``eof``.

Camera words (:data:`eyestereo.tools.camera.WORD`): 16 bits per pixel, Y in bits 7..0, the pixel's chroma
sample in bits 15..8 (U for even x, V for odd x).

Timing: 2x1 frames (two words each): a good frame with a consumer stall, a frame aborted after its first
word, the next good frame (``#`` high, ``_`` low, ``.`` don't care; ``*``: a word moves at the rising edge
that ends the cycle)::

    cycle   0    1    2    3    4    5    6    7    8    9
    valid   _    #    #    #    _    #    #    #    #    _
    ready   #    _    #    #    #    #    #    #    #    #
    eol     .    _    _    #    .    _    _    _    #    .
    eof     .    _    _    #    .    _    #    _    #    .
    data    .   0,0  0,0  1,0   .   0,0  tok  0,0  1,0   .
    moves             *    *         *    *    *    *
"""

import numbers

from myhdl import Signal, intbv

from eyestereo.hdl.common.checks import block_error
from eyestereo.tools.packed import PackedWord


class QueuePort:
    """A MyHDL interface bundle for one queue read port (see the module docstring for the handshake).

    Parameters:
        data_width: bits of ``data``, or the :class:`~eyestereo.tools.packed.PackedWord` it carries.
    """

    def __init__(self, data_width: int | PackedWord = 16):
        self.word = None
        if isinstance(data_width, PackedWord):
            self.word = data_width
            data_width = data_width.width
        if isinstance(data_width, bool) or not isinstance(data_width, numbers.Integral) or data_width < 1:
            raise ValueError(f"QueuePort data_width must be an int >= 1 or a PackedWord, got {data_width!r}")
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


def check_queue(name: str, port, *, width: int | None = None) -> None:
    """A :class:`QueuePort` port of ``width`` data bits, else a ValueError naming the port."""
    if not isinstance(port, QueuePort):
        what = "None" if port is None else type(port).__name__
        raise block_error(f"port {name} must be a QueuePort (valid/ready/data/eol/eof), got {what}")
    if width is not None and port.data_width != width:
        raise block_error(f"port {name} must carry {width}-bit data, got a QueuePort of {port.data_width} bits")
