"""The stereo front end (thesis Fig. 7.2): cameras -> SRAM -> rectifier -> stereo Harris -> features, on AXI4-Lite."""

from __future__ import annotations

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.streaming.async_fifo import DEFAULT_DEPTH as FIFO_DEPTH
from eyestereo.hdl.streaming.async_fifo import MAX_DEPTH
from eyestereo.hdl.interfaces.axil import check_axil
from eyestereo.hdl.camera.camera_stream import check_camera
from eyestereo.hdl.camera.camera_interface import camera_pair
from eyestereo.hdl.common.checks import block_error, check_bool, check_choice, check_clock, check_int, check_reset
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.harris.feature_list import addr_bits, count_bits, feature_list
from eyestereo.hdl.rectify.fetch_interpolate import DEFAULT_DEPTH
from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.memory.frame_buffers import FrameControl
from eyestereo.hdl.system.frame_handshake import frame_handshake
from eyestereo.hdl.system.frontend_sequencer import frontend_sequencer
from eyestereo.hdl.harris.harris_stereo import harris_stereo
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.rectify.rectifier import rectifier
from eyestereo.hdl.rectify.stream_rectifier import stream_rectifier
from eyestereo.hdl.rectify.fetch_gate import fetch_gate
from eyestereo.hdl.dense.dense_stereo import dense_stereo
from eyestereo.hdl.dense.sgm import PU_CHOICES
from eyestereo.hdl.system.disparity_writer import disparity_writer
from eyestereo.hdl.system.list_append import list_append
from eyestereo.hdl.system.threshold_replay import threshold_replay
from eyestereo.hdl.matching.feature_matcher import feature_matcher
from eyestereo.hdl.harris.harris_stereo import latency as harris_latency
from eyestereo.tools.models.match_engine import COSTS as MATCH_COSTS, WINDOWS as MATCH_WINDOWS, MAX_DISPARITY, MAX_ROWS
from eyestereo.tools.models.sram_arbiter import list_words, match_offset
from eyestereo.tools.models.sgm import D_RANGE, PATHS
from eyestereo.tools.models.sram_arbiter import AddressMap
from eyestereo.hdl.system.register_bank import RegisterPorts, register_bank
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramPins, StatPort, check_bundle
from eyestereo.hdl.memory.sram_subsystem import sram_subsystem
from eyestereo.hdl.memory.sdram_subsystem import sdram_subsystem
from eyestereo.hdl.interfaces.sdram_bus import SdramPins
from eyestereo.tools.sdram import ULX3S
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.queue_slice import queue_slice
from eyestereo.hdl.streaming.stream_cdc import stream_cdc
from eyestereo.hdl.streaming.word_cdc import word_cdc
from eyestereo.tools.models import poly_unit as unit_model
from eyestereo.tools.models.sram_arbiter import CAMERA_WORD
from eyestereo.tools.camera import ORDERS
from eyestereo.tools.constants import DENSE_DEFAULTS, NMS_DEFAULT, NMS_SIZES, THRESHOLD_BLOCKS
from eyestereo.tools.regmap import REGMAP
from eyestereo.tools.sram import KINDS

__all__ = ["stereo_frontend", "dense_option", "matcher_option", "dense_fifo", "BLOCKS", "CAM_DEPTH", "MEMORY",
           "RECTIFY", "THR_BITS"]

#: The rectification choices: from the frame store (the thesis's) or from an on-chip line cache.
RECTIFY = ("fetch", "stream")
#: The frame stores: the EyeBot's synchronous SRAM, or a 16-bit SDR SDRAM.
MEMORY = ("sram", "sdram")

#: Threshold blocks per camera (:data:`eyestereo.tools.constants.THRESHOLD_BLOCKS`): the register map's 16
#: thresholds and 32 per-block counts.
BLOCKS = THRESHOLD_BLOCKS
THR_BITS = REGMAP["THR_LEFT"].fields[0].width
#: Each camera FIFO's default depth (async_fifo's): the arbiter serves the cameras first (urgent writers):
#: at every camera rate the SRAM sustains, the FIFO held at most 2 words (docs/sram.md), so 32 leave room for
#: the crossing and the bursts. In LUT-RAM, the read side's word comes from a flip-flop; from a block RAM it
#: came 5.8 ns after the clock edge, and the FIFO's frame logic behind it was the memory clock's slowest path
#: (issue 23).
CAM_DEPTH = FIFO_DEPTH


