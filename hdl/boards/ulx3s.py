"""The stereo front end on a ULX3S (ECP5-85F): two OV7670 cameras, the SDRAM, the HDMI monitor, the USB serial link."""

from __future__ import annotations

from myhdl import ResetSignal, Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.axi.axil_arbiter import axil_arbiter
from eyestereo.hdl.axi.axil_split import axil_split
from eyestereo.hdl.boards.board_regs import board_regs
from eyestereo.hdl.boards.ecp5 import ecp5_pll, oddr, tristate
from eyestereo.hdl.boards.sdram_pins import sdram_pins
from eyestereo.hdl.camera.sccb_master import sccb_master
from eyestereo.hdl.common.checks import block_error, check_choice, check_int
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.interfaces.sdram_bus import SdramPins
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.serial.uart_bridge import uart_bridge
from eyestereo.hdl.system.stereo_frontend import stereo_frontend
from eyestereo.hdl.video.pair_display import pair_display
from eyestereo.hdl.video.tmds_encoder import tmds_encoder
from eyestereo.hdl.video.tmds_serializer import tmds_serializer
from eyestereo.tools.board.ecp5_pll import plan as pll_plan
from eyestereo.tools.board.regmap import BOARD_BASE
from eyestereo.tools.models.feature_list import MAX_FEATURES
from eyestereo.tools.models.sram_arbiter import AddressMap, list_words
from eyestereo.tools.models.video_timing import mode_of
from eyestereo.tools.ov7670 import TABLE as OV7670_TABLE
from eyestereo.tools.regmap import REGMAP
from eyestereo.tools.sdram import ULX3S

__all__ = ["ulx3s", "board_clocks", "BAUD", "CLOCKS", "MATCHER_MEMORY_MHZ", "SDRAM_CLOCK"]

#: The board's clocks (MHz): the oscillator and the PLL's four outputs in its order (CLKOP, CLKOS, CLKOS2, CLKOS3).
#: The memory clock is 75 MHz, not the front end's usual 100: the stream front end's slowest path (the rectifier's
#: reuse rule, fetch_interpolate's requester) reaches about 86 MHz on the 85F (docs/boards.md), and 75 MHz keeps the
#: project's 10 % margin while QVGA cameras at 30 frames/s need a small part of it. 75, 125, 50 and 25 divide one
#: VCO (750 MHz) exactly.
CLOCKS = dict(osc=25.0, mem=75.0, tmds=125.0, harris=50.0, pixel=25.0)
#: The memory clock with the hardware matcher (``matcher=True``): its corner rings' handshake (match_engine's sink
#: side, spread over the block-RAM columns beside the rest of the board) reached 72-87 MHz over nextpnr's seeds
#: 1-4 at 75 MHz; 62.5 MHz (the same VCO / 12) keeps the 10 % margin. The cameras' QVGA still leaves about 24
#: memory clocks a pixel.
MATCHER_MEMORY_MHZ = 62.5
#: The serial link's baud rate the default ``clocks_per_bit`` aims at: the FT231X's fastest standard rate.
BAUD = 3_000_000


def board_clocks(*, matcher: bool = False, memory_mhz: float | None = None) -> dict:
    """The clocks (MHz) of a board top built with ``matcher`` and ``memory_mhz`` (None: 75, or
    :data:`MATCHER_MEMORY_MHZ` with the matcher): :data:`CLOCKS` with that memory clock."""
    if memory_mhz is None:
        memory_mhz = MATCHER_MEMORY_MHZ if matcher else CLOCKS["mem"]
    return dict(CLOCKS, mem=float(memory_mhz))
#: How the SDRAM's clock pin is driven from the memory clock (an ODDRX1F): "same" (the memory clock's phase, the
#: timing the SDRAM controller and its model were verified with: docs/sdram.md) or "inverted" (the part samples
#: the commands half a clock after the FPGA launched them; for a board whose I/O delays need it).
SDRAM_CLOCK = ("same", "inverted")


