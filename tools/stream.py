"""Image stream on the Python side: frames <-> beats and a protocol checker (pure Python/numpy).

The protocol itself is documented once, in :mod:`eyestereo.hdl.interfaces.stream`. Here a *beat* is one valid
cycle, a tuple ``(data, eol, eof)``; idle cycles are not beats. The reset token is ``(0, False, True)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.constants import FRAME_MAX

Beat = tuple[int, bool, bool]
TOKEN: Beat = (0, False, True)


class ProtocolError(Exception):
    """A stream broke the image-stream protocol (wrong line length, eof misplaced, ...)."""


def check_geometry(width: int, height: int, *, min_size: int = 1, max_size: int = FRAME_MAX) -> None:
    """Raise ValueError unless width x height is a frame size the blocks can be built for."""
    for name, v in (("width", width), ("height", height)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool):
            raise ValueError(f"{name} must be an int, got {v!r}")
        if v < min_size:
            raise ValueError(f"{name}={v} is too small: this block needs at least {min_size}")
        if v > max_size:
            raise ValueError(f"{name}={v} is too large: counters are sized for at most {max_size}")


def frame_to_beats(frame: np.ndarray) -> list[Beat]:
    """Beats of one frame in raster order, eol on each line's last pixel, eof with the frame's last."""
    frame = np.asarray(frame)
    if frame.ndim != 2 or frame.size == 0:
        raise ValueError(f"a frame must be a non-empty 2-D array, got shape {frame.shape}")
    if not np.issubdtype(frame.dtype, np.integer):
        raise ValueError(f"a frame must hold integer pixel codes, got dtype {frame.dtype}")
    if frame.min() < 0:
        raise ValueError("frame pixel codes must be unsigned (pack signed values first)")
    h, w = frame.shape
    beats: list[Beat] = []
    for y in range(h):
        row = frame[y].tolist()
        for x in range(w):
            eol = x == w - 1
            beats.append((int(row[x]), eol, eol and y == h - 1))
    return beats


@dataclass
class FrameAssembler:
    """Rebuilds frames from beats and raises ProtocolError on any protocol fault.

    Feed it every valid beat with :meth:`push`. Complete frames collect in ``frames``; each reset token
    is recorded in ``events`` as ``("token", pixels_dropped)`` and a complete frame as ``("frame", i)``.
    """

    width: int
    height: int
    frames: list[np.ndarray] = field(default_factory=list)
    events: list[tuple[str, int]] = field(default_factory=list)
    _rows: list[list[int]] = field(default_factory=list)
    _line: list[int] = field(default_factory=list)

    @property
    def pixels_pending(self) -> int:
        """Pixels of the frame in progress (0 between frames)."""
        return sum(len(r) for r in self._rows) + len(self._line)

    def push(self, data: int, eol: bool, eof: bool) -> None:
        where = f"line {len(self._rows)}, pixel {len(self._line)}"
        if eof and not eol:
            self.events.append(("token", self.pixels_pending))
            self._rows, self._line = [], []
            return
        self._line.append(int(data))
        if len(self._line) > self.width:
            raise ProtocolError(f"{where}: line longer than width={self.width} (eol missing)")
        if not eol:
            return
        if len(self._line) != self.width:
            raise ProtocolError(f"{where}: eol after {len(self._line)} pixels, expected {self.width}")
        self._rows.append(self._line)
        self._line = []
        last_line = len(self._rows) == self.height
        if eof and not last_line:
            raise ProtocolError(f"eof on line {len(self._rows) - 1}, expected on line {self.height - 1}")
        if last_line and not eof:
            raise ProtocolError(f"line {self.height - 1} ended without eof (frame has {self.height} lines)")
        if eof:
            self.frames.append(np.array(self._rows, dtype=np.int64))
            self.events.append(("frame", len(self.frames) - 1))
            self._rows = []

    def push_all(self, beats) -> None:
        for b in beats:
            self.push(*b)


def beats_to_frames(beats, width: int, height: int) -> list[np.ndarray]:
    """Frames rebuilt from a list of beats (ProtocolError on any fault, or if a frame is left open)."""
    asm = FrameAssembler(width, height)
    asm.push_all(beats)
    if asm.pixels_pending:
        raise ProtocolError(f"stream ended inside a frame ({asm.pixels_pending} pixels pending)")
    return asm.frames
