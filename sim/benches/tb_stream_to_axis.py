"""cocotb bench: stream_to_axis, image stream in, cocotbext-axi AxiStreamSink (with back-pressure) out.

Two kinds of run (``expect`` in the config):

* ``"exact"``: the FIFO absorbs the back-pressure; every frame comes out bit for bit as
  :func:`eyestereo.tools.models.stream_to_axis.to_axis` of its input (a frame cut by a reset token
  excepted, which must come out as its complete lines), and ``overflow`` never pulses.
* ``"cut"``: the AXI side stalls longer than the FIFO holds; every frame that comes out is a sent
  frame, whole or its first complete lines (line commit) and never anything else, frames may be
  missing, the number of frames not delivered whole equals the number of ``overflow`` pulses, and
  the frames listed in ``whole`` (sent after the stall) come out whole.
"""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from eyestereo.sim.lib.axis import axis_sink, packets_to_beats, pauses
from eyestereo.sim.lib.bench import frame_params, load_config, make_frame, write_report
from eyestereo.sim.lib.stream import IdleGenerator, StreamSource
from eyestereo.tools.models.stream_to_axis import match_frames, split_frames, to_axis
from eyestereo.tools.stream import frame_to_beats


class StreamToAxisTB:
    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.clk = dut.clk
        Clock(dut.clk, 10, unit="ns").start()
        self.source = StreamSource(dut, "sink", dut.clk, IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0)))
        self.axis = None
        self.overflows = 0
        self.cycles = 0
        cocotb.start_soon(self._count_overflows())

    async def _count_overflows(self):
        while True:
            await RisingEdge(self.clk)
            self.cycles += 1
            await ReadOnly()
            if self.dut.rst.value == 0 and self.dut.overflow.value == 1:
                self.overflows += 1

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.clk, 3)
        # cocotbext-axi starts on a bus that the reset has defined (GHDL starts registers at U).
        self.axis = axis_sink(self.dut, "source", self.clk, self.dut.rst)
        self.axis.set_pause_generator(pauses(self.cfg.get("pause", 0.0), self.cfg.get("seed", 0) + 1,
                                             [tuple(s) for s in self.cfg.get("stalls", [])]))
        await RisingEdge(self.clk)
        self.dut.rst.value = 0
        await RisingEdge(self.clk)

    async def drain(self, timeout: int):
        """Wait until the source is done and the AXI side has been quiet (tvalid low) for 16 clocks."""
        quiet = 0
        for _ in range(timeout):
            await RisingEdge(self.clk)
            busy = self.source.queue or self.dut.source_tvalid.value == 1
            quiet = 0 if busy else quiet + 1
            if quiet >= 16:
                return
        raise AssertionError(f"timeout: the AXI side still busy after {timeout} clocks")


@cocotb.test()
async def stream_to_axis_frames(dut):
    cfg = load_config()
    w, h, bits = frame_params(cfg)
    commit = cfg["params"].get("commit", "line")
    tb = StreamToAxisTB(dut, cfg)
    await tb.reset()
    frames = [make_frame(s, w, h, bits) for s in cfg["frames"]]
    sent = list(frames)
    if cfg.get("token_after") is not None:
        tok = make_frame(cfg.get("token_frame", "random:99"), w, h, bits)
        tb.source.send_beats(frame_to_beats(tok)[:cfg["token_after"]])
        tb.source.send_token()
        sent = [tok] + frames
    for f in frames:
        tb.source.send_frame(f)
    total = sum(f.size for f in frames) + (cfg.get("token_after") or 0)
    stall = sum(s[1] for s in cfg.get("stalls", []))
    await tb.drain(int(total / cfg.get("duty", 1.0) / (1 - cfg.get("pause", 0.0)) * 2) + stall + 2000)

    packets = []
    while not tb.axis.empty():
        packets.append(tb.axis.recv_nowait(compact=False))
    beats = packets_to_beats(packets)
    received = split_frames(beats)
    tw = len(dut.source_tdata)
    assert all(0 <= d < (1 << bits) for d, _, _ in beats), f"tdata bits above the {bits}-bit pixel are set"
    assert len(dut.source_tdata) == 8 * ((bits + 7) // 8), f"tdata is {tw} bits for {bits}-bit pixels"
    whole, cut = match_frames(sent, received, commit=commit)
    token_cut = [0] if cfg.get("token_after") is not None else []
    if cfg.get("expect", "exact") == "exact":
        assert tb.overflows == 0, f"overflow pulsed {tb.overflows} times"
        assert cut == token_cut, f"frames {cut} did not come out whole (only a token-cut frame may)"
        # Bit for bit against the model, beat by beat with SOF and EOL: the token-cut frame's complete
        # lines (line commit; nothing with frame commit), then every frame whole.
        exp = []
        if token_cut:
            k = cfg["token_after"] // w if commit == "line" else 0
            exp += to_axis(sent[0])[:k * w]
        for f in frames:
            exp += to_axis(f)
        assert len(beats) == len(exp), f"{len(beats)} beats out, the model says {len(exp)}"
        bad = [i for i, (a, b) in enumerate(zip(beats, exp)) if a != b]
        assert not bad, f"{len(bad)} beats differ from the model, first at {bad[0]}: {beats[bad[0]]} vs {exp[bad[0]]}"
    else:
        assert tb.overflows >= 1, "expected an overflow (the stall is longer than the FIFO)"
        assert len(cut) - len(token_cut) == tb.overflows, (
            f"{len(cut)} frames not delivered whole (token: {len(token_cut)}), overflow pulsed {tb.overflows} times")
        for i in cfg.get("whole", []):
            assert i in whole, f"frame {i} (sent after the stall) did not come out whole: whole={whole}"
    report = dict(frames=len(frames), received=len(received), whole=whole, cut=cut, overflows=tb.overflows,
                  beats_out=len(beats), cycles=tb.cycles,
                  pixels_compared=sum(sent[i].size for i in whole))
    write_report(cfg, report)