@block
def rs_sync(clk, arst, rst, *, stages: int = 3):
    """rst: ``arst`` (any clock) held for ``stages`` clocks of ``clk`` after it falls, released in step with
    ``clk`` (a reset synchroniser: a shift register of ones, filled while arst is high, emptied after)."""
    ones = (1 << stages) - 1
    sh = Signal(intbv(ones)[stages:])

    @always_seq(clk.posedge, reset=None)
    def sync():
        if arst:
            sh.next = ones
        else:
            sh.next = concat(sh[stages - 1:0], False)

    @always_comb
    def out():
        rst.next = sh[stages - 1]

    return sync, out


@block
def ulx3s(clk_25mhz, led, btn, ftdi_txd, ftdi_rxd, sdram_clk, sdram_cke, sdram_csn, sdram_wen, sdram_rasn,
          sdram_casn, sdram_a, sdram_ba, sdram_dqm, sdram_d, gpdi_dp, cam_l, cam_l_xclk, cam_l_sioc, cam_l_siod,
          cam_l_resetn, cam_l_pwdn, cam_r, cam_r_xclk, cam_r_sioc, cam_r_siod, cam_r_resetn, cam_r_pwdn, *,
          quantizers="rig:320x240", mode: str = "640x480@60", clocks_per_bit: int | None = None,
          sccb_table=OV7670_TABLE, sccb_hz: float = 100e3, sdram_clock: str = "same", order: str = "YUYV",
          matcher: bool = False, match_rows: int = 1, memory_mhz: float | None = None, reset_hold: int = 3):
    """The board top: the stereo front end with ``memory="sdram"`` and ``rectify="stream"`` on the ULX3S, the cameras
    configured over SCCB at start, the newest rectified pair and its corners on the HDMI monitor, the register map
    on the USB serial port (docs/boards.md: wiring, building, programming, the host tool).

    Clocks: one EHXPLLL (:func:`~eyestereo.hdl.boards.ecp5.ecp5_pll`, :func:`eyestereo.tools.board.ecp5_pll.plan`)
    makes :func:`board_clocks` from the 25 MHz oscillator: memory 75 MHz (62.5 with the matcher; SDRAM, front end,
    bridge, display's copy, SCCB),
    TMDS 125 MHz (two bits a clock through ODDRX1F cells), Harris 50 MHz, pixel 25 MHz (the monitor; also the
    cameras' XCLK). Each domain's reset is held while the PLL is unlocked (a synchroniser each); each camera's PCLK
    domain likewise. The cameras are held in reset (RESET low) until the memory clock's reset ends.

    Blocks: the front end (``system.stereo_frontend``); the host's ``serial.uart_bridge`` (24 address bits) ->
    ``axi.axil_split`` (bit 23: the front end's map, or the board's ``boards.board_regs``) -> ``axi.axil_arbiter``
    shared with ``video.pair_display`` (the monitor's copy, which also starts the front end: overlapped,
    continuous) -> the front end's register bank; three ``video.tmds_encoder`` and a ``video.tmds_serializer``
    to the GPDI connector; ``camera.sccb_master`` for both cameras.

    Ports (the names of the board's constraint file; tools/board/ulx3s.py has the sites):
        clk_25mhz: the oscillator.
        led (8): 0 PLL locked, 1 left camera answered, 2 right camera answered, 3 SCCB busy, 4 toggles with each
            pair copied to the monitor, 5 a serial-link error seen, 6 blinks (1 Hz, pixel clock alive), 7 display
            running.
        btn (7): btn[1] (FIRE1) writes the cameras' table again; btn[2] (FIRE2) held freezes the picture.
        ftdi_txd, ftdi_rxd: the FT231X's serial lines (the FPGA receives on txd), 8N1 at the memory clock /
            ``clocks_per_bit``.
        sdram_*: the SDRAM (sdram_d bidirectional).
        gpdi_dp (4): TMDS blue, green, red, clock (LVCMOS33D pairs).
        cam_l, cam_r: :class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus` (PCLK, VSYNC, HREF, data), the
            cameras' outputs; cam_*_xclk, cam_*_sioc out; cam_*_siod bidirectional (open drain); cam_*_resetn,
            cam_*_pwdn out.

    Parameters:
        quantizers: the rig's calibration (as the front end's); its size is the cameras' (320 x 240: the OV7670's
            QVGA, :data:`eyestereo.tools.ov7670.TABLE`), and two images side by side must fit ``mode``.
        mode: the monitor's video mode (:data:`eyestereo.tools.models.video_timing.MODES`).
        clocks_per_bit: the serial link's bit time in memory clocks (default: the nearest to :data:`BAUD`, 3 Mbaud,
            the FT231X's fastest standard rate: 25 at 75 MHz, 21 at 62.5 MHz (2.976 Mbaud, 0.8 % slow, well inside
            a UART's tolerance); 651 at 75 MHz: 115,200 baud).
        sccb_table: the cameras' register table ((register, value) pairs; :mod:`eyestereo.tools.ov7670`).
        sccb_hz: the SCCB clock (at most 400 kHz).
        sdram_clock: :data:`SDRAM_CLOCK`.
        order: the cameras' byte order (the table's COM13/TSLB settings give YUYV).
        matcher: the front end's hardware matcher (the match list follows the features; the monitor draws each
            match as a segment in the anaglyph, from the right corner's column to the left's:
            :func:`~eyestereo.hdl.video.pair_display.pair_display`).
        match_rows: with ``matcher``, the rows searched above and below a left corner's (0..7; default 1: a rig's
            rectification seldom lines its rows up to the pixel; the front end's own default is 0).
        memory_mhz: the memory clock (MHz; None: 75, or :data:`MATCHER_MEMORY_MHZ` with ``matcher``); the PLL
            planner must reach it from the VCO that gives the other three clocks.
        reset_hold: flip-flops of each reset synchroniser (2..8).

    Latency: the picture shows a pair about a monitor frame after the front end finished it (the copy starts
    when the scan enters the lower half).

    Resources: docs/boards.md (Yosys synth_ecp5 and nextpnr-ecp5 of this top, the bitstream's netlist).
    """
    try:
        vmode = mode_of(mode)
    except ValueError as e:
        raise block_error(str(e)) from None
    check_choice("sdram_clock", sdram_clock, SDRAM_CLOCK)
    check_int("reset_hold", reset_hold, 2, 8)
    cal = calibration_param(quantizers)
    width, height = cal.width, cal.height
    if 2 * width > vmode.h_active or 2 * height > vmode.v_active:
        raise block_error(f"a {width}x{height} pair side by side with its anaglyph below needs {2 * width}x{2 * height}"
                          f" pixels; mode {vmode.name} has {vmode.h_active}x{vmode.v_active}")
    for name, port, w in (("led", led, 8), ("btn", btn, 7), ("gpdi_dp", gpdi_dp, 4)):
        if len(port) != w:
            raise block_error(f"port {name} must be {w} bits, got {len(port)}")

    ck = board_clocks(matcher=matcher, memory_mhz=memory_mhz)
    if clocks_per_bit is None:
        clocks_per_bit = round(ck["mem"] * 1e6 / BAUD)
    try:
        plan = pll_plan(ck["osc"], (ck["mem"], ck["tmds"], ck["harris"], ck["pixel"]))
    except ValueError as e:
        raise block_error(f"parameter memory_mhz={memory_mhz!r}: {e}") from None
    insts = []

    # ---- clocks and resets ------------------------------------------------------------------------
    mclk, tclk, hclk, pclk = (Signal(bool(0)) for _ in range(4))
    locked = Signal(bool(0))
    insts.append(ecp5_pll(clk_25mhz, mclk, tclk, hclk, pclk, locked, plan=plan))
    unlocked = Signal(bool(1))

    locked_m = Signal(bool(0))  # LOCK in the memory clock (for the board register): the reset's inverse

    @always_comb
    def lock_n():
        unlocked.next = not locked
        locked_m.next = not rst_m

    rst_m, rst_h, rst_p, rst_t, wrst_l, wrst_r = (ResetSignal(1, active=1, isasync=False) for _ in range(6))
    insts += [lock_n] + [rs_sync(c, unlocked, r, stages=reset_hold) for c, r in (
        (mclk, rst_m), (hclk, rst_h), (pclk, rst_p), (tclk, rst_t), (cam_l.pclk, wrst_l), (cam_r.pclk, wrst_r))]

    # ---- the front end ----------------------------------------------------------------------------
    fe_bus = AxiLite(REGMAP.addr_bits)
    sdram = SdramPins(ULX3S)
    amap = AddressMap(width, height, list_words(1023, 1023 if matcher else None), cameras=False)
    insts.append(stereo_frontend(mclk, rst_m, hclk, rst_h, cam_l, wrst_l, cam_r, wrst_r, fe_bus, sdram,
                                 quantizers=cal, memory="sdram", sdram_part=ULX3S, memory_mhz=ck["mem"],
                                 rectify="stream", order=order,
                                 matcher=matcher, match_rows=match_rows, feature_words=amap.feature_words))

    # the constants the primitives' instances take, each from a flip-flop of its own clock (a signal that only
    # user-defined code reads is not declared in MyHDL's HDL: it must be driven by a process)
    one, zero = Signal(bool(1)), Signal(bool(0))

    @always_seq(mclk.posedge, reset=None)
    def constants():
        one.next = 1
        zero.next = 0

    insts.append(constants)
    ck0, ck1 = (zero, one) if sdram_clock == "inverted" else (one, zero)
    insts += [sdram_pins(sdram, sdram_cke, sdram_csn, sdram_wen, sdram_rasn, sdram_casn, sdram_a, sdram_ba, sdram_dqm,
                         sdram_d), oddr(mclk, ck0, ck1, sdram_clk, label="sdram_clk_oddr")]

    # ---- the host's bus: bridge -> split -> (arbiter with the display -> front end | board registers) -------
    br_bus = AxiLite(24)
    fe_side, board_bus, disp_bus = AxiLite(REGMAP.addr_bits), AxiLite(8), AxiLite(REGMAP.addr_bits)
    uart_errors = Signal(intbv(0)[16:])
    insts.append(uart_bridge(mclk, rst_m, ftdi_txd, ftdi_rxd, br_bus, uart_errors, clocks_per_bit=clocks_per_bit,
                             addr_bits=24))
    insts.append(axil_split(mclk, rst_m, br_bus, fe_side, board_bus, split_bit=(BOARD_BASE.bit_length() - 1)))
    insts.append(axil_arbiter(mclk, rst_m, fe_side, disp_bus, fe_bus, addr_bits=REGMAP.addr_bits))

    display_run, sccb_restart, sccb_busy, sccb_done, display_idle = (Signal(bool(0)) for _ in range(5))
    present = Signal(intbv(0)[2:])
    copies = Signal(intbv(0)[16:])
    insts.append(board_regs(mclk, rst_m, board_bus, display_run, sccb_restart, locked_m, sccb_busy, display_idle,
                            present, copies,
                            uart_errors, mem_mhz=int(ck["mem"]), harris_mhz=int(ck["harris"]),
                            pixel_mhz=int(ck["pixel"]), tmds_mhz=int(ck["tmds"])))

    # ---- buttons --------------------------------------------------------------------------------------
    f1a, f1b, f1c, f2a, f2b = (Signal(bool(0)) for _ in range(5))  # the buttons' synchronisers
    fire1, run = Signal(bool(0)), Signal(bool(0))

    @always_seq(mclk.posedge, reset=rst_m)
    def buttons():
        f1a.next = btn[1]
        f1b.next = f1a
        f1c.next = f1b
        f2a.next = btn[2]
        f2b.next = f2a
        fire1.next = sccb_restart or (f1b and not f1c)
        run.next = display_run and not f2b

    insts.append(buttons)

    # ---- the monitor ----------------------------------------------------------------------------------
    hs, vs, de = (Signal(bool(0)) for _ in range(3))
    red, green, blue = (Signal(intbv(0)[8:]) for _ in range(3))
    insts.append(pair_display(mclk, rst_m, pclk, rst_p, disp_bus, run, copies, display_idle, hs, vs, de, red, green,
                              blue,
                              width=width, height=height, rect_base=(amap.rectified(0), amap.rectified(1)),
                              feat_base=(amap.features(0), amap.features(1)),
                              max_features=min(1023, MAX_FEATURES), mode=vmode.name, autostart=True, matches=matcher,
                              max_matches=1023))
    q_b, q_g, q_r = (Signal(intbv(0)[10:]) for _ in range(3))
    insts += [tmds_encoder(pclk, rst_p, blue, hs, vs, de, q_b), tmds_encoder(pclk, rst_p, green, zero, zero, de, q_g),
              tmds_encoder(pclk, rst_p, red, zero, zero, de, q_r)]
    p_b, p_g, p_r, p_c = (Signal(intbv(0)[2:]) for _ in range(4))
    insts.append(tmds_serializer(pclk, tclk, rst_p, q_b, q_g, q_r, p_b, p_g, p_r, p_c))
    # each lane's two bits (ODDRX1F's D0, D1) and its pin, as single signals (a list read in a process would
    # become an array in the HDL, and an array's word cannot take an instance's output)
    b0, b1, g0, g1, r0, r1, k0, k1 = (Signal(bool(0)) for _ in range(8))
    lane_b, lane_g, lane_r, lane_c = (Signal(bool(0)) for _ in range(4))

    @always_comb
    def lane_bits():
        b0.next = p_b[0]
        b1.next = p_b[1]
        g0.next = p_g[0]
        g1.next = p_g[1]
        r0.next = p_r[0]
        r1.next = p_r[1]
        k0.next = p_c[0]
        k1.next = p_c[1]

    @always_comb
    def gpdi():
        gpdi_dp.next = concat(lane_c, lane_r, lane_g, lane_b)

    insts += [lane_bits, gpdi, oddr(tclk, b0, b1, lane_b, label="tmds_oddr_b"),
              oddr(tclk, g0, g1, lane_g, label="tmds_oddr_g"), oddr(tclk, r0, r1, lane_r, label="tmds_oddr_r"),
              oddr(tclk, k0, k1, lane_c, label="tmds_oddr_c")]

    # ---- the cameras: XCLK, reset, SCCB -----------------------------------------------------------------
    sio_c, sio_d_oe = Signal(bool(1)), Signal(bool(0))
    sio_d_i = Signal(intbv(3)[2:])
    insts.append(sccb_master(mclk, rst_m, fire1, sio_c, sio_d_oe, sio_d_i, sccb_busy, sccb_done, present,
                             table=sccb_table, clk_hz=ck["mem"] * 1e6, sccb_hz=sccb_hz, cameras=2))
    siod_l, siod_r = Signal(bool(1)), Signal(bool(1))

    @always_comb
    def sccb_pins():
        cam_l_sioc.next = sio_c
        cam_r_sioc.next = sio_c
        cam_l_resetn.next = not rst_m
        cam_r_resetn.next = not rst_m
        cam_l_pwdn.next = 0
        cam_r_pwdn.next = 0

    @always_comb
    def sccb_in():
        sio_d_i.next = concat(siod_r, siod_l)

    # open drain: SIO_D driven 0 while sio_d_oe, released otherwise (the module's pull-up makes the 1)
    insts += [tristate(zero, sio_d_oe, siod_l, cam_l_siod, label="siod_l"),
              tristate(zero, sio_d_oe, siod_r, cam_r_siod, label="siod_r")]
    insts += [sccb_pins, sccb_in, oddr(pclk, one, zero, cam_l_xclk, label="xclk_l_oddr"),
              oddr(pclk, one, zero, cam_r_xclk, label="xclk_r_oddr")]

    # ---- LEDs --------------------------------------------------------------------------------------------
    blink = Signal(intbv(0, min=0, max=int(ck["pixel"] * 1e6) // 2))
    beat = Signal(bool(0))
    seen_err = Signal(bool(0))

    @always_seq(pclk.posedge, reset=rst_p)
    def heartbeat():
        if blink == blink.max - 1:
            blink.next = 0
            beat.next = not beat
        else:
            blink.next = blink + 1

    @always_seq(mclk.posedge, reset=rst_m)
    def errors_seen():
        if uart_errors != 0:
            seen_err.next = 1

    @always_comb
    def leds():
        led.next = concat(run, beat, seen_err, copies[0], sccb_busy, present, locked)

    insts += [heartbeat, errors_seen, leds]
    return insts
