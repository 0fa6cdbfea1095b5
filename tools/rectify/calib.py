"""Stereo calibration from chessboard image pairs (Rectification Toolbox, step 1).

The thesis calibrated the EyeBot M6 stereo rig with Bouguet's Camera Calibration Toolbox for MATLAB
(thesis 3.5, Appendix A); here OpenCV does the same job:

1. every image pair is searched for the chessboard's inner corners (``findChessboardCorners``, then
   ``cornerSubPix`` with a window sized from the corner spacing, then a least-squares fit of a blurred
   saddle to the pixels around each corner); a pair whose board is not found in
   *both* images is skipped and reported, fewer than 3 usable pairs is an error;
2. each camera is calibrated on its own (``calibrateCamera``, model k1, k2, p1, p2, k3: the thesis's
   k1, k2, k5 radial and k3, k4 tangential terms in OpenCV's order);
3. ``stereoCalibrate`` estimates the rotation ``R`` and translation ``T`` between the cameras
   (``X_right = R @ X_left + T``, ``T`` in the units of ``square``). By default it starts from step 2's
   intrinsics and **refines all parameters jointly** (``CALIB_USE_INTRINSIC_GUESS``): the stereo
   constraint then helps the intrinsics too, and the reprojection error is the maximum-likelihood one.
   ``refine=False`` keeps the per-camera intrinsics fixed (``CALIB_FIX_INTRINSIC``), as the thesis's
   two-step MATLAB procedure did.

The result is a :class:`StereoCalibration`, stored as an OpenCV FileStorage YAML file with exactly the
keys ``M1, D1, M2, D2, R, T, image_width, image_height, rms`` (:func:`write_yaml`, :func:`read_yaml`).
Every file this toolbox writes is written atomically (:func:`eyestereo.tools.io.atomic_output`): a
temporary file in the same folder, renamed over the target only when complete.
"""

from __future__ import annotations

import glob as _glob
import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from eyestereo.tools.io import atomic_output, read_image, to_grey8
from eyestereo.tools.progress import progress_bar
from eyestereo.tools.rectify.judge import judge_calibration

__all__ = [
    "YAML_KEYS",
    "StereoCalibration",
    "board_object_points",
    "calibrate_stereo",
    "expand_images",
    "find_corners",
    "parse_board",
    "read_yaml",
    "write_yaml",
]

#: The keys of a calibration file, in the order they are written.
YAML_KEYS = ("M1", "D1", "M2", "D2", "R", "T", "image_width", "image_height", "rms")

#: Distortion vector lengths OpenCV knows: (k1 k2 p1 p2), + k3, + k4 k5 k6 (rational),
#: + s1..s4 (thin prism), + tau_x tau_y (tilted sensor).
DIST_LENGTHS = (4, 5, 8, 12, 14)

#: Plausibility limits of a calibration (see ``StereoCalibration._check_plausible``): image side;
#: focal length as a multiple of the image side (a field of view of 170 .. 0.1 degrees); distortion
#: coefficients; baseline (units of the square size); reprojection error (px).
MAX_IMAGE_SIDE = 16384
#: The square size a calibration accepts (any unit: 1e-6 .. 1e6 keeps OpenCV's arithmetic sound).
SQUARE_RANGE = (1e-6, 1e6)
FOCAL_RANGE = (1 / (2 * np.tan(np.radians(85))), 1 / (2 * np.tan(np.radians(0.05))))
MAX_DISTORTION = 1e4
MAX_BASELINE = 1e6
MAX_RMS = 1e3

_SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 60, 1e-4)
_CALIB_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-9)


# --------------------------------------------------------------------------------------------------
# The calibration record


