"""The image stream: the one pixel interface every eyestereo block speaks.

A stream carries one frame after another in raster order (left to right, top to bottom), one pixel per
valid beat, with no back-pressure: a block must take every valid beat in the clock it is offered. All
signals are active high and sampled on the rising edge of ``clk``.

Fields (VHDL/Verilog ports come out as ``<arg>_<field>``, e.g. ``sink_data``, ``source_valid``):

``data``
    The pixel, ``data_width`` bits, unsigned bit vector. Blocks that carry several or signed values pack
    them into it as a :class:`~eyestereo.tools.packed.PackedWord`, declared once next to the block's model
    (e.g. ``eyestereo.tools.models.sobel.WORD``: ``Iy`` in bits 17..9, ``Ix`` in 8..0, two's complement);
    ``ImageStream(WORD)`` sizes the stream from it.
``valid``
    The other fields mean something only while ``valid`` is high. Idle cycles (``valid`` low) may come
    anywhere, as many as the source likes, also inside a line.
``eol``
    End of line: high with the last pixel of every line.
``eof``
    End of frame: high together with ``eol`` on the last pixel of the frame.
``cam``
    Stereo streams only (``stereo=True``): which camera the beat belongs to (0 left, 1 right).

Reset token: a valid beat with ``eof`` high and ``eol`` low carries no pixel. It aborts the frame in
progress and puts a block back to its start-of-frame state; each block forwards it to its source at once,
so one token sent after power-up initialises a whole chain. The next beat after a token is pixel (0, 0).

Timing of a 4x2 frame with idle cycles, then a reset token and the next frame (``#`` high, ``_`` low,
``.`` don't care; data shows the pixel's (x,y))::

    cycle   0    1    2    3    4    5    6    7    8    9    10   11   12
    valid   _    #    #    _    #    #    #    #    #    #    _    #    #
    eol     .    _    _    .    _    #    _    _    _    #    .    _    _
    eof     .    _    _    .    _    _    _    _    _    #    .    #    _
    data    .   0,0  1,0   .   2,0  3,0  0,1  1,1  2,1  3,1   .   tok  0,0

Stereo streams (``ImageStream(n, stereo=True)``): two frames of the same geometry, interleaved pixel by
pixel: left pixel (x, y) with ``cam`` = 0, then right pixel (x, y) with ``cam`` = 1, then (x + 1, y), ...
``eol`` is high on both beats of a line's last pixel, ``eof`` (with ``eol``) on both beats of the frame's
last pixel; a reset token (``eof`` high, ``eol`` low) with either ``cam`` resets both sides, also between
the two beats of a pixel. Idle cycles may come anywhere, between the two beats of a pixel too; a block
may ask for a minimum spacing of the beats (``harris_stereo``: at least ``share`` clocks apart). Timing
of a 2x2 stereo frame with idle cycles, then a reset token after a left beat and the next frame
(``L``/``R`` = ``cam`` 0/1)::

    cycle   0    1    2    3    4    5    6    7    8    9    10   11   12   13
    valid   #    #    _    #    #    #    #    #    #    _    #    #    #    #
    cam     _    #    .    _    #    _    #    _    #    .    _    #    _    #
    eol     _    _    .    #    #    _    _    #    #    .    _    _    _    _
    eof     _    _    .    _    _    _    _    #    #    .    _    #    _    _
    data   L0,0 R0,0  .   L1,0 R1,0 L0,1 R0,1 L1,1 R1,1  .   L0,0 tok  L0,0 R0,0

Frame geometry is fixed at elaboration (``width`` x ``height`` parameters of each block). A block's source
emits frames of the geometry its docstring states (the sink's, for all filters), with the same
valid/eol/eof pattern per frame, after a latency given in the block's docstring.
"""

from eyestereo.hdl.interfaces.bundle import OUT, Bundle, Member, word_width
from eyestereo.tools.packed import PackedWord


class ImageStream(Bundle):
    """A MyHDL interface bundle for one image stream (see the module docstring for the protocol).

    Parameters:
        data_width: bits of ``data`` (>= 1), or the :class:`~eyestereo.tools.packed.PackedWord` the
            stream carries (its width is taken, and the word is kept as ``stream.word``).
        stereo: add the ``cam`` field.
    """

    PARAMS = ("data_width", "stereo")
    MEMBERS = (Member("data", "data_width", OUT), Member("valid", bool, OUT), Member("eol", bool, OUT),
               Member("eof", bool, OUT), Member("cam", bool, OUT, when="stereo"))

    def __init__(self, data_width: int | PackedWord = 8, *, stereo: bool = False):
        self.data_width, self.word = word_width("ImageStream", data_width)
        if not isinstance(stereo, bool):
            raise ValueError(f"ImageStream stereo must be True or False, got {stereo!r}")
        self.stereo = stereo
        self.make()
