"""Dense disparity of a rectified stereo stream: census, semi-global matching and the median (issue 28)."""

from myhdl import block

from eyestereo.hdl.common.checks import (block_error, check_bool, check_choice, check_clock, check_distinct,
                                         check_frame, check_int, check_reset, check_signal, check_stream)
from eyestereo.hdl.dense.census import census
from eyestereo.hdl.dense.median3 import median3
from eyestereo.hdl.dense.sgm import PU_CHOICES, sgm
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.census import WINDOWS, census_bits
from eyestereo.tools.models.dense_stereo import DEFAULTS, WIDTHS
from eyestereo.tools.models.sgm import D_RANGE, PATHS


def fifo_depth(window: int, width: int) -> int:
    """sgm's FIFO in the chain: a power of two that holds census's frame tail (``window // 2`` lines and
    pixels, pushed out at up to a pixel per two clocks after the frame's last beat) and 64 more."""
    r = window // 2
    return 1 << (r * width + r + 64 - 1).bit_length()


@block
def dense_stereo(clk, rst, sink, source, p1, p2, uniqueness, lr_check, subpixel, overrun, *,
                 window: int = DEFAULTS["window"], disparities: int = DEFAULTS["disparities"], pu: int = 4,
                 paths: int = DEFAULTS["paths"], median: bool = DEFAULTS["median"],
                 path_bits: int = WIDTHS["path_bits"], sum_shift: int = WIDTHS["sum_shift"],
                 frac_bits: int = WIDTHS["frac_bits"], fifo: int | None = None, width: int = FRAME_WIDTH,
                 height: int = FRAME_HEIGHT):
    """Disparity codes of the left image of a rectified stereo stream
    (:func:`eyestereo.tools.models.dense_stereo.dense_stereo`, bit for bit).

    The chain: :func:`~eyestereo.hdl.dense.census.census` (both cameras), :func:`~eyestereo.hdl.dense.sgm.sgm`
    (costs, paths, winner take all, uniqueness, left-right check, sub-pixel) and, with ``median``,
    :func:`~eyestereo.hdl.dense.median3.median3`. Each stage speaks the image stream; the sgm block's input
    FIFO takes the census words at the camera's pace.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 8-bit grey pixels (left and right beat of each pixel), rectified. On
            average at most one pixel per :func:`eyestereo.hdl.dense.sgm.spacing` clocks.
        source: mono ImageStream(16): the code of each left pixel (1/16 px, 0xFFFF invalid), raster order,
            a row at a time at one beat per clock.
        p1, p2, uniqueness, lr_check, subpixel: the run-time settings (8, 8, 7, 1, 1 bits; see sgm).
        overrun: sgm's FIFO lost a pixel (sticky until ``rst`` or a reset token).

    Parameters:
        window, disparities, pu, paths, path_bits, sum_shift, frac_bits: as :func:`sgm` (and census's
            window). fifo: sgm's input FIFO; None (default): the power of two that holds the census's frame
            tail, ``window // 2`` lines + ``window // 2`` pixels + 64, which census pushes out at up to a pixel
            per two clocks after the frame's last beat (352 x 288, 5 x 5: 1024).
        median: the 3 x 3 median after sgm (an elaboration choice: without it the
            block is smaller and one row + 8 clocks faster). width, height: the frame.

    Latency: census's (window // 2 rows and pixels + window + 3 clocks), then sgm's (a row's codes follow
    its last pixel; see sgm), then median3's (one row + one pixel + 7 clocks).

    Resources: the sum of the three blocks' (see each); nothing else.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8, stereo=True)
    check_stream("source", source, width=16, stereo=False)
    for name, sig, bits in (("p1", p1, 8), ("p2", p2, 8), ("uniqueness", uniqueness, 7), ("lr_check", lr_check, 1),
                            ("subpixel", subpixel, 1), ("overrun", overrun, 1)):
        check_signal(name, sig, width=bits)
    check_distinct(dict(source=source, overrun=overrun),
                   dict(clk=clk, rst=rst, sink=sink, p1=p1, p2=p2, uniqueness=uniqueness, lr_check=lr_check,
                        subpixel=subpixel))
    # the chain's own checks first, so that a bad value is reported with this block's name
    median = check_bool("median", median)
    window = check_choice("window", window, WINDOWS)
    disparities = check_int("disparities", disparities, *D_RANGE)
    pu = check_choice("pu", pu, PU_CHOICES)
    paths = check_choice("paths", paths, PATHS)
    width, height = check_frame(width, height)
    if fifo is None:
        fifo = fifo_depth(window, width)
    fifo = check_int("fifo", fifo, 2, 1 << 14)
    path_bits, sum_shift, frac_bits = (check_int(n, v) for n, v in (("path_bits", path_bits),
                                                                    ("sum_shift", sum_shift),
                                                                    ("frac_bits", frac_bits)))
    if width <= disparities:
        raise block_error(f"frame {width}x{height}: width must exceed the {disparities} disparities")
    words = ImageStream(census_bits(window), stereo=True)
    codes = ImageStream(16)
    insts = [census(clk, rst, sink, words, window=window, width=width, height=height),
             sgm(clk, rst, words, codes if median else source, p1, p2, uniqueness, lr_check, subpixel, overrun,
                 disparities=disparities, pu=pu, paths=paths, window=window, path_bits=path_bits,
                 sum_shift=sum_shift, frac_bits=frac_bits, fifo=fifo, width=width, height=height)]
    if median:
        insts.append(median3(clk, rst, codes, source, width=width, height=height))
    return insts
