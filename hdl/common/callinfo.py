"""Shallow call-stack look-ups for MyHDL's elaboration: the same block tree, without reading every frame.

MyHDL finds the function that defines a block (and its caller) with ``inspect.stack()``, which builds a
record of *every* frame up to the interpreter's top, reading each frame's source file to do it. It only
looks at the nearest five or six. Called once per block and per ``@always`` at elaboration, its cost grows
with the depth of the caller's stack: under pytest (pluggy, xdist, cocotb's runner: about 80 frames)
converting ``harris_mono`` took 14 s instead of 1.9 s, and ``make test`` spent minutes there.

:func:`install` gives MyHDL's modules that look up their callers a stand-in for :mod:`inspect` whose
``stack()`` and ``getouterframes()`` return only the nearest :data:`DEPTH` frames, as records with the
frame, its file name, line and function (what MyHDL reads; the source-context fields are ``None``).
Every other attribute is the real :mod:`inspect`'s. What MyHDL builds is unchanged:
``tests/hdl/test_callinfo.py`` converts blocks with and without it and compares the files byte for byte.
"""

from __future__ import annotations

import inspect
import sys
import types

# MyHDL reads stack records 0..5 (_block._getCallInfo: 3, 4 and 5 after a list comprehension;
# _instance: 2 and 3; _hdlclass: 3; _misc.instances: 1). Twelve leaves room.
DEPTH = 12

# The MyHDL modules that look up their callers through ``inspect``.
_MODULES = ("myhdl._block", "myhdl._instance", "myhdl._hdlclass", "myhdl._misc")


def _records(frame, depth: int) -> list[inspect.FrameInfo]:
    out = []
    while frame is not None and len(out) < depth:
        out.append(inspect.FrameInfo(frame, frame.f_code.co_filename, frame.f_lineno, frame.f_code.co_name,
                                     None, None))
        frame = frame.f_back
    return out


def stack(context: int = 1) -> list[inspect.FrameInfo]:
    """The nearest :data:`DEPTH` records of the caller's stack, the caller first (like ``inspect.stack``)."""
    return _records(sys._getframe(1), DEPTH)


def getouterframes(frame, context: int = 1) -> list[inspect.FrameInfo]:
    """The nearest :data:`DEPTH` records from ``frame`` outwards (like ``inspect.getouterframes``)."""
    return _records(frame, DEPTH)


def _shallow_inspect() -> types.ModuleType:
    mod = types.ModuleType("inspect", "inspect, with stack() and getouterframes() cut to the nearest frames")
    mod.__dict__.update({k: v for k, v in vars(inspect).items() if not k.startswith("__")})
    mod.stack = stack
    mod.getouterframes = getouterframes
    return mod


_SHALLOW = _shallow_inspect()


def install() -> None:
    """Point MyHDL's caller look-ups at the shallow stand-in (idempotent)."""
    import importlib

    for name in _MODULES:
        importlib.import_module(name).inspect = _SHALLOW


def uninstall() -> None:
    """Give MyHDL back the real :mod:`inspect` (for the comparison in the tests)."""
    import importlib

    for name in _MODULES:
        importlib.import_module(name).inspect = inspect


def installed() -> bool:
    return all(getattr(sys.modules.get(n), "inspect", None) is _SHALLOW for n in _MODULES)
