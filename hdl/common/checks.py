"""Elaboration-time checks of a block's ports and parameters, with messages that name the port.

Every block calls these first, so a wrong port (a plain ``Signal`` for the reset, an asynchronous or
active-low reset, ``None``, an int, a stream of the wrong width, a stereo stream where a mono one is
wanted) or a wrong parameter (a float size, an out-of-range value) ends in one ``ValueError`` that says
which port or parameter and why, before MyHDL sees it::

    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8)
    check_stream("source", source, width=1, stereo=sink.stereo)
    check_signal("k", k, width=8)
    width, height = check_frame(width, height, min_size=3)
    size = check_choice("size", size, (1, 3, 5))
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, k=k))

Numpy integers are accepted wherever an int is and come back as Python ints (use the returned value:
MyHDL's ``intbv`` refuses numpy integers); floats, bools and strings are refused. Called inside a
``@block`` function, a message starts with the block's name (``sobel: port rst is an asynchronous
reset; ...``), so a user who builds a large design sees which block refused what.

The stereo rule of the library: a block that handles stereo streams says so in its docstring, forwards
``cam`` and checks its ports with ``stereo=None`` (either kind; the source must match the sink); every
other block rejects a stereo stream here (``stereo=False``, the default) with a message that says it
takes mono streams only.
"""

from __future__ import annotations

import numbers
import sys

import numpy as np
from myhdl import ResetSignal, intbv
from myhdl._Signal import _Signal

from eyestereo.hdl.interfaces.axis import AxiStream
from eyestereo.hdl.interfaces.bundle import Bundle
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.constants import FRAME_MAX

__all__ = ["check_axis", "check_clock", "check_reset", "check_stream", "check_signal", "check_int", "check_choice",
           "check_bool", "check_frame", "check_distinct", "check_port", "block_error", "checked"]

#: The largest frame side the blocks' counters are sized for.
MAX_SIZE = FRAME_MAX


def _block_name() -> str | None:
    """Name of the innermost ``@block`` function being elaborated (None outside any block)."""
    f = sys._getframe(1)
    while f is not None and f.f_back is not None:
        caller = f.f_back.f_code
        if caller.co_name == "__init__" and caller.co_filename.replace("\\", "/").endswith("myhdl/_block.py"):
            return f.f_code.co_name
        f = f.f_back
    return None


def block_error(msg: str) -> ValueError:
    """A ValueError for a check of the block's own, with the block's name in front like the others'::

        raise block_error(f"port sink carries {dw} bits, at most 36 fit one block RAM word")
    """
    name = _block_name()
    return ValueError(f"{name}: {msg}" if name else msg)


_fail = block_error


def checked(check, *args, **kwargs):
    """Run a check written on the model side (``tools/``, which knows nothing of blocks) and put the
    block's name in front of its ValueError; returns what the check returns::

        blocks = checked(check_blocks, width, height, blocks)
    """
    try:
        return check(*args, **kwargs)
    except ValueError as e:
        name = _block_name()
        if name is None or str(e).startswith(f"{name}: "):
            raise
        raise ValueError(f"{name}: {e}") from None


def _what(x) -> str:
    """A short description of what the user passed (for 'got ...')."""
    if x is None:
        return "None"
    if isinstance(x, ResetSignal):
        return "a ResetSignal"
    if isinstance(x, _Signal):
        v = x.val
        if isinstance(v, bool):
            return "a Signal(bool)"
        if isinstance(v, intbv):
            if len(x) == 0:
                return "a Signal(intbv) without a bit width"
            kind = "signed" if x.min is not None and x.min < 0 else "unsigned"
            n = len(x)
            article = "an" if str(n).startswith("8") or n in (11, 18) else "a"
            return f"{article} {n}-bit {kind} Signal(intbv)"
        return f"a Signal of {type(v).__name__} {v!r}"[:80]
    if isinstance(x, Bundle):
        return repr(x)
    return f"{type(x).__name__} {x!r}"[:80]


def _bits(sig) -> int:
    return 1 if isinstance(sig.val, bool) else len(sig)