@dataclass
class StereoCalibration:
    """Intrinsics of both cameras and their relative pose.

    ``M1``/``M2``: 3x3 camera matrices; ``D1``/``D2``: distortion vectors in OpenCV's order
    ``k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]``; ``R`` (3x3), ``T`` (3,): pose of the right
    camera relative to the left, ``X_right = R @ X_left + T``; ``image_width``/``image_height``: the
    calibrated image size in pixels; ``rms``: the stereo reprojection error in pixels (0 for a
    calibration that was not estimated, e.g. the synthetic rig's truth). ``info`` holds what the
    estimation found out (pairs used and skipped, per-camera RMS); it is not stored in the YAML file.
    """

    M1: np.ndarray
    D1: np.ndarray
    M2: np.ndarray
    D2: np.ndarray
    R: np.ndarray
    T: np.ndarray
    image_width: int
    image_height: int
    rms: float = 0.0
    info: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        self.M1 = _as_matrix(self.M1, (3, 3), "M1")
        self.M2 = _as_matrix(self.M2, (3, 3), "M2")
        self.D1 = _as_dist(self.D1, "D1")
        self.D2 = _as_dist(self.D2, "D2")
        self.R = _as_rotation(self.R, "R")
        self.T = _as_vector3(self.T, "T")
        for name in ("image_width", "image_height"):
            v = getattr(self, name)
            if isinstance(v, bool) or not float(v).is_integer() or int(v) < 1:
                raise ValueError(f"{name} must be a positive integer, got {v!r}")
            setattr(self, name, int(v))
        rms = float(self.rms)
        if not np.isfinite(rms) or rms < 0:
            raise ValueError(f"rms must be a finite number >= 0, got {self.rms!r}")
        self.rms = rms
        for name in ("M1", "M2"):
            m = getattr(self, name)
            if not (m[0, 0] > 0 and m[1, 1] > 0 and abs(m[2, 2] - 1) < 1e-9
                    and np.abs(m[[1, 2, 2], [0, 0, 1]]).max() < 1e-9):
                raise ValueError(f"{name} is not a camera matrix [[fx s cx] [0 fy cy] [0 0 1]] with fx, fy > 0")
        if np.linalg.norm(self.T) == 0:
            raise ValueError("T is zero: the two cameras must not coincide")
        self._check_plausible()

    def _check_plausible(self) -> None:
        """Refuse values no camera has (they pass the shape checks and then overflow or mislead)."""
        w, h = self.image_width, self.image_height
        if w > MAX_IMAGE_SIDE or h > MAX_IMAGE_SIDE:
            raise ValueError(f"image size {w}x{h} is implausible (at most {MAX_IMAGE_SIDE} pixels per side)")
        for name in ("M1", "M2"):
            m = getattr(self, name)
            for k, (i, side, n) in {"fx": (0, "wide", w), "fy": (1, "high", h)}.items():
                lo, hi = n * FOCAL_RANGE[0], n * FOCAL_RANGE[1]
                if not lo <= m[i, i] <= hi:
                    raise ValueError(
                        f"{name}: focal length {k} = {m[i, i]:.6g} px is implausible for an image {n} px {side} "
                        f"(a field of view of 0.1 to 170 degrees needs {lo:.3g} .. {hi:.3g} px)")
            if not (-w <= m[0, 2] <= 2 * w and -h <= m[1, 2] <= 2 * h):
                raise ValueError(f"{name}: principal point ({m[0, 2]:.6g}, {m[1, 2]:.6g}) lies implausibly far "
                                 f"outside the {w}x{h} image")
            if abs(m[0, 1]) > m[0, 0]:
                raise ValueError(f"{name}: skew {m[0, 1]:.6g} is implausible (larger than fx)")
        for name in ("D1", "D2"):
            d = getattr(self, name)
            if np.abs(d).max() > MAX_DISTORTION:
                raise ValueError(f"{name}: distortion coefficient {d[np.argmax(np.abs(d))]:.6g} is implausible "
                                 f"(|k| <= {MAX_DISTORTION:g})")
        if np.linalg.norm(self.T) > MAX_BASELINE:
            raise ValueError(f"T: a baseline of {np.linalg.norm(self.T):.6g} is implausible (at most {MAX_BASELINE:g} "
                             "units of the square size)")
        if self.rms > MAX_RMS:
            raise ValueError(f"rms {self.rms:.6g} px is implausible (at most {MAX_RMS:g})")

    @property
    def image_size(self) -> tuple[int, int]:
        """``(width, height)`` as OpenCV wants sizes."""
        return (self.image_width, self.image_height)

    @property
    def baseline(self) -> float:
        """Distance between the optical centres, in the units of ``T``."""
        return float(np.linalg.norm(self.T))


def _numeric(a: Any, name: str, what: str) -> np.ndarray:
    """``a`` as a float64 array, or a one-line ValueError naming ``name``."""
    try:
        return np.array(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} is not a numeric {what}") from None


def _finite(x: np.ndarray, name: str) -> np.ndarray:
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return x


