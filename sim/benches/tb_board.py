"""cocotb bench: the whole ULX3S board top (``board_harness``): cameras -> SDRAM -> rectification -> Harris ->
HDMI, configured over SCCB, driven by the host tool's own code over a simulated serial line.

What is around the board top (:mod:`eyestereo.sim.harnesses.board_harness`): the oscillator; two camera players
playing the same stereo pair frame after frame with an OV7670-like DVP timing; two SCCB slave models
(:class:`eyestereo.sim.lib.sccb.SccbSlave`: the rules of the SCCB specification, the writes recorded); the SDRAM part
(:class:`eyestereo.sim.lib.sdram_model.SdramModel`: the ULX3S's part, its rules checked every clock) on the board's
DQ pins; a UART line on the FT231X's pins with the host tool's :class:`~eyestereo.tools.board.host.Board` on
:class:`~eyestereo.tools.board.serial_bus.SerialBus` over it; a DVI receiver
(:func:`eyestereo.tools.models.dvi_receiver.receive`) on the four TMDS pins, sampled at both edges of the TMDS clock.

The run: the board starts itself (PLL lock, resets, the SCCB table, the display starts the front end); the host
checks both IDs and the status, writes the block thresholds (chosen with the model for ``target`` features) and k,
waits two frames, takes a pair and its features (the display stopped meanwhile, then restarted); the display's
next copies go to the monitor; the TMDS pins are recorded for ``monitor_frames`` frames and decoded.

Checks: the pair and the features the host read equal the numpy model's (the rectifier, stereo Harris and feature
list models on the camera frames); with the top's ``matcher`` the match list the host read equals the feature
matcher model's on that pair (the MATCH register's reset settings); the last decoded HDMI frame equals the model's
picture of that pair, those features and those matches' segments
(:func:`eyestereo.tools.models.pair_display.picture`); the SCCB slaves recorded exactly the table and the
board reports both cameras present; no SDRAM rule broken; no serial-link error; the LEDs say locked and present.

Config: ``params`` (the board top's), ``frames`` (camera frames played), ``scene`` (:func:`stereo_frames`'s),
``target``, ``k``, ``match`` (the MATCH settings the host writes: ``t_max``, ``uniqueness``, ``lr_check``),
``monitor_frames``, ``cam_mhz`` (the camera players' PCLK), ``timing`` (CameraTiming fields).
"""

from __future__ import annotations

import time

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import FallingEdge, RisingEdge, Timer
from cocotb.types import LogicArray

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.fast_system import write_script
from eyestereo.sim.lib.frontend_model import (choose_thresholds, match_list_of, match_settings, model_params,
                                              stereo_frames)
from eyestereo.sim.lib.harness_files import SCRIPT_FILES
from eyestereo.sim.lib.sccb import SccbBus, SccbSlave
from eyestereo.sim.lib.sdram_model import SdramModel
from eyestereo.sim.lib.uart import SerialTransport, UartReceiver, UartSender
from eyestereo.tools.board.host import Board
from eyestereo.tools.board.regmap import BOARD_BASE, BOARD_REGMAP
from eyestereo.tools.board.serial_bus import READ_PIECE, SerialBus
from eyestereo.tools.camera import CameraTiming, frame_schedule
from eyestereo.tools.models import stereo_frontend as model
from eyestereo.tools.models.dvi_receiver import receive
from eyestereo.tools.models.match_engine import parse_list
from eyestereo.tools.models.pair_display import copy_pair, match_plane, picture
from eyestereo.tools.models.sram_arbiter import AddressMap, list_words
from eyestereo.tools.models.video_timing import mode_of
from eyestereo.tools.sdram import ULX3S


def inner(dut, suffix: str):
    """The one signal of the flattened board top whose name ends with ``suffix`` (an internal net the models
    need: the FPGA's own DQ drive, the SCCB master's SIO_D drive, the TMDS clock)."""
    found = [h for h in dut if h._name.endswith(suffix)]
    assert len(found) == 1, f"{len(found)} signals end with {suffix!r}: {[h._name for h in found][:5]}"
    return found[0]


