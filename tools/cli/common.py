"""What every ``eyestereo`` subcommand shares: the parser, the argument types, the error line, the exit codes.

**Exit codes** (the same kind of mistake gives the same code in every command):

====  ==========================================================================================
0     success
1     bad input found at run time: a missing, unreadable, corrupt or implausible file or image,
      a calibration that cannot be used, an output that cannot be written, a bound not reached
2     bad command line: unknown command or option, a value of the wrong form or out of range
3     internal error: an exception the toolbox did not expect (a bug; the line says so)
130   interrupted by SIGINT (Ctrl-C); 143 by SIGTERM; 129 by SIGHUP (128 + the signal number)
====  ==========================================================================================

Every failure prints exactly one line, ``eyestereo: error: ...``, on stderr: no traceback, no
library warning before it (Python warnings, numpy floating-point warnings, OpenCV's log and the
image decoders' messages are silenced while a command runs), and never the name of a temporary
file (:func:`eyestereo.tools.io.user_text`). Outputs follow :mod:`eyestereo.tools.io`'s policy:
all or nothing, also when a signal ends the command (SIGINT, SIGTERM and SIGHUP raise
:class:`Interrupted` in the main thread, so every ``with Outputs()`` block removes its temporaries).

**Groups.** A group of subcommands is a module with ``register(subparsers)``, which adds its
commands with :meth:`argparse._SubParsersAction.add_parser` and stores each handler as ``func``
(``handler(args) -> int``, the exit status) with ``set_defaults``. ``eyestereo.tools.cli.main``
registers the toolbox's own groups and then every entry point of the group ``eyestereo.cli``
(``[project.entry-points."eyestereo.cli"]`` in ``pyproject.toml``), which is how layers above
``tools`` (the simulation commands of ``eyestereo.sim``) add theirs without ``tools`` importing
them. A group should import its heavy dependencies inside its handlers, so ``eyestereo --help``
stays fast.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import re
import signal
import sys
import warnings
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

import numpy as np

from eyestereo.tools.io import Interrupted, check_interrupt, clear_interrupt, interrupt, user_text

__all__ = [
    "EXIT_ERROR",
    "EXIT_INTERNAL",
    "EXIT_OK",
    "EXIT_USAGE",
    "PROG",
    "Interrupted",
    "Parser",
    "board",
    "count",
    "error_line",
    "integer",
    "nonneg_bits",
    "number",
    "positive",
    "print_error",
    "print_note",
    "quiet_libraries",
    "run_command",
    "size",
    "square",
    "window",
]

PROG = "eyestereo"
EXIT_OK = 0
EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``eyestereo: error: ...`` and exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{PROG}: error: {' '.join(message.split())}\n")


# --------------------------------------------------------------------------------------------------
# Argument types (each raises argparse.ArgumentTypeError with a one-line reason -> exit status 2)


def _type_error(text: str) -> argparse.ArgumentTypeError:
    return argparse.ArgumentTypeError(text)


def number(text: str, kind: type = float, lo: float | None = None, hi: float | None = None,
           what: str = "value") -> Any:
    """``text`` as ``kind`` (int or float), finite, within ``lo..hi`` (inclusive)."""
    try:
        v = kind(str(text).strip())
    except (ValueError, OverflowError):
        raise _type_error(f"not a{'n integer' if kind is int else ' number'}: {text!r}") from None
    if isinstance(v, float) and not math.isfinite(v):
        raise _type_error(f"{what} must be finite, got {text!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        rng = f"{lo if lo is not None else '-inf'}..{hi if hi is not None else 'inf'}"
        raise _type_error(f"{what} must lie in {rng}, got {text}")
    return v


def integer(lo: int | None = None, hi: int | None = None, what: str = "value") -> Callable[[str], int]:
    """An argparse type: an integer in ``lo..hi``."""
    def parse(text: str) -> int:
        return number(text, int, lo, hi, what)
    parse.__name__ = "integer"
    return parse


def square(text: str) -> float:
    """A chessboard square size, 1e-6 .. 1e6 in any unit."""
    from eyestereo.tools.rectify.calib import SQUARE_RANGE

    v = positive(text)
    if not SQUARE_RANGE[0] <= v <= SQUARE_RANGE[1]:
        raise _type_error(f"must lie in {SQUARE_RANGE[0]:g} .. {SQUARE_RANGE[1]:g} (any unit), got {text!r}")
    return v


def positive(text: str) -> float:
    """A finite number > 0."""
    try:
        v = float(text)
    except (ValueError, OverflowError):
        raise _type_error(f"not a number: {text!r}") from None
    if not (v > 0 and math.isfinite(v)):
        raise _type_error(f"must be a positive number, got {text!r}")
    return v


#: A view count 1..99.
count = integer(1, 99, "the view count")

#: An extra-precision bit count 0..62 (the FFC's L and H).
nonneg_bits = integer(0, 62, "the extra precision")


def size(text: str) -> tuple[int, int]:
    """``WxH``, 1..16384 pixels per side, at most 2**24 pixels."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if m is None or not (1 <= int(m.group(1)) <= 16384 and 1 <= int(m.group(2)) <= 16384):
        raise _type_error(f"size must be WxH with 1..16384 pixels per side, e.g. 352x288; got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    if w * h > 1 << 24:
        raise _type_error(f"size {w}x{h} has {w * h} pixels; at most {1 << 24} (e.g. 4096x4096)")
    return w, h


def board(text: str) -> tuple[int, int]:
    """``COLSxROWS`` inner chessboard corners."""
    from eyestereo.tools.rectify.calib import parse_board

    try:
        return parse_board(text)
    except ValueError as e:
        raise _type_error(str(e)) from None


def window(text: str) -> tuple[int, int]:
    """``N`` or ``WxH``, odd sides."""
    from eyestereo.tools.matching.evaluate import parse_window

    try:
        return parse_window(text)
    except ValueError as e:
        raise _type_error(str(e)) from None


# --------------------------------------------------------------------------------------------------
# Errors


def error_line(exc: BaseException) -> tuple[str, int]:
    """The one-line message and exit status of an exception ending a command."""
    if isinstance(exc, Interrupted):
        name = signal.Signals(exc.signum).name
        if exc.written:
            return f"interrupted ({name}) after some outputs were written", exc.status
        return f"interrupted ({name}); nothing was written", exc.status
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted (SIGINT); nothing was written", 128 + signal.SIGINT
    if isinstance(exc, OSError):
        if exc.filename is not None:
            text = f"{exc.filename}: {exc.strerror or exc}"
        else:
            text = exc.strerror or str(exc) or type(exc).__name__
        return _one_line(text), EXIT_ERROR
    if isinstance(exc, ValueError):
        return _one_line(str(exc) or type(exc).__name__), EXIT_ERROR
    if isinstance(exc, MemoryError):
        return "out of memory (the input is too large for this machine)", EXIT_ERROR
    first = (str(exc).strip().splitlines() or [""])[0]
    return _one_line(f"internal error ({type(exc).__name__}: {first}); please report it"), EXIT_INTERNAL


def _one_line(text: str) -> str:
    return " ".join(user_text(str(text)).split())


def print_error(text: str) -> None:
    """``eyestereo: error: TEXT`` on stderr, as one line."""
    print(f"{PROG}: error: {_one_line(text)}", file=sys.stderr, flush=True)


def print_note(text: str) -> None:
    """``eyestereo: note: TEXT`` on stderr (after a successful command only)."""
    print(f"{PROG}: note: {_one_line(text)}", file=sys.stderr)


# --------------------------------------------------------------------------------------------------
# Running a command


def quiet_libraries() -> None:
    """Silence what libraries print on their own: Python warnings, numpy's floating-point warnings,
    matplotlib's logging, OpenCV's log (image decoders are silenced where images are read)."""
    warnings.simplefilter("ignore")
    np.seterr(all="ignore")
    logging.getLogger("matplotlib").setLevel(logging.ERROR)
    os.environ.setdefault("OPENCV_LOG_LEVEL", "SILENT")
    cv2 = sys.modules.get("cv2")
    if cv2 is not None:
        try:
            cv2.setLogLevel(0)
        except (AttributeError, Exception):  # noqa: BLE001 - older bindings lack it
            pass


def run_command(parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> int:
    """Parse ``argv`` with ``parser``, run the chosen handler, return the exit status (never raises
    for bad input; see the module docstring for the codes and the one-line errors)."""
    try:
        args, extra = parser.parse_known_args(None if argv is None else [str(a) for a in argv])
        if extra:  # a command may explain the usual cause (``usage_hint`` in its defaults)
            text = " ".join(extra)
            text = text if len(text) <= 120 else text[:117] + "..."
            hint = getattr(args, "usage_hint", "")
            parser.error(f"unrecognized arguments: {text}" + (f" ({hint})" if hint else ""))
    except SystemExit as e:  # --help, or a usage error already printed in one line
        return e.code if isinstance(e.code, int) else (EXIT_OK if e.code is None else EXIT_USAGE)
    old_handlers: dict[int, Any] = {}
    main_thread = _in_main_thread()
    saved_warnings = warnings.filters[:]
    saved_np = np.geterr()
    try:
        quiet_libraries()
        clear_interrupt()
        if main_thread:
            for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None), signal.SIGINT):
                if sig is not None:
                    old_handlers[sig] = signal.signal(sig, interrupt)
        status = int(args.func(args))
        check_interrupt()  # a signal whose exception was swallowed (see eyestereo.tools.io.interrupt)
        return status
    except SystemExit as e:  # a handler's own parser-style exit
        return e.code if isinstance(e.code, int) else EXIT_ERROR
    except BaseException as e:  # noqa: BLE001 - every failure becomes one line, never a traceback
        text, status = error_line(e)
        print_error(text)
        return status
    finally:
        for sig, h in old_handlers.items():
            signal.signal(sig, h)
        clear_interrupt()  # a signal of this command must not interrupt the caller's next step (tests, a library)
        warnings.filters[:] = saved_warnings
        np.seterr(**saved_np)


def _in_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()
