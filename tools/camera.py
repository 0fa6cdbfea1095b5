"""The camera bus on the Python side: OV6630 timing, YUV 4:2:2 words, and the bus schedule of a frame sequence.

The bus itself (PCLK, VSYNC, HREF, 8-bit data, the byte orders and a timing diagram) is documented once, in
:mod:`eyestereo.hdl.interfaces.camera_bus`. This module is pure Python/numpy; the cocotb camera model
(:mod:`eyestereo.sim.lib.camera`) plays what it builds, and the bit-true models
(:mod:`eyestereo.tools.models.camera_stream`, :mod:`eyestereo.tools.models.camera_interface`) read the same
schedule, so the bench and the model see one description of what the camera did.

Frames are arrays of 16-bit camera words (:data:`WORD`): Y in bits 7..0 and the pixel's chroma sample in
bits 15..8 -- U for even x, V for odd x -- which is what the converter delivers for each pixel. A camera
frame is built from a grey image (Y) and a colour image or constants (U, V) with :func:`yuv_frame`.

A *schedule* is a list of runs, each one or more PCLK periods in which the bus holds one kind of state:

``("vsync", n)``
    n samples with VSYNC active, HREF inactive (the frame's vertical sync pulse).
``("idle", n)``
    n samples with both inactive (horizontal and vertical blanking).
``("line", bytes)``
    ``len(bytes)`` samples with HREF active, one data byte each.

Sample ``j`` of a schedule is on the bus at PCLK rising edge ``j`` (edge 0 is the first edge of the played
schedule). :func:`frame_schedule` builds the schedule of a sequence of frames from a :class:`CameraTiming`,
optionally with faults (short frames, short or long lines); :func:`cut` starts it part-way, as a camera
does that is switched on, or an FPGA that leaves reset, in the middle of a frame.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_MAX, FRAME_MIN, FRAME_WIDTH
from eyestereo.tools.packed import PackedWord

__all__ = ["WORD", "ORDERS", "CameraTiming", "DEFAULT_TIMING", "VGA_TIMING", "CIF_PCLK_HZ", "VGA_PCLK_HZ", "yuv_frame",
           "line_bytes", "frame_schedule", "cut",
           "schedule_length", "vsyncs_before", "Fault"]

#: One camera word per pixel: Y in bits 7..0, the chroma sample (U for even x, V for odd x) in 15..8.
WORD = PackedWord("yuv422", [("y", 8), ("c", 8)])

#: Byte orders of one pixel pair on the 8-bit bus (the OV6630 offers the first; the others are common).
ORDERS = ("YUYV", "YVYU", "UYVY", "VYUY")


@dataclass(frozen=True)
class CameraTiming:
    """Geometry and blanking of the camera's output, in PCLK periods and line periods.

    Defaults: CIF, 8-bit YUV 4:2:2 (two PCLK per pixel), a line of 2 x 352 data bytes plus 192 PCLK of
    horizontal blanking (896 PCLK, 448 pixel times), 396 line periods per frame (288 active): 354,816 PCLK,
    50.0 frames/s at the OV6630's 17.73 MHz. The blanking is our assumption (the data sheet text we could
    reach gives the CIF array, the rising-edge latching and the byte order, not the blanking); every
    figure is a parameter.

    Attributes:
        width, height: active pixels per line (even: pixels come in Y/U/Y/V pairs) and lines per frame.
        h_blank: PCLK with HREF inactive after each line's ``2 * width`` bytes (>= 1).
        v_sync: line periods with VSYNC active at the start of a frame (>= 1 PCLK in total).
        v_back: blank line periods between the end of VSYNC and the first line.
        v_front: blank line periods after the last line.
        order: byte order of a pixel pair, one of :data:`ORDERS`.
        vsync_active, href_active: the active level (1 or 0) of VSYNC and HREF.
    """

    width: int = FRAME_WIDTH
    height: int = FRAME_HEIGHT
    h_blank: int = 192
    v_sync: int = 3
    v_back: int = 19
    v_front: int = 86
    order: str = "YUYV"
    vsync_active: int = 1
    href_active: int = 1

    def __post_init__(self):
        for name in ("width", "height", "h_blank", "v_sync", "v_back", "v_front", "vsync_active",
                     "href_active"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise ValueError(f"CameraTiming {name} must be an int, got {v!r}")
        if self.width < FRAME_MIN or self.width % 2 or self.width > FRAME_MAX:
            raise ValueError(f"CameraTiming width={self.width}: must be even and in {FRAME_MIN}..{FRAME_MAX} "
                             "(pixel pairs)")
        if not 1 <= self.height <= FRAME_MAX:
            raise ValueError(f"CameraTiming height={self.height}: must be in 1..{FRAME_MAX}")
        if self.h_blank < 1:
            raise ValueError(f"CameraTiming h_blank={self.h_blank}: HREF must go inactive between lines (>= 1)")
        if self.v_sync < 1 or self.v_back < 0 or self.v_front < 0:
            raise ValueError("CameraTiming needs v_sync >= 1, v_back >= 0 and v_front >= 0 line periods")
        if self.order not in ORDERS:
            raise ValueError(f"CameraTiming order must be one of {ORDERS}, got {self.order!r}")
        if self.vsync_active not in (0, 1) or self.href_active not in (0, 1):
            raise ValueError("CameraTiming vsync_active and href_active must be 0 or 1")

    @property
    def line_pclk(self) -> int:
        """PCLK periods per line period (data bytes and horizontal blanking)."""
        return 2 * self.width + self.h_blank

    @property
    def lines(self) -> int:
        """Line periods per frame."""
        return self.v_sync + self.v_back + self.height + self.v_front

    @property
    def frame_pclk(self) -> int:
        """PCLK periods per frame."""
        return self.lines * self.line_pclk

    @property
    def first_line_pclk(self) -> int:
        """Sample index of the first data byte of a frame, counted from the start of its VSYNC."""
        return (self.v_sync + self.v_back) * self.line_pclk

    def fps(self, pclk_hz: float) -> float:
        return pclk_hz / self.frame_pclk

    def word_rate(self, pclk_hz: float) -> float:
        """Words per second averaged over a frame."""
        return self.width * self.height * self.fps(pclk_hz)


#: The default timing (CIF, the OV6630's): one instance, the default of every function that takes a timing.
DEFAULT_TIMING = CameraTiming()
#: An OV7670-class camera at VGA (its data sheet's VGA frame: 784 pixel times a line, 510 lines: VSYNC 3, 17
#: before the first line, 480, 10 after): 30 frames/s at a 24 MHz PCLK (two PCLK per pixel).
VGA_TIMING = CameraTiming(width=640, height=480, h_blank=2 * (784 - 640), v_sync=3, v_back=17, v_front=10)
#: The pixel clocks of the two timings (Hz).
CIF_PCLK_HZ, VGA_PCLK_HZ = 17.73e6, 24e6


def yuv_frame(y, u=128, v=128) -> np.ndarray:
    """Camera words (H, W) from Y (H, W) and U, V: scalars, (H, W / 2) planes or (H, W) planes.

    A full-resolution U or V plane is subsampled 4:2:2 by taking the mean of each pixel pair (floor).
    Even pixels carry U, odd pixels V (both samples belong to the pair).
    """
    y = np.asarray(y)
    if y.ndim != 2 or y.shape[1] % 2 or y.size == 0:
        raise ValueError(f"Y must be a non-empty (H, W) array with W even, got shape {y.shape}")
    h, w = y.shape

    def plane(c, name):
        c = np.asarray(c)
        if c.ndim == 0:
            c = np.full((h, w // 2), int(c))
        elif c.shape == (h, w):
            c = (c[:, 0::2].astype(np.int64) + c[:, 1::2]) // 2
        elif c.shape != (h, w // 2):
            raise ValueError(f"{name} must be a scalar, ({h}, {w // 2}) or ({h}, {w}), got shape {c.shape}")
        return c.astype(np.int64)

    cu, cv = plane(u, "U"), plane(v, "V")
    c = np.empty((h, w), dtype=np.int64)
    c[:, 0::2] = cu
    c[:, 1::2] = cv
    return WORD.pack(y=y.astype(np.int64), c=c)


def yuv_from_bgr(bgr: np.ndarray, grey: np.ndarray | None = None) -> np.ndarray:
    """Camera words from a colour image (BGR, uint8): Y from ``grey`` (default: the image's own luma),
    U and V from its YCrCb conversion (OpenCV, BT.601), subsampled 4:2:2."""
    import cv2

    bgr = np.asarray(bgr)
    if bgr.ndim != 3 or bgr.shape[2] != 3 or bgr.dtype != np.uint8:
        raise ValueError(f"want a (H, W, 3) uint8 BGR image, got {bgr.shape} {bgr.dtype}")
    ycc = cv2.cvtColor(bgr, cv2.COLOR_BGR2YCrCb)
    y = ycc[..., 0] if grey is None else np.asarray(grey)
    return yuv_frame(y, u=ycc[..., 2], v=ycc[..., 1])


def line_bytes(words: np.ndarray, order: str = "YUYV") -> np.ndarray:
    """The bus bytes of one line of camera words (length 2 W), in the given byte order."""
    words = np.asarray(words, dtype=np.int64)
    if words.ndim != 1 or words.size % 2:
        raise ValueError("a line must be a 1-D array of an even number of words")
    f = WORD.unpack(words)
    y0, y1 = f["y"][0::2], f["y"][1::2]
    u, v = f["c"][0::2], f["c"][1::2]
    cols = {"Y0": y0, "Y1": y1, "U": u, "V": v}
    seq = {"YUYV": ("Y0", "U", "Y1", "V"), "YVYU": ("Y0", "V", "Y1", "U"),
           "UYVY": ("U", "Y0", "V", "Y1"), "VYUY": ("V", "Y0", "U", "Y1")}[order]
    return np.stack([cols[s] for s in seq], axis=1).reshape(-1).astype(np.uint8)


@dataclass(frozen=True)
class Fault:
    """What goes wrong with one frame on the bus.

    Attributes:
        lines: lines sent (fewer than the frame's height: VSYNC comes early); None = all.
        line_bytes: ``{line: n}``: line ``line`` carries ``n`` bytes instead of ``2 * width`` (shorter:
            HREF drops early; longer: extra bytes 0x5A follow).
    """

    lines: int | None = None
    line_bytes: Mapping[int, int] = field(default_factory=dict)


def frame_schedule(frames: Sequence[np.ndarray], timing: CameraTiming = DEFAULT_TIMING, *,
                   faults: Mapping[int, Fault] | None = None) -> list[tuple[str, object]]:
    """The bus schedule of ``frames`` (camera words, each ``height x width``) played back to back."""
    faults = dict(faults or {})
    t = timing
    lp = t.line_pclk
    runs: list[tuple[str, object]] = []
    for i, f in enumerate(frames):
        f = np.asarray(f)
        if f.shape != (t.height, t.width):
            raise ValueError(f"frame {i} is {f.shape[1]}x{f.shape[0]}, the timing says {t.width}x{t.height}")
        fault = faults.pop(i, Fault())
        n_lines = t.height if fault.lines is None else int(fault.lines)
        if not 0 <= n_lines <= t.height:
            raise ValueError(f"frame {i}: fault lines={n_lines} outside 0..{t.height}")
        runs.append(("vsync", t.v_sync * lp))
        if t.v_back:
            runs.append(("idle", t.v_back * lp))
        for y in range(n_lines):
            b = line_bytes(f[y], t.order)
            n = fault.line_bytes.get(y)
            if n is not None:
                if n < 1:
                    raise ValueError(f"frame {i} line {y}: a line needs at least one byte, got {n}")
                b = b[:n] if n <= b.size else np.concatenate([b, np.full(n - b.size, 0x5A, np.uint8)])
            runs.append(("line", b))
            # A longer line eats into the blanking, a shorter one adds to it: the line period stays.
            runs.append(("idle", max(1, lp - b.size)))
        rest = (t.height - n_lines + t.v_front) * lp
        if rest:
            runs.append(("idle", rest))
    if faults:
        raise ValueError(f"faults for frames {sorted(faults)} but only {len(frames)} frames")
    return _merge(runs)


def _merge(runs):
    out: list[tuple[str, object]] = []
    for kind, p in runs:
        if kind != "line" and out and out[-1][0] == kind:
            out[-1] = (kind, out[-1][1] + p)
        else:
            out.append((kind, p))
    return out


def run_length(run) -> int:
    kind, p = run
    return len(p) if kind == "line" else int(p)


def schedule_length(runs) -> int:
    """Samples (PCLK periods) in a schedule."""
    return sum(run_length(r) for r in runs)


def cut(runs, start: int, *, preroll: int = 0) -> list[tuple[str, object]]:
    """The schedule from sample ``start`` on (the bus as seen by an FPGA that starts watching there),
    after ``preroll`` idle samples."""
    if start < 0 or preroll < 0:
        raise ValueError("cut needs start >= 0 and preroll >= 0")
    out = [("idle", preroll)] if preroll else []
    pos = 0
    for kind, p in runs:
        n = run_length((kind, p))
        if pos + n <= start:
            pos += n
            continue
        skip = max(0, start - pos)
        out.append((kind, p[skip:]) if kind == "line" else (kind, n - skip))
        pos += n
    return _merge([r for r in out if run_length(r) > 0])


def vsyncs_before(runs, start: int) -> int:
    """VSYNC pulses of a schedule that end at or before sample ``start``: frame ``i`` of ``cut(runs, start)``
    (counted by its VSYNC pulses) is frame ``i + vsyncs_before(runs, start)`` of ``runs``."""
    pos, n = 0, 0
    for kind, p in runs:
        ln = run_length((kind, p))
        if kind == "vsync":
            if pos + ln > start:
                return n
            n += 1
        pos += ln
    return n
