"""Progress bars for the long toolbox steps: `tqdm`, drawn only where a person watches.

A bar is drawn on stderr when it is a terminal, or when forced (``force=True`` or the environment
variable ``EYESTEREO_PROGRESS=1``); ``EYESTEREO_PROGRESS=0`` silences it everywhere. Redirected
output, pytest's captured stderr and pipes therefore stay clean, and a finished bar is erased
(``leave=False``), so a command's own one-line result is what remains on the screen::

    with progress_bar(len(pairs), "chessboard corners") as bar:
        for pair in pairs:
            ...
            bar.update()
"""

from __future__ import annotations

import os
import sys
from typing import IO, Any

from tqdm import tqdm

__all__ = ["progress_bar", "progress_enabled"]


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


def progress_bar(total: int, desc: str = "", *, force: bool | None = None, stream: IO[str] | None = None,
                 **kw: Any) -> tqdm:
    """A :class:`tqdm.tqdm` bar of ``total`` steps, disabled unless :func:`progress_enabled`."""
    if total < 0:
        raise ValueError(f"total must be >= 0, got {total}")
    stream = sys.stderr if stream is None else stream
    return tqdm(total=total, desc=desc, file=stream, disable=not progress_enabled(stream, force), leave=False,
                dynamic_ncols=True, **kw)