def check_clock(clk, name: str = "clk") -> None:
    """``clk`` must be a 1-bit ``Signal(bool(0))`` (not the reset)."""
    if isinstance(clk, ResetSignal):
        raise _fail(f"port {name} must be the clock, a 1-bit Signal(bool(0)), got a ResetSignal "
                    f"(clock and reset swapped?)")
    if not isinstance(clk, _Signal) or not isinstance(clk.val, bool):
        raise _fail(f"port {name} must be a 1-bit Signal(bool(0)), got {_what(clk)}")


def check_reset(rst, name: str = "rst") -> None:
    """``rst`` must be the library's reset: ``ResetSignal(0, active=1, isasync=False)``."""
    if not isinstance(rst, ResetSignal):
        raise _fail(f"port {name} must be a ResetSignal(0, active=1, isasync=False), got {_what(rst)}")
    if rst.active != 1 or rst.isasync:
        kind = " ".join(k for k, on in (("asynchronous", rst.isasync), ("active-low", rst.active != 1)) if on)
        raise _fail(f"port {name} is an {kind} reset; eyestereo blocks take a synchronous "
                    f"active-high reset: ResetSignal(0, active=1, isasync=False)")


def check_signal(name: str, sig, *, width: int | None = None, signed: bool | None = None) -> None:
    """A control port: ``Signal(bool)`` or a ``Signal(intbv)`` of ``width`` bits (1 bit: either kind),
    optionally of a signedness."""
    if isinstance(sig, Bundle):
        raise _fail(f"port {name} must be a MyHDL Signal, got {_article(type(sig).__name__)} (ports out of order?)")
    if not isinstance(sig, _Signal):
        raise _fail(f"port {name} must be a MyHDL Signal, got {_what(sig)}")
    if not isinstance(sig.val, (bool, intbv)):
        raise _fail(f"port {name} must be a Signal(bool) or Signal(intbv(...)[n:]), got {_what(sig)}")
    if isinstance(sig.val, intbv) and len(sig) == 0:
        raise _fail(f"port {name} has no bit width: make it Signal(intbv(0)[n:]) (or intbv(0, min=, max=))")
    n = _bits(sig)
    if width is not None and n != width:
        raise _fail(f"port {name} must be {width} bit{'s' if width != 1 else ''} wide, got {n}")
    if signed is not None:
        is_signed = getattr(sig, "min", None) is not None and sig.min < 0
        if is_signed != signed:
            raise _fail(f"port {name} must be {'signed' if signed else 'unsigned'}, got {_what(sig)}")


def _article(word: str) -> str:
    return f"{'an' if word[0] in 'AEIOU' else 'a'} {word}"


def check_port(name: str, port, cls: type) -> None:
    """A port of the bundle class ``cls`` whose every declared member is a Signal of its declared kind
    and width (``bool``: a Signal(bool); bits: a Signal(intbv) of that many bits), else a ValueError that
    names the port, the member and, when the port is not a ``cls`` at all, the members ``cls`` declares."""
    kind = cls.__name__
    if not isinstance(port, cls):
        raise _fail(f"port {name} must be {_article(kind)}, got {_what(port)} ({kind} members: {cls.member_list()})")
    for m in port.members():
        sig = getattr(port, m.name, None)
        if not isinstance(sig, _Signal):
            raise _fail(f"port {name}: field {m.name} of the {kind} is {_what(sig)}, not a Signal")
        if m.width is bool:
            if not isinstance(sig.val, bool):
                raise _fail(f"port {name}: field {m.name} must be a Signal(bool), got {_what(sig)}")
        elif not isinstance(sig.val, intbv) or len(sig) != m.bits(port):
            raise _fail(f"port {name}: its {m.name} field is {_what(sig)}, the {kind} says {m.bits(port)} bits")


