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

from eyestereo.hdl.common.checks import block_error, check_port
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member, word_width
from eyestereo.tools.packed import PackedWord


class QueuePort(Bundle):
    """A MyHDL interface bundle for one queue read port (see the module docstring for the handshake).

    Parameters:
        data_width: bits of ``data``, or the :class:`~eyestereo.tools.packed.PackedWord` it carries.
    """

    PARAMS = ("data_width",)
    MEMBERS = (Member("data", "data_width", OUT), Member("valid", bool, OUT), Member("ready", bool, IN),
               Member("eol", bool, OUT), Member("eof", bool, OUT))

    def __init__(self, data_width: int | PackedWord = 16):
        self.data_width, self.word = word_width("QueuePort", data_width)
        self.make()



def check_queue(name: str, port, *, width: int | None = None) -> None:
    """A :class:`QueuePort` port of ``width`` data bits, else a ValueError naming the port."""
    check_port(name, port, QueuePort)
    if width is not None and port.data_width != width:
        raise block_error(f"port {name} must carry {width}-bit data, got a QueuePort of {port.data_width} bits")
