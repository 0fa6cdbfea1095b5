"""The descriptor port: the corners of both cameras, each with the words describing its window, row by row.

The matcher's two halves meet here (issue 29): the front half sees the rectified pixels and the corner
flags and sends, for every corner, its position and its **descriptor** (the window's grey levels, a row of
the window per word, or its census word; :mod:`eyestereo.tools.models.match_engine` declares the words);
the engine stores them and matches. No back-pressure: the consumer takes every beat (the engine writes each
word into its stores as it comes and flags what it cannot keep).

Fields (ports come out as ``<arg>_<field>``: ``sink_data``, ``sink_valid``, ...):

``valid``
    A beat.
``data``
    A descriptor word (ignored on a row-end beat).
``last``
    The corner's last word: its descriptor is complete (a one-word descriptor has ``last`` on its only word).
``cam``
    0 left, 1 right: the camera of the corner.
``x``, ``y``
    The corner's position, the same on every word of one corner.
``row_end``
    No corner: every corner of row ``y`` of both cameras has been sent. Every row of the frame gets one,
    in order, rows without corners too; ``eof`` with it on the frame's last row.
``eof``
    With ``row_end``: the frame ends.

Order: the corners of each camera in raster order, all words of one corner in a row (other beats may not
come between them); the two cameras' corners may interleave. The corners of row y come before row y's
row-end beat, and after row y - 1's.

Timing: a two-word descriptor of a left corner, a one-clock gap, a right corner at the same row, the row's
end (``#`` high, ``_`` low, ``.`` don't care)::

    cycle    0    1    2    3    4    5
    valid    #    #    _    #    #    #
    data    d0   d1    .   e0   e1    .
    last     _    #    .    _    #    .
    cam      _    _    .    #    #    .
    x,y     5,3  5,3   .   2,3  2,3  .,3
    row_end  _    _    .    _    _    #
    eof      _    _    .    _    _    _
"""

from eyestereo.hdl.common.checks import block_error, check_port
from eyestereo.hdl.interfaces.bundle import OUT, Bundle, Member
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH


class DescriptorPort(Bundle):
    """A MyHDL interface bundle for one descriptor port (see the module docstring).

    Parameters:
        data_width: bits of a descriptor word (>= 1).
        width, height: the frame size: ``x`` counts 0..width-1, ``y`` 0..height-1.
    """

    PARAMS = ("data_width", "width", "height")
    MEMBERS = (Member("data", "data_width", OUT), Member("valid", bool, OUT), Member("last", bool, OUT),
               Member("cam", bool, OUT), Member("x", "width", OUT, ranged=True),
               Member("y", "height", OUT, ranged=True), Member("row_end", bool, OUT), Member("eof", bool, OUT))

    def __init__(self, data_width: int = 40, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
        for name, v, lo in (("data_width", data_width, 1), ("width", width, 2), ("height", height, 2)):
            if isinstance(v, bool) or not isinstance(v, int) or v < lo:
                raise ValueError(f"DescriptorPort {name} must be an int >= {lo}, got {v!r}")
        self.data_width, self.width, self.height = data_width, width, height
        self.make()


def check_descriptor(name: str, port, *, data_width: int | None = None, width: int | None = None,
                     height: int | None = None) -> None:
    """A :class:`DescriptorPort` of the given sizes, else a ValueError naming the port."""
    check_port(name, port, DescriptorPort)
    for what, want in (("data_width", data_width), ("width", width), ("height", height)):
        if want is not None and getattr(port, what) != want:
            raise block_error(f"port {name} must have {what} {want}, got a DescriptorPort with {what} "
                              f"{getattr(port, what)}")
