"""Model of :func:`eyestereo.hdl.video.video_timing.video_timing`: the display modes and every output, clock by clock.

A mode is the usual four numbers per direction (active, front porch, sync, back porch) and the two sync
polarities. The block counts from the leading edge of the sync pulses, so one line and one frame are::

    h:  | sync (h_sync) | back porch (h_back) | active (h_active) = de | front porch (h_front) |
        0             h_sync            h_sync + h_back                           h_total - 1
    v:  the same order in lines: sync, back porch, active, front porch; the line counter steps when h wraps

and a vertical sync edge falls on a horizontal sync's leading edge (as VESA DMT and CEA-861 draw them).
``MODES["640x480@60"]`` is VESA DMT's 640x480 at 60 Hz (DMT ID 04h) = CEA-861-D's video format 1 (640x480p):
H 640 + 16 + 96 + 48 = 800, V 480 + 10 + 2 + 33 = 525, both syncs negative (DMT lists 8-pixel and 8-line
borders separately; they are folded into the porches here, as CEA-861 does). Its pixel clock is 25.175 MHz;
the board makes 25.0 MHz from its 25 MHz oscillator, so the frame rate is 25e6 / (800 * 525) = 59.52 Hz
instead of 59.94 Hz, a line 31.25 kHz instead of 31.47 kHz (0.7 % slow). Monitors lock to it and take it
as the 640x480 60 Hz mode (the usual way boards with a 25 MHz oscillator drive it); a board that wants the
exact rate needs a PLL setting for 25.175 MHz (and 125.875 MHz for the serializer).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["VideoMode", "MODES", "mode_of", "signals", "OUTPUTS"]


@dataclass(frozen=True)
class VideoMode:
    """One display mode: widths in pixels (h) and lines (v); ``*_pol`` True = the sync pulse is high."""

    name: str
    h_active: int
    h_front: int
    h_sync: int
    h_back: int
    v_active: int
    v_front: int
    v_sync: int
    v_back: int
    h_pol: bool
    v_pol: bool
    pixel_mhz: float

    def __post_init__(self):
        for f in ("h_active", "h_front", "h_sync", "h_back", "v_active", "v_front", "v_sync", "v_back"):
            v = getattr(self, f)
            if not isinstance(v, int) or isinstance(v, bool) or v < 1:
                raise ValueError(f"mode {self.name}: {f} must be a positive integer, got {v!r}")

    @property
    def h_total(self) -> int:
        return self.h_active + self.h_front + self.h_sync + self.h_back

    @property
    def v_total(self) -> int:
        return self.v_active + self.v_front + self.v_sync + self.v_back

    @property
    def h_start(self) -> int:
        """The h count of a line's first active pixel (sync and back porch before it)."""
        return self.h_sync + self.h_back

    @property
    def v_start(self) -> int:
        """The line count of a frame's first active line."""
        return self.v_sync + self.v_back

    @property
    def frame_clocks(self) -> int:
        return self.h_total * self.v_total

    def frame_rate(self, pixel_hz: float | None = None) -> float:
        """Frames per second at ``pixel_hz`` (default: the mode's own pixel clock)."""
        return (pixel_hz if pixel_hz is not None else self.pixel_mhz * 1e6) / self.frame_clocks


MODES: dict[str, VideoMode] = {m.name: m for m in (
    # VESA DMT 640x480@60 (ID 04h) = CEA-861-D format 1; pixel clock 25.175 MHz (the board: 25.0, 59.52 Hz)
    VideoMode("640x480@60", 640, 16, 96, 48, 480, 10, 2, 33, h_pol=False, v_pol=False, pixel_mhz=25.175),
    # small modes for simulation: the same shape with short porches (blanking long enough for a receiver to
    # find the symbol boundary in the control periods), one of each polarity
    VideoMode("sim-64x48", 64, 4, 8, 4, 48, 2, 2, 3, h_pol=False, v_pol=False, pixel_mhz=25.0),
    VideoMode("sim-32x24", 32, 4, 8, 6, 24, 2, 2, 3, h_pol=True, v_pol=False, pixel_mhz=25.0),
)}

#: The block's outputs, in the order :func:`signals` returns them.
OUTPUTS = ("hsync", "vsync", "de", "x", "y", "line_start", "frame_start")


def mode_of(mode: str | VideoMode) -> VideoMode:
    """A :class:`VideoMode` from a name of :data:`MODES` (or the mode itself); ValueError naming the modes."""
    if isinstance(mode, VideoMode):
        return mode
    if isinstance(mode, str) and mode in MODES:
        return MODES[mode]
    raise ValueError(f"unknown video mode {mode!r}; the modes are {sorted(MODES)}")


def signals(mode: str | VideoMode, n: int, start: int = 0) -> dict[str, np.ndarray]:
    """The block's outputs for counter states ``start .. start + n - 1`` (state k = after the k-th clock
    edge since the reset, the first edge with ``rst`` low being edge 0), as int arrays keyed by
    :data:`OUTPUTS`.

    ``x``, ``y``: the active pixel's coordinates while ``de``, 0 outside; ``line_start``: one clock at the
    horizontal sync's leading edge of every line that has active pixels; ``frame_start``: one clock at the
    leading edge of every vertical sync (state 0).
    """
    m = mode_of(mode)
    k = np.arange(start, start + n, dtype=np.int64) % m.frame_clocks
    h, v = k % m.h_total, k // m.h_total
    h_act = (h >= m.h_start) & (h < m.h_start + m.h_active)
    v_act = (v >= m.v_start) & (v < m.v_start + m.v_active)
    de = h_act & v_act
    return dict(hsync=((h < m.h_sync) == m.h_pol).astype(np.int64),
                vsync=((v < m.v_sync) == m.v_pol).astype(np.int64),
                de=de.astype(np.int64),
                x=np.where(de, h - m.h_start, 0), y=np.where(de, v - m.v_start, 0),
                line_start=((h == 0) & v_act).astype(np.int64),
                frame_start=(k == 0).astype(np.int64))
