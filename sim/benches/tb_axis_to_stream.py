"""cocotb bench: axis_to_stream, cocotbext-axi AxiStreamSource (with random pauses) in, image stream out.

The stimulus is a sequence of AXI4-Stream video beats: whole frames, with the faults named in the
config's ``faults`` spliced in before frame i (``[[i, kind], ...]``):

``junk``        3 transfers without SOF (before the first frame: dropped silently; later: one error)
``early_sof``   frame i is cut after ``width + 2`` transfers by the next frame's SOF
``short_line``  ``tlast`` one pixel early on line 1 of frame i (the rest of that frame is dropped)
``long_line``   no ``tlast`` on line 1 of frame i
``extra_line``  one line more after frame i

The output must equal :func:`eyestereo.tools.models.axis_to_stream.axis_to_stream` of the same beats:
the same frames, bit for bit, and the same reset tokens in the same places (checked with the
image-stream protocol checker), the same number of ``error`` pulses, and ``tready`` low exactly once
per early SOF.
"""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from eyestereo.sim.lib.axis import axis_source, beats_to_packets, pauses
from eyestereo.sim.lib.bench import frame_params, load_config, make_frame, write_report
from eyestereo.sim.lib.stream import StreamSink
from eyestereo.tools.models.axis_to_stream import axis_to_stream
from eyestereo.tools.models.stream_to_axis import to_axis
from eyestereo.tools.stream import FrameAssembler


def stimulus(frames, faults, width):
    """AXI beats of ``frames`` with the configured faults spliced in."""
    kinds = {}
    for i, kind in faults:
        kinds.setdefault(int(i), []).append(kind)
    beats = []
    for i, f in enumerate(frames):
        b = to_axis(f)
        for kind in kinds.get(i, []):
            if kind == "junk":
                beats += [(7, False, False), (8, False, False), (9, True, False)]
            elif kind == "early_sof":
                b = b[:width + 2]
            elif kind == "short_line":
                j = 2 * width - 2  # pixel width - 2 of line 1 gets tlast
                b = b[:j] + [(b[j][0], True, False)] + b[j + 1:]
            elif kind == "long_line":
                j = 2 * width - 1
                b = b[:j] + [(b[j][0], False, False)] + b[j + 1:]
            elif kind == "extra_line":
                b = b + [(x, x == width - 1, False) for x in range(width)]
            else:
                raise ValueError(f"unknown fault {kind!r}")
        beats += b
    return beats


@cocotb.test()
async def axis_to_stream_frames(dut):
    cfg = load_config()
    w, h, bits = frame_params(cfg)
    dut.rst.value = 1
    dut.sink_tvalid.value = 0
    Clock(dut.clk, 10, unit="ns").start()
    sink = StreamSink(dut, "source", dut.clk, w, h)
    counts = dict(errors=0, not_ready=0, cycles=0)

    async def monitor():
        while True:
            await RisingEdge(dut.clk)
            counts["cycles"] += 1
            await ReadOnly()
            if dut.rst.value == 1:
                continue
            counts["errors"] += int(dut.error.value)
            counts["not_ready"] += 1 - int(dut.sink_tready.value)

    await ClockCycles(dut.clk, 3)
    # cocotbext-axi starts on a bus that the reset has defined (GHDL starts registers at U).
    src = axis_source(dut, "sink", dut.clk, dut.rst)
    src.set_pause_generator(pauses(cfg.get("pause", 0.0), cfg.get("seed", 0)))
    await RisingEdge(dut.clk)
    dut.rst.value = 0
    sink.active = True
    await RisingEdge(dut.clk)
    cocotb.start_soon(monitor())
    # The bridge raises tready one clock after rst; cocotbext-axi waits for it by itself.
    frames = [make_frame(s, w, h, bits) for s in cfg["frames"]]
    beats = stimulus(frames, cfg.get("faults", []), w)
    for pk in beats_to_packets(beats):
        await src.send(pk)
    await src.wait()
    await ClockCycles(dut.clk, 32)
    sink.check()

    exp_beats, exp_errors = axis_to_stream(beats, w, h)
    exp = FrameAssembler(w, h)
    exp.push_all(exp_beats)
    assert sink.asm.pixels_pending == exp.pixels_pending == 0, "a frame was left open"
    assert sink.events == exp.events, f"frames/tokens out {sink.events}, the model says {exp.events}"
    for i, (got, want) in enumerate(zip(sink.frames, exp.frames)):
        assert (got == want).all(), f"frame {i} differs from the model at {(got != want).nonzero()}"
    assert counts["errors"] == exp_errors, f"error pulsed {counts['errors']} times, the model says {exp_errors}"
    early = sum(1 for _, k in cfg.get("faults", []) if k == "early_sof")
    assert counts["not_ready"] == early, f"tready low {counts['not_ready']} clocks, expected {early} (early SOFs)"
    write_report(cfg, dict(frames=len(sink.frames), tokens=sum(e[0] == "token" for e in sink.events),
                           errors=counts["errors"], pixels_compared=sum(f.size for f in sink.frames),
                           beats_in=len(beats), cycles=counts["cycles"]))
