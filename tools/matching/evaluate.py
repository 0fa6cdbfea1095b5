"""Evaluating sparse matching on a stereo pair with ground truth: the computations behind
``eyestereo evaluate`` and ``eyestereo sweep`` (thesis 7.3).

**The ground truth only scores.** Every parameter of the matcher comes from the caller or from the
images: the disparity range defaults to a quarter of the image width (:func:`default_d_max`), never to
anything read from the ground truth.

**Defaults** (:data:`DEFAULTS`, what ``eyestereo evaluate`` uses unless told otherwise): about 500
Harris corners per image (one threshold code for both, thesis 7.3), normalized cross-correlation over
11x11 windows accepted at NCC >= 0.75, the left-right consistency check, and disparities
0 .. width / 4. Why these (measured by ``tools/reports/bench_matching.py``, ``docs/matching.md``
section "Defaults"):

* *NCC* (a design decision, not tuned) ignores a gain and an offset between the two views. Two
  cameras with their own exposure control differ exactly so, and Middlebury 2014's Motorcycle does:
  with SAD 9x9, t_max 11 it keeps 86 good matches of 500 corners.
* *The left-right check* removes a pair unless each corner is the other's best match; it costs
  little and is what makes a wide disparity range safe.
* *A quarter of the width* covers the usual rigs (Tsukuba uses 4 % of its width, Motorcycle 8 %);
  with the check on, the bad count at width / 4 equals that at the true range on every scene here.
* *11x11 and 0.75* were chosen on Tsukuba and Venus only, by one rule: the most good matches (summed)
  with at most 5 % bad on each (half the 10 % goal, a margin for unseen scenes), over windows 5..19
  and NCC thresholds 0.60..0.95. Motorcycle was held out of that choice.
"""

from __future__ import annotations

import math
import re
import time
from typing import Any

import numpy as np

from eyestereo.tools.constants import K_DEFAULT, NMS_DEFAULT
from eyestereo.tools.matching import metrics as Q
from eyestereo.tools.matching import sparse as M

__all__ = ["DEFAULTS", "VARY", "default_d_max", "evaluate_pair", "match_params", "parse_values", "parse_window",
           "summary", "sweep_pair"]

#: The matcher's defaults for a user (``eyestereo evaluate``); see the module docstring.
DEFAULTS: dict[str, Any] = dict(corners=500, k=K_DEFAULT, nms=NMS_DEFAULT, cost="ncc", window=(11, 11), ncc_min=0.75,
                                t_max=11.0, split=1, rows=0, lr_check=True, d_range=0.25)

#: Matching parameters ``sweep`` can vary.
VARY = ("t_max", "window", "split", "cost", "rows", "ncc_min")


def default_d_max(width: int, fraction: float = DEFAULTS["d_range"]) -> int:
    """The default largest disparity: ``fraction`` (a quarter) of the image width, at least 1."""
    if isinstance(width, bool) or int(width) < 1:
        raise ValueError(f"width must be a positive integer, got {width!r}")
    if not 0 < fraction <= 1:
        raise ValueError(f"fraction must lie in (0, 1], got {fraction}")
    return max(1, int(width * fraction))


def match_params(**overrides: Any) -> dict[str, Any]:
    """The matching keywords of :data:`DEFAULTS` (for :func:`~eyestereo.tools.matching.sparse.match_features`)
    with ``overrides`` applied."""
    keys = ("cost", "window", "ncc_min", "t_max", "split", "rows", "lr_check")
    out = {k: DEFAULTS[k] for k in keys}
    unknown = set(overrides) - set(keys)
    if unknown:
        raise ValueError(f"unknown matching parameter(s): {', '.join(sorted(unknown))}")
    out.update(overrides)
    return out


def evaluate_pair(left, right, gt, *, corners: int = DEFAULTS["corners"], threshold: int | None = None,
                  k: float = DEFAULTS["k"], nms: int = DEFAULTS["nms"], d_max: int | None = None, left_xy=None,
                  right_xy=None, **match_kw) -> dict:
    """Corners (unless given), matching and scores of one stereo pair; a dict with the figures and the
    objects (``result["matches"]`` is a :class:`~eyestereo.tools.matching.sparse.Matches`).

    ``gt`` is used for the scores only. ``d_max`` None: :func:`default_d_max` of the image width.
    Matching keywords not given take :data:`DEFAULTS`.
    """
    left, right = M.check_pair(left, right)
    gt = Q.check_gt(gt, left.shape)
    if d_max is None:
        d_max = default_d_max(left.shape[1])
    kw = match_params(**match_kw)
    t0 = time.perf_counter()
    if left_xy is None or right_xy is None:
        if threshold is None:
            threshold = M.threshold_for_count(left, corners, k=k, nms=nms)
        left_xy = M.detect_corners(left, k=k, threshold=threshold, nms=nms)
        right_xy = M.detect_corners(right, k=k, threshold=threshold, nms=nms)
    t1 = time.perf_counter()
    if len(left_xy) == 0 or len(right_xy) == 0:
        side = "left" if len(left_xy) == 0 else "right"
        raise ValueError(f"no corners found in the {side} image (threshold code {threshold}); "
                         "lower --threshold or ask for more --corners")
    m = M.match_features(left, right, left_xy, right_xy, d_max=d_max, **kw)
    t2 = time.perf_counter()
    s = Q.sparse_scores(m.left, m.disparity, gt)
    return dict(matches=m, scores=s, left_xy=np.asarray(left_xy), right_xy=np.asarray(right_xy),
                threshold=threshold, d_max=int(d_max), seconds=t2 - t1, seconds_features=t1 - t0)