def _as_matrix(a: Any, shape: tuple[int, int], name: str) -> np.ndarray:
    m = _numeric(a, name, "matrix")
    if m.shape != shape:
        raise ValueError(f"{name} must be {shape[0]}x{shape[1]}, got shape {m.shape}")
    return _finite(m, name)


def _as_dist(a: Any, name: str) -> np.ndarray:
    d = _numeric(a, name, "vector")
    if d.ndim > 2 or (d.ndim == 2 and 1 not in d.shape):
        raise ValueError(f"{name} must be a vector (1xN or Nx1), got shape {d.shape}")
    d = d.ravel()
    if d.size not in DIST_LENGTHS:
        raise ValueError(f"{name} must have 4, 5, 8, 12 or 14 coefficients, got {d.size}")
    return _finite(d, name)


def _as_vector3(a: Any, name: str) -> np.ndarray:
    v = _numeric(a, name, "vector")
    if v.size != 3 or (v.ndim == 2 and 1 not in v.shape) or v.ndim > 2:
        raise ValueError(f"{name} must have 3 elements (3x1 or 1x3), got shape {v.shape}")
    return _finite(v.ravel(), name)


def _as_rotation(a: Any, name: str) -> np.ndarray:
    r = _numeric(a, name, "matrix")
    if r.size == 3 and r.ndim <= 2:  # a rotation vector (Rodrigues), as some tools store it
        r = cv2.Rodrigues(_as_vector3(r, name))[0]
    if r.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 rotation matrix (or a 3-element rotation vector), got shape {r.shape}")
    _finite(r, name)
    if np.abs(r @ r.T - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0:
        raise ValueError(f"{name} is not a rotation matrix (R R^T != I or det(R) < 0)")
    return r


# --------------------------------------------------------------------------------------------------
# YAML


def write_yaml(calib: StereoCalibration, path: str | os.PathLike[str]) -> None:
    """Store ``calib`` as an OpenCV FileStorage file (YAML unless ``path`` ends in .xml or .json).

    Keys: ``M1, D1, M2, D2, R`` (``!!opencv-matrix``, D as 1xN), ``T`` (3x1), ``image_width``,
    ``image_height`` (integers), ``rms`` (real). Written atomically.
    """
    suffix = Path(path).suffix.lower()
    with atomic_output(path, suffix=suffix if suffix in (".yml", ".yaml", ".xml", ".json") else ".yml") as tmp:
        fs = cv2.FileStorage(str(tmp), cv2.FILE_STORAGE_WRITE)
        if not fs.isOpened():
            raise ValueError(f"cannot open {path} for writing")
        try:
            fs.write("M1", calib.M1)
            fs.write("D1", calib.D1.reshape(1, -1))
            fs.write("M2", calib.M2)
            fs.write("D2", calib.D2.reshape(1, -1))
            fs.write("R", calib.R)
            fs.write("T", calib.T.reshape(3, 1))
            fs.write("image_width", int(calib.image_width))
            fs.write("image_height", int(calib.image_height))
            fs.write("rms", float(calib.rms))
        finally:
            fs.release()


def read_yaml(path: str | os.PathLike[str]) -> StereoCalibration:
    """Read a calibration file written by :func:`write_yaml` or by other tools.

    Matrices may be ``!!opencv-matrix`` nodes or plain sequences; D may be 1xN or Nx1 (N = 4, 5, 8,
    12, 14), T 3x1 or 1x3, R a 3x3 matrix or a rotation vector. Anything missing or malformed raises
    a ``ValueError`` with a one-line message naming the file and the key.
    """
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"calibration file {p} does not exist")
    try:
        fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    except (cv2.error, SystemError):  # OpenCV's parser reports syntax errors either way
        fs = None
    if fs is None or not fs.isOpened():
        raise ValueError(f"{p} is not an OpenCV YAML/XML calibration file (cannot parse it)")
    try:
        values: dict[str, Any] = {}
        for key in YAML_KEYS:
            node = fs.getNode(key)
            if node.empty() or node.isNone():
                raise ValueError(f"{p}: key '{key}' is missing")
            values[key] = _read_node(node, key, p)
    finally:
        fs.release()
    try:
        return StereoCalibration(**values)
    except ValueError as e:
        raise ValueError(f"{p}: {e}") from None


