"""The pixel fetch port: the rectifier (master) asks for up to four pixels of a 2x2 neighbourhood.

Master: the rectifier's fetch-and-interpolate unit. Slave: the memory side (the SRAM arbiter), which
reads the pixels from the camera frame buffers. Fields (ports ``<arg>_<field>``, e.g. ``fetch_req_x``):

Request (master -> slave, moves on a rising edge with ``req_valid`` and ``req_ready`` high):

``req_valid``  a request is offered (held, unchanged, until it moves)
``req_ready``  slave -> master: the slave takes it
``req_x``      integer source column x of the neighbourhood, 0..width-1 (``intbv(min=0, max=width)``)
``req_y``      integer source row y, 0..height-1
``req_cam``    0 left camera, 1 right camera (which camera's frame buffer)
``req_mask``   4 bits, the pixels wanted; index i is
               0 = (x+1, y+1), 1 = (x, y+1), 2 = (x+1, y), 3 = (x, y).
               Index 0 comes first: its weight dx*dy is ready first in the interpolator (the thesis's
               order). A mask of 0 is not allowed (send no request instead). The master guarantees
               x+1 <= width-1 and y+1 <= height-1 for the indices it asks for.

Response (slave -> master, one pixel per beat, no back-pressure):

``rsp_valid``  a pixel comes back
``rsp_idx``    2 bits, its index i
``rsp_data``   8 bits, the pixel's grey value (Y)

Rules: for every request taken the slave returns exactly popcount(mask) beats, in request order and
within a request by increasing index (indices not asked for are skipped), each after any number of
wait clocks. The master takes every beat; it must be able to hold the responses of all requests it has
outstanding. The slave may take further requests before earlier ones are answered (pipelining);
responses never overtake.

Timing of two requests, mask 1111 and 0101, as the SRAM arbiter answers them on a quiet bus (part of
read latency 2; ``#`` high, ``_`` low, ``.`` don't care; the arbiter takes a request every other clock,
the first pixel comes 11 clocks after its request is taken, then one per clock)::

    cycle      0    1    2    3   ..   10   11   12   13   14   15   16   17
    req_valid  #    #    #    _   ..   _    _    _    _    _    _    _    _
    req_ready  #    _    #    _   ..   #    #    #    #    #    #    #    #
    req_mask   1111 0101 0101 .   ..   .    .    .    .    .    .    .    .
    rsp_valid  _    _    _    _   ..   _    #    #    #    #    #    #    _
    rsp_idx    .    .    .    .   ..   .    0    1    2    3    0    2    .

Under load the arbiter adds wait clocks anywhere between the beats; docs/sram.md has the measured
latencies.
"""

from __future__ import annotations

import numbers

from eyestereo.hdl.common.checks import check_port
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_MAX, FRAME_MIN, FRAME_WIDTH

__all__ = ["FetchPort", "MASK_BITS", "OFFSETS", "check_fetch"]

MASK_BITS = 4
#: (dx, dy) of index i of the 2x2 neighbourhood.
OFFSETS = ((1, 1), (0, 1), (1, 0), (0, 0))


class FetchPort(Bundle):
    """A pixel fetch port bundle for ``width`` x ``height`` source images (see the module docstring); the
    rectifier is the producer (master), the memory side the consumer (slave)."""

    PARAMS = ("width", "height")
    MEMBERS = (Member("req_valid", bool, OUT), Member("req_ready", bool, IN),
               Member("req_x", "width", OUT, ranged=True), Member("req_y", "height", OUT, ranged=True),
               Member("req_cam", bool, OUT), Member("req_mask", MASK_BITS, OUT),
               Member("rsp_valid", bool, IN), Member("rsp_idx", 2, IN), Member("rsp_data", 8, IN))

    def __init__(self, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
        for name, v in (("width", width), ("height", height)):
            if isinstance(v, bool) or not isinstance(v, numbers.Integral) or not FRAME_MIN <= v <= FRAME_MAX:
                raise ValueError(f"FetchPort {name} must be an int in [{FRAME_MIN}, {FRAME_MAX}], got {v!r}")
        self.width, self.height = int(width), int(height)
        self.make()



def check_fetch(name: str, port) -> None:
    """A :class:`FetchPort` port, else a ValueError naming the port and the block."""
    check_port(name, port, FetchPort)
