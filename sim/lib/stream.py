"""cocotb drivers for the image stream: a source with random idle cycles and a checking sink.

The protocol is documented in :mod:`eyestereo.hdl.interfaces.stream`; the frame bookkeeping (and every protocol
check) is :class:`eyestereo.tools.stream.FrameAssembler`, shared with the pure-Python side.
"""

from __future__ import annotations

import random
from collections import deque

import cocotb
from cocotb.triggers import Event, FallingEdge, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from eyestereo.tools.stream import TOKEN, FrameAssembler, ProtocolError, frame_to_beats

UNKNOWN = -1  # data read back as X/U/Z (allowed only where a block's output is unspecified)
STREAM_PORTS = ("data", "valid", "eol", "eof")


def resolved(value) -> int:
    """A value read from a handle (a LogicArray) as an int, UNKNOWN when a bit is not 0 or 1."""
    return int(value) if value.is_resolvable else UNKNOWN


def port_handles(dut, prefix: str, names=STREAM_PORTS) -> list:
    """The DUT's ``<prefix>_<name>`` handles, in the order of ``names`` (an image stream's by default)."""
    return [getattr(dut, f"{prefix}_{name}") for name in names]


def int_reader(handle):
    """A function returning ``handle``'s value as an int, or UNKNOWN when a bit is not 0 or 1.

    Reads the simulator's bit string and converts it directly (``int(bits, 2)``): several times cheaper
    than building a ``LogicArray`` per read, which is much of a Verilator bench's time.
    """
    raw = getattr(getattr(handle, "_handle", None), "get_signal_val_binstr", None)
    if raw is None:  # not a simulator signal handle as cocotb 2.1 has it: the public way
        def public():
            return resolved(handle.value)

        return public

    def fast():
        try:
            return int(raw(), 2)
        except ValueError:
            return UNKNOWN

    return fast


class IdleGenerator:
    """Decides, cycle by cycle, whether the source offers a beat: ``duty`` is the fraction that do."""

    def __init__(self, duty: float = 1.0, seed: int = 0):
        if not 0.0 < duty <= 1.0:
            raise ValueError(f"duty must be in (0, 1], got {duty}")
        self.duty = duty
        self.rng = random.Random(seed)

    def __call__(self) -> bool:
        return self.duty >= 1.0 or self.rng.random() < self.duty


class EdgeTime:
    """Cycle numbers from simulation time: rising edge 1 is the first one a driver saw, ``period`` apart.

    The drivers learn the period from their first two rising edges (:meth:`learn`) and from then on
    sleep across stretches where nothing happens, so they count cycles from the time instead of edge by
    edge. Times are in ``unit`` (simulator steps by default; the HDL drivers' files hold ns).
    """

    def __init__(self, unit: str = "step"):
        self.unit = unit
        self.t1: int | None = None
        self.period: int | None = None

    def now(self) -> int:
        return int(get_sim_time(unit=self.unit))

    async def learn(self, edge) -> None:
        """Wait for rising edges 1 and 2 (``edge``: the clock's RisingEdge) and take t1 and the period."""
        await edge
        self.t1 = self.now()
        await edge
        self.period = self.now() - self.t1

    def cycle(self, t: int | None = None) -> int:
        """Rising edges seen up to time ``t`` (now by default)."""
        if self.t1 is None:
            return 0
        t = self.now() if t is None else t
        if self.period is None:
            return 1
        return (t - self.t1) // self.period + 1


class BeatQueue:
    """The queue side every stream source shares: beats wait in ``queue`` until the source drives them."""

    queue: deque | list

    def send_frame(self, frame) -> None:
        self.send_beats(frame_to_beats(frame))

    def send_beats(self, beats) -> None:
        self.queue.extend(beats)
        self._queued()

    def send_token(self) -> None:
        self.send_beats([TOKEN])

    def _queued(self) -> None:
        """Called after beats were queued: a source that sleeps on an empty queue wakes here."""

    @property
    def idle_now(self) -> bool:
        """Nothing queued any more."""
        return not self.queue

    def _drive(self, dut, prefix: str, clk, idle: IdleGenerator | None) -> None:
        """Take the ``<prefix>_*`` stream ports (all driven to 0), the clock and the idle generator."""
        self.clk = clk
        self.data, self.valid, self.eol, self.eof = port_handles(dut, prefix)
        for h in (self.valid, self.data, self.eol, self.eof):
            h.value = 0
        self.idle = idle or IdleGenerator()
        self.queue = deque()
        self.sent_cycles: list[int] = []  # cycle number of every beat sent


