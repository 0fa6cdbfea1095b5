"""Backward rectification maps of a calibrated stereo rig (thesis 3.4 and 3.5).

For every pixel ``(x, y)`` of each *rectified* image the maps hold the coordinate in the *distorted
camera image* to interpolate from (0-based pixels, OpenCV's convention: pixel centres at integers).
The construction, for each camera ``i`` (left = 1, right = 2):

1. **Half rotations.** The rotation ``R`` between the cameras (``X_right = R X_left + T``) is split
   in two halves with Rodrigues' formula, ``r = rodrigues(-om / 2)`` with ``om = rodrigues(R)``; the
   left camera turns by ``r^T``, the right by ``r``, and the views become parallel. The baseline is
   then ``t = r T``.
2. **Baseline rotation.** ``R_rect`` turns ``t`` onto the x axis. ``rotation="bouguet"`` (default)
   uses the smallest such rotation, about the axis ``t x e_x`` (Bouguet's toolbox, which the thesis
   used, and OpenCV). ``rotation="thesis"`` builds ``R_rect`` from the rows ``v1 = t/|t|``,
   ``v2 = (-t_y, t_x, 0)/sqrt(t_x^2 + t_y^2)``, ``v3 = v1 x v2`` (thesis eqs. 3.3-3.5), with both
   ``v1`` and ``v2`` multiplied by the sign of ``t_x`` so that the images stay upright (without it a
   right camera at ``t_x < 0``, OpenCV's convention, gets images turned by 180 degrees). The two differ
   only by a rotation about the baseline, tiny for a nearly ideal rig (1e-5 rad for the synthetic
   one), because the thesis's ``v2`` has no z component. The camera rotations are
   ``R1 = R_rect r^T`` and ``R2 = R_rect r``.
3. **Common camera matrix** ``K = [[f, 0, cx], [0, f, cy], [0, 0, 1]]`` of both rectified images.
   ``focal="mean"`` (default) takes the mean of the two vertical focal lengths ``fy`` (as OpenCV's
   ``stereoRectify``); ``focal="min"`` the smaller one (the thesis's choice, which keeps a little more of
   the distorted images). The principal point: for each camera, the one that centres the rectified
   images of the four corner pixels of the distorted image (undistorted exactly, here by Newton
   iteration), then the **mean of the two** for both cameras (zero disparity at infinity; the thesis's
   "mean value between both principal points", OpenCV's ``CALIB_ZERO_DISPARITY``). For an output size
   different from the calibrated one, ``f`` scales with the height ratio and ``cx, cy`` with the width
   and height ratios, so the rectified image is an exactly scaled copy (OpenCV instead centres the
   corners with the scaled ``f`` around the unscaled image centre, which moves the image).
4. **Backward mapping** of each rectified pixel ``p``: ray ``K^-1 p``, rotated back by ``R_i^T``,
   normalised by its z, distorted by camera ``i``'s lens model and projected with its camera matrix
   ``M_i`` (including the skew term ``M_i[0, 1]``, which OpenCV's own functions ignore; it is 0 for
   every calibration OpenCV makes).

The lens model (thesis 3.3, Slama/Heikkila/Bouguet; OpenCV's order of coefficients ``k1 k2 p1 p2 k3
[k4 k5 k6 [s1 s2 s3 s4 [tau_x tau_y]]]``; the thesis calls k3 "k5" and p1, p2 "k3, k4"):
``x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
+ s1 r^2 + s2 r^4`` and likewise for y, then the tilted-sensor projection. It is implemented in numpy
(:func:`distort`), vectorised, and checked against ``cv2.projectPoints``.

``method="opencv"`` computes the same maps with ``cv2.stereoRectify`` (``CALIB_ZERO_DISPARITY``,
``alpha=-1``: OpenCV's own choice of ``f`` = mean ``fy`` and of the principal point, no extra scaling)
and ``cv2.initUndistortRectifyMap`` (``CV_32FC1``). At the calibrated size the two paths differ only in how
precisely the four image corners are undistorted for the principal point (OpenCV: a few fixed-point
iterations, in float32) and in the maps' float32 rounding; docs/toolbox.md gives the measured
difference.
"""