def _read_node(node: Any, key: str, p: Path) -> Any:
    if key in ("image_width", "image_height", "rms"):
        if not (node.isInt() or node.isReal()):
            raise ValueError(f"{p}: key '{key}' must be a number")
        return node.real()
    if node.isMap():
        try:
            mat = node.mat()
        except (cv2.error, SystemError):
            raise ValueError(f"{p}: key '{key}' is a malformed matrix (rows x cols != number of values)") from None
        if mat is None:
            raise ValueError(f"{p}: key '{key}' is not a matrix")
        return np.asarray(mat, dtype=np.float64)
    if node.isSeq():
        vals = []
        for i in range(node.size()):
            item = node.at(i)
            if item.isSeq():  # nested rows
                row = []
                for j in range(item.size()):
                    sub = item.at(j)
                    if not (sub.isInt() or sub.isReal()):
                        raise ValueError(f"{p}: key '{key}' holds a non-number")
                    row.append(sub.real())
                vals.append(row)
            elif item.isInt() or item.isReal():
                vals.append(item.real())
            else:
                raise ValueError(f"{p}: key '{key}' holds a non-number")
        try:
            arr = np.array(vals, dtype=np.float64)
        except ValueError:
            raise ValueError(f"{p}: key '{key}' has rows of different lengths") from None
        if key in ("M1", "M2", "R") and arr.ndim == 1 and arr.size == 9:
            arr = arr.reshape(3, 3)
        return arr
    raise ValueError(f"{p}: key '{key}' must be a matrix or a sequence of numbers")


# --------------------------------------------------------------------------------------------------
# Corner detection


