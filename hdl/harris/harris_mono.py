"""Mono Harris corner detector: Sobel -> window -> cornerness -> pre-threshold -> NMS, one pixel per clock."""

from myhdl import block

from eyestereo.hdl.harris.cornerness import LATENCY as CORNER_LATENCY
from eyestereo.hdl.harris.cornerness import cornerness
from eyestereo.hdl.harris.harris_window import LATENCY as WINDOW_LATENCY
from eyestereo.hdl.harris.harris_window import harris_window
from eyestereo.hdl.harris.nms import nms as nms_block
from eyestereo.hdl.harris.prethreshold import prethreshold
from eyestereo.hdl.harris.sobel import LATENCY as SOBEL_LATENCY
from eyestereo.hdl.harris.sobel import sobel
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models.harris_mono import check_params, k_code, radius, threshold_code  # noqa: F401 (re-export)
from eyestereo.tools.models.prethreshold import check_blocks
from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct, check_frame,
                                         check_reset, check_signal, check_stream, checked)


def latency(nms: int) -> tuple[int, int]:
    """(clocks, window lead r): flag (x, y) comes that many clocks after input pixel (x + r, y + r)."""
    nms_lat = 1 if nms == 1 else nms + 3
    return SOBEL_LATENCY + WINDOW_LATENCY + CORNER_LATENCY + 1 + nms_lat, radius(nms)


@block
def harris_mono(clk, rst, sink, source, k, thr_we, thr_addr, thr_data, *, width: int = 352,
                height: int = 288, blocks: tuple[int, int] = (4, 4), nms: int = 3):
    """Harris corners of an 8-bit grey stream: ``source`` flag (x, y) = 1 for a corner at input pixel (x, y).

    The chain of :func:`~eyestereo.hdl.harris.sobel.sobel`, :func:`~eyestereo.hdl.harris.harris_window.harris_window`,
    :func:`~eyestereo.hdl.harris.cornerness.cornerness`, :func:`~eyestereo.hdl.harris.prethreshold.prethreshold` and
    :func:`~eyestereo.hdl.harris.nms.nms`, each keeping the frame geometry, so the output frame has the input's
    size and flags. Flags within r = 3 + nms // 2 pixels of the border are unspecified.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: ImageStream, 8-bit grey pixels; mono only (a stereo stream is refused).
        source: ImageStream, 1 bit: the feature flag.
        k: input, 8 bits unsigned, ufix[8,8] (k = code / 256); ``k_code(0.04)`` gives the code.
        thr_we, thr_addr, thr_data: the pre-threshold's register port (block index by*BX + bx, 20-bit
            threshold code; ``threshold_code(c)`` converts a threshold in harris_float units). All
            thresholds are 0 after ``rst``.

    Parameters:
        width, height: frame size, each 5..4096, default 352x288.
        blocks: (BX, BY) threshold blocks, default (4, 4): 88x72-pixel blocks at 352x288.
        nms: 1, 3 or 5: non-maximum suppression window.

    Latency: :func:`latency` -- nms 3: 4 lines + 4 pixels + 29 clocks; nms 5: 5 lines + 5 pixels +
    31 clocks; nms 1: 3 lines + 3 pixels + 24 clocks.

    Resources: 6 (nms 1) to 10 (nms 5) RAMB16, 7 multipliers (3 window, 4 cornerness); see docs/benchmarks.md.
    """
    # Every port and parameter is checked here, so no error comes from inside one of the five blocks.
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8)
    check_stream("source", source, width=1)
    check_signal("k", k, width=corner_model.K.wl, signed=False)
    check_signal("thr_we", thr_we, width=1)
    check_signal("thr_addr", thr_addr, signed=False)
    check_signal("thr_data", thr_data, width=nb, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, k=k, thr_we=thr_we, thr_addr=thr_addr,
                                             thr_data=thr_data))
    width, height = check_frame(width, height, min_size=5)
    nms = check_choice("nms", nms, (1, 3, 5))
    blocks = checked(check_blocks, width, height, blocks)
    abits = max(1, (blocks[0] * blocks[1] - 1).bit_length())
    if len(thr_addr) < abits:
        raise block_error(f"port thr_addr needs {abits} bits for {blocks[0] * blocks[1]} blocks, has {len(thr_addr)}")
    s_sobel = ImageStream(sobel_model.WORD)
    s_window = ImageStream(window_model.WORD)
    s_corner = ImageStream(corner_model.WORD)
    s_pre = ImageStream(corner_model.WORD)
    return [
        sobel(clk, rst, sink, s_sobel, width=width, height=height),
        harris_window(clk, rst, s_sobel, s_window, width=width, height=height),
        cornerness(clk, rst, s_window, s_corner, k, width=width, height=height),
        prethreshold(clk, rst, s_corner, s_pre, thr_we, thr_addr, thr_data, width=width, height=height,
                     blocks=blocks),
        nms_block(clk, rst, s_pre, source, width=width, height=height, size=nms),
    ]