def summary(result: dict) -> dict:
    """The JSON-able figures of :func:`evaluate_pair`'s result."""
    s: Q.Scores = result["scores"]
    m: M.Matches = result["matches"]
    p = dict(m.params)
    p["window"] = list(p["window"])
    out = {"matches": len(m), "good": s.good, "bad": s.bad,
           "bad_percent": None if math.isnan(s.bad_percent) else round(s.bad_percent, 4),
           "rms": None if math.isnan(s.rms) else round(s.rms, 6),
           "seconds": round(result["seconds"], 6), "seconds_features": round(result["seconds_features"], 6),
           "unknown": s.unknown, "evaluated": s.evaluated, "candidates": m.candidates,
           "left_corners": int(len(result["left_xy"])), "right_corners": int(len(result["right_xy"])),
           "threshold_code": None if result["threshold"] is None else int(np.max(result["threshold"])),
           "params": p}
    if "dense" in result:
        out["dense"] = result["dense"]
    return out


def sweep_pair(left, right, gt, vary: str, values, *, repeat: int = 1, **kw) -> list[dict]:
    """:func:`evaluate_pair` for each value of one matching parameter (corners detected once).

    ``repeat`` > 1 times the matching step that many times and keeps the fastest."""
    if vary not in VARY:
        raise ValueError(f"vary must be one of {VARY}, got {vary!r}")
    values = list(values)
    if not values:
        raise ValueError("no values to sweep")
    base = evaluate_pair(left, right, gt, **kw)
    kw = {k: v for k, v in kw.items() if k not in ("corners", "threshold", "k", "nms")}
    kw["d_max"] = base["d_max"]
    rows = []
    for v in values:
        best = None
        for _ in range(max(1, repeat)):
            r = evaluate_pair(left, right, gt, left_xy=base["left_xy"], right_xy=base["right_xy"],
                              **{**kw, vary: v})
            if best is None or r["seconds"] < best["seconds"]:
                best = r
        best["threshold"] = base["threshold"]
        best["seconds_features"] = base["seconds_features"]
        row = summary(best)
        row["value"] = list(v) if isinstance(v, tuple) else v
        rows.append(row)
    return rows


def parse_window(text: str) -> tuple[int, int]:
    """'9' or '5x7' (W x H) -> (W, H), odd sides 1..255."""
    m = re.fullmatch(r"\s*(\d+)\s*(?:[xX]\s*(\d+)\s*)?", str(text))
    if m is None:
        raise ValueError(f"window must be N or WxH, e.g. 9 or 5x7; got {text!r}")
    w = int(m.group(1))
    h = int(m.group(2)) if m.group(2) else w
    if not (1 <= w <= 255 and 1 <= h <= 255 and w % 2 and h % 2):
        raise ValueError(f"window sides must be odd, 1..255; got {text!r}")
    return w, h


def _float(v: str, what: str) -> float:
    try:
        f = float(v)
    except ValueError:
        raise ValueError(f"{what} values must be numbers, got {v!r}") from None
    if not math.isfinite(f):
        raise ValueError(f"{what} values must be finite, got {v!r}")
    return f


def parse_values(vary: str, text: str) -> list:
    """'1,5,9' or 'a:b[:step]' (inclusive; t_max, ncc_min and rows) -> the values of parameter ``vary``."""
    if vary not in VARY:
        raise ValueError(f"vary must be one of {VARY}, got {vary!r}")
    text = str(text).strip()
    if not text:
        raise ValueError("empty --values")
    if ":" in text and vary in ("t_max", "rows", "ncc_min"):
        parts = text.split(":")
        if len(parts) not in (2, 3):
            raise ValueError(f"range must be a:b or a:b:step, got {text!r}")
        a, b = _float(parts[0], vary), _float(parts[1], vary)
        st = _float(parts[2], vary) if len(parts) == 3 else 1.0
        if not (st > 0 and b >= a and (b - a) / st <= 1000):
            raise ValueError(f"range {text!r} must rise with a positive step (at most 1000 values)")
        vals = [str(a + i * st) for i in range(int(math.floor((b - a) / st + 1e-9)) + 1)]
    else:
        vals = [v.strip() for v in text.split(",") if v.strip()]
    out: list[Any] = []
    for v in vals:
        if vary == "t_max":
            f = _float(v, vary)
            if not f > 0:
                raise ValueError(f"t_max values must be positive, got {v}")
            out.append(round(f, 9))
        elif vary == "ncc_min":
            f = _float(v, vary)
            if not -1 <= f <= 1:
                raise ValueError(f"ncc_min values must lie in -1..1, got {v}")
            out.append(round(f, 9))
        elif vary == "rows":
            f = _float(v, vary)
            if f != int(f) or not 0 <= f <= 16:
                raise ValueError(f"rows values must be integers 0..16, got {v}")
            out.append(int(f))
        elif vary == "window":
            out.append(parse_window(v))
        elif vary == "split":
            if v not in ("1", "5", "9"):
                raise ValueError(f"split values must be 1, 5 or 9, got {v!r}")
            out.append(int(v))
        else:  # cost
            if v not in M.COSTS:
                raise ValueError(f"cost values must be among {', '.join(M.COSTS)}, got {v!r}")
            out.append(v)
    return out
