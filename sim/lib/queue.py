"""cocotb helpers for multi-clock benches: queue read port consumer, reset and stall drivers, beat players.

Everything here is driven by time, not by clocks: a bench knows every clock's period and phase (in ps)
and the edges at which it wants a signal to change, so Python sleeps with a ``Timer`` until then. Signals
are changed half a period before the edge that should see them (at the falling edge), never at a rising
edge. The monitor wakes on ``valid`` and on the edges that move words, not on every clock.

* :class:`EdgeClock` -- a clock of known period and phase (edge k at ``phase + k * period`` ps), started
  as the simulator's own clock (``impl="gpi"``: no Python per clock).
* :func:`drive_intervals` -- a 1-bit signal at ``active`` during edge intervals (resets, stalls).
* :class:`QueueMonitor` -- records every word that moves on a queue read port (``valid & ready`` at a
  rising edge), with its edge index.
* :class:`BeatPlayer` -- plays image-stream beats at given edges (for a block's stream sink).
"""

from __future__ import annotations

from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import RisingEdge, Timer

from eyestereo.sim.lib.stream import STREAM_PORTS, port_handles, resolved
from eyestereo.tools.models.async_fifo import ClockSpec


class EdgeClock:
    """A clock on ``signal`` with edge k at ``spec.phase + k * spec.period`` ps."""

    def __init__(self, signal, spec: ClockSpec):
        if spec.period % 2:
            raise ValueError(f"clock period {spec.period} ps must be even")
        self.signal = signal
        self.spec = spec
        signal.value = 0

    async def start(self):
        if self.spec.phase:
            await Timer(self.spec.phase, unit="ps")
        Clock(self.signal, self.spec.period, unit="ps", impl="gpi").start(start_high=True)

    def before(self, k: int) -> int:
        """The time (ps) half a period before edge k: when to change a signal edge k should see."""
        return self.spec.time(k) - self.spec.period // 2

    def edge_now(self) -> int:
        """Index of the rising edge at the current simulation time (the caller woke on it)."""
        t = get_sim_time(unit="ps")
        k, r = divmod(t - self.spec.phase, self.spec.period)
        if r:
            raise AssertionError(f"not at an edge of the clock: {t} ps, phase {self.spec.phase}, "
                                 f"period {self.spec.period}")
        return int(k)


async def wait_until(t_ps: int) -> None:
    now = get_sim_time(unit="ps")
    if t_ps > now:
        await Timer(t_ps - now, unit="ps")


def random_stalls(rng, share: float, start: int, until: int) -> list[tuple[int, int]]:
    """Random ``(first, end)`` edge intervals from ``start`` to ``until`` covering about ``share`` of the edges
    (stretches of 1..11 edges), for :func:`drive_intervals` on a consumer's ``ready`` (0: none)."""
    out, e = [], start
    while share and e < until:
        length = int(rng.integers(1, 12))
        gap = max(1, int(length * (1 - share) / share * rng.uniform(0.5, 1.5)))
        e += gap
        out.append((e, e + length))
        e += length + 1
    return out


async def drive_intervals(signal, clock: EdgeClock, intervals, *, active: int = 1) -> None:
    """Hold ``signal`` at ``active`` at the edges of each ``(first, end)`` interval, else at the other level.

    Edges are those of ``clock``; intervals must be sorted and apart.
    """
    signal.value = 1 - active
    for a, b in intervals:
        await wait_until(max(0, clock.before(a)))
        signal.value = active
        await wait_until(clock.before(b))
        signal.value = 1 - active


class QueueMonitor:
    """Records the words moved on ``<prefix>_valid/ready/data/eol/eof`` at rising edges of ``clock``.

    ``beats``: ``[(data, eol, eof, edge), ...]``; data of a word with undefined bits is -1 and noted in
    ``undefined``. The ``ready`` signal is read, not driven (drive it with :func:`drive_intervals`).
    ``ignore``: edge intervals in which a move does not count (the port's reset).
    """

    def __init__(self, dut, prefix: str, clock: EdgeClock, ignore=()):
        self.data, self.valid, self.eol, self.eof, self.ready = port_handles(dut, prefix, (*STREAM_PORTS, "ready"))
        self.clock = clock
        self.ignore = list(ignore)
        self.beats: list[tuple[int, bool, bool, int]] = []
        self.undefined: list[str] = []
        self.wakes = 0

    async def run(self) -> None:
        clk = self.clock.signal
        while True:
            await RisingEdge(clk)
            self.wakes += 1
            # Right after the edge the signals still hold the values the edge sampled.
            v, r = resolved(self.valid.value), resolved(self.ready.value)
            k = self.clock.edge_now()
            if v == 1 and r == 1 and not any(a <= k < b for a, b in self.ignore):
                raw = self.data.value
                d = resolved(raw)
                if d < 0 or resolved(self.eol.value) < 0 or resolved(self.eof.value) < 0:
                    self.undefined.append(f"edge {k}: data {raw} eol {self.eol.value} eof {self.eof.value}")
                self.beats.append((d, bool(resolved(self.eol.value) == 1), bool(resolved(self.eof.value) == 1),
                                   k))
            elif v == -1:
                self.undefined.append(f"edge {k}: valid {self.valid.value}")
            # Sleep until a word can move: valid high (it is registered: it rises after an edge) and
            # ready high (driven between edges). The values read here are still the pre-edge ones, so at
            # worst this wakes once more than needed.
            if resolved(self.valid.value) != 1:
                await RisingEdge(self.valid)
                self.wakes += 1
            elif resolved(self.ready.value) != 1:
                await RisingEdge(self.ready)
                self.wakes += 1


class BeatPlayer:
    """Plays ``(data, eol, eof, edge)`` beats on ``<prefix>_data/valid/eol/eof``: beat at edge k."""

    def __init__(self, dut, prefix: str, clock: EdgeClock):
        self.data, self.valid, self.eol, self.eof = port_handles(dut, prefix)
        self.clock = clock
        for h in (self.valid, self.data, self.eol, self.eof):
            h.value = 0

    async def play(self, beats) -> None:
        last = None
        for data, eol, eof, k in beats:
            if last is not None and k != last + 1:
                await wait_until(self.clock.before(last + 1))
                self.valid.value = 0
            await wait_until(self.clock.before(k))
            self.data.value = int(data)
            self.eol.value = int(eol)
            self.eof.value = int(eof)
            self.valid.value = 1
            last = k
        if last is not None:
            await wait_until(self.clock.before(last + 1))
            self.valid.value = 0
