"""The host driver's bus over the board's serial port: the UART bridge's requests on any byte transport.

:class:`SerialBus` is the bus object of :class:`eyestereo.tools.host_driver.HostDriver` (``read``, ``write``,
``wait``) plus bursts (``read_burst``, ``write_burst``: up to 256 words per request, longer ones split),
built on the bridge's protocol (:mod:`eyestereo.tools.board.protocol`). The transport is anything with
``write(bytes)`` and ``read(n) -> bytes``, plain or coroutines: pyserial's ``serial.Serial`` (open it with
a read ``timeout`` that covers :data:`READ_PIECE` bytes: a short read means the board did not answer),
or a simulated line in a cocotb bench
(:class:`eyestereo.sim.lib.uart.SerialTransport`). A short read raises ``TimeoutError``; a reply that does
not fit the request raises :class:`~eyestereo.tools.board.protocol.ProtocolError`.

One request at a time, each reply read whole before the next request goes out: the bridge's receive
FIFO holds only a few bytes ahead of what it is doing. A write burst goes out in one piece; its words are
written as they arrive.
"""

from __future__ import annotations

import asyncio
import inspect

from eyestereo.tools.board.protocol import (MAX_WORDS, check_address, decode_identify, decode_read, decode_write,
                                            encode_identify, encode_read, encode_write)

__all__ = ["SerialBus", "READ_PIECE"]

#: the most reply bytes asked of the port at once: its read timeout must cover this many bytes (256 bytes at
#: 115200 baud: 22 ms; at 3 Mbaud: 0.9 ms), however long the burst
READ_PIECE = 256


async def _done(result):
    """The value of a transport call, plain or awaitable."""
    return await result if inspect.isawaitable(result) else result


class SerialBus:
    """The bus interface over a byte transport ``port`` (see the module docstring).

    ``clock_hz``: the bus clock, for :meth:`wait` (clocks -> seconds); ``sleep``: the coroutine function
    that lets time pass (default ``asyncio.sleep``; a cocotb bench passes one on simulated time).
    """

    def __init__(self, port, *, clock_hz: float = 100e6, sleep=None):
        self.port = port
        self.clock_hz = float(clock_hz)
        self._sleep = sleep or asyncio.sleep
        self.requests = 0

    async def _request(self, request: bytes, reply_bytes: int) -> bytes:
        await _done(self.port.write(request))
        self.requests += 1
        reply = b""
        while len(reply) < reply_bytes:  # in pieces: the port's timeout need only cover one piece
            piece = bytes(await _done(self.port.read(min(READ_PIECE, reply_bytes - len(reply)))))
            reply += piece
            if not piece or len(reply) < reply_bytes and len(piece) < READ_PIECE:
                break
        if len(reply) < reply_bytes:
            raise TimeoutError(f"no reply from the board: {len(reply)} of {reply_bytes} bytes to a "
                               f"{chr(request[0])!r} request before the port's timeout (is the board connected, "
                               f"configured, at this baud rate?)")
        return reply

    async def identify(self) -> int:
        """The bridge's version word (:data:`~eyestereo.tools.board.protocol.VERSION`)."""
        return decode_identify(await self._request(encode_identify(), 5))

    async def read(self, address: int) -> tuple[int, int]:
        """One 32-bit bus read: (data, resp)."""
        return (await self.read_burst(address, 1))[0]

    async def write(self, address: int, data: int, strb: int = 0xF) -> int:
        """One bus write: resp."""
        return (await self.write_burst(address, [data], strb))[0]

    async def read_burst(self, address: int, n: int) -> list[tuple[int, int]]:
        """``n`` words from ``address``, ``address + 4``, ...: ``[(data, resp), ...]`` (requests of <= 256 words)."""
        address = check_address(address)
        out: list[tuple[int, int]] = []
        while len(out) < n:
            k = min(MAX_WORDS, n - len(out))
            a = (address + 4 * len(out)) & 0xFFFFFFFF
            out += decode_read(await self._request(encode_read(a, k), 1 + 5 * k), k)
        return out

    async def write_burst(self, address: int, words, strb: int = 0xF) -> list[int]:
        """``words`` to ``address``, ``address + 4``, ... with strobe ``strb``: the responses."""
        address = check_address(address)
        words = list(words)
        out: list[int] = []
        while len(out) < len(words):
            chunk = words[len(out):len(out) + MAX_WORDS]
            a = (address + 4 * len(out)) & 0xFFFFFFFF
            out += decode_write(await self._request(encode_write(a, chunk, strb), 1 + len(chunk)), len(chunk))
        return out

    async def wait(self, clocks: int) -> None:
        """Lets ``clocks`` bus clocks pass (polling)."""
        await self._sleep(clocks / self.clock_hz)
