"""Model of :func:`eyestereo.hdl.rectify.line_cache.line_cache`: the lines a rectifier fed straight from the
cameras must keep on chip (``rectify="stream"``), and what a fetch reads.

The stream rectifier (:func:`eyestereo.hdl.rectify.line_cache.line_cache` under the rectifier) keeps the last
L lines of each camera in block RAM, written as the camera delivers them, and answers the rectifier's 2x2
fetches from there. A fetch waits until its lower row is complete; a camera cannot wait, so each new line
overwrites the oldest. L must hold every line the rectifier still needs while the cameras write on:

* **span**: the rows one rectified row's fetches touch, and the rows later rectified rows still need
  (a rotated map can reach further up in a later row than in this one): for rectified row r,
  ``top(r) = min over r' >= r of the lowest row fetched in r'`` and ``bottom(r) = max over r' <= r of the
  lowest row + 1 (the interpolation's second row)``; the rows ``top(r) .. bottom(r)`` are held together.
* **lag**: while the rectifier works on row r (a fetch at a time, about 8 clocks per stereo pixel), the cameras
  go on: the rows they have begun by the end of row r's last fetch are in the cache too. A timing model of
  the two (cameras from :class:`~eyestereo.tools.camera.CameraTiming` and their pixel clock, the rectifier at
  ``clocks_per_pair`` memory clocks per stereo pixel, row r begun when the row it waits for is complete and the
  previous row done) gives, per row, the line the cameras write when it ends.
* **skew**: the two cameras' frames do not start at the same instant; the one ahead writes ``skew`` lines
  more before the other's rows release the rectifier.

``L >= max over r of (line written at the end of row r) - top(r) + 2 + skew`` (one line more for the
block's own margin: it calls a fetch late once the camera writes the line after the one that overwrites
it), rounded up to a power of two (the cache finds a row's slot from its low bits). What a fetch reads is
the camera frame's pixel (:func:`fetch`): the cache changes where the pixels come from, not their values.
The plan also checks the frame's end: the rectifier must be done with a frame before the cameras' next frame
reaches the lines it still reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyestereo.tools.camera import CIF_PCLK_HZ, DEFAULT_TIMING, CameraTiming
from eyestereo.tools.models import coordinate_warper as warper
from eyestereo.tools.models.fetch_interpolate import OFFSETS
from eyestereo.tools.models.poly_unit import DEFAULT_FRAC, Calibration, resolve_frac

__all__ = ["DEFAULT_CLOCK_HZ", "DEFAULT_PIXEL_CLOCK_HZ", "CLOCKS_PER_PAIR", "DEFAULT_SKEW", "MAX_LINES",
           "LineCachePlan", "fetch", "row_spans", "plan"]

#: The memory clock the stream rectifier runs at (the front end's).
DEFAULT_CLOCK_HZ = 100e6
#: The OV6630's pixel clock (two PCLK per pixel): CameraTiming's 50 frames/s at CIF.
DEFAULT_PIXEL_CLOCK_HZ = CIF_PCLK_HZ
#: Memory clocks per stereo pixel of the rectifier when both sides are in range (fetch_interpolate's two
#: multipliers, four steps a side): an upper bound on its pace, the timing model's assumption.
CLOCKS_PER_PAIR = 8
#: Lines by which one camera's frame may lead the other's (cameras sharing one XCLK and started together
#: are within a line; two free-running oscillators drift apart and need the front end to resynchronise).
DEFAULT_SKEW = 2
#: The largest cache: 64 lines per camera (2 x 64 x 640 bytes = 655 kbit at VGA, most of an ECP5-25F's block
#: RAM).
MAX_LINES = 64


@dataclass(frozen=True)
class LineCachePlan:
    """The line cache a calibration needs, and why.

    ``lines``: L (a power of two), the lines kept per camera; ``needed``: the lines the model says must be
    held at once (``lines`` is the next power of two); ``span``: the largest ``bottom(r) - top(r) + 1``; ``lag``:
    the most lines the cameras wrote beyond ``bottom(r)`` while row r was worked on; ``skew``: the lines
    allowed between the two cameras; ``worst_row``: the rectified row that needs the most;
    ``frame_margin_lines``: line periods between the rectifier's end of a frame and the cameras' next frame
    reaching a line it reads (>= 0, else the plan is refused); ``bits``: the cache's block RAM, both cameras.
    """

    calibration: str
    width: int
    height: int
    lines: int
    needed: int
    span: int
    lag: int
    skew: int
    worst_row: int
    frame_margin_lines: float
    clocks_per_pair: int
    clock_hz: float
    pixel_clock_hz: float

    @property
    def bits(self) -> int:
        return 2 * self.lines * self.width * 8

    def as_dict(self) -> dict:
        return dict(calibration=self.calibration, source=f"{self.width}x{self.height}", lines=self.lines,
                    needed=self.needed, span=self.span, lag=self.lag, skew=self.skew, worst_row=self.worst_row,
                    frame_margin_lines=round(self.frame_margin_lines, 1), kbit=round(self.bits / 1024, 1))


def fetch(frames: tuple[np.ndarray, np.ndarray], x: int, y: int, cam: int, mask: int) -> list[tuple[int, int]]:
    """The beats ``(index, pixel)`` the cache answers a fetch with: the mask's pixels of the camera frame in
    increasing index order (index i at ``(x, y) + OFFSETS[i]``, the fetch port's order)."""
    img = np.asarray(frames[cam])
    out = []
    for i, (ox, oy) in enumerate(OFFSETS):
        if mask >> i & 1:
            out.append((i, int(img[y + oy, x + ox])))
    return out


def row_spans(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> tuple[np.ndarray, np.ndarray]:
    """Per rectified row (``cal.height`` entries): the lowest and the highest source row any in-range side of
    either camera reads (``y0`` and ``y0 + 1``); rows with every side out of range get ``(-1, -1)``."""
    frac = resolve_frac(cal, frac)
    p = warper.coordinate_warper(cal, frac)
    h = cal.height
    lo = np.full(h, -1, dtype=np.int64)
    hi = np.full(h, -1, dtype=np.int64)
    big = np.int64(1) << 40
    y0 = np.concatenate([np.where(p["oor_l"] == 0, p["yl"] >> frac, big),
                         np.where(p["oor_r"] == 0, p["yr"] >> frac, big)], axis=1)
    y1 = np.concatenate([np.where(p["oor_l"] == 0, (p["yl"] >> frac) + 1, -1),
                         np.where(p["oor_r"] == 0, (p["yr"] >> frac) + 1, -1)], axis=1)
    # the second row is read only when the neighbourhood needs it, but the rectifier may ask for it: count it
    y1 = np.minimum(y1, cal.source_height - 1)
    any_in = (y0 < big).any(axis=1)
    lo[any_in] = y0.min(axis=1)[any_in]
    hi[any_in] = y1.max(axis=1)[any_in]
    return lo, hi


def plan(cal: Calibration, frac: int | None = DEFAULT_FRAC, *, timing: CameraTiming | None = None,
         pixel_clock_hz: float = DEFAULT_PIXEL_CLOCK_HZ, clock_hz: float = DEFAULT_CLOCK_HZ,
         clocks_per_pair: int = CLOCKS_PER_PAIR, skew: int = DEFAULT_SKEW, max_lines: int = MAX_LINES,
         name: str | None = None) -> LineCachePlan:
    """The line cache of ``cal`` with cameras of ``timing`` (default: CIF at 50 frames/s, resized to the
    calibration's camera size) at ``pixel_clock_hz`` and the rectifier at ``clock_hz``.

    Raises ValueError naming the calibration when it needs more than ``max_lines`` lines, or when the
    rectifier would not finish a frame before the next one overwrites its lines.
    """
    label = name or cal.origin or "the calibration"
    for what, v in (("pixel_clock_hz", pixel_clock_hz), ("clock_hz", clock_hz)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{what} must be a positive number, got {v!r}")
    if not (isinstance(clocks_per_pair, int) and clocks_per_pair >= 1):
        raise ValueError(f"clocks_per_pair must be an int >= 1, got {clocks_per_pair!r}")
    if not (isinstance(skew, int) and skew >= 0):
        raise ValueError(f"skew must be an int >= 0, got {skew!r}")
    if not (isinstance(max_lines, int) and max_lines >= 2 and max_lines & (max_lines - 1) == 0):
        raise ValueError(f"max_lines must be a power of two >= 2, got {max_lines!r}")
    if timing is None:
        timing = CameraTiming(width=cal.source_width, height=cal.source_height,
                              **{k: getattr(DEFAULT_TIMING, k) for k in ("h_blank", "v_sync", "v_back", "v_front")})
    if (timing.width, timing.height) != (cal.source_width, cal.source_height):
        raise ValueError(f"camera timing is {timing.width}x{timing.height}; {label} needs "
                         f"{cal.source_width}x{cal.source_height} camera images")
    lo, hi = row_spans(cal, frac)
    h, w = cal.height, cal.width
    used = lo >= 0
    # top(r): the lowest row this or any later rectified row reads; bottom(r): the highest any row so far reads
    top = np.where(used, lo, np.iinfo(np.int64).max)
    top = np.minimum.accumulate(top[::-1])[::-1]
    bottom = np.maximum.accumulate(np.where(used, hi, -1))
    # timing, in memory clocks from the frame's first active line's start
    line = 2 * timing.width + timing.h_blank
    line_clocks = line * clock_hz / pixel_clock_hz
    data_clocks = 2 * timing.width * clock_hz / pixel_clock_hz
    row_clocks = w * clocks_per_pair
    t = 0.0
    lines_at_end = np.zeros(h, dtype=np.int64)
    for r in range(h):
        # row r's last fetch waits for camera row bottom(r) to be complete (its last pixel in)
        ready = (bottom[r] * line_clocks + data_clocks) if bottom[r] >= 0 else 0.0
        t = max(t, ready) + row_clocks
        # the line being written at t (a line's slot is overwritten from its first pixel on)
        lines_at_end[r] = int(t // line_clocks)
    span = int(np.max(np.where(used, bottom - top + 1, 0))) if used.any() else 0
    need_r = np.where(used, lines_at_end - top + 2, 0)
    worst = int(np.argmax(need_r))
    needed = int(need_r[worst]) + skew
    lines = 1 << max(1, math.ceil(math.log2(max(needed, 2))))
    if lines > max_lines:
        raise ValueError(f"{label} needs a line cache of {needed} lines per camera (rectified row {worst} reads "
                         f"from row {int(top[worst])} while the cameras write row {int(lines_at_end[worst])}); "
                         f"the stream rectifier keeps at most {max_lines}: use rectify='fetch' for it")
    # the frame's end: the next frame's first line overwrites slot 0, which may hold a row the last rectified
    # rows read: the rectifier must be done before the leading camera begins it
    frame_lines = timing.height + timing.v_sync + timing.v_back + timing.v_front
    end_line = t / line_clocks
    margin = frame_lines - skew - end_line
    if margin < 0:
        raise ValueError(f"{label}: the rectifier ends a frame {end_line:.1f} line periods after its first line, "
                         f"after the cameras' next frame begins overwriting the lines it reads ({frame_lines} "
                         f"line periods a frame)")
    return LineCachePlan(label, cal.source_width, cal.source_height, lines, needed, span,
                         int(np.max(np.where(used, lines_at_end - bottom, 0))), skew, worst, float(margin),
                         clocks_per_pair, float(clock_hz), float(pixel_clock_hz))
