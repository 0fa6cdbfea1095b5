r"""The camera bus: what an OmniVision OV6630 (or any camera with a DVP-style parallel port) drives.

Thesis 7.1 (Fig. 7.3): each camera sends 8-bit YUV 4:2:2 with its own pixel clock, a frame sync and a
line reference. The FPGA only listens; all four signals come from the camera.

Fields (ports come out as ``<arg>_<field>``, e.g. ``cam_pclk``, ``cam_data``):

``pclk``
    The camera's pixel clock (about 18 MHz for the OV6630 in 8-bit mode: two clocks per pixel). The
    camera changes ``vsync``, ``href`` and ``data`` after the falling edge; the FPGA samples them on the
    rising edge (the OV6630 data sheet: "PCLK rising edge latch data bus").
``vsync``
    Frame sync: active for a few line periods before each frame's first line (polarity: a parameter of
    the receiving block).
``href``
    Line reference: active while a line's ``2 * width`` data bytes are on the bus, inactive in the
    horizontal and vertical blanking (polarity: a parameter).
``data``
    One byte per PCLK while ``href`` is active. A line is a sequence of pixel pairs, four bytes each,
    in the camera's byte order: ``YUYV`` (the thesis's Y U Y V, the default), ``YVYU``, ``UYVY`` or
    ``VYUY``; Y0 and Y1 are the luma of the pair's even and odd pixel, U and V the chroma both share.

Timing of the end of a frame, the vertical sync and a 4-pixel line (8 bytes; ``#`` high = active, ``_``
low, ``.`` don't care; one column per PCLK: the values the rising edge ``/`` of that column samples)::

    pclk    _/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\_/~~\
    vsync    _    #    #    #    _    _    _    _    _    _    _    _    _    _    _    _    _    _
    href     _    _    _    _    _    #    #    #    #    #    #    #    #    _    _    #    #    #
    data     .    .    .    .    .    Y0   U0   Y1   V0   Y2   U2   Y3   V2   .    .    Y0   U0   Y1
             |  vertical sync |       line 0: 2 x width bytes         |h.blank | line 1 ...

(The blanking is shortened; the defaults of :class:`eyestereo.tools.camera.CameraTiming` are 192 PCLK of
horizontal blanking and 3 + 19 + 86 blank line periods around the 288 lines: 50 frames/s at 17.73 MHz.)

The receiving block, :func:`eyestereo.hdl.camera.camera_stream.camera_stream`, turns this into one 16-bit word
per pixel (Y in bits 7..0, U for even and V for odd pixels in bits 15..8) and an image stream; the
Python side (timing, schedules, byte orders) is :mod:`eyestereo.tools.camera`, the cocotb camera model
:mod:`eyestereo.sim.lib.camera`.
"""

import numbers

from eyestereo.hdl.interfaces.bundle import OUT, Bundle, Member


class CameraBus(Bundle):
    """A MyHDL interface bundle for one camera port (see the module docstring for the timing); the camera
    is the producer of every member.

    Parameters:
        data_width: bits of ``data`` (8 for the OV6630's 8-bit mode).
    """

    PARAMS = ("data_width",)
    MEMBERS = (Member("pclk", bool, OUT), Member("vsync", bool, OUT), Member("href", bool, OUT),
               Member("data", "data_width", OUT))

    def __init__(self, data_width: int = 8):
        if isinstance(data_width, bool) or not isinstance(data_width, numbers.Integral) or data_width < 1:
            raise ValueError(f"CameraBus data_width must be an int >= 1, got {data_width!r}")
        self.data_width = int(data_width)
        self.make()
