"""cocotb UART line agents: a sender that drives a line, a receiver that decodes one, a serial transport on both.

8N1 frames (start 0, 8 data bits LSB first, stop 1; idle high), timed in picoseconds, asynchronous to any
clock: the agents wake once per line transition (the sender, with a ``Timer``) or once per bit (the
receiver: the falling edge of a start bit, then a ``Timer`` to each bit's middle), never per clock.

* :class:`UartSender` -- plays bytes on a line at a bit time of its own (a sender a few percent off in
  baud: ``bit_ps``), with idle gaps, 0 stop bits (framing errors) and glitches; keeps every transition
  it made with its time (``transitions``), so a bench can sample the line at the receiver's clock edges
  for the bit-level model (:func:`eyestereo.tools.models.uart_rx.sample`).
* :class:`UartReceiver` -- decodes a line: every byte with the time of its start edge, and the framing
  errors (a 0 stop bit).
* :class:`SerialTransport` -- ``write(bytes)`` / ``read(n)`` coroutines on a sender and a receiver, with a
  read timeout in simulated time: the byte transport of :class:`eyestereo.tools.board.serial_bus.SerialBus`,
  so the host's own code drives a bridge in simulation.
"""

from __future__ import annotations

from cocotb.simtime import get_sim_time
from cocotb.triggers import Event, FallingEdge, First, Timer

from eyestereo.tools.models.uart_rx import waveform

__all__ = ["UartSender", "UartReceiver", "SerialTransport"]


def _now() -> int:
    return int(get_sim_time(unit="ps"))


async def _until(t_ps: int) -> None:
    now = _now()
    if t_ps > now:
        await Timer(t_ps - now, unit="ps")


class UartSender:
    """Drives ``line`` (idle high from construction) at ``bit_ps`` picoseconds per bit."""

    def __init__(self, line, bit_ps: int):
        self.line = line
        self.bit_ps = int(bit_ps)
        self.transitions: list[tuple[int, int]] = [(0, 1)]
        line.value = 1

    def _drive(self, level: int) -> None:
        self.line.value = level
        self.transitions.append((_now(), level))

    async def send(self, data, *, bit_ps: int | None = None, gap_ps: int = 0, stop_bits=None) -> None:
        """Sends the bytes of ``data`` from now on, ``gap_ps`` idle after each stop bit; ``bit_ps`` overrides
        the bit time for these bytes; ``stop_bits``: per byte its stop bit level (0: a framing error)."""
        t0 = _now()
        trans, end = waveform(list(data), bit_ps or self.bit_ps, start=t0, gap=gap_ps, stop_bits=stop_bits)
        for t, level in trans:
            await _until(round(t))
            self._drive(level)
        await _until(round(end))

    async def glitch(self, width_ps: int) -> None:
        """A low pulse of ``width_ps`` on the idle line."""
        self._drive(0)
        await Timer(int(width_ps), unit="ps")
        self._drive(1)


class UartReceiver:
    """Decodes ``line`` at ``bit_ps`` per bit: ``received`` = ``[(start time ps, byte), ...]``, ``framing`` =
    start times of bytes with a 0 stop bit (not in ``received``). Starts when constructed."""

    def __init__(self, line, bit_ps: int):
        import cocotb

        self.line = line
        self.bit_ps = int(bit_ps)
        self.received: list[tuple[int, int]] = []
        self.framing: list[int] = []
        self.glitches = 0
        self._new = Event()
        self._task = cocotb.start_soon(self._run())

    async def _run(self) -> None:
        half = self.bit_ps // 2
        while True:
            await FallingEdge(self.line)
            t0 = _now()
            await Timer(half, unit="ps")
            if int(self.line.value):
                self.glitches += 1  # a start bit shorter than half a bit
                continue
            byte = 0
            for i in range(8):
                await Timer(self.bit_ps, unit="ps")
                byte |= int(self.line.value) << i
            await Timer(self.bit_ps, unit="ps")
            if int(self.line.value):
                self.received.append((t0, byte))
            else:
                self.framing.append(t0)
            self._new.set()

    async def wait_bytes(self, n: int, timeout_ps: int) -> bool:
        """Waits until at least ``n`` bytes were received or ``timeout_ps`` passed; True when they were."""
        end = _now() + int(timeout_ps)
        while len(self.received) < n:
            left = end - _now()
            if left <= 0:
                return False
            self._new.clear()
            await First(self._new.wait(), Timer(left, unit="ps"))
        return True

    def data(self) -> bytes:
        return bytes(b for _, b in self.received)


class SerialTransport:
    """A byte transport (``write``/``read`` coroutines) on a simulated line: what a host's serial port is to
    :class:`~eyestereo.tools.board.serial_bus.SerialBus`. ``read(n)`` returns fewer than ``n`` bytes when
    ``timeout_ps`` of simulated time pass first (as pyserial's ``read`` does after its timeout)."""

    def __init__(self, sender: UartSender, receiver: UartReceiver, *, timeout_ps: int):
        self.sender, self.receiver = sender, receiver
        self.timeout_ps = int(timeout_ps)
        self._taken = 0

    async def write(self, data: bytes) -> int:
        await self.sender.send(bytes(data))
        return len(data)

    async def read(self, n: int) -> bytes:
        await self.receiver.wait_bytes(self._taken + n, self.timeout_ps)
        got = self.receiver.data()[self._taken:self._taken + n]
        self._taken += len(got)
        return got
