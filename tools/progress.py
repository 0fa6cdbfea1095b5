"""A tiny progress bar for the Rectification Toolbox (stderr, no dependency).

It draws only when the stream is a terminal, or when forced (``force=True`` or the environment
variable ``EYESTEREO_PROGRESS=1``); ``EYESTEREO_PROGRESS=0`` silences it everywhere. Redirected
output, pytest's captured stderr and pipes therefore stay clean::

    with Progress(len(pairs), "corners") as bar:
        for pair in pairs:
            ...
            bar.update()
"""

from __future__ import annotations

import os
import sys
import time
from typing import IO

__all__ = ["Progress", "progress_enabled"]


def progress_enabled(stream: IO[str] | None = None, force: bool | None = None) -> bool:
    """Whether a bar should be drawn on ``stream`` (default: ``sys.stderr``)."""
    if force is not None:
        return bool(force)
    env = os.environ.get("EYESTEREO_PROGRESS", "").strip()
    if env in ("0", "1"):
        return env == "1"
    stream = sys.stderr if stream is None else stream
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # closed or exotic streams
        return False


class Progress:
    """``[#####.....] label 5/10 1.2s`` on one line of ``stream``, redrawn at most every 0.1 s."""

    def __init__(self, total: int, label: str = "", *, stream: IO[str] | None = None,
                 force: bool | None = None, width: int = 30) -> None:
        if total < 0:
            raise ValueError(f"total must be >= 0, got {total}")
        self.total = int(total)
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = progress_enabled(self.stream, force)
        self.width = width
        self.done = 0
        self._t0 = time.monotonic()
        self._last = -1.0
        self._drawn = False

    def __enter__(self) -> Progress:
        self._draw(final=False)
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def update(self, n: int = 1) -> None:
        """Count ``n`` more steps done."""
        self.done = min(self.total, self.done + n)
        self._draw(final=False)

    def close(self) -> None:
        """Draw the final state and end the line (once)."""
        if self.enabled and self._drawn:
            self._draw(final=True)
            self.stream.write("\n")
            self.stream.flush()
            self._drawn = False
            self.enabled = False

    def _draw(self, final: bool) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if not final and self._drawn and now - self._last < 0.1 and self.done < self.total:
            return
        self._last = now
        frac = 1.0 if self.total == 0 else self.done / self.total
        filled = int(round(frac * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        text = f"\r[{bar}] {self.label} {self.done}/{self.total} {now - self._t0:.1f}s"
        self.stream.write(text)
        self.stream.flush()
        self._drawn = True
