"""cocotb bench: pair_display, the monitor's copy of a rectified pair and the picture it shows.

The bus slave is a model of the front end's side of the buffer handshake (:class:`FrontEnd`): the registers the
display touches (CTRL, CMD, STATUS) and the SRAM window, holding one rectified pair and one feature list at the
buffers the configuration names. It checks the display's writes as it takes them: the wants only in CTRL's byte 1,
the autostart's words, the release once per copy; the pair becomes "held" ``hold_delay`` bus accesses after it was
wanted. A monitor records the picture (``de`` and the colours) per pixel clock; once a copy is done, the next whole
frame must equal the model's picture (``tools.models.pair_display``: ``picture`` of ``copy_pair`` of the pair and
features, numpy, from the config), and the sync signals must follow the mode
(:func:`eyestereo.tools.models.video_timing.signals`) two pixel clocks late.

With the block's ``matches`` parameter the list buffer also holds a match list after the features (from
:func:`~eyestereo.tools.models.sram_arbiter.match_offset`: random matches, some reaching past the image's left edge,
packed by :data:`~eyestereo.tools.models.match_engine.MATCH`, and the trailer), and the expected picture has their
segments (``match_plane``).

Config: ``params`` (the block's), ``seed``, ``features`` (how many random corners, some on the border),
``matches`` (how many random matches, with ``params["matches"]``), ``rect_buf``/``feat_buf`` (the buffers held),
``hold_delay``, ``frames`` (whole frames to check after the copy), ``absent`` (no pair ever becomes held: the
display must give up and withdraw its wants).
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge
from cocotbext.axi import AxiLiteBus, AxiLiteSlave

from eyestereo.sim.lib.axil import AxiLiteChecker
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.models.feature_list import MARKER
from eyestereo.tools.models.match_engine import MARKER as MATCH_MARKER
from eyestereo.tools.models.match_engine import MATCH, TRAILER
from eyestereo.tools.models.pair_display import SRAM_BASE, copy_pair, ctrl_words, match_plane, picture, start_words
from eyestereo.tools.models.sram_arbiter import match_offset
from eyestereo.tools.models.video_timing import mode_of, signals
from eyestereo.tools.regmap import REGMAP

CTRL, CMD, STATUS = (REGMAP[n].offset for n in ("CTRL", "CMD", "STATUS"))
BITS = {n: REGMAP.field(f"STATUS.{n}")[1].lsb for n in ("rect_held", "feat_held", "rect_buf", "feat_buf")}


class FrontEnd:
    """The front end's registers and SRAM as the display sees them (a cocotbext-axi target)."""

    def __init__(self, words: dict[int, int], *, rect_buf: int, feat_buf: int, hold_delay: int, absent: bool):
        self.words, self.rect_buf, self.feat_buf = words, rect_buf, feat_buf
        self.hold_delay, self.absent = hold_delay, absent
        self.want = 0
        self.since_want = 0
        self.held = False
        self.log: list[tuple[str, int, int, int]] = []  # (kind, address, data, strobe)
        self.releases = 0
        self.sram_reads = 0
        self.want_word, self.release_word, self.strb = ctrl_words()

    async def write(self, address, data):
        # cocotbext-axi hands the bytes the strobe selects, from the address of the first
        value = int.from_bytes(data, "little")
        word, first = address & ~3, address & 3
        strobe = ((1 << len(data)) - 1) << first
        self.log.append(("w", word, value << (8 * first), strobe))
        if word == CTRL:
            assert strobe in (0b0001, 0b0010), f"CTRL written with strobe {strobe:#06b}"
            if strobe == 0b0010:
                self.want = (value << 8) & self.want_word
                self.since_want = 0
        elif word == CMD:
            v = value << (8 * first)
            if v & self.release_word:
                assert v & self.release_word == self.release_word and self.held, \
                    f"CMD {v:#x} releases what is not held"
                self.held = False
                self.releases += 1
        else:
            raise AssertionError(f"the display wrote {address:#x}, which it has no business with")

    async def read(self, address, length):
        assert length == 4 and address % 4 == 0, f"a read of {length} bytes at {address:#x}"
        self.since_want += 1
        if address == STATUS:
            if self.want == self.want_word and self.since_want > self.hold_delay and not self.absent:
                self.held = True
            v = 0
            if self.held:
                v = ((1 << BITS["rect_held"]) | (1 << BITS["feat_held"]) | (self.rect_buf << BITS["rect_buf"])
                     | (self.feat_buf << BITS["feat_buf"]))
            return v.to_bytes(4, "little")
        if address >= SRAM_BASE:
            assert self.held, f"SRAM word {(address - SRAM_BASE) // 4} read while no buffer is held"
            self.sram_reads += 1
            return self.words.get((address - SRAM_BASE) // 4, 0).to_bytes(4, "little")
        raise AssertionError(f"the display read {address:#x}")


@cocotb.test()
async def pair_display_picture(dut):
    cfg = load_config()
    p = cfg["params"]
    rng = np.random.default_rng(cfg.get("seed", 1))
    w, h = p["width"], p["height"]
    mode = mode_of(p["mode"])
    left = rng.integers(0, 256, (h, w), dtype=np.uint8)
    right = rng.integers(0, 256, (h, w), dtype=np.uint8)
    left[0, :4] = 255  # codes that must be clipped
    feats = [(int(rng.integers(0, w)), int(rng.integers(0, h)), int(rng.integers(0, 2)))
             for _ in range(cfg.get("features", 12))] + [(0, 0, 0), (w - 1, h - 1, 1)]
    rect_base, feat_base = p["rect_base"], p["feat_base"]
    rb, fb = cfg.get("rect_buf", 1), cfg.get("feat_buf", 0)
    words = {}
    for i, (l, r) in enumerate(zip(left.ravel(), right.ravel())):
        words[rect_base[rb] + i] = int(l) | (int(r) << 8)
    for i, (x, y, c) in enumerate(feats):
        words[feat_base[fb] + 2 * i] = x | (c << 15)
        words[feat_base[fb] + 2 * i + 1] = y
    words[feat_base[fb] + 2 * len(feats)] = MARKER
    words[feat_base[fb] + 2 * len(feats) + 1] = len(feats)
    matches = []
    if p.get("matches"):
        # (x, y, disparity): some segments reach past the left edge (x < disparity), one is a single pixel
        matches = [(int(rng.integers(0, w)), int(rng.integers(0, h)), int(rng.integers(0, 12)))
                   for _ in range(cfg.get("matches", 6))] + [(2, h - 1, 9), (w - 1, 0, 0)]
        base = feat_base[fb] + match_offset(p["max_features"])
        for i, (x, y, d) in enumerate(matches):
            v = int(MATCH.pack(x=x, dy=int(rng.integers(-1, 2)), y=y, disparity=d, cost=int(rng.integers(0, 4096))))
            for j in range(3):
                words[base + 3 * i + j] = (v >> (16 * j)) & 0xFFFF
        t = int(TRAILER.pack(marker=MATCH_MARKER, count=len(matches), overflow=0, candidates=3 * len(matches)))
        for j in range(3):
            words[base + 3 * len(matches) + j] = (t >> (16 * j)) & 0xFFFF
    fe = FrontEnd(words, rect_buf=rb, feat_buf=fb, hold_delay=cfg.get("hold_delay", 3),
                  absent=cfg.get("absent", False))

    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    cocotb.start_soon(Clock(dut.pclk, 40, unit="ns").start())
    dut.rst.value = 1
    dut.prst.value = 1
    dut.run.value = 1
    await ClockCycles(dut.clk, 2)  # the ports settled before the bus models sample them
    AxiLiteSlave(AxiLiteBus.from_prefix(dut, "bus"), dut.clk, dut.rst, target=fe)
    checker = AxiLiteChecker(dut, "bus", dut.clk, dut.rst)
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await FallingEdge(dut.pclk)
    dut.prst.value = 0

    # the picture, pixel clock by pixel clock: (hsync, vsync, de, r, g, b)
    rows: list[tuple[int, ...]] = []

    async def watch():
        while True:
            await RisingEdge(dut.pclk)
            rows.append((int(dut.hsync.value), int(dut.vsync.value), int(dut.de.value), int(dut.red.value),
                         int(dut.green.value), int(dut.blue.value)))

    cocotb.start_soon(watch())
    frame = mode.frame_clocks
    if cfg.get("absent", False):
        limit = (p["polls"] + 2) * (p["poll_gap"] + 20) + 4 * frame * 4
        await ClockCycles(dut.clk, limit)
        writes = [(a, d, s) for k, a, d, s in fe.log if k == "w"]
        assert fe.releases == 0 and not fe.held
        wants = [d for a, d, s in writes if a == CTRL and s == 0b0010]
        assert wants and wants[-1] == 0, f"the wants were not withdrawn: {writes[-3:]}"
        assert int(dut.copies.value) == 0
        checker.check()
        write_report(cfg, dict(writes=len(writes), copies=0))
        return
    # wait for the first copy, then for the start of the next whole frame
    for _ in range(40 * frame):
        await RisingEdge(dut.clk)
        if int(dut.copies.value) >= 1:
            break
    assert int(dut.copies.value) >= 1, "no copy within 10 frames"
    n_frames = cfg.get("frames", 1)
    await ClockCycles(dut.pclk, (n_frames + 2) * frame)
    ram_m = match_plane(matches, w, h, max_matches=p.get("max_matches", 1023)) if p.get("matches") else None
    exp = picture(*copy_pair(left, right, feats), mode, ram_m)
    ref = signals(mode, frame * (len(rows) // frame + 2))  # the mode's own sync, de and coordinates
    # align: the block's outputs are the timing generator's two pixel clocks later
    sync = np.array([r[:3] for r in rows])
    lat = next(k for k in range(0, 8) if np.array_equal(
        sync[200 + k:200 + k + frame, 2], np.asarray(ref["de"][200:200 + frame], dtype=int)))
    got = np.array([r[3:] for r in rows])
    de = sync[:, 2].astype(bool)
    # whole frames after the copy: the last n_frames complete ones
    starts = [i for i in range(1, len(rows)) if de[i] and not de[i - 1]]
    first_px = [i for i in starts if ref["y"][(i - lat) % len(ref["y"])] == 0]
    assert len(first_px) >= n_frames + 1, f"only {len(first_px)} frames seen"
    checked = 0
    for f0 in first_px[-(n_frames + 1):-1]:
        pix = got[f0:f0 + frame][de[f0:f0 + frame]]
        assert pix.shape[0] == mode.h_active * mode.v_active, f"{pix.shape[0]} active pixels in a frame"
        img = pix.reshape(mode.v_active, mode.h_active, 3)
        bad = np.argwhere((img != exp).any(axis=2))
        assert bad.size == 0, f"{len(bad)} pixels differ, first at (y, x) = {tuple(bad[0])}: {img[tuple(bad[0])]} " \
                              f"!= {exp[tuple(bad[0])]}; the first ten (y, x): {[tuple(map(int, b)) for b in bad[:10]]}"
        for name, col in (("hsync", 0), ("vsync", 1)):
            want = np.asarray(ref[name][f0 - lat:f0 - lat + frame], dtype=int)
            assert np.array_equal(sync[f0:f0 + frame, col], want), f"{name} differs from the mode's"
        checked += 1
    # stop: the copy in progress ends, its buffers given back, the wants withdrawn; nothing is left over
    dut.run.value = 0
    await ClockCycles(dut.pclk, 3 * frame)
    writes = [(a, d, s) for k, a, d, s in fe.log if k == "w"]
    assert not fe.held, "a pair is still held after the display stopped"
    assert int(dut.idle.value) == 1, "the display is not idle after it stopped"
    wants = [d for a, d, s in writes if a == CTRL and s == 0b0010]
    assert wants[-1] == 0, "the wants were not withdrawn"
    if p.get("autostart"):
        run_word, start_word = start_words()
        assert writes[0] == (CTRL, run_word, 1) and writes[1] == (CMD, start_word, 1), writes[:2]
    else:
        assert all(a != CMD or d & 1 == 0 for a, d, s in writes), "CMD.start written without autostart"
    assert fe.releases == int(dut.copies.value), (fe.releases, int(dut.copies.value))
    checker.check()
    write_report(cfg, dict(frames_checked=checked, latency=lat, copies=int(dut.copies.value),
                           sram_reads=fe.sram_reads, writes=len(writes),
                           segment_pixels=0 if ram_m is None else int(ram_m.sum())))