from __future__ import annotations

import io
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np

from eyestereo.tools.io import atomic_output
from eyestereo.tools.rectify.calib import StereoCalibration
from eyestereo.tools.rectify.lens import distort, undistort

if TYPE_CHECKING:
    from eyestereo.tools.rectify.rig import StereoRig

__all__ = [
    "MAP_KEYS",
    "Maps",
    "backward_map",
    "BUDGET_GROUPS",
    "check_map_entries",
    "compare_up_to_frame",
    "compute_maps",
    "distort",
    "ground_truth_maps",
    "load_maps",
    "map_difference",
    "maps_for_frame",
    "rectified_camera",
    "rectify_points",
    "recovery_budget",
    "rectify_rotations",
    "row_alignment",
    "save_maps",
    "undistort",
]

#: The four float arrays of a maps file, each (height, width).
MAP_KEYS = ("left_x", "left_y", "right_x", "right_y")


# --------------------------------------------------------------------------------------------------
# Lens model


#: Most pixels a rectified image may have (the maps hold several float64 arrays of that size).
MAX_PIXELS = 1 << 24


# --------------------------------------------------------------------------------------------------
# Rectifying rotations and camera


def rectify_rotations(R: np.ndarray, T: np.ndarray, rotation: str = "bouguet") -> tuple[np.ndarray, np.ndarray]:
    """``(R1, R2)``: rotations turning the left and right camera frames into the rectified ones."""
    R = np.asarray(R, dtype=np.float64)
    T = np.asarray(T, dtype=np.float64).reshape(3)
    om = cv2.Rodrigues(R)[0].ravel()
    r_r = cv2.Rodrigues(-0.5 * om)[0]  # half of the inverse rotation: the right camera turns by it
    t = r_r @ T
    if abs(t[0]) < abs(t[1]):
        raise ValueError("the baseline is closer to vertical than to horizontal: only horizontal "
                         "(side-by-side) stereo rigs are supported")
    sign = 1.0 if t[0] > 0 else -1.0
    if rotation == "bouguet":
        e = np.array([sign, 0.0, 0.0])
        w = np.cross(t, e)
        nw = np.linalg.norm(w)
        ang = np.arccos(np.clip(abs(t[0]) / np.linalg.norm(t), -1.0, 1.0))
        r_rect = cv2.Rodrigues(w * (ang / nw) if nw > 0 else np.zeros(3))[0]
    elif rotation == "thesis":
        v1 = sign * t / np.linalg.norm(t)
        v2 = sign * np.array([-t[1], t[0], 0.0]) / np.hypot(t[0], t[1])
        v3 = np.cross(v1, v2)
        r_rect = np.vstack([v1, v2, v3])
    else:
        raise ValueError(f"rotation must be 'bouguet' or 'thesis', got {rotation!r}")
    return r_rect @ r_r.T, r_rect @ r_r


def _parse_size(size: tuple[int, int] | None, calib: StereoCalibration) -> tuple[int, int]:
    if size is None:
        return calib.image_size
    w, h = (int(v) for v in size)
    if w < 1 or h < 1 or w > 16384 or h > 16384:
        raise ValueError(f"rectified size must be 1..16384 pixels per side, got {w}x{h}")
    if w * h > MAX_PIXELS:
        raise ValueError(f"rectified size {w}x{h} has {w * h} pixels; at most {MAX_PIXELS} (e.g. 4096x4096) fit "
                         "the maps in memory")
    return w, h


