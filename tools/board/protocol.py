"""The UART bridge's byte protocol, host side: requests encoded, replies decoded and checked.

The byte format and its constants are declared once, in :mod:`eyestereo.tools.models.uart_bridge` (the
bridge's bit-true model, which the HDL block takes them from); this module re-exports them and is the
host's only way to build and read the bytes. The protocol (big-endian fields)::

    'I'                                  -> 'i' version[4]                       (version "ESB1")
    'R' addr[4] count[1]                 -> 'r' (resp[1] data[4]) x (count + 1)
    'W' addr[4] count[1] strb[1] data[4] x (count + 1)
                                         -> 'w' resp[1] x (count + 1)
    anything else b                      -> '?' b
    a request cut short by a pause       -> ... '?' 'T'

A reply that is not what the request asks for raises :class:`ProtocolError` with what came instead.
Pure Python.
"""

from __future__ import annotations

from eyestereo.tools.models.uart_bridge import (IDENTIFY, MAX_WORDS, READ, REPLY_ERROR, REPLY_IDENTIFY, REPLY_READ,
                                                REPLY_WRITE, TIMEOUT, VERSION, WRITE)

__all__ = ["IDENTIFY", "READ", "WRITE", "REPLY_IDENTIFY", "REPLY_READ", "REPLY_WRITE", "REPLY_ERROR", "TIMEOUT",
           "VERSION", "MAX_WORDS", "ProtocolError", "encode_identify", "encode_read", "encode_write",
           "reply_length", "decode_identify", "decode_read", "decode_write", "check_word", "check_address",
           "check_strb", "check_words"]


class ProtocolError(RuntimeError):
    """The board's reply is not the one the request asks for (a '?' reply, a wrong code, a short reply)."""


def _int(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise ValueError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} {v:#x} does not fit ({lo:#x}..{hi:#x})")
    return v


def check_address(address) -> int:
    """A 32-bit byte address (the bridge ignores the bits above its bus's)."""
    return _int("address", address, 0, 0xFFFFFFFF)


def check_word(data) -> int:
    """A 32-bit data word."""
    return _int("data word", data, 0, 0xFFFFFFFF)


def check_strb(strb) -> int:
    """A 4-bit byte strobe."""
    return _int("strb", strb, 0, 0xF)


def check_words(n) -> int:
    """Words of one request: 1..256."""
    return _int("words per request", n, 1, MAX_WORDS)


def encode_identify() -> bytes:
    return bytes((IDENTIFY,))


def encode_read(address: int, n: int = 1) -> bytes:
    """A read of ``n`` (1..256) words from byte address ``address`` on (address + 4 per word)."""
    return bytes((READ,)) + check_address(address).to_bytes(4, "big") + bytes((check_words(n) - 1,))


def encode_write(address: int, words, strb: int = 0xF) -> bytes:
    """A write of ``words`` (1..256 of them) from byte address ``address`` on, each with strobe ``strb``."""
    words = [check_word(w) for w in words]
    head = bytes((WRITE,)) + check_address(address).to_bytes(4, "big") + bytes((check_words(len(words)) - 1,
                                                                                check_strb(strb)))
    return head + b"".join(w.to_bytes(4, "big") for w in words)


def reply_length(request: bytes) -> int:
    """The bytes of the reply to one whole request (encoded by this module)."""
    op = request[0]
    if op == IDENTIFY:
        return 5
    if op == READ:
        return 1 + 5 * (request[5] + 1)
    if op == WRITE:
        return 1 + (request[5] + 1)
    return 2


def _expect_code(reply: bytes, code: int, what: str) -> None:
    if not reply:
        raise ProtocolError(f"{what}: empty reply")
    if reply[0] == REPLY_ERROR and len(reply) >= 2:
        why = "the request timed out on the board" if reply[1] == TIMEOUT else f"byte {reply[1]:#04x} not understood"
        raise ProtocolError(f"{what}: the board answered '?' ({why})")
    if reply[0] != code:
        raise ProtocolError(f"{what}: reply code {reply[0]:#04x}, expected {code:#04x}")


def decode_identify(reply: bytes) -> int:
    """The version word of an identify reply."""
    _expect_code(reply, REPLY_IDENTIFY, "identify")
    if len(reply) != 5:
        raise ProtocolError(f"identify: {len(reply)} reply bytes, expected 5")
    return int.from_bytes(reply[1:5], "big")


def decode_read(reply: bytes, n: int) -> list[tuple[int, int]]:
    """``[(data, resp), ...]`` of the reply to a read of ``n`` words."""
    _expect_code(reply, REPLY_READ, "read")
    if len(reply) != 1 + 5 * n:
        raise ProtocolError(f"read: {len(reply)} reply bytes, expected {1 + 5 * n}")
    return [(int.from_bytes(reply[2 + 5 * i:6 + 5 * i], "big"), reply[1 + 5 * i]) for i in range(n)]


def decode_write(reply: bytes, n: int) -> list[int]:
    """The responses of the reply to a write of ``n`` words."""
    _expect_code(reply, REPLY_WRITE, "write")
    if len(reply) != 1 + n:
        raise ProtocolError(f"write: {len(reply)} reply bytes, expected {1 + n}")
    return list(reply[1:])