class StreamSource(BeatQueue):
    """Drives ``<prefix>_data/valid/eol/eof`` of a DUT from a queue of beats, with idle cycles.

    The beat of cycle n is written at the falling edge in the middle of cycle n, and the DUT samples it
    at rising edge n + 1, as if it were written just after edge n. Python runs once per beat: an idle
    stretch is drawn from the idle generator in advance and slept across with one Timer, and an empty
    queue waits for :meth:`send_frame` & co. The idle generator is drawn once per cycle while beats are
    queued, as a cycle-by-cycle driver would. The first beat can go out in cycle 2 (the source learns
    the clock period from rising edges 1 and 2). ``changed`` is set whenever the queue runs empty.
    A DUT with a combinational path from its sink to its source port needs :class:`ClockedStreamSource`
    and :class:`ClockedStreamSink` (a mid-cycle write would show at the sink's mid-cycle sample).
    """

    def __init__(self, dut, prefix: str, clk, idle: IdleGenerator | None = None):
        self._drive(dut, prefix, clk, idle)
        self.time = EdgeTime()
        self.changed = Event()
        self._more = Event()
        self._task = cocotb.start_soon(self._run())

    @property
    def cycle(self) -> int:
        """Rising edges since the source started."""
        return self.time.cycle()

    def _queued(self) -> None:
        self._more.set()

    async def _run(self):
        edge, fall = RisingEdge(self.clk), FallingEdge(self.clk)
        await self.time.learn(edge)
        period = self.time.period
        await fall
        valid = eol = eof = 0
        while True:  # at a falling edge: what is written now, the DUT samples at the next rising edge
            if not self.queue:
                if valid:
                    self.valid.value = valid = 0
                self.changed.set()
                self._more.clear()
                await self._more.wait()
                await fall
                continue
            idle = 0
            while not self.idle():
                idle += 1
            if idle:
                if valid:
                    self.valid.value = valid = 0
                # To a quarter period after the falling edge ``idle`` cycles on: not onto the edge itself,
                # where the order of the Timer and the edge would decide which cycle the write is in.
                await Timer(idle * period + period // 4, unit="step")
            data, e, f = self.queue.popleft()
            self.data.value = data
            if e != eol:
                self.eol.value = eol = int(e)
            if f != eof:
                self.eof.value = eof = int(f)
            if not valid:
                self.valid.value = valid = 1
            self.sent_cycles.append(self.time.cycle())
            await fall


class SinkResults:
    """What every stream sink gives its bench: the frames and events it assembled (``asm``, a
    FrameAssembler) and the first protocol error it saw (``error``), raised by :meth:`check`; and what
    every sink does with a beat (:meth:`_push`). ``changed`` (an Event, if the sink has one) is set on
    the first protocol error."""

    asm: FrameAssembler
    error: ProtocolError | None
    changed: Event | None = None

    def _start(self, width: int, height: int) -> None:
        self.asm = FrameAssembler(width, height)
        self.received_cycles: list[int] = []
        self.beats = 0
        self.error = None

    def _fail(self, msg: str) -> None:
        if self.error is None:
            self.error = ProtocolError(msg)
            if self.changed is not None:
                self.changed.set()

    def _shown(self) -> str:
        """How the ``eol`` and ``eof`` handles read now."""
        return f"{self.eol.value}, {self.eof.value}"

    def _push(self, cycle: int, data: int, eol: int, eof: int, shown=None) -> None:
        """One valid beat of ``cycle``: counted, and handed to the frame assembler while no error was
        seen. ``eol`` / ``eof`` are 0, 1 or UNKNOWN (an error); ``shown()`` tells how they read then
        (:meth:`_shown` by default)."""
        self.beats += 1
        self.received_cycles.append(cycle)
        if self.error is None:
            try:
                if eol == UNKNOWN or eof == UNKNOWN:
                    raise ProtocolError(f"eol/eof undefined ({(shown or self._shown)()})")
                self.asm.push(data, bool(eol), bool(eof))
            except (ProtocolError, ValueError) as err:
                self._fail(f"cycle {cycle}: {err}")

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


class StreamSink(SinkResults):
    """Monitors ``<prefix>_*`` and rebuilds frames; any protocol fault is recorded and re-raised.

    ``received_cycles`` holds the cycle number of every beat, counted like the source's: a beat the
    source drives in cycle n (after rising edge n) is sampled by the DUT at edge n + 1; an output
    registered at that edge is seen in cycle n + 1, a latency of 1 clock.

    The outputs are sampled at the falling edge in the middle of each cycle (registered outputs and
    everything combinational after the rising edge have settled), once per cycle while ``valid`` is
    1 or undefined; while it is 0 the sink sleeps until ``valid`` changes. ``changed`` is set when a
    frame or token completes and on the first protocol error.
    """

    def __init__(self, dut, prefix: str, clk, width: int, height: int):
        self.clk = clk
        self.data, self.valid, self.eol, self.eof = port_handles(dut, prefix)
        self._start(width, height)
        self.time = EdgeTime()
        self.changed = Event()
        self.active = False  # set once the DUT is out of reset: before that its outputs are undefined
        self._task = cocotb.start_soon(self._run())

    @property
    def cycle(self) -> int:
        """Rising edges since the sink started."""
        return self.time.cycle()

    async def _run(self):
        fall = FallingEdge(self.clk)
        valid, data, eol, eof = (int_reader(h) for h in (self.valid, self.data, self.eol, self.eof))
        await self.time.learn(RisingEdge(self.clk))
        while True:
            await fall
            if not self.active:
                continue
            v = valid()
            if v == UNKNOWN:
                self._fail(f"source_valid is {self.valid.value} at cycle {self.time.cycle()}")
                continue
            if not v:
                await self.valid.value_change  # rises (or turns undefined) in a later cycle
                continue
            f = eof()
            self._push(self.time.cycle(), data(), eol(), f)
            if f == 1 and self.error is None:
                self.changed.set()


class ClockedStreamSource(BeatQueue):
    """The cycle-by-cycle source the benches used before :class:`StreamSource` (Python on every clock).

    Kept so ``make bench`` can measure both in one run (bench config ``drivers="clocked"``).
    """

    def __init__(self, dut, prefix: str, clk, idle: IdleGenerator | None = None):
        self._drive(dut, prefix, clk, idle)
        self.cycle = 0
        self._task = cocotb.start_soon(self._run())

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


class ClockedStreamSink(SinkResults):
    """The cycle-by-cycle sink the benches used before :class:`StreamSink` (RisingEdge + ReadOnly per clock).

    Kept so ``make bench`` can measure both in one run (bench config ``drivers="clocked"``).

    ``received_cycles`` holds the cycle number of every beat, counted like the source's: a beat the
    source drives in cycle n (after rising edge n) is sampled by the DUT at edge n + 1; an output
    registered at that edge is seen in cycle n + 1, a latency of 1 clock.
    """

    def __init__(self, dut, prefix: str, clk, width: int, height: int):
        self.clk = clk
        self.data, self.valid, self.eol, self.eof = port_handles(dut, prefix)
        self._start(width, height)
        self.cycle = 0
        self.active = False  # set once the DUT is out of reset: before that its outputs are undefined
        self._task = cocotb.start_soon(self._run())

    async def _run(self):
        while True:
            await RisingEdge(self.clk)
            self.cycle += 1
            await ReadOnly()
            if not self.active:
                continue
            if not self.valid.value.is_resolvable:
                self._fail(f"source_valid is {self.valid.value} at cycle {self.cycle}")
                continue
            if int(self.valid.value):
                self._push(self.cycle, resolved(self.data.value), resolved(self.eol.value), resolved(self.eof.value))


class BeatSource(StreamSource):
    """A source for any beats, protocol faults included: ``(data, eol, eof)`` or ``(data, eol, eof, cam)``.

    Unlike :class:`StreamSource` it drives ``<prefix>_cam`` too (stereo streams) and keeps nothing of the
    frame structure: it is for benches that feed broken streams on purpose (the stream checker's).
    ``sent_cycles`` counts cycles like :class:`BeatMonitor` (simulation time / clock period).
    """

    def __init__(self, dut, prefix: str, clk, idle: IdleGenerator | None = None, *, period_ns: float = 10):
        self.cam = getattr(dut, f"{prefix}_cam", None)
        self.period_ns = period_ns
        if self.cam is not None:
            self.cam.value = 0
        super().__init__(dut, prefix, clk, idle)

    async def _run(self):
        from cocotb.utils import get_sim_time

        while True:
            await RisingEdge(self.clk)
            if self.queue and self.idle():
                beat = self.queue.popleft()
                self.data.value = int(beat[0])
                self.eol.value = int(bool(beat[1]))
                self.eof.value = int(bool(beat[2]))
                if self.cam is not None:
                    self.cam.value = int(beat[3]) if len(beat) > 3 else 0
                self.valid.value = 1
                self.sent_cycles.append(round(get_sim_time(unit="ns") / self.period_ns))
            else:
                self.valid.value = 0


class BeatMonitor:
    """Records every valid beat of ``<prefix>_*`` as it is, without protocol checks, with extra outputs.

    ``beats`` holds ``(cycle, data, eol, eof, cam, *extra)`` per valid beat (cycle = simulation time /
    clock period, sampled just after the rising edge the beat was registered on; data ``UNKNOWN`` when
    not 0/1; cam 0 for mono streams), ``extra`` the values of the named single ports on that beat.
    ``changes[name]`` lists ``(cycle, value)`` of every change of an extra port, found by waiting for its
    edges (no Python runs per clock for them).
    """

    def __init__(self, dut, prefix: str, clk, *, extra: tuple[str, ...] = (), period_ns: float = 10):
        self.clk = clk
        self.period_ns = period_ns
        self.data, self.valid, self.eol, self.eof = port_handles(dut, prefix)
        self.cam = getattr(dut, f"{prefix}_cam", None)
        self.extra = {name: getattr(dut, name) for name in extra}
        self.beats: list[tuple] = []
        self.undefined: list[str] = []
        self.changes: dict[str, list[tuple[int, int]]] = {name: [] for name in extra}
        self.active = True
        self._tasks = [cocotb.start_soon(self._run())]
        self._tasks += [cocotb.start_soon(self._watch(n, s)) for n, s in self.extra.items()]

    def _cycle(self) -> int:
        from cocotb.utils import get_sim_time

        return int(get_sim_time(unit="ns") // self.period_ns)

    async def _watch(self, name, sig):
        while True:
            await sig.value_change
            await ReadOnly()
            if self.active:
                self.changes[name].append((self._cycle(), resolved(sig.value)))

    async def _run(self):
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if not self.active:
                continue
            v = self.valid.value
            if not v.is_resolvable:
                self.undefined.append(f"cycle {self._cycle()}: valid is {v}")
                continue
            if not int(v):
                continue
            beat = [self._cycle(), resolved(self.data.value), resolved(self.eol.value), resolved(self.eof.value),
                    resolved(self.cam.value) if self.cam is not None else 0]
            beat += [resolved(s.value) for s in self.extra.values()]
            if UNKNOWN in beat[1:]:
                self.undefined.append(f"cycle {beat[0]}: beat {beat[1:]} has undefined bits")
            self.beats.append(tuple(beat))
