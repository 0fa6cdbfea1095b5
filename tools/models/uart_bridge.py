"""Bit-true model of :func:`eyestereo.hdl.serial.uart_bridge.uart_bridge`: request bytes + a bus -> reply bytes.

The bridge's protocol, byte for byte (the byte diagrams are in the block's docstring; the host side,
:mod:`eyestereo.tools.board.protocol`, encodes and decodes it with the constants declared here). All
multi-byte fields are big-endian.

* ``I`` (0x49): reply ``i`` (0x69) and the 4-byte version word :data:`VERSION` ("ESB1").
* ``R`` (0x52) addr[4] count[1]: ``count + 1`` reads at addr, addr + 4, ...; reply ``r`` (0x72), then per
  word resp[1] (AXI RRESP: 0 OKAY, 2 SLVERR, 3 DECERR) and data[4].
* ``W`` (0x57) addr[4] count[1] strb[1] data[4] x (count + 1): writes at addr, addr + 4, ... with that
  strobe (its low 4 bits; the high 4 are ignored); reply ``w`` (0x77) as soon as the header is in, then
  resp[1] (BRESP) after each write.
* any other first byte: reply ``?`` (0x3F) and that byte; the bridge waits for the next request.
* a request whose bytes stop for longer than the bridge's ``timeout`` is abandoned: ``?`` ``T`` (0x3F
  0x54) after whatever reply bytes it had sent; the bytes that come later start a new request.

Addresses keep their low ``addr_bits`` bits (the bus's; the bits above are ignored) and wrap there;
the two low bits go to the bus as given. ``errors`` counts framing errors and lost bytes (the items
:data:`DROPPED`), unknown request bytes and abandoned requests, saturating at 0xFFFF.

The model takes *items*: a byte (0..255) as the bridge's receiver delivers it, :data:`PAUSE` (the line
quiet for longer than the timeout) or :data:`DROPPED` (a byte the receiver dropped: framing error or
overrun; it never reaches the request machine). The bus is any object with ``read(address) -> (data,
resp)`` and ``write(address, data, strb) -> resp``; every access the bridge makes is recorded in order
in :attr:`UartBridge.accesses`. Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["IDENTIFY", "READ", "WRITE", "REPLY_IDENTIFY", "REPLY_READ", "REPLY_WRITE", "REPLY_ERROR", "TIMEOUT",
           "VERSION", "MAX_WORDS", "ERRORS_MAX", "DEFAULT_TIMEOUT", "PAUSE", "DROPPED", "Access", "UartBridge",
           "uart_bridge"]

#: request opcodes (host -> board)
IDENTIFY, READ, WRITE = 0x49, 0x52, 0x57
#: reply codes (board -> host): each request's first reply byte, and ``?`` for an unknown byte or a timeout
REPLY_IDENTIFY, REPLY_READ, REPLY_WRITE, REPLY_ERROR = 0x69, 0x72, 0x77, 0x3F
#: the byte after ``?`` when a request was abandoned ("T")
TIMEOUT = 0x54
#: the identify reply's version word: "ESB1" (eyestereo serial bridge, protocol 1)
VERSION = 0x45534231
#: words per request (the count byte is words - 1)
MAX_WORDS = 256
#: the error counter saturates here (16 bits)
ERRORS_MAX = 0xFFFF
#: the bridge's default timeout: 1 ms at 100 MHz
DEFAULT_TIMEOUT = 100_000

#: an item: the line quiet for longer than the timeout
PAUSE = "pause"
#: an item: a byte the receiver dropped (framing error, overrun)
DROPPED = "dropped"


@dataclass(frozen=True)
class Access:
    """One bus access: ``kind`` "R" or "W", byte address, data (read: what came back), strobe (reads: 0), resp."""

    kind: str
    address: int
    data: int
    strb: int
    resp: int


class UartBridge:
    """The bridge fed item by item (:meth:`feed`); ``reply`` grows with the bytes it sends."""

    def __init__(self, bus, *, addr_bits: int = 24):
        if not 3 <= int(addr_bits) <= 32:
            raise ValueError(f"addr_bits must be 3..32, got {addr_bits!r}")
        self.bus = bus
        self.mask = (1 << int(addr_bits)) - 1
        self.reply = bytearray()
        self.accesses: list[Access] = []
        self._errors = 0
        self._pending: list[int] = []  # the bytes of the request in progress
        self._busy = False

    @property
    def errors(self) -> int:
        """The error counter's value (saturating 16 bits)."""
        return min(self._errors, ERRORS_MAX)

    def feed(self, items) -> None:
        """Items in order: bytes, :data:`PAUSE`, :data:`DROPPED` (see the module docstring)."""
        for it in items:
            if isinstance(it, str) and it == DROPPED:
                self._errors += 1
            elif isinstance(it, str) and it == PAUSE:
                if self._busy:
                    self.reply += bytes((REPLY_ERROR, TIMEOUT))
                    self._errors += 1
                    self._pending.clear()
                    self._busy = False
            else:
                b = int(it)
                if not 0 <= b <= 0xFF:
                    raise ValueError(f"a byte is 0..255, got {it!r}")
                self._byte(b)

    # The request machine: the bytes of the request so far are in _pending; each byte moves it on as far
    # as those bytes allow (a write's word is written when its fourth byte is in, as the hardware does).
    def _byte(self, b: int) -> None:
        if not self._busy:
            if b == IDENTIFY:
                self.reply += bytes((REPLY_IDENTIFY,)) + VERSION.to_bytes(4, "big")
            elif b in (READ, WRITE):
                self._busy = True
                self._pending = [b]
            else:
                self.reply += bytes((REPLY_ERROR, b))
                self._errors += 1
            return
        p = self._pending
        p.append(b)
        if p[0] == READ and len(p) == 6:
            address, words = int.from_bytes(bytes(p[1:5]), "big"), p[5] + 1
            self.reply.append(REPLY_READ)
            for i in range(words):
                a = (address + 4 * i) & self.mask
                data, resp = self.bus.read(a)
                data, resp = int(data) & 0xFFFFFFFF, int(resp) & 3
                self.accesses.append(Access("R", a, data, 0, resp))
                self.reply += bytes((resp,)) + data.to_bytes(4, "big")
            self._busy = False
        elif p[0] == WRITE and len(p) >= 7:
            address, words, strb = int.from_bytes(bytes(p[1:5]), "big"), p[5] + 1, p[6] & 0xF
            if len(p) == 7:
                self.reply.append(REPLY_WRITE)
                return
            if (len(p) - 7) % 4:
                return
            i = (len(p) - 7) // 4 - 1
            a = (address + 4 * i) & self.mask
            data = int.from_bytes(bytes(p[-4:]), "big")
            resp = int(self.bus.write(a, data, strb)) & 3
            self.accesses.append(Access("W", a, data, strb, resp))
            self.reply.append(resp)
            if i == words - 1:
                self._busy = False


def uart_bridge(items, bus, *, addr_bits: int = 24) -> tuple[bytes, list[Access], int]:
    """(reply bytes, bus accesses in order, error count) of the bridge fed ``items`` from reset."""
    m = UartBridge(bus, addr_bits=addr_bits)
    m.feed(items)
    return bytes(m.reply), m.accesses, m.errors