def check_stream(name: str, stream, *, width: int | None = None, stereo: bool | None = False) -> None:
    """An :class:`~eyestereo.hdl.interfaces.stream.ImageStream` port of ``width`` data bits.

    ``stereo``: False (default) = mono only, a stereo stream is refused; True = must be stereo;
    None = either kind (blocks that forward ``cam``; check the source with ``stereo=sink.stereo``).
    """
    check_port(name, stream, ImageStream)
    if width is not None and stream.data_width != width:
        raise _fail(f"port {name} must carry {width}-bit data, got an ImageStream of {stream.data_width} bits")
    if stream.stereo and stereo is False:
        raise _fail(f"port {name} is a stereo stream (with cam); this block takes mono streams only "
                    f"(blocks that take stereo streams say so in their docstring)")
    if stereo is True and not stream.stereo:
        raise _fail(f"port {name} must be a stereo stream (ImageStream(..., stereo=True)), got a mono one")


def check_axis(name: str, port, *, data_width: int | None = None) -> None:
    """An :class:`~eyestereo.hdl.interfaces.axis.AxiStream` port carrying ``data_width``-bit pixels."""
    check_port(name, port, AxiStream)
    if data_width is not None and port.data_width != data_width:
        raise _fail(f"port {name} must carry {data_width}-bit pixels, got an AxiStream of {port.data_width} bits")


def check_distinct(outputs: dict, inputs: dict) -> None:
    """No signal a block drives may belong to any other port: ``sobel(clk, rst, s, s)`` is refused.

    ``outputs`` and ``inputs`` map port names to ports, Signals or bundles. A Signal among ``outputs``
    is driven by the block. A bundle among ``outputs`` is one the block produces (the source of a
    stream, the master of a request port): it drives the members the bundle declares ``out``; a bundle
    among ``inputs`` is one it consumes (serves): it drives the members declared ``in`` (a queue's
    ``ready``, a fetch port's ``req_ready`` and responses). The directions come from the bundle's
    declaration (:mod:`eyestereo.hdl.interfaces.bundle`), so a caller names whole bundles, never their
    members. Signals a block only reads may be shared (a signal can feed two inputs). A bundle class
    without a declaration is skipped.
    """
    def signals(port, producer: bool):
        """(signal, driven by the block) of a port."""
        if isinstance(port, Bundle):
            driven = set(port.driven(producer))
            return [(getattr(port, f), f in driven) for f in port.fields()]
        return [(port, producer)] if isinstance(port, _Signal) else []

    owner: dict[int, tuple[str, bool]] = {}
    for producer, ports in ((True, outputs), (False, inputs)):
        for name, port in ports.items():
            for sig, driven in signals(port, producer):
                other = owner.get(id(sig))
                if other is not None and other[0] != name and (other[1] or driven):
                    out = other[0] if other[1] else name
                    raise _fail(f"ports {other[0]} and {name} share a signal; the output port {out} "
                                f"needs signals of its own")
                if other is None or driven:  # the same port again (or a new one): remember if it drives
                    owner[id(sig)] = (name, driven or bool(other and other[1]))


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """An integer parameter (Python or numpy integer, not bool or float) in [lo, hi]; returns it as int."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise _fail(f"parameter {name} must be an integer, got {_what(value)}")
    value = int(value)
    if lo is not None and value < lo:
        raise _fail(f"parameter {name}={value} is too small: at least {lo}")
    if hi is not None and value > hi:
        raise _fail(f"parameter {name}={value} is too large: at most {hi}")
    return value


def check_frame(width, height, *, min_size: int = 1, max_size: int = MAX_SIZE) -> tuple[int, int]:
    """The frame size parameters: two integers in [min_size, max_size]; returns them as ints."""
    return check_int("width", width, min_size, max_size), check_int("height", height, min_size, max_size)


def check_choice(name: str, value, choices) -> object:
    """A parameter that must be one of ``choices`` (compared by value and type: 3.0 is not 3)."""
    for c in choices:
        if isinstance(c, bool) or not isinstance(c, int):
            if type(value) is type(c) and value == c:
                return c
        elif isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_)) and int(value) == c:
            return c
    raise _fail(f"parameter {name} must be one of {list(choices)}, got {_what(value)}")


def check_bool(name: str, value) -> bool:
    """A flag parameter: True or False (numpy bools too); returns a Python bool."""
    if not isinstance(value, (bool, np.bool_)):
        raise _fail(f"parameter {name} must be True or False, got {_what(value)}")
    return bool(value)
