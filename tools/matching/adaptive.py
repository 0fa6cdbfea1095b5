"""Adaptive Harris thresholds (thesis 7.2): set the BX x BY block thresholds frame by frame.

The hardware's pre-threshold stage holds one threshold code per block (default 4 x 4); the CPU sees each
frame's corners, counts them per block and writes the next frame's 16 codes, so that the number of
corners per block approaches a target (the feature list must fit a fixed SRAM area, and a full list
should not be cut off in the lower right part of the image). One frame of delay is inherent: frame t's
counts set frame t + 1's codes.

Controllers (``update(counts) -> codes``, integer codes for the ``thr_data`` port, clipped to
0 .. 524287, the positive range of the 20-bit cornerness):

* :class:`IController` -- the thesis's I-controller: u += gain * (count - target), code = round(u).
  Linear in the code, so one gain cannot suit every scene: the cornerness of a corner grows with the
  4th power of the image contrast, and the count falls roughly as code^-0.5, so the slope
  d count / d code varies by orders of magnitude between textured and flat blocks and between a dark
  and a bright frame.
* :class:`LogController` -- the improvement: the same integral action on logarithms,
  log(code + 1) += gain * (log(count + 1) - log(target + 1)). A change of contrast or brightness scales
  the cornerness, which is a constant shift in log(code), so the loop behaves the same at every
  operating point; with count ~ code^-alpha (alpha about 0.5) a gain of about 1 / alpha settles in one
  or two frames. ``max_step`` bounds the change per frame (a factor of 2**max_step) so one noisy count
  cannot throw a block's threshold far off. Its weakness: alpha differs between scenes (about 0.5 on
  Tsukuba, steeper on Venus, where a fixed gain of 1.5 already oscillates).
* :class:`SecantController` -- the recommended one: the log-domain step divided by each block's own
  slope alpha = -d log(count) / d log(code), estimated from its last two frames (secant; kept when the
  code moved enough, clipped to ``alpha_range``, averaged with the previous estimate). A Newton step
  on a plant whose gain it measures: no gain to tune per scene.

:func:`run_sequence` runs a controller over frames with the bit-true model :func:`harris_mono`;
:func:`step_sequence` builds the step-response test sequence (a panning crop with contrast steps).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.models import harris_mono as _hm
from eyestereo.tools.models import prethreshold as _pre

__all__ = ["CODE_MAX", "IController", "LogController", "SecantController", "History", "block_counts", "run_sequence",
           "step_sequence", "settling_frames"]

#: largest useful threshold code: the positive end of the 20-bit cornerness output
CODE_MAX = (1 << 19) - 1


def block_counts(flags, mask, blocks=THRESHOLD_BLOCKS) -> np.ndarray:
    """Corners per block (listed by block index by * BX + bx), counting only specified pixels."""
    f = np.asarray(flags).astype(bool)
    if mask is not None:
        m = np.asarray(mask, bool)
        if m.shape != f.shape:
            raise ValueError(f"mask shape {m.shape} differs from the flags' {f.shape}")
        f = f & m
    h, w = f.shape
    _pre.check_blocks(w, h, tuple(blocks))
    idx = _pre.block_index(h, w, tuple(blocks))
    return np.bincount(idx[f], minlength=blocks[0] * blocks[1]).astype(np.int64)


def _check_common(target, n_blocks: int, init) -> tuple[np.ndarray, np.ndarray]:
    t = np.broadcast_to(np.asarray(target, np.float64), (n_blocks,)).copy()
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        raise ValueError(f"targets must be finite and >= 0, got {target!r}")
    c = np.broadcast_to(np.asarray(init, np.float64), (n_blocks,)).copy()
    if not np.all(np.isfinite(c)) or np.any(c < 0) or np.any(c > CODE_MAX):
        raise ValueError(f"initial codes must lie in 0..{CODE_MAX}, got {init!r}")
    return t, c


def _check_counts(counts, n: int) -> np.ndarray:
    c = np.asarray(counts, np.float64).reshape(-1)
    if c.shape != (n,) or np.any(c < 0) or not np.all(np.isfinite(c)):
        raise ValueError(f"need {n} non-negative counts, got {np.asarray(counts).shape}")
    return c


class IController:
    """Thesis 7.2: integral control of each block's code, u += gain * (count - target)."""

    def __init__(self, target, *, gain: float = 0.5, init=0, n_blocks: int = 16):
        if not (np.isfinite(gain) and gain > 0):
            raise ValueError(f"gain must be a positive number, got {gain}")
        self.target, self.u = _check_common(target, n_blocks, init)
        self.gain = float(gain)
        self.n = n_blocks

    @property
    def codes(self) -> np.ndarray:
        return np.clip(np.round(self.u), 0, CODE_MAX).astype(np.int64)

    def update(self, counts) -> np.ndarray:
        c = _check_counts(counts, self.n)
        self.u = np.clip(self.u + self.gain * (c - self.target), 0, CODE_MAX)  # clamp: no wind-up
        return self.codes