def parse_board(text: str) -> tuple[int, int]:
    """``"9x6"`` -> ``(9, 6)``: inner corners per row and per column, each 3..100 (OpenCV's finder needs
    more than 2)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", str(text))
    if m is None:
        raise ValueError(f"board must be COLSxROWS inner corners, e.g. 9x6; got {text!r}")
    cols, rows = int(m.group(1)), int(m.group(2))
    if cols < 3 or rows < 3 or cols > 100 or rows > 100:
        raise ValueError(f"board needs 3..100 inner corners per side, got {cols}x{rows}")
    if cols == rows:
        raise ValueError(f"a square board ({cols}x{rows}) has an ambiguous orientation; use e.g. 9x6")
    return cols, rows


def board_object_points(board: tuple[int, int], square: float) -> np.ndarray:
    """The board's inner corners in its own frame (z = 0), in OpenCV's row-major corner order."""
    cols, rows = board
    if not SQUARE_RANGE[0] <= square <= SQUARE_RANGE[1]:
        raise ValueError(f"square size must lie in {SQUARE_RANGE[0]:g} .. {SQUARE_RANGE[1]:g} (any unit), got {square}")
    obj = np.zeros((rows * cols, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square
    return obj


def _saddle_refine(gray: np.ndarray, corners: np.ndarray, board: tuple[int, int], spacing: float,
                   iterations: int = 20) -> np.ndarray:
    """Refine chessboard corners by fitting a blurred saddle to the pixels around each one.

    Around each corner (a disc of radius 45 % of the smallest corner spacing, at least 3 px) the grey
    values are fitted, by least squares (batched Levenberg-Marquardt), with the model
    ``a + b tanh(d1 / s) tanh(d2 / s)``: ``d1``, ``d2`` are the signed distances to the two board lines
    through the corner (angles free), ``s`` the edge width. The model is evaluated at the same pixel
    centres as the data, so it has none of the pixel-locking of ``cornerSubPix``'s gradient equations,
    and, being point-symmetric about the corner like the blurred image, it leaves no bias from its
    profile shape. A corner whose fit fails or moves more than 1 px keeps its ``cornerSubPix``
    position. Returns ``(N, 1, 2)`` float32.
    """
    img = np.asarray(gray, np.float64)
    h, w = img.shape
    cols, rows = board
    c = np.asarray(corners, np.float64).reshape(rows, cols, 2)
    along_row, along_col = np.gradient(c, axis=1).reshape(-1, 2), np.gradient(c, axis=0).reshape(-1, 2)
    c = c.reshape(-1, 2)
    n = len(c)
    r = max(3.0, 0.45 * spacing)
    off = np.arange(-int(np.ceil(r)) - 1, int(np.ceil(r)) + 2)
    oy, ox = (v.ravel() for v in np.meshgrid(off, off, indexing="ij"))
    base = np.round(c).astype(int)
    xi, yi = base[:, :1] + ox, base[:, 1:] + oy
    wgt = (((xi - c[:, :1]) ** 2 + (yi - c[:, 1:]) ** 2 <= r * r) & (xi >= 0) & (xi < w) & (yi >= 0)
           & (yi < h)).astype(np.float64)
    data = img[np.clip(yi, 0, h - 1), np.clip(xi, 0, w - 1)]
    X, Y = xi.astype(np.float64), yi.astype(np.float64)
    # start: the lines along the grid's rows and columns (angles of their normals), s = 0.9 px,
    # a and b by linear least squares
    th1 = np.arctan2(along_row[:, 1], along_row[:, 0]) + np.pi / 2
    th2 = np.arctan2(along_col[:, 1], along_col[:, 0]) + np.pi / 2
    p = np.stack([c[:, 0], c[:, 1], th1, th2, np.full(n, 0.9), np.zeros(n), np.ones(n)], axis=1)

    def terms(p: np.ndarray) -> tuple[np.ndarray, ...]:
        x0, y0, t1, t2, sw = (p[:, k:k + 1] for k in range(5))
        dx, dy = X - x0, Y - y0
        d1 = dx * np.cos(t1) + dy * np.sin(t1)
        d2 = dx * np.cos(t2) + dy * np.sin(t2)
        return dx, dy, d1, d2, np.tanh(d1 / sw), np.tanh(d2 / sw)

    _, _, _, _, e1, e2 = terms(p)
    e = e1 * e2
    sw_, se, see = wgt.sum(1), (wgt * e).sum(1), (wgt * e * e).sum(1)
    si, sei = (wgt * data).sum(1), (wgt * e * data).sum(1)
    det = sw_ * see - se * se
    ok = np.abs(det) > 1e-9
    p[ok, 5] = (see * si - se * sei)[ok] / det[ok]
    p[ok, 6] = (sw_ * sei - se * si)[ok] / det[ok]

    def residual_jacobian(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dx, dy, d1, d2, e1, e2 = terms(p)
        t1, t2, sw, a, b = (p[:, k:k + 1] for k in range(2, 7))
        g1, g2 = (1 - e1 * e1) / sw, (1 - e2 * e2) / sw
        c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
        jac = np.empty(X.shape + (7,))
        jac[..., 0] = -b * (g1 * c1 * e2 + e1 * g2 * c2)
        jac[..., 1] = -b * (g1 * s1 * e2 + e1 * g2 * s2)
        jac[..., 2] = b * g1 * (dy * c1 - dx * s1) * e2
        jac[..., 3] = b * e1 * g2 * (dy * c2 - dx * s2)
        jac[..., 4] = -b * (g1 * d1 * e2 + e1 * g2 * d2) / sw
        jac[..., 5] = 1.0
        jac[..., 6] = e1 * e2
        return a + b * e1 * e2 - data, jac

    res, jac = residual_jacobian(p)
    cost = (wgt * res * res).sum(1)
    lam = np.full(n, 1e-3)
    eye = np.eye(7)
    for _ in range(iterations):
        jw = jac * wgt[..., None]
        A = np.einsum("npi,npj->nij", jw, jac)
        g = np.einsum("npi,np->ni", jw, res)
        diag = np.maximum(np.einsum("nii->ni", A), 1e-12)
        try:
            step = np.linalg.solve(A + lam[:, None, None] * eye * diag[:, :, None], -g[..., None])[..., 0]
        except np.linalg.LinAlgError:
            break
        trial = p + step
        trial[:, 4] = np.maximum(trial[:, 4], 0.2)
        r2, j2 = residual_jacobian(trial)
        c2 = (wgt * r2 * r2).sum(1)
        better = np.isfinite(c2) & (c2 < cost)
        p[better], res[better], jac[better], cost[better] = trial[better], r2[better], j2[better], c2[better]
        lam = np.where(better, lam * 0.3, lam * 10.0)
    out = p[:, :2]
    keep = ~np.all(np.isfinite(out), axis=1) | (np.linalg.norm(out - c, axis=1) > 1.0)
    out[keep] = c[keep]
    return out.reshape(-1, 1, 2).astype(np.float32)


#: Corner refinements of :func:`find_corners`.
CORNER_REFINEMENTS = ("saddle", "subpix")


def find_corners(gray: np.ndarray, board: tuple[int, int], refine: str = "saddle") -> np.ndarray | None:
    """Sub-pixel inner corners ``(N, 1, 2)`` float32 of ``board`` in a grey image, or None.

    The corners of ``findChessboardCorners`` are refined by ``cornerSubPix``, with a half-window of
    40 % of the smallest corner spacing, clipped to 3..11 px, so small boards (the 352x288 EyeBot
    images) do not pull neighbouring corners into the window. ``refine="saddle"`` (default) then fits
    a blurred saddle to the pixels around each corner (:func:`_saddle_refine`), which is several
    times more accurate (on the synthetic rig 0.009 px RMS instead of 0.048 px); ``"subpix"`` stops
    after ``cornerSubPix``.
    """
    if refine not in CORNER_REFINEMENTS:
        raise ValueError(f"refine must be one of {CORNER_REFINEMENTS}, got {refine!r}")
    gray = np.asarray(gray)
    if gray.ndim != 2 or gray.dtype != np.uint8:
        raise ValueError(f"find_corners wants a 2-D uint8 grey image, got {gray.dtype} {gray.shape}")
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    if min(gray.shape) < 4 * min(board) or max(gray.shape) < 4 * max(board):
        return None  # too small to hold the board (and OpenCV's finder asserts on tiny images)
    try:
        ok, corners = cv2.findChessboardCorners(gray, board, flags=flags)
    except cv2.error:  # OpenCV refuses some degenerate images outright: no board there
        return None
    if not ok or corners is None or len(corners) != board[0] * board[1]:
        return None
    grid = corners.reshape(board[1], board[0], 2)
    spacing = min(np.linalg.norm(np.diff(grid, axis=0), axis=2).min(),
                  np.linalg.norm(np.diff(grid, axis=1), axis=2).min())
    half = int(np.clip(round(0.4 * spacing), 3, 11))
    corners = cv2.cornerSubPix(gray, corners, (half, half), (-1, -1), _SUBPIX_CRITERIA)
    if refine == "saddle":
        corners = _saddle_refine(gray, corners, board, float(spacing))
    return corners


def expand_images(spec: str | os.PathLike[str] | Sequence[Any], side: str) -> list[Any]:
    """A glob pattern -> sorted list of paths (ValueError if none); sequences are returned as lists."""
    if isinstance(spec, (str, os.PathLike)):
        paths = sorted(_glob.glob(os.fspath(spec)))
        if not paths:
            raise ValueError(f"no {side} images match {os.fspath(spec)!r}")
        return paths
    items = list(spec)
    if not items:
        raise ValueError(f"no {side} images given")
    return items


def _load_gray(item: Any) -> tuple[np.ndarray, str]:
    if isinstance(item, np.ndarray):
        return to_grey8(item, "image <array>"), "<array>"
    name = os.fspath(item)
    return to_grey8(read_image(name, grey=True), f"image {name}"), name


# --------------------------------------------------------------------------------------------------
# Calibration


def calibrate_stereo(left: str | Sequence[Any], right: str | Sequence[Any], *,
                     board: tuple[int, int] = (9, 6), square: float = 0.025, refine: bool = True,
                     log: Callable[[str], None] | None = None,
                     progress: bool | None = None, judge: bool = True) -> StereoCalibration:
    """Calibrate a stereo rig from chessboard image pairs.

    ``left``/``right``: glob patterns (sorted, paired in order), lists of paths or lists of grey
    uint8 arrays. ``board``: inner corners (cols, rows); ``square``: square size (the unit of ``T``).
    ``refine``: refine the intrinsics in the stereo step (default) or keep the per-camera ones.
    ``log`` receives one line per skipped pair. Raises ValueError on unreadable or damaged images,
    mixed image sizes, unequal list lengths, identical left and right images, or fewer than 3 pairs
    with the board found in both images; with ``judge`` (default) the result is checked by
    :func:`eyestereo.tools.rectify.judge.judge_calibration` (a
    :class:`~eyestereo.tools.rectify.judge.CalibrationProblem` names the camera and the remedy) and
    ``info["notes"]`` holds its notes.
    """
    lefts = expand_images(left, "left")
    rights = expand_images(right, "right")
    if len(lefts) != len(rights):
        raise ValueError(f"{len(lefts)} left images but {len(rights)} right images: they must pair up")
    obj = board_object_points(board, square)
    objpoints: list[np.ndarray] = []
    pts_l: list[np.ndarray] = []
    pts_r: list[np.ndarray] = []
    used: list[tuple[str, str]] = []
    skipped: list[tuple[str, str, str]] = []
    size: tuple[int, int] | None = None
    with progress_bar(len(lefts), "chessboard corners", force=progress) as bar:
        for a, b in zip(lefts, rights):
            (ga, na), (gb, nb) = _load_gray(a), _load_gray(b)
            for g, n in ((ga, na), (gb, nb)):
                s = (g.shape[1], g.shape[0])
                if size is None:
                    size = s
                elif s != size:
                    raise ValueError(f"image {n} is {s[0]}x{s[1]} but the first image is {size[0]}x{size[1]}")
            if ga.shape == gb.shape and np.array_equal(ga, gb):
                raise ValueError(f"the left and right images of a pair are identical ({Path(na).name} / "
                                 f"{Path(nb).name}): give each camera's own images")
            ca, cb = find_corners(ga, board), find_corners(gb, board)
            bar.update()
            if ca is None or cb is None:
                if ca is None and cb is None:
                    where = "either image"
                else:
                    where = "the left image" if ca is None else "the right image"
                reason = f"{board[0]}x{board[1]} board not found in {where}"
                skipped.append((na, nb, reason))
                if log is not None:
                    log(f"skipped pair {Path(na).name} / {Path(nb).name}: {reason}")
                continue
            # findChessboardCorners may start at either end of the (180-degree symmetric) grid;
            # the two views of one pair must list the corners in the same order.
            va, vb = ca[-1, 0] - ca[0, 0], cb[-1, 0] - cb[0, 0]
            if float(np.dot(va, vb)) < 0:
                cb = cb[::-1].copy()
            objpoints.append(obj)
            pts_l.append(ca)
            pts_r.append(cb)
            used.append((na, nb))
    if len(used) < 3:
        raise ValueError(f"the {board[0]}x{board[1]} board was found in both images of only {len(used)} "
                         f"of {len(lefts)} pairs; at least 3 are needed")
    assert size is not None
    rms1, m1, d1, _, tv1, sd1 = _calibrate_one(objpoints, pts_l, size)
    rms2, m2, d2, _, _, sd2 = _calibrate_one(objpoints, pts_r, size)
    flags = cv2.CALIB_USE_INTRINSIC_GUESS if refine else cv2.CALIB_FIX_INTRINSIC
    try:
        rms, m1, d1, m2, d2, r, t, _, _ = cv2.stereoCalibrate(
            objpoints, pts_l, pts_r, m1, d1, m2, d2, size, flags=flags, criteria=_CALIB_CRITERIA)
    except cv2.error as e:
        raise ValueError(f"the stereo calibration failed ({_cv_reason(e)}): use more views, with the board in "
                         "different positions and angles") from None
    if not np.isfinite(rms):
        raise ValueError("stereo calibration did not converge")
    try:
        calib = StereoCalibration(m1, d1, m2, d2, r, t, size[0], size[1], rms)
    except ValueError as e:
        raise ValueError(f"the calibration failed ({e}): add views with the board in more positions") from None
    calib.info.update(used=used, skipped=skipped, rms_left=float(rms1), rms_right=float(rms2),
                      refine=refine, board=tuple(board), square=float(square),
                      points_left=pts_l, points_right=pts_r,
                      board_distance=float(np.median([np.linalg.norm(v) for v in tv1])),
                      focal_spread_left=float(sd1[0] / m1[0, 0]), focal_spread_right=float(sd2[0] / m2[0, 0]))
    if judge:
        calib.info["notes"] = judge_calibration(calib, where="calibration refused")
    return calib


def _cv_reason(e: Exception) -> str:
    """What an OpenCV exception of the calibration means to the user (its assertion text would not help)."""
    return "OpenCV found the views degenerate"


def _calibrate_one(objpoints: list[np.ndarray], points: list[np.ndarray], size: tuple[int, int]) -> tuple:
    """One camera: (rms, M, D, rvecs, tvecs, standard deviations of fx, fy, cx, cy, k1, ...)."""
    try:
        rms, m, d, rv, tv, sd, _, _ = cv2.calibrateCameraExtended(objpoints, points, size, None, None,
                                                                   criteria=_CALIB_CRITERIA)
    except cv2.error as e:
        raise ValueError(f"the calibration failed ({_cv_reason(e)}): use more views, with the board in "
                         "different positions and angles") from None
    sd = np.asarray(sd, np.float64).ravel()
    sd = np.where(np.isfinite(sd), sd, np.inf)
    return rms, m, d, rv, tv, sd