def default_list_timeout(width: int) -> int:
    """The list watchdog's default (memory clocks): 128 per pixel of a line, at least 16384. The lists come a few
    lines after the rectifier's end (CIF: 5,700 clocks measured, 16 clocks per pixel of a line; the matcher's list
    up to 3,241 clocks after the last flag); the default leaves eight times that, and stays right for a Harris
    clock down to half the memory clock."""
    return max(128 * int(width), 16384)


@block
def stereo_frontend(clk, rst, hclk, hrst, cam_l, wrst_l, cam_r, wrst_r, bus, sram, *, quantizers="rig",
                    frac: int | None = unit_model.DEFAULT_FRAC, nms: int = NMS_DEFAULT, border: int | None = None,
                    max_features: int = 1023, feature_words: int | None = None, cam_depth: int = CAM_DEPTH,
                    kind: str = "nobl", read_latency: int = 2, order: str = "YUYV", rect_depth: int = DEFAULT_DEPTH,
                    single_clock: bool = False, rectify: str = "fetch", cache_lines: int | None = None,
                    memory: str = "sram", sdram_part: str = ULX3S, memory_mhz: float = 100.0, dense: bool = False,
                    disparities: int = DENSE_DEFAULTS["disparities"], pu: int = 4,
                    paths: int = DENSE_DEFAULTS["paths"], matcher: bool = False, match_cost: str = "sad",
                    match_window: int = 9, match_d_max: int = 64, match_rows: int = 0, max_matches: int = 1023,
                    list_timeout: int | None = None):
    """The complete stereo front end of the thesis's Fig. 7.2, with the processor's register bus.

    Data flow: each camera bus -> :func:`~eyestereo.hdl.camera.camera_interface.camera_pair` (converter and
    async FIFO into the memory clock; a :func:`~eyestereo.hdl.streaming.queue_slice.queue_slice` puts each
    FIFO's port on flip-flops) -> its double-buffered frame in the SRAM (the arbiter's camera
    writers). When both frames of a pair are in, :func:`~eyestereo.hdl.system.frontend_sequencer.frontend_sequencer`
    starts the :func:`~eyestereo.hdl.rectify.rectifier.rectifier`, which reads them through the arbiter's fetch
    port; its 8-bit stereo stream goes both into the rectified-image buffers (the arbiter's rect writer:
    left and right pixel of (x, y) in one word) and, through a
    :func:`~eyestereo.hdl.streaming.stream_cdc.stream_cdc`, into
    :func:`~eyestereo.hdl.harris.harris_stereo.harris_stereo` in the Harris clock. Its corner flags come
    back through a second stream_cdc into the memory clock, where
    :func:`~eyestereo.hdl.harris.feature_list.feature_list` makes the feature words (the arbiter's feature
    writer) and the per-block counts (the register bank's FCOUNT window, read directly). k (a
    :func:`~eyestereo.hdl.streaming.word_cdc.word_cdc`) and the block thresholds (one-beat frames of 25 bits: camera,
    block, code, through a stream_cdc) cross into the Harris clock; the crossing's dropped-frame count
    comes back through a word_cdc. The :func:`~eyestereo.hdl.system.register_bank.register_bank` (AXI4-Lite,
    the register map of eyestereo.tools.regmap) runs in the memory clock: the processor's bus must be
    in that clock (no AXI clock converter inside).

    Ports:
        clk, rst: the memory clock (100 MHz: SRAM, arbiter, rectifier, feature list, register bus) and
            its synchronous active-high reset.
        hclk, hrst: the Harris clock (50 MHz in the thesis; harris_stereo, built with share 1, takes a beat
            per clock, so any hclk of at least half the memory clock keeps up with the rectifier) and its reset;
            not used with ``single_clock`` (tie them to ``clk``/``rst`` or leave them open).
        cam_l, wrst_l, cam_r, wrst_r: the camera buses (:class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus`,
            each clocked by its own PCLK) and each camera domain's synchronous reset.
        bus: :class:`~eyestereo.hdl.interfaces.axil.AxiLite` slave (the register map's address bits), memory clock.
        sram: the memory's pins: :class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`, or
            :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins` with ``memory="sdram"`` (the ports keep the
            prefix ``sram_``).

    Parameters:
        quantizers, frac: the calibration (a spec such as ``"rig:64x48"``, a quantizers.json or a
            Calibration; its rectified size must equal its camera size: the frame buffers are one size),
            as for the rectifier. The frame size is the calibration's.
        nms: harris_stereo's. Its ``share`` is not a parameter here: the rectifier's stream comes up to a beat
            every 2 Harris clocks with no back-pressure, which only share 1 (a beat per clock) takes.
        border: feature_list's border (default harris_stereo's r = 3 + nms // 2).
        max_features, feature_words: features per list and the SRAM words of each list buffer (default
            :func:`~eyestereo.tools.models.sram_arbiter.list_words`: 2048 for 1023 features; with the matcher
            5123, the match list's room too).
        cam_depth: each camera FIFO's entries (default :data:`CAM_DEPTH` = 32, LUT-RAM; 1024 = one RAMB16).
        kind, read_latency: the SRAM part (sram_controller).
        order: the cameras' byte order.
        rect_depth: fetch_interpolate's sides in flight.
        single_clock: False (default): harris_stereo in its own clock ``hclk``, the rectified stream, k, the
            thresholds and the flags cross through stream_cdc / word_cdc; True: harris_stereo in the memory
            clock, wired straight (no crossings, HARRIS_OVF stays 0; the whole Harris chain must then meet
            the memory clock: docs/benchmarks.md).
        rectify: ``"fetch"`` (default, the thesis's): the camera frames go into their SRAM double buffers and the
            rectifier fetches its 2x2 neighbourhoods from there (about 1.9 reads per pixel); ``"stream"``: the
            cameras' words go straight into :func:`~eyestereo.hdl.rectify.stream_rectifier.stream_rectifier` (a
            line cache of ``cache_lines`` lines per camera in block RAM), which rectifies each frame as it
            arrives: no camera frames and no rectifier reads in the SRAM; the address map has no camera buffers
            (AddressMap's ``cameras=False``: the rectified buffers from address 0, so 640x480 fits the 1M words). The
            sequencer's modes are the same: a stereo frame is "held" when both cameras have begun one (the
            sequential mode's arming waits for frames that begin after it); a frame whose lines the cameras
            overwrote before the rectifier read them (the cache too small, or the cameras too far apart) still
            runs through and is counted, once, in both DROPPED registers.
        cache_lines: the line cache's lines per camera (``rectify="stream"``); default: the calibration's plan
            (:func:`eyestereo.tools.models.line_cache.plan`).
        memory: ``"sram"`` (default, the EyeBot's 1M x 18 synchronous SRAM: ``sram`` is
            :class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`, ``kind`` and ``read_latency`` describe it) or
            ``"sdram"`` (a 16-bit SDR SDRAM such as the ULX3S's: ``sram`` is
            :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins` of ``sdram_part``, run at 100 MHz, CAS latency 2,
            by :func:`~eyestereo.hdl.memory.sdram_subsystem.sdram_subsystem`): the same masters, address map,
            register map and host driver. Pair it with ``rectify="stream"`` (the 2x2 fetches jump rows).
        sdram_part: the SDRAM part (:mod:`eyestereo.tools.sdram`'s name or spec), for ``memory="sdram"``.
        memory_mhz: the memory clock's frequency for ``memory="sdram"`` (default 100 MHz): the controller counts the
            part's timings (tRCD, tRP, the refresh interval, ...) in its clocks (the ULX3S board runs it at 75 MHz).
        dense: False (default) or True: the disparity map of every rectified pair (:func:`dense_option`:
            :func:`~eyestereo.hdl.dense.dense_stereo.dense_stereo` on the rectified stream in the memory clock,
            census 5 x 5, semi-global matching, the median) into two disparity buffers
            (:class:`~eyestereo.tools.models.sram_arbiter.AddressMap`'s ``dense``), written through the host port by
            :func:`~eyestereo.hdl.system.disparity_writer.disparity_writer`; the host takes them like the rectified
            pairs (CTRL.disp_want, CMD.disp_release, STATUS.disp_held/disp_buf) and sets P1, P2, the uniqueness and
            the checks in DENSE. The dense core paces the rectifier (its fetches wait while the core is full), so
            a rectified pair takes ``width x height x`` :func:`~eyestereo.hdl.dense.sgm.spacing` clocks (D 64,
            PU 4, CIF: 1.82 M, 18.2 ms at 100 MHz: within the cameras' 20 ms with ``rectify="fetch"``). With
            ``rectify="stream"`` the rows must also keep up with the cameras' lines (the line cache): a row's
            ``width x spacing`` clocks within a camera line period (CIF at 50 frames/s: 5,050 clocks; PU 8 takes
            3,872, PU 4 6,336: too slow).
        disparities, pu, paths: the dense core's D (16..128, below ``width``), disparities per clock and
            aggregation paths (2 or 4), as :func:`~eyestereo.hdl.dense.sgm.sgm`'s.
        matcher: False (default) or True: the frame's Harris corners matched on the FPGA (issue 29):
            :func:`~eyestereo.hdl.matching.feature_matcher.feature_matcher` in the memory clock on the rectified
            stream and the flags the feature list takes (its border, Harris's lead of ``3 + nms // 2`` rows);
            its match list goes into the frame's feature-list buffer after the features, from word
            :func:`~eyestereo.tools.models.sram_arbiter.match_offset` (``2 * max_features + 2``), by
            :func:`~eyestereo.hdl.system.list_append.list_append`: the host takes features and matches with the
            feature lists' handshake and reads the matches alone at that word. MATCH sets the threshold, the
            uniqueness and the left-right check; MATCH_STATUS and MATCH_FAULTS report.
        match_cost, match_window, match_d_max, match_rows, max_matches: the matcher's cost ("sad" or "census"),
            window (5, 7, 9, 11; at most ``2 * border + 1``), disparities 0..``match_d_max`` (at most 255), rows
            searched above and below (R, 0..7: for a calibration that leaves rows off by a pixel), matches per list.
        list_timeout: the sequencer's list watchdog
            (:func:`~eyestereo.hdl.system.frontend_sequencer.frontend_sequencer`):
            memory clocks without a ``list_done`` after which the lists of the frames waited for are given up
            (counted in LOST.lists_lost); default :func:`default_list_timeout` (128 clocks per pixel of a line, at least
            16384: 45,056 at CIF, eight times the lists' measured 5,700 after the rectifier). A Harris-domain reset
            (``hrst``) can cut a frame whose lists then never come; without the watchdog the front end stayed busy
            for ever (found by the fault soak, docs/reliability.md).

    Latency: a frame's features are complete a few lines (Harris's lead, :func:`harris_stereo.latency`)
    after the rectifier's last beat; the sequencer's ``frame_clocks`` measures the whole.

    Resources: the sum of the blocks (docs/system.md: Yosys, Spartan-3E 500); with ``dense``, the dense core's
    (docs/dense.md) and the writer's block RAM: only the ECP5-85F class holds it.
    """
    check_clock(clk)
    check_reset(rst)
    check_clock(hclk, "hclk")
    check_reset(hrst, "hrst")
    check_camera("cam_l", cam_l)
    check_camera("cam_r", cam_r)
    check_reset(wrst_l, "wrst_l")
    check_reset(wrst_r, "wrst_r")
    check_axil("bus", bus, addr_bits=REGMAP.addr_bits)
    memory = check_choice("memory", memory, MEMORY)
    check_bundle("sram", sram, SramPins if memory == "sram" else SdramPins)
    cal = calibration_param(quantizers, None, None)
    if (cal.width, cal.height) != (cal.source_width, cal.source_height):
        raise block_error(f"parameter quantizers: the calibration rectifies {cal.source_width}x{cal.source_height} "
                          f"camera images to {cal.width}x{cal.height}; the front end's buffers need one size")
    width, height = cal.width, cal.height
    nms = check_choice("nms", nms, NMS_SIZES)
    border = 3 + nms // 2 if border is None else check_int("border", border, 1)
    max_features = check_int("max_features", max_features, 1, 32767)
    matcher = check_bool("matcher", matcher)
    # checked with or without the option (a bad value is refused, not ignored); how they fit the frame only with it
    match_cost = check_choice("match_cost", match_cost, MATCH_COSTS)
    match_window = check_choice("match_window", match_window, MATCH_WINDOWS)
    match_d_max = check_int("match_d_max", match_d_max, 0, MAX_DISPARITY)
    match_rows = check_int("match_rows", match_rows, 0, MAX_ROWS)
    max_matches = check_int("max_matches", max_matches, 1, 32767)
    need = list_words(max_features, max_matches if matcher else None)
    feature_words = need if feature_words is None else check_int("feature_words", feature_words, 2, 65536)
    if feature_words < need:
        what = f" and a match list of {max_matches} matches from word {match_offset(max_features)}" if matcher else ""
        raise block_error(f"parameter feature_words={feature_words}: a list of {max_features} features and its "
                          f"trailer{what} need {need} words")

    cam_depth = check_int("cam_depth", cam_depth, 4, MAX_DEPTH)
    if cam_depth & (cam_depth - 1):
        raise block_error(f"parameter cam_depth={cam_depth} must be a power of two (the camera FIFOs)")
    kind = check_choice("kind", kind, KINDS)
    read_latency = check_int("read_latency", read_latency, 1, 3)
    order = check_choice("order", order, ORDERS)
    single_clock = check_bool("single_clock", single_clock)
    rect_depth = check_int("rect_depth", rect_depth, 1, 16)
    if frac is not None:
        frac = check_int("frac", frac, 0, unit_model.MAX_FRAC)
    rectify = check_choice("rectify", rectify, RECTIFY)
    stream = rectify == "stream"
    if cache_lines is not None and not stream:
        raise block_error("parameter cache_lines is for rectify='stream' (the line cache)")

    dense = check_bool("dense", dense)
    # checked with or without the option (a bad value is refused, not ignored); how they fit the frame only with it
    disparities = check_int("disparities", disparities, *D_RANGE)
    pu = check_choice("pu", pu, PU_CHOICES)
    paths = check_choice("paths", paths, PATHS)
    if dense:
        if disparities % pu or disparities // pu < 2:
            raise block_error(f"parameters disparities={disparities}, pu={pu}: pu must divide the disparities into "
                              "groups of at least two")
        if width <= disparities:
            raise block_error(f"parameter disparities={disparities}: the {width}-pixel rows must be wider")
    try:
        amap = AddressMap(width, height, feature_words, cameras=not stream, dense=dense)
    except ValueError as exc:
        raise block_error(f"parameter quantizers: {exc}") from None

    insts = []
    # ---- cameras into the memory clock ---------------------------------------------------------
    fifo0, fifo1 = QueuePort(CAMERA_WORD), QueuePort(CAMERA_WORD)
    cam0, cam1 = QueuePort(CAMERA_WORD), QueuePort(CAMERA_WORD)
    dropped_l, dropped_r = Signal(intbv(0)[16:]), Signal(intbv(0)[16:])
    insts.append(camera_pair(cam_l, wrst_l, cam_r, wrst_r, clk, rst, fifo0, fifo1, dropped_l, dropped_r,
                             width=width, height=height, order=order, depth=cam_depth))
    # the camera FIFOs' words come from block RAM: the camera writers' logic starts at flip-flops (issue 23:
    # the block RAM's clock-to-output into the writer was the memory clock's critical path)
    insts += [queue_slice(clk, rst, fifo0, cam0), queue_slice(clk, rst, fifo1, cam1)]
    # rectify="stream": the cameras' words go to the line cache; the SRAM's camera writers and fetch port idle
    # (their inputs undriven: constant 0, no frame comes, no request)
    m_cam0, m_cam1 = (QueuePort(CAMERA_WORD), QueuePort(CAMERA_WORD)) if stream else (cam0, cam1)

    # ---- SRAM subsystem and register bank --------------------------------------------------------
    fetch = FetchPort(width, height)
    rect = ImageStream(8, stereo=True)
    feat = QueuePort(16)
    host, stat, ctl = HostPort(), StatPort(), FrameControl()
    fcount = StatPort(5, 16)
    regs = RegisterPorts()
    # dense: the disparity writer shares the memory's host port with the register bank
    bank_host = HostPort() if dense else host
    mem_ready = Signal(bool(memory == "sram"))  # the SRAM: always (undriven: a constant); the SDRAM: after power-up
    if memory == "sram":
        insts.append(sram_subsystem(clk, rst, m_cam0, m_cam1, fetch, rect, feat, host, ctl, stat, sram, kind=kind,
                                    read_latency=read_latency, width=width, height=height,
                                    feature_words=feature_words, cameras=not stream))
    else:
        insts.append(sdram_subsystem(clk, rst, m_cam0, m_cam1, fetch, rect, feat, host, ctl, stat, sram, mem_ready,
                                     part=sdram_part, clock_mhz=memory_mhz, width=width, height=height,
                                     feature_words=feature_words, cameras=not stream))
    insts.append(register_bank(clk, rst, bus, regs, stat, fcount, bank_host, width=width, height=height))

    # ---- rectifier and sequencer -----------------------------------------------------------------
    r_start, r_busy = Signal(bool(0)), Signal(bool(0))
    hold = Signal(bool(0))  # dense: the rectifier waits (the dense core is full)
    top = (1 << 16) - 1
    overrun = Signal(bool(0))
    overruns = Signal(intbv(0)[16:])
    if stream:
        # the sequencer's camera handshake: a pair is "held" when both cameras have begun a frame
        sctl = FrameControl()
        s_arm, s_begun = Signal(bool(0)), Signal(bool(0))
        insts.append(stream_rectifier(clk, rst, cam0, cam1, rect, r_start, s_arm, s_begun, r_busy, overrun, None,
                                      hold if dense else None, quantizers=cal, frac=frac, lines=cache_lines,
                                      depth=rect_depth))

        @always_comb
        def stream_handshake():
            # begun is a register the arm pulse clears a clock later: a pair begun before the arming is not held
            sctl.cam_held.next = s_begun and sctl.cam_arm == 0
            s_arm.next = sctl.cam_arm != 0

        @always_seq(clk.posedge, reset=rst)
        def overrun_count():
            if overrun and overruns != top:
                overruns.next = overruns + 1

        insts += [stream_handshake, overrun_count]
    else:
        sctl = ctl
        r_fetch = fetch
        if dense:
            r_fetch = FetchPort(width, height)
            insts.append(fetch_gate(clk, rst, r_fetch, fetch, hold))
        insts.append(rectifier(clk, rst, r_start, r_fetch, rect, r_busy, quantizers=cal, frac=frac, depth=rect_depth))
    l_done, l_ovf = Signal(bool(0)), Signal(bool(0))
    insts.append(frontend_sequencer(clk, rst, regs.mode, regs.continuous, regs.start, regs.stop, sctl, r_start,
                                    r_busy, l_done, l_ovf, regs.busy, regs.frames, regs.frame_clocks,
                                    regs.list_overflows, mem_ready, regs.lists_lost,
                                    list_timeout=default_list_timeout(width) if list_timeout is None
                                    else list_timeout))

    # ---- into the Harris clock and back (or, single_clock, straight) ------------------------------------
    hclk_, hrst_ = (clk, rst) if single_clock else (hclk, hrst)
    h_in = rect if single_clock else ImageStream(8, stereo=True)
    h_dropped_m, f_dropped = Signal(intbv(0)[16:]), Signal(intbv(0)[16:])
    k_m, k_h = Signal(intbv(0)[16:]), Signal(intbv(0)[16:])
    k_l_h, k_r_h = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    tbits = 1 + 4 + THR_BITS
    thr_m = ImageStream(tbits)
    thr_h = thr_m if single_clock else ImageStream(tbits)
    h_flags = ImageStream(1, stereo=True)
    flags = h_flags if single_clock else ImageStream(1, stereo=True)
    if single_clock:
        insts.append(assign(k_m, k_h))
    else:
        h_dropped, thr_dropped = Signal(intbv(0)[16:]), Signal(intbv(0)[16:])
        insts.append(stream_cdc(clk, rst, rect, hclk, hrst, h_in, h_dropped, depth=16))
        insts.append(word_cdc(hclk, h_dropped, clk, h_dropped_m))
        insts.append(word_cdc(clk, k_m, hclk, k_h))
        insts.append(stream_cdc(clk, rst, thr_m, hclk, hrst, thr_h, thr_dropped, depth=16))
        insts.append(stream_cdc(hclk, hrst, h_flags, clk, rst, flags, f_dropped, depth=16))
    thr_we, thr_cam = Signal(bool(0)), Signal(bool(0))
    thr_addr, thr_data = Signal(intbv(0)[4:]), Signal(intbv(0)[THR_BITS:])

    @always_comb
    def to_harris_m():
        k_m.next = concat(regs.k_right, regs.k_left)

    # the thresholds as one-beat frames, and all 32 again after a reset of the Harris domain alone (its reset
    # clears harris_stereo's table; the soak found the frames after it thresholded at 0: threshold_replay)
    insts.append(threshold_replay(clk, rst, Signal(bool(0)) if single_clock else hrst, regs.thr_left_we,
                                  regs.thr_left_addr, regs.thr_left_data, regs.thr_right_we, regs.thr_right_addr,
                                  regs.thr_right_data, thr_m))

    @always_comb
    def to_harris_h():
        k_l_h.next = k_h[8:0]
        k_r_h.next = k_h[16:8]
        thr_we.next = thr_h.valid
        thr_cam.next = thr_h.data[tbits - 1]
        thr_addr.next = thr_h.data[tbits - 1:THR_BITS]
        thr_data.next = thr_h.data[THR_BITS:0]

    insts += [to_harris_m, to_harris_h]
    insts.append(harris_stereo(hclk_, hrst_, h_in, h_flags, k_l_h, k_r_h, thr_we, thr_cam, thr_addr, thr_data,
                               width=width, height=height, blocks=BLOCKS, nms=nms, share=1))

    # ---- feature list, counts -----------------------------------------------------------------------------
    cb = count_bits(width, height)
    c_addr = Signal(intbv(0)[addr_bits(BLOCKS):])
    c_data, tot_l, tot_r = Signal(intbv(0)[cb:]), Signal(intbv(0)[cb:]), Signal(intbv(0)[cb:])
    # The flags beat into the feature list from registers beside it: the list reads its counter a clock ahead
    # from the beat's camera and block, and from the crossing's FIFO (or the Harris chain) that path was the
    # memory clock's slowest (issue 23). One clock more to each list's end.
    list_in = ImageStream(1, stereo=True)

    @always_seq(clk.posedge, reset=rst)
    def to_list_valid():
        list_in.valid.next = flags.valid

    @always(clk.posedge)
    def to_list_beat():
        list_in.data.next = flags.data
        list_in.cam.next = flags.cam
        list_in.eol.next = flags.eol
        list_in.eof.next = flags.eof

    insts += [to_list_valid, to_list_beat]
    f_list = QueuePort(16) if matcher else feat
    insts.append(feature_list(clk, rst, list_in, f_list, c_addr, c_data, tot_l, tot_r, l_ovf, l_done, width=width,
                              height=height, blocks=BLOCKS, border=border, max_features=max_features))
    if matcher:
        insts.append(matcher_option(clk, rst, rect, list_in, f_list, feat, regs, width=width, height=height,
                                    border=border, lead=harris_latency(nms, 1)[1], cost=match_cost,
                                    window=match_window, d_max=match_d_max, rows=match_rows,
                                    max_features=max_features, max_matches=max_matches))
    c_reg = Signal(intbv(0)[16:])

    @always_comb
    def count_port():
        # FCOUNT's address is camera << 4 | block; feature_list's 2 * block + camera
        c_addr.next = concat(fcount.addr[4:0], fcount.addr[4])

    @always_seq(clk.posedge, reset=rst)
    def count_regs():
        # the window's latency of 2 clocks (the combinational LUT-RAM read, then two registers)
        c_reg.next = c_data if c_data <= top else top
        fcount.data.next = c_reg
        regs.features_left.next = tot_l if tot_l <= top else top
        regs.features_right.next = tot_r if tot_r <= top else top

    insts.append(frame_handshake(regs, ctl))

    @always_comb
    def wiring():
        regs.dropped_left.next = dropped_l + overruns
        regs.dropped_right.next = dropped_r + overruns
        regs.harris_overflows.next = h_dropped_m + f_dropped

    insts += [count_port, count_regs, wiring]
    if dense:
        insts.append(dense_option(clk, rst, rect, hold, regs, bank_host, host, amap=amap, disparities=disparities,
                                  pu=pu, paths=paths))
    return insts


