"""Stereo Harris corner detector: one datapath for both cameras, shared line delays and multipliers (thesis 6.3)."""

from myhdl import ConcatSignal, block

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct, check_frame,
                                         check_reset, check_signal, check_stream, checked)
from eyestereo.hdl.harris.cornerness import cornerness
from eyestereo.hdl.harris.cornerness import latency as corner_latency
from eyestereo.hdl.harris.cornerness import multipliers as corner_multipliers
from eyestereo.hdl.harris.harris_window import harris_window
from eyestereo.hdl.harris.harris_window import latency as window_latency
from eyestereo.hdl.harris.harris_window import multipliers as window_multipliers
from eyestereo.hdl.harris.nms import nms as nms_block
from eyestereo.hdl.harris.nms import stereo_latency as nms_latency
from eyestereo.hdl.harris.nms import stereo_lead as nms_lead
from eyestereo.hdl.harris.prethreshold import prethreshold
from eyestereo.hdl.harris.sobel import LATENCY as SOBEL_LATENCY
from eyestereo.hdl.harris.sobel import sobel
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models.harris_mono import k_code, radius, threshold_code  # noqa: F401 (re-export)
from eyestereo.tools.constants import SHARE_FACTORS
from eyestereo.tools.models.prethreshold import check_blocks


def latency(nms: int, share: int) -> tuple[int, int, int]:
    """(clocks, lines, pixels): camera c's flag (x, y) comes that many clocks after its input beat of pixel
    (x + pixels, y + lines): Sobel 1 + window 2 + the NMS's :func:`~eyestereo.hdl.harris.nms.stereo_lead`."""
    lines, pixels = nms_lead(nms)
    return (SOBEL_LATENCY + window_latency(share, stereo=True) + corner_latency(share) + 1 + nms_latency(nms),
            3 + lines, 3 + pixels)


def multipliers(share: int) -> int:
    """MULT18X18s of the detector: window products + cornerness."""
    return window_multipliers(share) + corner_multipliers(share)


@block
def harris_stereo(clk, rst, sink, source, k_left, k_right, thr_we, thr_cam, thr_addr, thr_data, *,
                  width: int = 352, height: int = 288, blocks: tuple[int, int] = (4, 4), nms: int = 3,
                  share: int = 3):
    """Harris corners of both cameras of a stereo stream: ``source`` flag (x, y, cam) = a corner of that camera.

    Sobel -> window -> cornerness -> pre-threshold -> NMS as in :func:`~eyestereo.hdl.harris.harris_mono.harris_mono`,
    each stage processing the left and right beats of the stereo stream in turn (the same blocks as the mono
    chain, each taking the camera count from its stereo sink). The line
    delays are stereo line delays (both cameras in one block RAM, 2 x width words); the multipliers are
    time-shared over ``share`` clocks: the window's three products take 3 / 2 / 1 multipliers and the
    cornerness's four take 4 / 2 / 2 for share 1 / 2 / 3 (7 / 4 / 3 in all; two mono detectors: 14).
    For each camera the flags equal bit for bit those of ``harris_mono`` on that camera's frame with
    that camera's ``k`` and thresholds. Flags within r = 3 + nms // 2 of the border are unspecified.

    Input rule: valid beats (reset tokens included) at least ``share`` clocks apart: share 3 takes a
    pixel pair every 6 clocks (50 MHz: 8.3 M pairs/s, 82 stereo frames/s at 352x288), share 1 a beat
    every clock. The output keeps the rule: its tail after each frame comes one beat every ``share``
    clocks.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 8-bit grey pixels, left and right pixel of each (x, y) in turn.
        source: stereo ImageStream, 1 bit: the feature flag, same geometry and interleaving.
        k_left, k_right: inputs, 8 bits unsigned, ufix[8,8] (k = code / 256, ``k_code(0.04)``), one per camera.
        thr_we, thr_cam, thr_addr, thr_data: the pre-threshold's register write port: camera select
            (0 left, 1 right), block index by*BX + bx, 20-bit threshold code (``threshold_code(c)``).
            All thresholds are 0 after ``rst``; write between frames.

    Parameters:
        width, height: frame size, each 5..4096, default 352x288.
        blocks: (BX, BY) threshold blocks per camera, default (4, 4) (2 x 16 thresholds).
        nms: 1, 3 or 5: non-maximum suppression window.
        share: 1, 2 or 3 (default 3, the thesis's design): clocks per beat the multipliers are shared over.

    Latency: :func:`latency`: flag (x, y) comes a constant number of clocks after the camera's input
    pixel (x + 3 + p, y + 3 + l) (nms 3: l = 1, p = 2; nms 1: 0, 0; nms 5: 2, 2); share 3, nms 3:
    4 lines + 5 pixels of the camera (2 (4 width + 5) beats) + 28 clocks (measured by the benches).

    Resources: stereo line delays: 2 Sobel (1 RAMB16 each), 4 window (2 each), 1 NMS 3x3 (2) -- 12
    RAMB16 at 352 wide for nms 3; :func:`multipliers` MULT18X18. Measured (make synth's flow, Yosys
    xc3se, 352x288, 4x4, nms 3): share 3: 1412 LUT + 40 LUT-RAM, 2133 FF, 12 RAMB16, 3 MULT18X18, 114.3 MHz
    on ECP5, the slowest of nextpnr seeds 1-4 (thesis Table 6.4: 3473 LUT, 12, 3); before issue 23's
    re-pipelining share 2: 1526 / 12 / 4, share 1: 1464 / 12 / 7; per module in docs/harris_stereo.md.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8, stereo=True)
    check_stream("source", source, width=1, stereo=True)
    check_signal("k_left", k_left, width=corner_model.K.wl, signed=False)
    check_signal("k_right", k_right, width=corner_model.K.wl, signed=False)
    check_signal("thr_we", thr_we, width=1)
    check_signal("thr_cam", thr_cam, width=1)
    check_signal("thr_addr", thr_addr, signed=False)
    check_signal("thr_data", thr_data, width=nb, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, k_left=k_left, k_right=k_right,
                                             thr_we=thr_we, thr_cam=thr_cam, thr_addr=thr_addr, thr_data=thr_data))
    width, height = check_frame(width, height, min_size=5)
    nms = check_choice("nms", nms, (1, 3, 5))
    share = check_choice("share", share, SHARE_FACTORS)
    blocks = checked(check_blocks, width, height, blocks)
    abits = max(1, (blocks[0] * blocks[1] - 1).bit_length())
    if len(thr_addr) < abits:
        raise block_error(f"port thr_addr needs {abits} bits for {blocks[0] * blocks[1]} blocks, has {len(thr_addr)}")
    s_sobel = ImageStream(sobel_model.WORD, stereo=True)
    s_window = ImageStream(window_model.WORD, stereo=True)
    s_corner = ImageStream(corner_model.WORD, stereo=True)
    s_pre = ImageStream(corner_model.WORD, stereo=True)
    return [
        sobel(clk, rst, sink, s_sobel, width=width, height=height, share=share),
        harris_window(clk, rst, s_sobel, s_window, width=width, height=height, share=share),
        cornerness(clk, rst, s_window, s_corner, k_left, k_right, width=width, height=height, share=share),
        prethreshold(clk, rst, s_corner, s_pre, thr_we, ConcatSignal(thr_addr, thr_cam), thr_data, width=width,
                     height=height, blocks=blocks),
        nms_block(clk, rst, s_pre, source, width=width, height=height, size=nms, share=share),
    ]
