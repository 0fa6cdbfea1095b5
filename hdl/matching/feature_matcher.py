"""Feature matcher: the rectified stereo stream and its corner flags in, each frame's match list out (issue 29)."""

from myhdl import block

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct, check_frame,
                                         check_int, check_reset, check_signal, check_stream)
from eyestereo.hdl.interfaces.descriptor import DescriptorPort
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.hdl.matching.corner_descriptors import DEFAULT_LEAD, corner_descriptors
from eyestereo.hdl.matching.match_engine import limit_bits, match_engine
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models import match_engine as engine_model


@block
def feature_matcher(clk, rst, sink, flags, source, limit, uniqueness, lr_check, dropped, late, lost, *,
                    cost: str = "sad", window: int = 9, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                    border: int = 4, lead: int = DEFAULT_LEAD, queue: int = 32, d_min: int = 0, d_max: int = 64,
                    rows: int = 0, slots: int = 64, corners: int = 1023, max_matches: int = 1023, events: int = 16):
    """The hardware matcher: every frame's corners of both cameras matched along the rows, the list out.

    :func:`~eyestereo.hdl.matching.corner_descriptors.corner_descriptors` joins the corner flags to the pixels
    and sends each corner with its window's descriptor, row by row; :func:`~eyestereo.hdl.matching.match_engine.
    match_engine` ranks the candidates and writes the list. Bit for bit
    :func:`eyestereo.tools.models.feature_matcher.feature_matcher` on the corners of the flags at least ``border``
    from each edge (:func:`eyestereo.tools.models.corner_descriptors.corners`) with ``limit`` its
    :func:`~eyestereo.tools.models.feature_matcher.cost_limit`, while ``dropped``, ``late`` and ``lost`` stay 0.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 8 bits: the rectified pixels (any beat spacing).
        flags: stereo ImageStream, 1 bit: their corner flags, up to ``lead`` rows (and a row) behind.
        source: QueuePort, 16 bits: each frame's match list (three words per match, then the trailer: the
            model's ``words``).
        limit, uniqueness, lr_check: the engine's run-time settings (:func:`match_engine`); change them between
            frames.
        dropped: output, sticky: the engine could not keep a corner, a row end or a left corner.
        late, lost: outputs, 16-bit counts: corners whose window had gone when their flag came, corners that
            found the pending queue full (:func:`corner_descriptors`).

    Parameters:
        cost, window: "sad" or "census", 5 / 7 / 9 / 11.
        width, height: the frame size.
        border, lead, queue: :func:`corner_descriptors`'s ``border``, ``lead`` and ``slots``.
        d_min, d_max, rows, slots, corners, max_matches, events: :func:`match_engine`'s.

    Latency: a frame's list starts a few hundred clocks after the flags of its last row (the last corners'
    windows, the engine's 2 R rows), then the engine's (its docstring).

    Resources: the two blocks' (their docstrings; docs/matching.md). Measured (make synth's flow on this block, the
    catalogue's configuration: SAD 9 x 9, 352 x 288, d 0..64, R 0): Yosys xc3se 2166 LUT + 15 LUT-RAM, 1761 FF,
    29 RAMB16, 2 MULT18X18; ECP5 (LFE5U-25F) 1598 FF, 26 DP16KD, 2 MULT18X18D, 113.6 / 116.0 / 121.0 MHz (min /
    median / max of nextpnr seeds 1-4; goal 100 MHz).
    """
    check_clock(clk)
    check_reset(rst)
    cost = check_choice("cost", cost, engine_model.COSTS)
    window = check_choice("window", window, engine_model.WINDOWS)
    width, height = check_frame(width, height)
    for name, v in dict(border=border, lead=lead, queue=queue, d_min=d_min, d_max=d_max, rows=rows, slots=slots,
                        corners=corners, max_matches=max_matches, events=events).items():
        check_int(name, v)
    check_stream("sink", sink, width=8, stereo=True)
    check_stream("flags", flags, width=1, stereo=True)
    check_queue("source", source, width=16)
    check_signal("limit", limit, width=limit_bits(), signed=False)
    check_signal("uniqueness", uniqueness, width=7, signed=False)
    check_signal("lr_check", lr_check, width=1)
    check_signal("dropped", dropped, width=1)
    check_signal("late", late, width=16, signed=False)
    check_signal("lost", lost, width=16, signed=False)
    check_distinct(dict(source=source, dropped=dropped, late=late, lost=lost),
                   dict(clk=clk, rst=rst, sink=sink, flags=flags, limit=limit, uniqueness=uniqueness,
                        lr_check=lr_check))
    desc = DescriptorPort(engine_model.word_bits(cost, window), width=width, height=height)
    try:
        front = corner_descriptors(clk, rst, sink, flags, desc, late, lost, cost=cost, window=window, width=width,
                                   height=height, border=border, lead=lead, slots=queue)
        back = match_engine(clk, rst, desc, source, limit, uniqueness, lr_check, dropped, cost=cost, window=window,
                            width=width, height=height, d_min=d_min, d_max=d_max, rows=rows, slots=slots,
                            corners=corners, max_matches=max_matches, events=events)
    except ValueError as e:
        # the parts name themselves; the user called feature_matcher (queue is corner_descriptors' slots)
        msg = str(e).split(": ", 1)[-1].replace("parameter slots=", "parameter queue=", 1) \
            if str(e).startswith("corner_descriptors: ") else str(e).split(": ", 1)[-1]
        raise block_error(msg) from None
    return front, back