class PadDriver:
    """The SDRAM model's ``dq_i`` on the board's DQ pins: a value with Z bits releases them, else drives them."""

    def __init__(self, val, drive):
        self.val, self.drive = val, drive

    @property
    def value(self):
        return self.val.value

    @value.setter
    def value(self, v):
        if isinstance(v, LogicArray) and not v.is_resolvable:
            s = str(v)
            if set(s) == {"Z"}:
                self.drive.value = 0
                return
            v = int(s.replace("Z", "0"), 2)
        self.val.value = int(v)
        self.drive.value = 1


class SdramPins:
    """The names SdramModel reads (``pins_*``) on the harness: the command pins, the FPGA's DQ drive, the pads."""

    def __init__(self, dut):
        for f in ("cke", "cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm"):
            setattr(self, f"pins_{f}", getattr(dut, f"mem_{f}"))
        self.pins_dq_o = inner(dut, "pins_dq_o")
        self.pins_dq_oe = inner(dut, "pins_dq_oe")
        self.pins_dq_i = PadDriver(dut.mem_dq_val, dut.mem_dq_drive)


class SioPins:
    """SccbBus's names on the harness: SIO_C, the master's SIO_D drive (internal), the slaves' pulls."""

    def __init__(self, dut):
        self.sio_c = dut.sioc_l
        self.sio_d_oe = inner(dut, "_sio_d_oe")
        self.sio_d_i = dut.pull_l  # SccbBus writes the lines here; PinSccbBus drives the pulls instead


class PinSccbBus(SccbBus):
    """The slaves pull the board's SIO_D pins (open drain) instead of writing the master's input."""

    def __init__(self, dut, slaves):
        super().__init__(SioPins(dut), slaves)
        self.pulls = (dut.pull_l, dut.pull_r)

    def _write_in(self):
        for pull, s in zip(self.pulls, self.slaves):
            pull.value = int(s.drive_low)


class BoardTB:
    def __init__(self, dut, cfg):
        from eyestereo.hdl.rectify.calibration import calibration_param

        self.dut, self.cfg = dut, cfg
        p = cfg["params"]
        self.cal = calibration_param(p["quantizers"], None, None)
        self.w, self.h = self.cal.width, self.cal.height
        self.mode = mode_of(p["mode"])
        self.mp = model_params({})
        self.timing = CameraTiming(width=self.w, height=self.h, **cfg.get("timing", {}))
        from eyestereo.hdl.boards.ulx3s import board_clocks

        self.mem_mhz = board_clocks(matcher=bool(p.get("matcher")), memory_mhz=p.get("memory_mhz"))["mem"]
        self.bit_ps = round(p["clocks_per_bit"] * 1e6 / self.mem_mhz)

    async def start(self, pair):
        d = self.dut
        d.btn.value = 1  # BTN_PWRn released (pulled up), the others low
        d.cam_go.value = 0
        d.mem_dq_drive.value = 0
        d.mem_dq_val.value = 0
        d.pull_l.value = 0
        d.pull_r.value = 0
        Clock(d.osc, 40, unit="ns").start()
        mhz = self.cfg.get("cam_mhz", 12.5)
        for base, m in zip((d.base_l, d.base_r), (mhz, mhz * 0.997)):
            Clock(base, 2 * int(round(1e6 / m / 2)), unit="ps").start(start_high=False)
        frames = [pair] * self.cfg.get("frames", 8)
        for idx, side in enumerate("lr"):
            write_script(SCRIPT_FILES[side], frame_schedule([f[idx] for f in frames], self.timing))
        # the part is clocked by the PLL's memory clock itself, not by the ODDR's copy on the pin: the copy changes
        # a delta cycle after the FPGA's flip-flops have taken the same edge, and would show the model their new
        # outputs. Its period is measured (the PLL model's 75 MHz is 13.333332 ns: whole femtoseconds)
        mclk = inner(d, "_mclk")
        await RisingEdge(mclk)
        t0 = get_sim_time(unit="fs")
        await RisingEdge(mclk)
        self.mclk_period_ns = (get_sim_time(unit="fs") - t0) / 1e6
        self.sdram = SdramModel(SdramPins(d), mclk, ULX3S, prefix="pins", period_ns=self.mclk_period_ns)
        self.sdram.start()
        self.slaves = [SccbSlave("left"), SccbSlave("right")]
        cocotb.start_soon(PinSccbBus(d, self.slaves).run())
        line = SerialTransport(UartSender(d.ftdi_txd, self.bit_ps), UartReceiver(d.ftdi_rxd, self.bit_ps),
                               timeout_ps=2 * READ_PIECE * 10 * self.bit_ps)
        self.link = SerialBus(line, clock_hz=self.mem_mhz * 1e6, sleep=lambda s: Timer(int(s * 1e12), unit="ps"))
        self.board = Board(self.link)
        await Timer(2, unit="us")
        d.cam_go.value = 1

    async def record_tmds(self, n_frames: int):
        """The three data lanes' bits for ``n_frames`` monitor frames (and a little more): both halves of each
        TMDS clock period (D0 in the high half, read at the falling edge; D1 in the low half, at the rising)."""
        tclk = inner(self.dut, "_tclk")
        pins = self.dut.gpdi_dp
        n = (n_frames + 1) * self.mode.frame_clocks * 5 + 64
        bits = np.zeros((3, 2 * n), dtype=np.uint8)
        await RisingEdge(tclk)
        for i in range(n):
            await FallingEdge(tclk)
            v = int(pins.value)
            bits[:, 2 * i] = (v & 1, v >> 1 & 1, v >> 2 & 1)
            await RisingEdge(tclk)
            v = int(pins.value)
            bits[:, 2 * i + 1] = (v & 1, v >> 1 & 1, v >> 2 & 1)
        return bits


