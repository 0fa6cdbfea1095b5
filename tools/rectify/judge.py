"""Is a stereo calibration usable? Judged when it is made (``eyestereo calibrate``) and again when a
calibration file is used (``maps``, ``rectifier``), with the camera named and a remedy in every message.

A calibration is refused (:class:`CalibrationProblem`, a ``ValueError``) when

* **the baseline** is not that of two side-by-side cameras: the two cameras coincide (the same images
  were given for both: the baseline is a tiny fraction of the board's distance), the right camera sits
  above or below the left one (the baseline is closer to vertical), or the "left" camera is to the
  right of the "right" one (the image sets are swapped);
* **a lens model is not invertible over its image**: the fitted distortion folds back before the image
  border, so the rectified image would repeat or lose parts of the picture. The usual cause is a
  calibration from few boards, all near the image centre: the polynomial is extrapolated to the
  corners;
* **it is poorly conditioned**: a camera's focal length is known only to worse than
  :data:`MAX_FOCAL_SPREAD` (relative standard deviation from OpenCV's estimate), e.g. because every
  board faced the camera at the same angle.

**Coverage** (the share of each image inside the convex hull of all detected corners) is reported,
and low coverage is named in the lens-model message; on its own it gives a note, not an error
(:data:`LOW_COVERAGE`): OpenCV's own 13 sample pairs cover 46 % and calibrate well.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from eyestereo.tools.rectify.lens import distort, undistort

__all__ = ["CalibrationProblem", "LOW_COVERAGE", "MAX_FOCAL_SPREAD", "MIN_BASELINE", "MIN_BASELINE_RATIO", "coverage",
           "check_baseline", "check_lens", "judge_calibration"]

#: Below this share of an image covered by the boards, a note says so.
LOW_COVERAGE = 0.30
#: Largest accepted relative standard deviation of a focal length.
MAX_FOCAL_SPREAD = 0.02
#: Smallest accepted baseline, as a share of the median distance of the boards.
MIN_BASELINE_RATIO = 0.005
#: Smallest accepted baseline in any unit (a micrometre when T is in metres): a file may not say how
#: far the boards were.
MIN_BASELINE = 1e-6

_SIDES = {"left": ("M1", "D1"), "right": ("M2", "D2")}


class CalibrationProblem(ValueError):
    """The calibration cannot be used; the message names the camera and the remedy."""


def coverage(points: list[np.ndarray], size: tuple[int, int]) -> float:
    """Share of the ``size`` (w, h) image inside the convex hull of all ``points`` (lists of (N, 1|2, 2))."""
    pts = np.concatenate([np.asarray(p, np.float32).reshape(-1, 2) for p in points])
    hull = cv2.convexHull(pts)
    return float(cv2.contourArea(hull)) / float(size[0] * size[1])


def check_baseline(R: np.ndarray, T: np.ndarray, *, board_distance: float | None = None,
                   where: str = "the calibration", allow_swapped: bool = False) -> None:
    """Refuse coinciding, stacked or swapped cameras (see the module docstring)."""
    T = np.asarray(T, np.float64).reshape(3)
    base = float(np.linalg.norm(T))
    if board_distance is not None and base < MIN_BASELINE_RATIO * board_distance:
        raise CalibrationProblem(
            f"{where}: the two cameras are only {base:.3g} apart, {100 * base / board_distance:.2g} % of the "
            f"boards' distance ({board_distance:.3g}): that is one camera seen twice. Give each camera's own "
            "images (LEFT_GLOB and RIGHT_GLOB must not name the same files)")
    if base < MIN_BASELINE:
        raise CalibrationProblem(
            f"{where}: the two cameras are only {base:.3g} apart: that is one camera seen twice. Calibrate again "
            "with each camera's own images (LEFT_GLOB and RIGHT_GLOB must not name the same files)")
    om = cv2.Rodrigues(np.asarray(R, np.float64))[0].ravel()
    t = cv2.Rodrigues(-0.5 * om)[0] @ T  # the baseline in the half-way frame, as the rectification sees it
    if abs(t[0]) < abs(t[1]):
        where_r = "below" if t[1] < 0 else "above"
        raise CalibrationProblem(
            f"{where}: the right camera sits {where_r} the left one (T = {np.round(T, 6).tolist()}); eyestereo "
            "rectifies side-by-side rigs: for cameras mounted one above the other, rotate every image by 90 "
            "degrees before calibrating")
    if t[0] > 0 and not allow_swapped:
        raise CalibrationProblem(
            f"{where}: the left camera is to the right of the right camera (T_x = {T[0]:.4g} > 0): the two image "
            "sets are swapped; give the left camera's images first")


def _border_points(size: tuple[int, int], n: int = 24) -> tuple[np.ndarray, np.ndarray]:
    w, h = size
    xs, ys = np.linspace(0, w - 1, n), np.linspace(0, h - 1, n)
    bx = np.concatenate([xs, xs, np.zeros(n), np.full(n, w - 1.0)])
    by = np.concatenate([np.zeros(n), np.full(n, h - 1.0), ys, ys])
    return bx, by


def check_lens(M: np.ndarray, D: np.ndarray, size: tuple[int, int], side: str, *, cover: float | None = None,
               where: str = "the calibration") -> None:
    """Refuse a lens model that is not one-to-one over the image (see the module docstring)."""
    M = np.asarray(M, np.float64)
    bx, by = _border_points(size)
    yn = (by - M[1, 2]) / M[1, 1]
    xn = (bx - M[0, 2] - M[0, 1] * yn) / M[0, 0]
    ok = True
    try:
        xu, yu = undistort(xn, yn, D)
    except ValueError:
        ok = False
    if ok:
        # along the ray from the centre to each border point the distorted radius must keep growing
        s = np.linspace(0.0, 1.0, 200)[:, None]
        dx, dy = distort(s * xu[None, :], s * yu[None, :], D)
        r = np.hypot(dx, dy)
        ok = bool(np.all(np.isfinite(r)) and np.all(np.diff(r, axis=0) > 0))
    if not ok:
        m, d = _SIDES[side]
        cov = "" if cover is None else f" (the boards cover {100 * cover:.0f} % of the {side} image)"
        raise CalibrationProblem(
            f"{where}: the {side} camera's lens model ({m}, {d}) folds back before the image border, so it "
            f"cannot be inverted there{cov}: the distortion was extrapolated from boards near the centre. "
            "Calibrate again with more views, with the board also near the corners and edges of the image")


def judge_calibration(calib: Any, *, where: str = "the calibration", allow_swapped: bool = False) -> list[str]:
    """Check a :class:`~eyestereo.tools.rectify.calib.StereoCalibration`; raises
    :class:`CalibrationProblem`, else returns notes (one line each) for a usable but weak one.

    Uses ``calib.info`` when the calibration was just estimated (``points_left``/``points_right``,
    ``board_distance``, ``focal_spread_left``/``_right``); a calibration read from a file gets the
    checks that need no estimation data (baseline direction, lens models). ``allow_swapped`` accepts a
    right camera to the left of the left one (a file from another tool may use that convention; the
    maps handle it).
    """
    info = getattr(calib, "info", {}) or {}
    size = (calib.image_width, calib.image_height)
    check_baseline(calib.R, calib.T, board_distance=info.get("board_distance"), where=where,
                   allow_swapped=allow_swapped)
    notes = []
    covers: dict[str, float | None] = {"left": None, "right": None}
    for side in ("left", "right"):
        pts = info.get(f"points_{side}")
        if pts:
            covers[side] = coverage(pts, size)
    for side, (m, d) in _SIDES.items():
        check_lens(getattr(calib, m), getattr(calib, d), size, side, cover=covers[side], where=where)
    for side in ("left", "right"):
        spread = info.get(f"focal_spread_{side}")
        if spread is not None and spread > MAX_FOCAL_SPREAD:
            raise CalibrationProblem(
                f"{where}: the calibration is poorly conditioned: the {side} camera's focal length is known only "
                f"to +-{100 * spread:.1f} % (at most {100 * MAX_FOCAL_SPREAD:g} % is accepted). Add views with the "
                "board tilted by 20 to 45 degrees in different directions")
    for side, c in covers.items():
        if c is not None and c < LOW_COVERAGE:
            notes.append(f"the boards cover only {100 * c:.0f} % of the {side} image; the rectification of the "
                         "image corners is extrapolated (add views with the board near the corners)")
    return notes
