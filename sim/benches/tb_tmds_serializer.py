"""cocotb bench: tmds_serializer, its DDR bit pairs against the model, then through a DVI receiver to the frames.

The pixel side gets the characters of a video: ``frames`` whole frames of a small mode with random test
images (the timing model's syncs and DE, the encoder model's characters; the video starts two lines before
a frame ends, so every frame is whole), after three pixel clocks of reset. A recorder takes the four 2-bit
outputs after every fast-clock edge. Then:

1. bit for bit: the pairs from the load of the first character after the reset to the last are
   :func:`eyestereo.tools.models.tmds_serializer.ddr_pairs` of the characters, each from the fast edge
   :func:`~eyestereo.tools.models.tmds_serializer.load_edge` says (latency and order checked), the clock
   channel included;
2. the three data channels' serial bit streams, each cut at its own arbitrary bit, into
   :func:`eyestereo.tools.models.dvi_receiver.receive`: it must find the symbol boundaries and return
   exactly the ``frames`` test images, and the mode's timing.

The two clocks come from one time base (pixel edges at 40 ns multiples, the fast clock 8 ns with a phase,
``fast_phase`` ps, that keeps its edges off the pixel clock's: see the block's latency).

Config: ``mode``, ``frames``, ``seed``, ``fast_phase``.
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.triggers import FallingEdge, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import EdgeClock, wait_until
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.dvi_receiver import receive
from eyestereo.tools.models.tmds_encoder import CONTROL, encode_stream
from eyestereo.tools.models.tmds_serializer import CLOCK_WORD, ddr_pairs, load_edge, pairs_to_bits
from eyestereo.tools.models.video_timing import mode_of, signals

RESET_CLOCKS = 3
OUTPUTS = ("q0", "q1", "q2", "qc")


def video(mode, frames: int, rng: np.random.Generator) -> tuple[np.ndarray, list[np.ndarray]]:
    """(characters (n, 3) per pixel clock, the whole frames' images) of ``frames`` frames of random images,
    from two lines before a frame's end to one line after the last frame's."""
    start = mode.frame_clocks - 2 * mode.h_total
    n = frames * mode.frame_clocks + 3 * mode.h_total
    s = signals(mode, n, start)
    images = rng.integers(0, 256, (frames + 2, mode.v_active, mode.h_active, 3))
    index = np.arange(start, start + n) // mode.frame_clocks
    rgb = images[index, s["y"], s["x"]]
    zero = np.zeros(n, dtype=np.int64)
    words = np.stack([encode_stream(rgb[:, 2], s["hsync"], s["vsync"], s["de"]),
                      encode_stream(rgb[:, 1], zero, zero, s["de"]),
                      encode_stream(rgb[:, 0], zero, zero, s["de"])], axis=1)
    return words, [images[f].astype(np.uint8) for f in range(1, frames + 1)]


class SerializerTB:
    """The two clocks, the pixel-side driver and the fast-side recorder."""

    def __init__(self, dut, fast_phase: int):
        self.dut = dut
        self.pix = ClockSpec(40000, 0)
        self.fast = ClockSpec(8000, fast_phase)
        self.clocks = [EdgeClock(dut.clk, self.pix), EdgeClock(dut.clk5, self.fast)]
        self.record: dict[int, tuple[int, ...]] = {}
        self.ports = [getattr(dut, n) for n in OUTPUTS]
        for i in range(3):
            getattr(dut, f"d{i}").value = 0

    async def start(self) -> None:
        for c in self.clocks:
            cocotb.start_soon(c.start())
        cocotb.start_soon(self._recorder())

    async def _recorder(self) -> None:
        """The outputs after every fast edge (read at the falling edge that follows it), by edge index."""
        while True:
            await RisingEdge(self.dut.clk5)
            j = self.clocks[1].edge_now()
            await FallingEdge(self.dut.clk5)
            vals = []
            for p in self.ports:
                v = p.value
                vals.append(int(v) if v.is_resolvable else -1)
            self.record[j] = tuple(vals)

    async def drive(self, words: np.ndarray) -> int:
        """Reset for pixel edges 1 .. RESET_CLOCKS, then one character per channel per pixel edge; returns the
        index of the pixel edge that captures ``words[0]``."""
        dut = self.dut
        dut.rst.value = 1
        first = RESET_CLOCKS + 1
        await wait_until(self.pix.time(first) - self.pix.period // 2)
        dut.rst.value = 0
        rows = words.tolist()
        for m, row in enumerate(rows):
            await wait_until(self.pix.time(first + m) - self.pix.period // 2)
            for i in range(3):
                getattr(dut, f"d{i}").value = row[i]
        return first


@cocotb.test()
async def serializer_to_receiver(dut):
    cfg = load_config()
    mode = mode_of(cfg.get("mode", "sim-32x24"))
    rng = np.random.default_rng(int(cfg.get("seed", 1)))
    words, images = video(mode, int(cfg.get("frames", 2)), rng)
    tb = SerializerTB(dut, int(cfg.get("fast_phase", 2000)))
    await tb.start()
    first = await tb.drive(words)
    last = first + len(words) - 1
    end = tb.fast.time(load_edge(tb.pix.time(last), tb.fast.phase, tb.fast.period) + 6)
    await wait_until(end)

    # 1. bit for bit: every character from the first reset edge on, at its load edge, five pairs
    blank = np.full((first - 1, 3), CONTROL[0], dtype=np.int64)  # held during the reset (edges 1 .. first - 1)
    sent = np.concatenate([blank, words])
    sent = np.concatenate([sent, np.full((len(sent), 1), CLOCK_WORD, dtype=np.int64)], axis=1)
    j0 = load_edge(tb.pix.time(1), tb.fast.phase, tb.fast.period)
    for m in range(1, len(sent) + 1):  # the loads come every five fast edges
        assert load_edge(tb.pix.time(m), tb.fast.phase, tb.fast.period) == j0 + 5 * (m - 1)
    want = ddr_pairs(sent)
    missing = [j for j in range(j0, j0 + len(want)) if j not in tb.record]
    assert not missing, f"no outputs recorded after fast edges {missing[:5]}"
    got = np.array([tb.record[j] for j in range(j0, j0 + len(want))], dtype=np.int64)
    bad = np.nonzero((got != want).any(axis=1))[0]
    assert not len(bad), (f"{len(bad)} of {len(want)} fast clocks differ, the first after fast edge {j0 + bad[0]} "
                          f"(character {bad[0] // 5}, pair {bad[0] % 5}): {got[bad[0]].tolist()}, the model "
                          f"{want[bad[0]].tolist()}")

    # 2. the serial streams through the receiver, each channel cut at its own arbitrary bit
    video_pairs = got[5 * (first - 1):]
    start = int(rng.integers(0, 10 * mode.h_total))  # somewhere in the first line
    cuts = [start + int(rng.integers(0, 20)) for _ in range(3)]  # and a few bits of skew between the channels
    bits = [pairs_to_bits(video_pairs[:, c])[cuts[c]:] for c in range(3)]
    cap = receive(bits, mode)
    assert len(cap.frames) == len(images), f"{len(cap.frames)} whole frames received, {len(images)} sent"
    for f, (a, b) in enumerate(zip(cap.frames, images, strict=True)):
        diff = np.argwhere(a != b)
        assert not len(diff), f"frame {f}: {len(diff)} samples differ, the first at (y, x, rgb) {diff[0].tolist()}"
    assert [(10 - c % 10) % 10 for c in cuts] == list(cap.offsets), (cuts, cap.offsets)
    t = cap.timing
    assert (t["h_active"], t["h_sync"], t["h_total"], t["v_sync"], t["v_active"]) == (
        mode.h_active, mode.h_sync, mode.h_total, mode.v_sync, mode.v_active), t
    write_report(cfg, dict(characters=len(words), fast_clocks=len(want), frames=len(cap.frames), cuts=cuts,
                           offsets=list(cap.offsets), skew=list(cap.skew), timing=t))
