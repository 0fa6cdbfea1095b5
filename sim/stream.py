"""cocotb drivers for the image stream: a source with random idle cycles and a checking sink.

The protocol is documented in :mod:`eyestereo.hdl.stream`; the frame bookkeeping (and every protocol
check) is :class:`eyestereo.tools.stream.FrameAssembler`, shared with the pure-Python side.
"""

from __future__ import annotations

import random
from collections import deque

import cocotb
from cocotb.triggers import ReadOnly, RisingEdge

from eyestereo.tools.stream import TOKEN, FrameAssembler, ProtocolError, frame_to_beats

UNKNOWN = -1  # data read back as X/U/Z (allowed only where a block's output is unspecified)


class IdleGenerator:
    """Decides, cycle by cycle, whether the source offers a beat: ``duty`` is the fraction that do."""

    def __init__(self, duty: float = 1.0, seed: int = 0):
        if not 0.0 < duty <= 1.0:
            raise ValueError(f"duty must be in (0, 1], got {duty}")
        self.duty = duty
        self.rng = random.Random(seed)

    def __call__(self) -> bool:
        return self.duty >= 1.0 or self.rng.random() < self.duty


class StreamSource:
    """Drives ``<prefix>_data/valid/eol/eof`` of a DUT from a queue of beats, with idle cycles."""

    def __init__(self, dut, prefix: str, clk, idle: IdleGenerator | None = None):
        self.clk = clk
        self.data = getattr(dut, f"{prefix}_data")
        self.valid = getattr(dut, f"{prefix}_valid")
        self.eol = getattr(dut, f"{prefix}_eol")
        self.eof = getattr(dut, f"{prefix}_eof")
        self.idle = idle or IdleGenerator()
        self.queue: deque = deque()
        self.sent_cycles: list[int] = []  # cycle number of every beat sent
        self.cycle = 0
        self.valid.value = 0
        self.data.value = 0
        self.eol.value = 0
        self.eof.value = 0
        self._task = cocotb.start_soon(self._run())

    def send_frame(self, frame) -> None:
        self.queue.extend(frame_to_beats(frame))

    def send_beats(self, beats) -> None:
        self.queue.extend(beats)

    def send_token(self) -> None:
        self.queue.append(TOKEN)

    @property
    def idle_now(self) -> bool:
        return not self.queue

    async def _run(self):
        while True:
            await RisingEdge(self.clk)
            self.cycle += 1
            if self.queue and self.idle():
                data, eol, eof = self.queue.popleft()
                self.data.value = data
                self.eol.value = int(eol)
                self.eof.value = int(eof)
                self.valid.value = 1
                self.sent_cycles.append(self.cycle)
            else:
                self.valid.value = 0


class StreamSink:
    """Monitors ``<prefix>_*`` and rebuilds frames; any protocol fault is recorded and re-raised.

    ``received_cycles`` holds the cycle number of every beat, counted like the source's: a beat the
    source drives in cycle n (after rising edge n) is sampled by the DUT at edge n + 1; an output
    registered at that edge is seen in cycle n + 1, a latency of 1 clock.
    """

    def __init__(self, dut, prefix: str, clk, width: int, height: int):
        self.clk = clk
        self.data = getattr(dut, f"{prefix}_data")
        self.valid = getattr(dut, f"{prefix}_valid")
        self.eol = getattr(dut, f"{prefix}_eol")
        self.eof = getattr(dut, f"{prefix}_eof")
        self.asm = FrameAssembler(width, height)
        self.received_cycles: list[int] = []
        self.beats = 0
        self.error: ProtocolError | None = None
        self.cycle = 0
        self.active = False  # set once the DUT is out of reset: before that its outputs are undefined
        self._task = cocotb.start_soon(self._run())

    @property
    def frames(self):
        return self.asm.frames

    @property
    def events(self):
        return self.asm.events

    def check(self) -> None:
        """Raise the first protocol error seen, if any."""
        if self.error is not None:
            raise self.error

    async def _run(self):
        while True:
            await RisingEdge(self.clk)
            self.cycle += 1
            await ReadOnly()
            if not self.active:
                continue
            if not self.valid.value.is_resolvable:
                self.error = self.error or ProtocolError(f"source_valid is {self.valid.value} at cycle {self.cycle}")
                continue
            if not int(self.valid.value):
                continue
            raw = self.data.value
            data = int(raw) if raw.is_resolvable else UNKNOWN
            self.beats += 1
            self.received_cycles.append(self.cycle)
            if self.error is None:
                try:
                    self.asm.push(data, bool(int(self.eol.value)), bool(int(self.eof.value)))
                except (ProtocolError, ValueError) as e:
                    self.error = ProtocolError(f"cycle {self.cycle}: {e}")