def rectified_camera(calib: StereoCalibration, R1: np.ndarray, R2: np.ndarray,
                     size: tuple[int, int] | None = None, focal: str = "mean") -> np.ndarray:
    """The common 3x3 camera matrix of both rectified images (see the module docstring, step 3)."""
    nx, ny = calib.image_size
    w, h = _parse_size(size, calib)
    fys = (calib.M1[1, 1], calib.M2[1, 1])
    if focal == "mean":
        f = 0.5 * (fys[0] + fys[1])
    elif focal == "min":
        f = min(fys)
    else:
        raise ValueError(f"focal must be 'mean' or 'min', got {focal!r}")
    f *= h / ny
    corners_x = np.array([0.0, nx - 1, 0.0, nx - 1])
    corners_y = np.array([0.0, 0.0, ny - 1, ny - 1])
    centres = []
    for M, D, Ri in ((calib.M1, calib.D1, R1), (calib.M2, calib.D2, R2)):
        yn = (corners_y - M[1, 2]) / M[1, 1]
        xn = (corners_x - M[0, 2] - M[0, 1] * yn) / M[0, 0]
        xu, yu = undistort(xn, yn, D)
        ray = Ri @ np.vstack([xu, yu, np.ones_like(xu)])
        px, py = f * ray[0] / ray[2], f * ray[1] / ray[2]
        # the principal point is placed at the calibrated size, then scaled like OpenCV does
        centres.append(((nx - 1) / 2 - px.mean() * ny / h, (ny - 1) / 2 - py.mean() * ny / h))
    cx = 0.5 * (centres[0][0] + centres[1][0]) * w / nx
    cy = 0.5 * (centres[0][1] + centres[1][1]) * h / ny
    return np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])