class LogController:
    """Integral control on logarithms: log2(code + 1) += gain * log2((count + 1) / (target + 1))."""

    def __init__(self, target, *, gain: float = 1.5, init=0, max_step: float = 4.0, n_blocks: int = 16):
        if not (np.isfinite(gain) and gain > 0):
            raise ValueError(f"gain must be a positive number, got {gain}")
        if not (np.isfinite(max_step) and max_step > 0):
            raise ValueError(f"max_step must be a positive number, got {max_step}")
        self.target, c = _check_common(target, n_blocks, init)
        self.s = np.log2(c + 1.0)
        self.gain, self.max_step, self.n = float(gain), float(max_step), n_blocks

    @property
    def codes(self) -> np.ndarray:
        return np.clip(np.round(np.exp2(self.s) - 1.0), 0, CODE_MAX).astype(np.int64)

    def update(self, counts) -> np.ndarray:
        c = _check_counts(counts, self.n)
        step = self.gain * (np.log2(c + 1.0) - np.log2(self.target + 1.0))
        self.s = np.clip(self.s + np.clip(step, -self.max_step, self.max_step), 0.0, np.log2(CODE_MAX + 1.0))
        return self.codes


class SecantController(LogController):
    """Log-domain Newton step with a per-block secant estimate of alpha = -d log2(count+1) / d log2(code+1)."""

    def __init__(self, target, *, alpha0: float = 0.6, alpha_range=(0.2, 1.5), min_move: float = 0.3,
                 init=0, max_step: float = 4.0, n_blocks: int = 16):
        lo, hi = (float(v) for v in alpha_range)
        if not (0 < lo <= alpha0 <= hi and np.isfinite(hi)):
            raise ValueError(f"need 0 < alpha_range[0] <= alpha0 <= alpha_range[1], got {alpha0}, {alpha_range}")
        super().__init__(target, gain=1.0 / alpha0, init=init, max_step=max_step, n_blocks=n_blocks)
        self.alpha = np.full(n_blocks, float(alpha0))
        self.lo, self.hi, self.min_move = lo, hi, float(min_move)
        self._prev = None

    def update(self, counts) -> np.ndarray:
        c = _check_counts(counts, self.n)
        y = np.log2(c + 1.0)
        s_used = np.log2(self.codes + 1.0)  # the codes this frame ran with
        if self._prev is not None:
            ps, py = self._prev
            ds = s_used - ps
            moved = np.abs(ds) >= self.min_move
            est = np.clip(-(y - py) / np.where(moved, ds, 1.0), self.lo, self.hi)
            self.alpha = np.where(moved, 0.5 * (self.alpha + est), self.alpha)
        self._prev = (s_used, y)
        step = (y - np.log2(self.target + 1.0)) / self.alpha
        self.s = np.clip(self.s + np.clip(step, -self.max_step, self.max_step), 0.0, np.log2(CODE_MAX + 1.0))
        return self.codes


@dataclass
class History:
    """Per frame: the codes the frame was processed with, and the corners it gave per block."""

    codes: np.ndarray    # (frames, blocks)
    counts: np.ndarray   # (frames, blocks)
    target: np.ndarray   # (blocks,)

    @property
    def totals(self) -> np.ndarray:
        return self.counts.sum(1)


def run_sequence(frames, controller, *, k: float = K_DEFAULT, blocks=THRESHOLD_BLOCKS,
                 nms: int = NMS_DEFAULT) -> History:
    """Process ``frames`` with the bit-true Harris model; frame t + 1 uses the codes from frame t's counts.

    Frame 0 uses the controller's initial codes (the hardware's are 0 after reset)."""
    frames = list(frames)
    if not frames:
        raise ValueError("no frames")
    kc = _hm.k_code(k)
    codes, counts = [], []
    cur = controller.codes
    for f in frames:
        f = np.asarray(f)
        if f.ndim != 2:
            raise ValueError(f"frames must be 2-D grey images, got shape {f.shape}")
        flags, mask = _hm.harris_mono(f, kc, cur, blocks=tuple(blocks), nms=nms)
        n = block_counts(flags, mask, blocks)
        codes.append(cur.copy())
        counts.append(n)
        cur = controller.update(n)
    return History(np.array(codes), np.array(counts), np.asarray(controller.target, np.float64))


def step_sequence(img, *, size=(FRAME_WIDTH, FRAME_HEIGHT), frames_per_step: int = 15,
                  gains=(1.0, 0.5, 1.0, 1.6), pan: int = 1) -> tuple[list[np.ndarray], list[int]]:
    """(frames, step frame indices): a ``size`` crop panning ``pan`` px per frame (back and forth over
    the image) whose contrast about mid-grey changes by the factors in ``gains`` every
    ``frames_per_step`` frames (clipped to 0..255)."""
    img = np.asarray(img)
    if img.ndim != 2:
        raise ValueError("step_sequence needs a grey image")
    w, h = size
    H, W = img.shape
    if w > W or h > H:
        raise ValueError(f"crop {w}x{h} is larger than the {W}x{H} image")
    span = W - w
    frames, steps = [], []
    t = 0
    for gi, g in enumerate(gains):
        if gi:
            steps.append(t)
        for _ in range(frames_per_step):
            if span:
                p = (t * pan) % (2 * span)
                x0 = p if p <= span else 2 * span - p
            else:
                x0 = 0
            y0 = (H - h) // 2
            crop = img[y0:y0 + h, x0:x0 + w].astype(np.float64)
            frames.append(np.clip(np.round(128.0 + g * (crop - 128.0)), 0, 255).astype(np.int64))
            t += 1
    return frames, steps


def settling_frames(totals, start: int, target: float, *, tol: float = 0.1, end: int | None = None) -> int | None:
    """Frames after ``start`` until the total stays within +-tol * target up to ``end`` (None: never)."""
    tot = np.asarray(totals, np.float64)[start:end]
    ok = np.abs(tot - target) <= tol * target
    for i in range(len(ok)):
        if ok[i:].all():
            return i
    return None
