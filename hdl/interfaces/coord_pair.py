"""The coordinate pair handshake: coordinate warper -> fetch and interpolation unit (thesis 4.2.3, Fig. 4.8).

For every pixel of the rectified image, in raster order, the warper offers one *pair* (Pl, Pr): where to
interpolate the left and the right camera image. The consumer takes a pair with ``read_ack`` whenever
it is ready; pairs are never lost, repeated or reordered. All signals are active high and sampled on the
rising edge of ``clk`` (VHDL/Verilog ports ``<arg>_<field>``, e.g. ``coord_valid``, ``coord_read_ack``).

Fields (warper -> consumer unless marked):

``valid``
    A complete pair sits in the output registers (the warper's R2 level). Once high it stays high, and
    every other field stays unchanged, until the pair is taken.
``read_ack`` (consumer -> warper)
    Takes the offered pair: the pair moves on every rising edge where ``valid`` and ``read_ack`` are both
    high (and the warper's ``enable`` is high). ``read_ack`` while ``valid`` is low does nothing. The
    thesis's consumer pulses it for one clock per pair; holding it high (a ready signal) takes one pair
    per clock for as long as pairs are offered. Any number of clocks may pass before a consumer takes a
    pair: it is never hurried.
``xl``, ``yl``, ``xr``, ``yr``
    Registers X-L, Y-L, X-R, Y-R: the source coordinates in the left and right camera image, unsigned,
    ufix[n, frac]: ``n = bits(S - 1) + frac`` bits, S = the camera image's width for x and its height for
    y, the low ``frac`` bits the fraction (``floor(v * 2**frac)`` of the polynomial's value v). A pixel's
    four neighbours for the bilinear interpolation are (x0, y0) .. (x0 + 1, y0 + 1) with
    ``x0 = xl >> frac`` and weights from ``dx = xl & (2**frac - 1)`` (likewise y).
``oor_l``, ``oor_r``
    Out of range: the left (right) source point lies outside ``[0, S_x - 2] x [0, S_y - 2]``, decided on
    the calculation unit's full precision before the cut; then the pixel is black and that side's
    coordinates are meaningless (they hold the low bits of whatever the polynomial gave). When the flag
    is low, ``x0 + 1 <= S_x - 1`` and ``y0 + 1 <= S_y - 1``: all four neighbours exist.
``eol``, ``eof``
    The image-stream flags of the pair's pixel: ``eol`` on the last pixel of each line, ``eof`` with it
    on the last pixel of the frame (the frame's last pair).

Timing (``#`` high, ``_`` low, ``.`` don't care). The calculation unit delivers one coordinate per clock
in the order X-L, Y-L, X-R, Y-R (``unit out``, the warper's ``select_coord_out``) into the first register
level R1; with the fourth the pair moves to R2 (``valid``). P0 and P1 are taken at once, P2 waits: P3 is
complete meanwhile and held in R1 while the unit stops (``enable cu`` low, the unit frozen with X-L of P4
at its output); the take of P2 moves P3 up at once (``valid`` stays high with new data), the unit resumes
one clock later, and P3 is taken at once::

    cycle      0   1   2   3   4   5   6   7   8   9  10  11  12  13  14  15  16  17  18  19
    unit out  YR0 XL1 YL1 XR1 YR1 XL2 YL2 XR2 YR2 XL3 YL3 XR3 YR3 XL4 XL4 XL4 YL4 XR4 YR4 XL5
    enable cu  #   #   #   #   #   #   #   #   #   #   #   #   #   _   _   #   #   #   #   #
    valid      _   #   _   _   _   #   _   _   _   #   #   #   #   #   #   #   _   _   _   #
    read_ack   _   #   _   _   _   #   _   _   _   _   _   _   _   _   #   #   _   _   _   #
    pair       .  P0   .   .   .  P1   .   .   .  P2  P2  P2  P2  P2  P2  P3   .   .   .  P4

With a consumer that takes every pair within four clocks the unit never stops: one pair every four
clocks. A consumer that registers ``valid`` and pulses ``read_ack`` in the next clock (the thesis's
FAI) takes P0 in clock 2 instead of 1 and keeps the same rate.
"""

from __future__ import annotations

from eyestereo.hdl.common.checks import check_int
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.tools.models import poly_unit as model

__all__ = ["CoordPair"]


class CoordPair(Bundle):
    """A MyHDL interface bundle for the coordinate pair handshake (see the module docstring); the warper
    is the producer.

    Parameters:
        source_width, source_height: the camera images (>= 2 each); they size the coordinates
            (``x_bits``, ``y_bits``: the word lengths of ``x_format``, ``y_format``).
        frac: fraction bits of the coordinates (0..16).
    """

    MEMBERS = (Member("valid", bool, OUT), Member("read_ack", bool, IN),
               Member("xl", "x_bits", OUT), Member("yl", "y_bits", OUT),
               Member("xr", "x_bits", OUT), Member("yr", "y_bits", OUT),
               Member("oor_l", bool, OUT), Member("oor_r", bool, OUT),
               Member("eol", bool, OUT), Member("eof", bool, OUT))

    def __init__(self, source_width: int, source_height: int, frac: int):
        self.source_width = check_int("source_width", source_width, 2, 65536)
        self.source_height = check_int("source_height", source_height, 2, 65536)
        self.frac = check_int("frac", frac, 0, model.MAX_FRAC)
        self.x_format = model.coord_format(self.frac, self.source_width)
        self.y_format = model.coord_format(self.frac, self.source_height)
        self.x_bits, self.y_bits = self.x_format.wl, self.y_format.wl
        self.make()

    def __repr__(self) -> str:
        return (f"CoordPair(source {self.source_width}x{self.source_height}, x {self.x_format}, "
                f"y {self.y_format})")
