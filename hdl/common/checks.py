"""Elaboration-time checks of a block's ports and parameters, with messages that name the port.

Every block calls these first, so a wrong port (a plain ``Signal`` for the reset, an asynchronous or
active-low reset, ``None``, an int, a stream of the wrong width, a stereo stream where a mono one is
wanted) or a wrong parameter (a float size, a numpy integer, an out-of-range value) ends in one
``ValueError`` that says which port or parameter and why, before MyHDL sees it::

    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8)
    check_stream("source", source, width=1, stereo=sink.stereo)
    check_signal("k", k, width=8)
    width = check_int("width", width, 5, 4096)

The stereo rule of the library: a block that handles stereo streams says so in its docstring and
forwards ``cam``; every other block rejects a stereo stream here (``stereo=False``, the default).
"""

from __future__ import annotations

import numbers

from myhdl import ResetSignal
from myhdl._Signal import _Signal

from eyestereo.hdl.stream import ImageStream

__all__ = ["check_clock", "check_reset", "check_stream", "check_signal", "check_int", "check_choice",
           "check_bool"]


def _what(x) -> str:
    if x is None:
        return "None"
    if isinstance(x, _Signal):
        return f"a {len(x) if not isinstance(x.val, bool) else 1}-bit Signal"
    return f"{type(x).__name__} {x!r}"[:80]


def check_clock(clk, name: str = "clk") -> None:
    """``clk`` must be a 1-bit Signal (bool)."""
    if not isinstance(clk, _Signal) or not isinstance(clk.val, bool):
        raise ValueError(f"port {name} must be a 1-bit Signal(bool(0)), got {_what(clk)}")


def check_reset(rst, name: str = "rst") -> None:
    """``rst`` must be the library's reset: ``ResetSignal(0, active=1, isasync=False)``."""
    if not isinstance(rst, ResetSignal):
        raise ValueError(f"port {name} must be a ResetSignal(0, active=1, isasync=False), got {_what(rst)}")
    if rst.active != 1 or rst.isasync:
        kind = ("asynchronous " if rst.isasync else "") + ("active-low" if rst.active != 1 else "")
        raise ValueError(f"port {name} is an {kind.strip()} reset; eyestereo blocks take a synchronous "
                         f"active-high reset: ResetSignal(0, active=1, isasync=False)")


def check_signal(name: str, sig, *, width: int | None = None, signed: bool | None = None) -> None:
    """A control port: a Signal of ``width`` bits (1 = bool or 1-bit intbv), optionally of a signedness."""
    if not isinstance(sig, _Signal):
        raise ValueError(f"port {name} must be a MyHDL Signal, got {_what(sig)}")
    n = 1 if isinstance(sig.val, bool) else len(sig)
    if width is not None and n != width:
        raise ValueError(f"port {name} must be {width} bits wide, got {n}")
    if signed is not None:
        is_signed = getattr(sig, "min", None) is not None and sig.min < 0
        if is_signed != signed:
            raise ValueError(f"port {name} must be {'signed' if signed else 'unsigned'}, got the other kind")


def check_stream(name: str, stream, *, width: int | None = None, stereo: bool = False) -> None:
    """An :class:`~eyestereo.hdl.stream.ImageStream` port of ``width`` data bits; stereo only if allowed."""
    if not isinstance(stream, ImageStream):
        raise ValueError(f"port {name} must be an ImageStream, got {_what(stream)}")
    if width is not None and stream.data_width != width:
        raise ValueError(f"port {name} must carry {width}-bit data, got an ImageStream of {stream.data_width} bits")
    if stream.stereo and not stereo:
        raise ValueError(f"port {name} is a stereo stream (with cam); this block handles mono streams only")
    if stereo and not stream.stereo:
        raise ValueError(f"port {name} must be a stereo stream (ImageStream(..., stereo=True))")


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """An integer parameter (Python or numpy integer, not bool or float) in [lo, hi]; returns it as int."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"parameter {name} must be an integer, got {_what(value)}")
    value = int(value)
    if lo is not None and value < lo:
        raise ValueError(f"parameter {name}={value} is too small: at least {lo}")
    if hi is not None and value > hi:
        raise ValueError(f"parameter {name}={value} is too large: at most {hi}")
    return value


def check_choice(name: str, value, choices) -> object:
    """A parameter that must be one of ``choices`` (compared by value and type: 3.0 is not 3)."""
    for c in choices:
        if type(value) is type(c) and value == c:
            return c
        if isinstance(c, int) and isinstance(value, numbers.Integral) and not isinstance(value, bool) \
                and int(value) == c:
            return c
    raise ValueError(f"parameter {name} must be one of {list(choices)}, got {_what(value)}")


def check_bool(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"parameter {name} must be True or False, got {_what(value)}")
    return value
