"""One line per step: run steps whose own output (simulator start-up, compiler, library logs) goes to a
log file each, and print what ran, on what, the result and where the pictures are.

::

    steps = StepRunner(Path("build/demo/logs"))
    steps.say(f"make demo: {what}; simulator logs in build/demo/logs/")
    steps.run("sobel", run_sobel)            # run_sobel() returns the step's one-line result
    ...
    return steps.finish()                   # 0 if every step passed, 1 otherwise

A step is a function returning its result as one line of text (or a ``(value, text)`` pair, whose
value :meth:`StepRunner.run` returns). While it runs, file descriptors 1 and 2 (Python's streams and
every child process: GHDL, cocotb, compilers) go to ``<log_dir>/<step>.log``. A failing step prints
``<name>  FAILED: <one line>  (log: <file>)`` and the run goes on with the next step only if the
caller wants (``stop_on_failure``). Imports nothing but the standard library, so any driver (the demo,
the complete-system demo) can use it.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

__all__ = ["StepFailed", "StepRunner", "redirected"]


class StepFailed(RuntimeError):
    """A step failed; its line has been printed."""


@contextlib.contextmanager
def redirected(path: Path) -> Iterator[None]:
    """Send file descriptors 1 and 2 (and so ``sys.stdout``/``sys.stderr`` and child processes) to ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    for s in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, ValueError):
            s.flush()
    saved = [os.dup(1), os.dup(2)]
    with open(path, "a", buffering=1, encoding="utf-8", errors="replace") as log:
        os.dup2(log.fileno(), 1)
        os.dup2(log.fileno(), 2)
        try:
            # Python's own streams too: they may not be descriptors 1 and 2 (pytest, IDEs)
            with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
                yield
        finally:
            with contextlib.suppress(ValueError):
                log.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")[:80] or "step"


class StepRunner:
    """Runs steps, one printed line each (see the module docstring)."""

    def __init__(self, log_dir: Path, *, stream: IO[str] | None = None, width: int = 22) -> None:
        self.log_dir = Path(log_dir)
        self.stream = stream
        self.width = width
        self.failed: list[str] = []
        self.seconds = 0.0

    def _print(self, text: str) -> None:
        stream = self.stream if self.stream is not None else sys.stdout
        print(text, file=stream, flush=True)

    def say(self, text: str) -> None:
        """Print one line of context (what is shown, on what)."""
        self._print(text)

    def log_path(self, name: str) -> Path:
        return self.log_dir / f"{_slug(name)}.log"

    def run(self, name: str, fn: Callable[[], Any], *, stop_on_failure: bool = True) -> Any:
        """Run ``fn`` with its output in the step's log; print one line; return its value."""
        log = self.log_path(name)
        if log.exists():
            log.unlink()
        t0 = time.perf_counter()
        try:
            with redirected(log):
                got = fn()
        except Exception as e:  # noqa: BLE001 - a failing step is reported in one line
            dt = time.perf_counter() - t0
            self.seconds += dt
            reason = " ".join(str(e).split()) or type(e).__name__
            self.failed.append(name)
            self._print(f"{name:<{self.width}} FAILED: {reason[:200]}  ({dt:.0f} s; log: {log})")
            if stop_on_failure:
                raise StepFailed(name) from None
            return None
        dt = time.perf_counter() - t0
        self.seconds += dt
        value, text = got if isinstance(got, tuple) and len(got) == 2 else (got, got)
        self._print(f"{name:<{self.width}} {' '.join(str(text).split())}  ({dt:.0f} s)")
        return value

    def finish(self) -> int:
        """Exit status: 0 when every step passed."""
        return 1 if self.failed else 0