@cocotb.test()
async def board_pair_to_monitor(dut):
    cfg = load_config()
    tb = BoardTB(dut, cfg)
    t_wall = time.perf_counter()
    pair = stereo_frames(cfg.get("scene", "shift:5"), 1, tb.w, tb.h)[0]
    k = cfg.get("k", 10)
    thr = choose_thresholds(tb.cal, [pair], k, cfg.get("target", 12), tb.mp)
    expect = model.stereo_frontend(tb.cal, pair[0], pair[1], k, [thr] * 16, **tb.mp)
    exp_feats = expect["list"]["features"]
    msets = match_settings(cfg)  # None without the matcher
    exp_matches = None
    if msets:
        ml = parse_list(match_list_of(expect, tb.mp, msets)["words"])
        exp_matches = [(int(x), int(y), int(d), int(c), int(dy)) for (x, y, d, c), dy in zip(ml["matches"], ml["dy"])]
    await tb.start(pair)

    b = tb.board
    await b.check()
    st0 = await b.status()
    # the host area of the memory (above the buffers): a burst written, read back as a burst and word by word
    amap_words = AddressMap(tb.w, tb.h, list_words(1023, 1023 if msets else None), cameras=False).host_base
    probe = [(0x1234 + 0x0101 * i) & 0xFFFF for i in range(40)]
    await b.fe.write_sram_words(amap_words, probe)
    back = await b.fe.read_sram_words(amap_words, len(probe))
    singles = [await b.fe.read("SRAM", amap_words + i) for i in range(4)]
    assert back == probe and singles == probe[:4], (probe[:6], back[:6], singles)
    # the board's registers refuse a write to a constant, and an unmapped word, with SLVERR (nothing changes)
    assert await tb.link.write(BOARD_BASE + BOARD_REGMAP["BOARD_ID"].offset, 0) == 2
    assert (await tb.link.read(BOARD_BASE + 0x1C))[1] == 2
    assert await b.regs.read("BOARD_ID") == BOARD_REGMAP["BOARD_ID"].reset_value()
    await b.set_harris(k_left=k, k_right=k, thresholds_left=[thr] * 16, thresholds_right=[thr] * 16)
    if msets:  # the matcher's run-time settings (MATCH), the model's
        await b.fe.set(match_limit=msets["limit"], match_uniqueness=msets["uniqueness"],
                       match_lr_check=int(msets["lr_check"]))
    f0 = await b.fe.read("FRAMES")
    await b.fe.wait_frame(after=f0, timeout_clocks=2_000_000, poll_clocks=20_000)
    f1 = await b.fe.wait_frame(timeout_clocks=2_000_000, poll_clocks=20_000)
    t_take = get_sim_time(unit="ns")
    got = await b.take_pair(matches=bool(msets))
    t_taken = get_sim_time(unit="ns")
    assert got.frame >= f1
    np.testing.assert_array_equal(got.left, expect["rectified"][0], err_msg="the rectified left image read over UART")
    np.testing.assert_array_equal(got.right, expect["rectified"][1], err_msg="the rectified right image")
    assert got.features == [tuple(f) for f in exp_feats], (got.features[:5], exp_feats[:5])
    assert got.matches == exp_matches, (got.matches if got.matches is None else got.matches[:5],
                                        exp_matches if exp_matches is None else exp_matches[:5])
    # the monitor: the display copies again after the host gave it back its run bit
    c0 = await b.regs.get("copies")
    for _ in range(200):
        if await b.regs.get("copies") >= c0 + 2:
            break
        await tb.link.wait(5_000)
    else:
        raise AssertionError(f"the display copied no pair after the host's (copies {c0}): the cameras stopped?")
    bits = await tb.record_tmds(cfg.get("monitor_frames", 2))
    cap = receive(list(bits), tb.mode)
    assert cap.frames, "no whole frame on the HDMI pins"
    ram_m = None if exp_matches is None else match_plane([m[:3] for m in exp_matches], tb.w, tb.h)
    want = picture(*copy_pair(expect["rectified"][0], expect["rectified"][1], exp_feats), tb.mode, ram_m)
    last = cap.frames[-1]
    bad = np.argwhere((last != want).any(axis=2))
    if bad.size:  # kept in the run's folder for a look (numpy arrays: every frame decoded, the expected picture,
        # both rectified buffers as the memory holds them now)
        np.save("hdmi_frames.npy", np.asarray(cap.frames))
        np.save("hdmi_want.npy", want)
        amap = AddressMap(tb.w, tb.h, list_words(1023, 1023 if msets else None), cameras=False)
        for buf in (0, 1):
            words = await b.fe.read_sram_words(amap.rectified(buf), tb.w * tb.h)
            np.save(f"rect_buf{buf}.npy", np.asarray(words))
        np.save("status.npy", np.asarray(list((await b.status()).items()), dtype=object), allow_pickle=True)
    assert bad.size == 0, f"{len(bad)} HDMI pixels differ, first (y, x) = {tuple(bad[0])}: {last[tuple(bad[0])]} != " \
                          f"{want[tuple(bad[0])]}"
    st = await b.status()
    # the cameras: the table recorded by both, both answered
    table = [tuple(e) for e in cfg["params"]["sccb_table"]]
    for s in tb.slaves:
        assert not s.errors, f"SCCB slave {s.name}: {s.errors[:3]}"
        assert s.writes == table, f"SCCB slave {s.name} recorded {s.writes}, the table is {table}"
    assert st["cam_present"] == 3 and st["pll_locked"] == 1 and st["uart_errors"] == 0, st
    leds = int(dut.led.value)
    assert leds & 0b111 == 0b111, f"LEDs {leds:08b}: locked and both cameras present expected"
    tb.sdram.finish()
    assert not tb.sdram.violations, f"SDRAM rules broken: {tb.sdram.violations[:3]}"
    write_report(cfg, dict(features=len(got.features), matches=None if got.matches is None else len(got.matches),
                           segment_pixels=0 if ram_m is None else int(ram_m.sum()),
                           threshold=thr, frames_at_grab=got.frame,
                           hdmi_frames=len(cap.frames), copies=st["copies"], status_at_start=st0,
                           requests=tb.link.requests, dropped=(st["dropped_left"], st["dropped_right"]),
                           frames=st["frames"],
                           sim_wall_s=round(time.perf_counter() - t_wall, 1),
                           sim_time_ns=get_sim_time(unit="ns"), take_start_ns=t_take, take_ns=t_taken - t_take))