def backward_map(K_rect: np.ndarray, R_i: np.ndarray, M: np.ndarray, D: np.ndarray,
                 size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Source coordinates ``(map_x, map_y)``, each (height, width) float64, of one rectified camera."""
    w, h = size
    u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    # ray of each rectified pixel in the rectified frame, then in the camera's own frame
    kinv = np.linalg.inv(np.asarray(K_rect, dtype=np.float64))
    back = np.asarray(R_i, dtype=np.float64).T @ kinv
    X = back[0, 0] * u + back[0, 1] * v + back[0, 2]
    Y = back[1, 0] * u + back[1, 1] * v + back[1, 2]
    Z = back[2, 0] * u + back[2, 1] * v + back[2, 2]
    xd, yd = distort(X / Z, Y / Z, D)
    map_x = M[0, 0] * xd + M[0, 1] * yd + M[0, 2]
    map_y = M[1, 1] * yd + M[1, 2]
    return map_x, map_y


# --------------------------------------------------------------------------------------------------
# Maps


@dataclass
class Maps:
    """Backward maps of both cameras: ``left_x[y, x]`` is the source column of rectified pixel (x, y).

    ``K`` is the common rectified camera matrix, ``R1``/``R2`` the rectifying rotations, ``P1``/``P2``
    the 3x4 projection matrices (``P2[0, 3] = f * baseline_x``), ``image_width``/``image_height`` the
    size of the camera images the maps point into. All optional (maps made elsewhere may lack them).
    """

    left_x: np.ndarray
    left_y: np.ndarray
    right_x: np.ndarray
    right_y: np.ndarray
    K: np.ndarray | None = None
    R1: np.ndarray | None = None
    R2: np.ndarray | None = None
    P1: np.ndarray | None = None
    P2: np.ndarray | None = None
    image_width: int | None = None
    image_height: int | None = None
    method: str = ""

    def __post_init__(self) -> None:
        shape = None
        for k in MAP_KEYS:
            a = np.asarray(getattr(self, k))
            if a.ndim != 2 or a.size == 0:
                raise ValueError(f"map {k} must be a non-empty 2-D array, got shape {a.shape}")
            if not np.issubdtype(a.dtype, np.floating):
                raise ValueError(f"map {k} must hold floats, got {a.dtype}")
            if shape is None:
                shape = a.shape
            elif a.shape != shape:
                raise ValueError(f"map {k} has shape {a.shape} but left_x has {shape}")
            setattr(self, k, a)
        check_map_entries(self)

    @property
    def width(self) -> int:
        return int(self.left_x.shape[1])

    @property
    def height(self) -> int:
        return int(self.left_x.shape[0])

    @property
    def source_size(self) -> tuple[int, int] | None:
        """``(width, height)`` of the camera images, when known."""
        if self.image_width is None or self.image_height is None:
            return None
        return (int(self.image_width), int(self.image_height))

    def side(self, side: str) -> tuple[np.ndarray, np.ndarray]:
        """``(map_x, map_y)`` of ``"left"`` or ``"right"``."""
        if side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {side!r}")
        return getattr(self, f"{side}_x"), getattr(self, f"{side}_y")


def check_map_entries(maps: Maps) -> None:
    """ValueError, in one line, if a map of ``maps`` holds an infinite entry.

    A map entry is a source coordinate, or NaN for a rectified pixel without a source pixel (the fit skips
    it, ``warp`` makes it black, the C table writes ``INVALID``); +-inf is neither (a division by zero
    somewhere upstream) and is refused, naming each array with the count and the first position."""
    parts = []
    for k in MAP_KEYS:
        bad = np.isinf(np.asarray(getattr(maps, k)))
        n = int(np.count_nonzero(bad))
        if n:
            y, x = divmod(int(np.argmax(bad)), bad.shape[1])
            parts.append(f"map {k} holds {n} infinite entr{'y' if n == 1 else 'ies'} (the first at x={x}, y={y})")
    if parts:
        raise ValueError(f"{', '.join(parts)}: a map entry is a source coordinate, or NaN for a pixel without "
                         f"a source")


def compute_maps(calib: StereoCalibration, *, method: str = "thesis", size: tuple[int, int] | None = None,
                 focal: str = "mean", rotation: str = "bouguet") -> Maps:
    """Backward maps of both cameras for a rectified image of ``size`` (default: the calibrated size).

    ``method="thesis"``: the numpy construction of the module docstring (``focal``/``rotation`` pick
    the variants); ``method="opencv"``: ``cv2.stereoRectify`` + ``cv2.initUndistortRectifyMap``
    (OpenCV's own choices; ``focal`` and ``rotation`` must keep their defaults).
    """
    w, h = _parse_size(size, calib)
    if method == "thesis":
        R1, R2 = rectify_rotations(calib.R, calib.T, rotation)
        K = rectified_camera(calib, R1, R2, (w, h), focal)
        lx, ly = backward_map(K, R1, calib.M1, calib.D1, (w, h))
        rx, ry = backward_map(K, R2, calib.M2, calib.D2, (w, h))
    elif method == "opencv":
        if focal != "mean" or rotation != "bouguet":
            raise ValueError("method='opencv' fixes focal='mean' and rotation='bouguet'")
        R1, R2, P1, P2, _, _, _ = cv2.stereoRectify(
            calib.M1, calib.D1, calib.M2, calib.D2, calib.image_size, calib.R, calib.T.reshape(3, 1),
            flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1, newImageSize=(w, h))
        K = P1[:, :3].copy()
        lx, ly = cv2.initUndistortRectifyMap(calib.M1, calib.D1, R1, P1, (w, h), cv2.CV_32FC1)
        rx, ry = cv2.initUndistortRectifyMap(calib.M2, calib.D2, R2, P2, (w, h), cv2.CV_32FC1)
        lx, ly, rx, ry = (a.astype(np.float64) for a in (lx, ly, rx, ry))
    else:
        raise ValueError(f"method must be 'thesis' or 'opencv', got {method!r}")
    t_rect = R2 @ calib.T
    P1 = np.hstack([K, np.zeros((3, 1))])
    P2 = np.hstack([K, np.array([[K[0, 0] * t_rect[0]], [0.0], [0.0]])])
    return Maps(lx, ly, rx, ry, K=K, R1=R1, R2=R2, P1=P1, P2=P2, image_width=calib.image_width,
                image_height=calib.image_height, method=method)


def maps_for_frame(calib: StereoCalibration, R1: np.ndarray, R2: np.ndarray, K: np.ndarray,
                   size: tuple[int, int] | None = None) -> Maps:
    """Maps of ``calib``'s cameras for a *given* rectified frame (rotations ``R1``, ``R2``, camera ``K``).

    With the frame of another calibration's maps this separates lens/intrinsic errors from the choice
    of the rectified frame (which depends on the estimated baseline direction and focal lengths).
    """
    w, h = _parse_size(size, calib)
    lx, ly = backward_map(K, R1, calib.M1, calib.D1, (w, h))
    rx, ry = backward_map(K, R2, calib.M2, calib.D2, (w, h))
    return Maps(lx, ly, rx, ry, K=np.asarray(K, dtype=np.float64), R1=np.asarray(R1, dtype=np.float64),
                R2=np.asarray(R2, dtype=np.float64), image_width=calib.image_width,
                image_height=calib.image_height, method="frame")


def rectify_points(points: np.ndarray, M: np.ndarray, D: np.ndarray, R_i: np.ndarray,
                   K: np.ndarray) -> np.ndarray:
    """Forward map: distorted camera pixels ``(N, 2)`` -> rectified pixels ``(N, 2)`` (exact inverse
    of the backward map of the camera ``(M, D)`` with rotation ``R_i`` and rectified camera ``K``)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    yn = (p[:, 1] - M[1, 2]) / M[1, 1]
    xn = (p[:, 0] - M[0, 2] - M[0, 1] * yn) / M[0, 0]
    xu, yu = undistort(xn, yn, D)
    ray = (np.asarray(K, dtype=np.float64) @ np.asarray(R_i, dtype=np.float64)) @ np.vstack([xu, yu, np.ones_like(xu)])
    return (ray[:2] / ray[2]).T


def compare_up_to_frame(maps: Maps, truth: StereoCalibration, mask: dict[str, np.ndarray] | None = None,
                        ) -> dict[str, float]:
    """How well ``maps`` match the true cameras, ignoring the choice of rectified frame.

    A calibration fixes the rectified frame (rotation and common camera matrix) only as well as it
    knows the baseline direction, focal lengths and principal points; a few tenths of a pixel of
    difference there move the whole rectified image without harming it. So each source point of
    ``maps`` is sent through the *true* camera into the true rectified frame, the best homography from
    the rectified pixel grid onto those points is fitted (least squares), and what it cannot explain
    -- lens-model error -- is reported in pixels: ``{side}_mean``, ``{side}_max`` and ``mean``,
    ``max`` over both; ``{side}_raw_mean`` is the plain distance before the homography.
    """
    R1, R2 = rectify_rotations(truth.R, truth.T)
    K = rectified_camera(truth, R1, R2, (maps.width, maps.height))
    out: dict[str, float] = {}
    both = []
    for side, M, D, Ri in (("left", truth.M1, truth.D1, R1), ("right", truth.M2, truth.D2, R2)):
        mx, my = maps.side(side)
        m = np.isfinite(mx) & np.isfinite(my)
        if mask is not None:
            m &= np.asarray(mask[side], dtype=bool)
        yy, xx = np.nonzero(m)
        if len(xx) < 8:
            raise ValueError(f"too few {side} pixels to compare ({len(xx)})")
        p = np.stack([xx, yy], axis=1).astype(np.float64)
        q = rectify_points(np.stack([mx[yy, xx], my[yy, xx]], axis=1), M, D, Ri, K)
        H, _ = cv2.findHomography(p, q, 0)
        ph = cv2.perspectiveTransform(p.reshape(-1, 1, 2), H).reshape(-1, 2)
        r = np.linalg.norm(ph - q, axis=1)
        out[f"{side}_mean"] = float(r.mean())
        out[f"{side}_max"] = float(r.max())
        out[f"{side}_raw_mean"] = float(np.linalg.norm(p - q, axis=1).mean())
        both.append(r)
    r = np.concatenate(both)
    out["mean"] = float(r.mean())
    out["max"] = float(r.max())
    return out


#: Parameter groups of :func:`recovery_budget`: name -> what of the estimate is put into the truth.
BUDGET_GROUPS = ("principal points", "focal lengths", "distortion", "rotation R", "baseline direction")


def _with_group(truth: StereoCalibration, est: StereoCalibration, group: str) -> StereoCalibration:
    """``truth`` with the parameters of ``group`` taken from ``est``."""
    M1, M2, D1, D2, R, T = truth.M1.copy(), truth.M2.copy(), truth.D1, truth.D2, truth.R, truth.T
    if group == "principal points":
        M1[:2, 2], M2[:2, 2] = est.M1[:2, 2], est.M2[:2, 2]
    elif group == "focal lengths":
        M1[0, :2], M1[1, 1], M2[0, :2], M2[1, 1] = est.M1[0, :2], est.M1[1, 1], est.M2[0, :2], est.M2[1, 1]
    elif group == "distortion":
        D1, D2 = est.D1, est.D2
    elif group == "rotation R":
        R = est.R
    elif group == "baseline direction":
        T = est.T * (np.linalg.norm(truth.T) / np.linalg.norm(est.T))
    else:
        raise ValueError(f"unknown parameter group {group!r}")
    return StereoCalibration(M1, D1, M2, D2, R, T, truth.image_width, truth.image_height, 0.0)


def recovery_budget(est: StereoCalibration, truth: StereoCalibration,
                    mask: dict[str, np.ndarray] | None = None,
                    size: tuple[int, int] | None = None) -> dict[str, Any]:
    """How far the maps of an estimated calibration are from the true maps, and why.

    Over the rectified pixels of ``mask`` (per side; default all), in pixels:

    * ``raw_mean``, ``raw_max``: the plain distance between the two maps' source points;
    * ``shift``: per side, the mean vector ``estimate - truth``, and ``after_shift_mean``: the mean
      distance left once each side's own mean vector is removed. A shift that is the same on both
      sides is a translation of both rectified images (a different principal point of the common
      rectified camera): harmless for stereo, since rows and disparities stay as they are;
    * ``up_to_frame_mean``: :func:`compare_up_to_frame` (what no change of frame explains);
    * ``only``: for each of :data:`BUDGET_GROUPS`, the raw mean of the maps of the *true*
      calibration with just that group of parameters taken from ``est`` (one at a time; the
      estimation errors are correlated and partly cancel, so these do not add up to ``raw_mean``);
    * ``K_shift``: ``est``'s rectified principal point minus the true one, and ``K_shift_lens``: how
      much of it goes away when the principal point of ``est``'s frame is placed with the *true*
      lens models at the image corners (the corners are where a stereo calibration extrapolates).
    """
    size = truth.image_size if size is None else size
    a, b = compute_maps(truth, size=size), compute_maps(est, size=size)
    raw = map_difference(a, b, mask)
    out: dict[str, Any] = {"raw_mean": raw["mean"], "raw_max": raw["max"], "shift": {}}
    resid = []
    for side in ("left", "right"):
        (ax, ay), (bx, by) = a.side(side), b.side(side)
        m = np.ones(ax.shape, bool) if mask is None else np.asarray(mask[side], dtype=bool)
        dx, dy = (bx - ax)[m], (by - ay)[m]
        out["shift"][side] = (float(dx.mean()), float(dy.mean()))
        resid.append(np.hypot(dx - dx.mean(), dy - dy.mean()))
    out["after_shift_mean"] = float(np.concatenate(resid).mean())
    out["up_to_frame_mean"] = compare_up_to_frame(b, truth, mask)["mean"]
    out["only"] = {g: map_difference(a, compute_maps(_with_group(truth, est, g), size=size), mask)["mean"]
                   for g in BUDGET_GROUPS}
    lens = StereoCalibration(est.M1, truth.D1, est.M2, truth.D2, est.R, est.T, est.image_width,
                             est.image_height, 0.0)
    k_lens = rectified_camera(lens, b.R1, b.R2, size)
    out["K_shift"] = tuple(float(v) for v in b.K[:2, 2] - a.K[:2, 2])
    out["K_shift_lens"] = tuple(float(v) for v in b.K[:2, 2] - k_lens[:2, 2])
    return out


def row_alignment(maps: Maps, calib: StereoCalibration, points_left: np.ndarray,
                  points_right: np.ndarray) -> np.ndarray:
    """Vertical disparity ``y_left - y_right`` (rectified pixels) of corresponding camera points.

    ``points_left``/``points_right``: (N, 2) distorted pixel positions of the same scene points in
    both cameras; rectified with ``calib``'s lens models and ``maps``' frame. Zero for a perfect
    rectification.
    """
    if maps.K is None or maps.R1 is None or maps.R2 is None:
        raise ValueError("row_alignment needs maps that carry K, R1 and R2")
    pl = rectify_points(points_left, calib.M1, calib.D1, maps.R1, maps.K)
    pr = rectify_points(points_right, calib.M2, calib.D2, maps.R2, maps.K)
    return pl[:, 1] - pr[:, 1]


def ground_truth_maps(rig: StereoRig, *, size: tuple[int, int] | None = None) -> Maps:
    """The exact maps of a synthetic rig, from its true parameters (thesis construction)."""
    return compute_maps(rig.calibration(), method="thesis", size=size)


def map_difference(a: Maps, b: Maps, mask: np.ndarray | None = None) -> dict[str, float]:
    """Euclidean distance between the source points of two maps, over both sides (and ``mask``).

    Returns ``mean``/``max`` over both sides and ``left_mean``, ``left_max``, ``right_mean``, ``right_max``.
    """
    if (a.height, a.width) != (b.height, b.width):
        raise ValueError(f"maps of different sizes: {a.width}x{a.height} and {b.width}x{b.height}")
    out: dict[str, float] = {}
    both = []
    for side in ("left", "right"):
        ax, ay = a.side(side)
        bx, by = b.side(side)
        d = np.hypot(ax - bx, ay - by)
        if mask is not None:
            m = mask[side] if isinstance(mask, dict) else mask
            d = d[np.asarray(m, dtype=bool)]
        d = d.ravel()
        out[f"{side}_mean"] = float(d.mean())
        out[f"{side}_max"] = float(d.max())
        both.append(d)
    d = np.concatenate(both)
    out["mean"] = float(d.mean())
    out["max"] = float(d.max())
    return out


# --------------------------------------------------------------------------------------------------
# Files


def save_maps(maps: Maps, path: str | os.PathLike[str]) -> None:
    """Write ``maps.npz``: float64 ``left_x, left_y, right_x, right_y`` (height, width), plus ``K``,
    ``R1``, ``R2``, ``P1``, ``P2`` and ``image_size`` (source width, height) when known. Atomic."""
    arrays: dict[str, np.ndarray] = {k: np.asarray(getattr(maps, k), dtype=np.float64) for k in MAP_KEYS}
    for k in ("K", "R1", "R2", "P1", "P2"):
        v = getattr(maps, k)
        if v is not None:
            arrays[k] = np.asarray(v, dtype=np.float64)
    if maps.source_size is not None:
        arrays["image_size"] = np.array(maps.source_size, dtype=np.int64)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    with atomic_output(path, suffix=".npz") as tmp:
        tmp.write_bytes(buf.getvalue())


def load_maps(path: str | os.PathLike[str]) -> Maps:
    """Read a maps file written by :func:`save_maps` (or any npz with the four float map arrays).

    Map entries may be NaN (no source pixel) but not infinite (:func:`check_map_entries`); ``K``, ``R1``,
    ``R2``, ``P1``, ``P2`` must be finite. ValueError naming the file otherwise."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"maps file {p} does not exist")
    try:
        with np.load(p, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError, KeyError) as e:
        raise ValueError(f"{p} is not a readable .npz maps file ({type(e).__name__})") from None
    missing = [k for k in MAP_KEYS if k not in data]
    if missing:
        raise ValueError(f"{p}: missing map array(s) {', '.join(missing)}")
    opt: dict[str, Any] = {}
    for k, shape in (("K", (3, 3)), ("R1", (3, 3)), ("R2", (3, 3)), ("P1", (3, 4)), ("P2", (3, 4))):
        if k in data:
            if data[k].shape != shape:
                raise ValueError(f"{p}: {k} must have shape {shape}, got {data[k].shape}")
            if not np.issubdtype(data[k].dtype, np.number) or not np.all(np.isfinite(data[k])):
                raise ValueError(f"{p}: {k} must hold finite numbers")
            opt[k] = data[k].astype(np.float64)
    if "image_size" in data:
        s = data["image_size"]
        if s.shape != (2,) or not np.issubdtype(s.dtype, np.integer) or s.min() < 1:
            raise ValueError(f"{p}: image_size must be two positive integers")
        opt["image_width"], opt["image_height"] = int(s[0]), int(s[1])
    try:
        return Maps(*(data[k] for k in MAP_KEYS), **opt)
    except ValueError as e:
        raise ValueError(f"{p}: {e}") from None
