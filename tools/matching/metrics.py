"""Disparity quality measures (thesis 7.3, adapted from Middlebury) and ground-truth loading.

Ground truth is a float disparity map of the LEFT view with NaN where it is unknown. Both measures are
taken over the evaluated points: matched features (sparse) or pixels with an estimate (dense) whose
ground truth is known. With e = d - d_true:

* RMS error  R = sqrt(mean(e^2)),
* bad matches: |e| > ``bad_threshold`` (sigma_d = 1 px in the thesis), as a count and a percentage.

``good`` = evaluated - bad. Points whose ground truth is unknown are counted apart (``unknown``), never
as good or bad. With nothing to evaluate, ``bad_percent`` and ``rms`` are NaN (``null`` in JSON).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from eyestereo.tools.io import read_image

__all__ = ["Scores", "load_disparity", "gt_from_array", "check_gt", "sparse_scores", "dense_scores",
           "read_pfm"]


@dataclass(frozen=True)
class Scores:
    """Evaluation of a set of disparities against ground truth."""

    evaluated: int      # points with an estimate and known ground truth
    good: int           # |d - d_true| <= threshold
    bad: int            # |d - d_true| >  threshold
    unknown: int        # points with an estimate but unknown ground truth
    bad_percent: float  # 100 * bad / evaluated (NaN if nothing evaluated)
    rms: float          # sqrt(mean (d - d_true)^2) over the evaluated points (NaN if none)
    missing: int = 0    # dense only: pixels with known ground truth but no estimate

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in asdict(self).items()}


def gt_from_array(gt, *, scale: float = 1.0, zero_unknown: bool = True) -> np.ndarray:
    """Float64 disparities from stored values: value / scale; 0 (if ``zero_unknown``), NaN, +-inf -> NaN."""
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive number, got {scale}")
    a = np.asarray(gt)
    if a.ndim == 3 and a.shape[2] in (3, 4) and np.all(a[..., :1] == a[..., 1:3]):
        a = a[..., 0]  # a grey image stored as RGB
    if a.ndim != 2:
        raise ValueError(f"ground truth must be a 2-D disparity map, got shape {a.shape}")
    if not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise ValueError(f"ground truth must be numeric, got dtype {a.dtype}")
    d = a.astype(np.float64)
    unknown = ~np.isfinite(d)
    if zero_unknown:
        unknown |= d == 0
    d = np.where(unknown, np.nan, d / scale)
    if np.any(d[~unknown] < 0):
        raise ValueError("ground truth holds negative disparities (left x - right x must be >= 0)")
    return d


def read_pfm(path) -> np.ndarray:
    """A single-channel PFM file as float32 (rows top to bottom)."""
    with open(path, "rb") as fh:
        head = fh.readline().strip()
        if head not in (b"Pf", b"PF"):
            raise ValueError(f"{path} is not a PFM file")
        try:
            dims = fh.readline().split()
            scale = float(fh.readline().strip())
            w, h = int(dims[0]), int(dims[1])
        except (ValueError, IndexError):
            raise ValueError(f"{path}: malformed PFM header") from None
        if not (0 < w <= 65536 and 0 < h <= 65536 and math.isfinite(scale) and scale != 0):
            raise ValueError(f"{path}: implausible PFM header ({w}x{h}, scale {scale})")
        ch = 3 if head == b"PF" else 1
        data = np.frombuffer(fh.read(), dtype="<f4" if scale < 0 else ">f4")
    if data.size != w * h * ch:
        raise ValueError(f"{path}: truncated PFM data")
    data = data.reshape(h, w, ch)[::-1, :, 0]
    return data.astype(np.float32)


def load_disparity(path, scale: float = 1.0) -> np.ndarray:
    """Ground truth from a file: PGM/PNG (8 or 16 bit, value = d * scale, 0 = unknown), PFM or .npy
    (float disparities, scaled the same way; 0, NaN and inf = unknown)."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"ground truth {p} does not exist")
    suffix = p.suffix.lower()
    if suffix == ".pfm":
        raw = read_pfm(p)
    elif suffix == ".npy":
        try:
            raw = np.load(p, allow_pickle=False)
        except Exception:  # noqa: BLE001 - numpy raises many kinds for a bad file
            raise ValueError(f"cannot read ground truth {p}: not a readable .npy file") from None
    else:
        raw = read_image(p, what="ground truth")
    try:
        return gt_from_array(raw, scale=scale)
    except ValueError as e:
        raise ValueError(f"ground truth {p}: {e}") from None


def check_gt(gt, shape) -> np.ndarray:
    """Float ground truth of exactly ``shape`` (h, w); ValueError otherwise."""
    g = np.asarray(gt, np.float64)
    if g.ndim != 2 or g.shape != tuple(shape):
        got = f"{g.shape[1]}x{g.shape[0]}" if g.ndim == 2 else f"shape {g.shape}"
        raise ValueError(f"ground truth is {got} but the images are {shape[1]}x{shape[0]} (width x height)")
    return g


def _scores(est: np.ndarray, true: np.ndarray, threshold: float, missing: int = 0) -> Scores:
    known = np.isfinite(true)
    e = est[known] - true[known]
    n = int(e.size)
    bad = int(np.count_nonzero(np.abs(e) > threshold))
    return Scores(evaluated=n, good=n - bad, bad=bad, unknown=int(np.count_nonzero(~known)),
                  bad_percent=100.0 * bad / n if n else float("nan"),
                  rms=float(np.sqrt(np.mean(e * e))) if n else float("nan"), missing=missing)


def sparse_scores(points, disparities, gt, *, bad_threshold: float = 1.0) -> Scores:
    """Scores of disparities at left-image points (x, y), shape (n, 2), against ``gt`` (NaN unknown)."""
    g = np.asarray(gt, np.float64)
    if g.ndim != 2:
        raise ValueError(f"ground truth must be 2-D, got shape {g.shape}")
    p = np.asarray(points)
    if p.size == 0:
        p = p.reshape(0, 2)
    d = np.asarray(disparities, np.float64).reshape(-1)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) != len(d):
        raise ValueError(f"need (n, 2) points and n disparities, got {p.shape} and {d.shape}")
    p = p.astype(np.int64)
    h, w = g.shape
    if len(p) and (p[:, 0].min() < 0 or p[:, 0].max() >= w or p[:, 1].min() < 0 or p[:, 1].max() >= h):
        raise ValueError(f"points lie outside the {w}x{h} ground truth")
    if not np.all(np.isfinite(d)):
        raise ValueError("sparse disparities must be finite")
    return _scores(d, g[p[:, 1], p[:, 0]], bad_threshold)


def dense_scores(disparity, gt, *, bad_threshold: float = 1.0, mask=None) -> Scores:
    """Scores of a dense map (NaN = no estimate) over pixels with known ground truth (and ``mask``)."""
    d = np.asarray(disparity, np.float64)
    g = check_gt(gt, d.shape)
    sel = np.ones(d.shape, bool) if mask is None else np.asarray(mask, bool)
    if sel.shape != d.shape:
        raise ValueError(f"mask shape {sel.shape} differs from the disparity map's {d.shape}")
    has = np.isfinite(d) & sel
    missing = int(np.count_nonzero(sel & ~np.isfinite(d) & np.isfinite(g)))
    return _scores(d[has], g[has], bad_threshold, missing)