@block
def matcher_option(clk, rst, rect, flags, features, feat, regs, *, width: int, height: int, border: int, lead: int,
                   cost: str, window: int, d_max: int, rows: int, max_features: int, max_matches: int):
    """The front end's ``matcher`` option: the hardware matcher on the rectified stream and the flags, its list
    after the features.

    :func:`~eyestereo.hdl.matching.feature_matcher.feature_matcher` (in the memory clock) takes every rectified
    pair of ``rect`` and the flags the feature list takes (``flags``: the same beats, the same border); its list
    and the feature list ``features`` join in :func:`~eyestereo.hdl.system.list_append.list_append` into ``feat``
    (the feature writer), the matches from word :func:`~eyestereo.tools.models.sram_arbiter.match_offset`. Wired
    here: MATCH (match_limit, match_uniqueness, match_lr_check), MATCH_STATUS (matches, match_overflow,
    match_dropped), MATCH_FAULTS (match_late, match_lost). The matcher's own settings: d 0..``d_max``, R = ``rows``,
    a left table of ``max_features`` corners, 64 slots per store, a pending queue of 32.

    Latency: the match list a few thousand clocks after the frame's last flag (the engine's; docs/matching.md).

    Resources: feature_matcher's (docs/matching.md) and list_append's.
    """
    m_list = QueuePort(16)
    count = Signal(intbv(0)[15:])
    try:
        fm = feature_matcher(clk, rst, rect, flags, m_list, regs.match_limit, regs.match_uniqueness,
                             regs.match_lr_check, regs.match_dropped, regs.match_late, regs.match_lost, cost=cost,
                             window=window, width=width, height=height, border=border, lead=lead, d_max=d_max,
                             rows=rows, corners=max_features, max_matches=max_matches)
    except ValueError as e:
        raise block_error(f"the matcher option: {str(e).split(': ', 1)[-1]}") from None
    app = list_append(clk, rst, features, m_list, feat, count, regs.match_overflow, offset=match_offset(max_features))

    @always_comb
    def status():
        regs.matches.next = count

    return fm, app, status


def dense_fifo(width: int, window: int = DENSE_DEFAULTS["window"]) -> int:
    """The dense option's sgm FIFO: a power of two of at least the pixels the core holds outside it (census's
    lead of ``window // 2`` rows and pixels, sgm's row in work and the row it drains, the median's row) and 128
    (352 wide: 2048). The pacing keeps the pixels inside the core at the depth less 64, so the FIFO then still
    holds at least 64: the core never waits for pixels, and the rectifier is never held for good."""
    r = window // 2
    return 1 << (r * width + r + 3 * width + 1 + 128 - 1).bit_length()


@block
def dense_option(clk, rst, rect, hold, regs, bank, mem, *, amap: AddressMap, disparities: int, pu: int, paths: int):
    """The front end's ``dense`` option: the dense core on the rectified stream, its pacing and its writer.

    :func:`~eyestereo.hdl.dense.dense_stereo.dense_stereo` (in the memory clock) takes every rectified pair of
    ``rect``. ``hold`` (to the rectifier's fetch gate) is high while the pixels inside the core (counted in as
    right beats and out as codes; a reset token clears the count) reach its FIFO's depth (:func:`dense_fifo`)
    less 64: every pixel in the FIFO is one of them, so the FIFO cannot overrun (after ``hold`` at most the
    rectifier's fetches in flight still come), and the count's level leaves the FIFO pixels to work on. The
    codes go to :func:`~eyestereo.hdl.system.disparity_writer.disparity_writer` (the two buffers of ``amap``),
    which shares the memory's host port ``mem`` with the register bank's ``bank``. Wired here: DENSE (p1, p2,
    uniqueness, lr_check, subpixel), DENSE_STATUS (disp_frames, dense_overrun, disp_lost) and the disp_*
    bits of CTRL, CMD and STATUS.

    Latency: dense_stereo's (census's ``window // 2`` rows, sgm's row, the median's row), then the writer's FIFO.

    Resources: dense_stereo's with the FIFO above, the writer's, a 12-bit counter and a comparator.
    """
    width, height = amap.width, amap.height
    window = DENSE_DEFAULTS["window"]
    depth = dense_fifo(width, window)
    limit = depth - 64
    codes = ImageStream(16)
    overrun, lost = Signal(bool(0)), Signal(bool(0))
    inside = Signal(intbv(0, min=0, max=depth + 1))
    insts = [dense_stereo(clk, rst, rect, codes, regs.p1, regs.p2, regs.uniqueness, regs.lr_check, regs.subpixel,
                          overrun, window=window, disparities=disparities, pu=pu, paths=paths, fifo=depth,
                          width=width, height=height),
             disparity_writer(clk, rst, codes, bank, mem, regs.disp_want, regs.disp_release, regs.disp_held,
                              regs.disp_avail, regs.disp_buf, regs.disp_frames, lost, base0=amap.disparity(0),
                              base1=amap.disparity(1), width=width, height=height)]

    @always_seq(clk.posedge, reset=rst)
    def pacing():
        pix_in = rect.valid and rect.cam and (rect.eol or not rect.eof)
        code_out = codes.valid and (codes.eol or not codes.eof)
        if rect.valid and rect.eof and not rect.eol:
            inside.next = 0
        elif pix_in and not code_out:
            inside.next = inside + 1
        elif code_out and not pix_in and inside != 0:
            inside.next = inside - 1
        hold.next = inside >= limit

    @always_comb
    def status():
        regs.dense_overrun.next = overrun
        regs.disp_lost.next = lost

    insts += [pacing, status]
    return insts
