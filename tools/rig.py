"""A synthetic EyeBot-M6-like stereo rig with known parameters, and chessboard views rendered with it.

The EyeBot M6 (thesis 3.1) carries two 352x288 cameras, focal length 4.9 mm at 9 um pixels
(f = 4.9 / 0.009 = 544.4 px), 66 mm apart. :func:`eyebot_rig` builds such a rig with lens distortion
(barrel, k1 about -0.3, plus a little tangential distortion) and a small misalignment: the right
camera is turned by about 1.4 degrees relative to the left one, the baseline is slightly off the x axis
and both principal points are several pixels off the image centre. Its exact backward maps
(:func:`eyestereo.tools.rectify.ground_truth_maps`) move pixels by up to about 25 px, like the
"none" row of the thesis's Table 4.1 (docs/toolbox.md gives the figure).

:func:`render_views` draws a 9x6-inner-corner chessboard at random but sensible poses, wholly visible
in both cameras: every square and the white paper around the board are polygons whose edges (split in
8 segments, so the lens bends them) are projected with ``cv2.projectPoints`` (distortion included)
and filled at ``supersample`` times the resolution, then area-averaged down, blurred a little
(Gaussian, sigma 0.6 px) and given mild noise (sigma 1.5 grey levels). The result is a list of grey
uint8 image pairs plus the true corner positions, so calibration and maps can be checked against
ground truth.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from eyestereo.tools.calib import StereoCalibration, atomic_write_bytes, board_object_points, write_yaml
from eyestereo.tools.progress import Progress

__all__ = [
    "BOARD",
    "SQUARE",
    "RenderedViews",
    "StereoRig",
    "eyebot_rig",
    "render_views",
    "write_rig",
]

#: The board of the rendered views: inner corners (cols, rows) and square size in metres.
BOARD = (9, 6)
SQUARE = 0.02

#: EyeBot M6 optics (thesis 3.1): focal length and pixel pitch in metres, baseline in metres.
FOCAL_M = 4.9e-3
PIXEL_M = 9e-6
BASELINE_M = 0.066


@dataclass(frozen=True)
class StereoRig:
    """True parameters of a stereo rig (same meaning as :class:`~eyestereo.tools.calib.StereoCalibration`)."""

    width: int
    height: int
    M1: np.ndarray
    D1: np.ndarray
    M2: np.ndarray
    D2: np.ndarray
    R: np.ndarray
    T: np.ndarray

    def calibration(self) -> StereoCalibration:
        """The rig's truth as a calibration record (rms = 0)."""
        return StereoCalibration(self.M1, self.D1, self.M2, self.D2, self.R, self.T, self.width,
                                 self.height, 0.0)


def eyebot_rig() -> StereoRig:
    """The fixed synthetic EyeBot-like rig used by the tests, the docs and ``eyestereo rig``."""
    f = FOCAL_M / PIXEL_M  # 544.4 px
    m1 = np.array([[f * 1.003, 0.0, 183.5], [0.0, f, 137.0], [0.0, 0.0, 1.0]])
    m2 = np.array([[f * 0.996, 0.0, 168.0], [0.0, f * 0.998, 152.5], [0.0, 0.0, 1.0]])
    d1 = np.array([-0.34, 0.16, 0.0012, -0.0009, 0.0])
    d2 = np.array([-0.31, 0.12, -0.0008, 0.0011, 0.0])
    r = cv2.Rodrigues(np.array([0.012, -0.018, 0.010]))[0]
    t = np.array([-BASELINE_M, 0.0008, -0.0005])
    return StereoRig(352, 288, m1, d1, m2, d2, r, t)


@dataclass
class RenderedViews:
    """Rendered image pairs and their ground truth.

    ``left``/``right``: grey uint8 images; ``poses``: (rvec, tvec) of the board in the left camera
    frame; ``corners_left``/``corners_right``: true projected inner corners (N, 2) per view, in
    OpenCV's corner order; ``board``/``square``: the board.
    """

    left: list[np.ndarray]
    right: list[np.ndarray]
    poses: list[tuple[np.ndarray, np.ndarray]]
    corners_left: list[np.ndarray]
    corners_right: list[np.ndarray]
    board: tuple[int, int] = BOARD
    square: float = SQUARE


def _right_pose(rig: StereoRig, rvec: np.ndarray, tvec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rb = cv2.Rodrigues(rvec)[0]
    return cv2.Rodrigues(rig.R @ rb)[0].ravel(), rig.R @ tvec + rig.T


def _project(points: np.ndarray, rvec: np.ndarray, tvec: np.ndarray, M: np.ndarray, D: np.ndarray) -> np.ndarray:
    p, _ = cv2.projectPoints(points.astype(np.float64).reshape(-1, 1, 3), rvec, tvec, M, D)
    return p.reshape(-1, 2)


def _paper_outline(board: tuple[int, int], square: float, margin: float) -> np.ndarray:
    cols, rows = board
    x0, y0 = -square - margin, -square - margin
    x1, y1 = cols * square + margin, rows * square + margin
    return np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]], dtype=np.float64)


def _sample_poses(rig: StereoRig, n: int, rng: np.random.Generator, board: tuple[int, int], square: float,
                  margin_px: float = 6.0) -> list[tuple[np.ndarray, np.ndarray]]:
    cols, rows = board
    centre = np.array([(cols - 1) / 2 * square, (rows - 1) / 2 * square, 0.0])
    outline = _paper_outline(board, square, 0.5 * square)
    w, h = rig.width, rig.height
    poses: list[tuple[np.ndarray, np.ndarray]] = []
    tries = 0
    while len(poses) < n:
        tries += 1
        if tries > 20000:
            raise RuntimeError("cannot place the board in view of both cameras")
        tilt = rng.uniform(-0.55, 0.55, size=2)  # about x and y, up to ~31 degrees
        spin = rng.uniform(-0.35, 0.35)  # in-plane, up to ~20 degrees
        rb = cv2.Rodrigues(np.array([tilt[0], tilt[1], 0.0]))[0] @ cv2.Rodrigues(np.array([0.0, 0.0, spin]))[0]
        z = rng.uniform(0.32, 0.55)
        # aim the board centre at a random pixel of the left image
        px = np.array([rng.uniform(0.2, 0.8) * w, rng.uniform(0.2, 0.8) * h])
        ray = np.linalg.inv(rig.M1) @ np.array([px[0], px[1], 1.0])
        tvec = z * ray - rb @ centre
        rvec = cv2.Rodrigues(rb)[0].ravel()
        ok = True
        for (rv, tv), M, D in (((rvec, tvec), rig.M1, rig.D1), (_right_pose(rig, rvec, tvec), rig.M2, rig.D2)):
            pts = _project(outline, rv, tv, M, D)
            if (pts[:, 0].min() < margin_px or pts[:, 1].min() < margin_px or pts[:, 0].max() > w - 1 - margin_px
                    or pts[:, 1].max() > h - 1 - margin_px):
                ok = False
                break
        if ok:
            poses.append((rvec, tvec))
    return poses


def _render(rig_side: tuple[np.ndarray, np.ndarray], rvec: np.ndarray, tvec: np.ndarray, size: tuple[int, int],
            board: tuple[int, int], square: float, supersample: int, rng: np.random.Generator,
            blur: float, noise: float) -> np.ndarray:
    M, D = rig_side
    w, h = size
    s = supersample
    cols, rows = board
    hi = np.full((h * s, w * s), 80, np.uint8)  # background
    shift = 8
    segs = 8
    t = np.linspace(0.0, 1.0, segs, endpoint=False)

    def polygon(corners: np.ndarray) -> np.ndarray:
        # corners (4, 3) in the board frame -> projected, edge-subdivided polygon at the high resolution
        pts = np.concatenate([a + t[:, None] * (b - a) for a, b in zip(corners, np.roll(corners, -1, axis=0))])
        p = _project(pts, rvec, tvec, M, D)
        p = (p + 0.5) * s - 0.5
        return np.round(p * (1 << shift)).astype(np.int32).reshape(-1, 1, 2)

    cv2.fillPoly(hi, [polygon(_paper_outline(board, square, 0.5 * square))], 215, cv2.LINE_8, shift)
    black = []
    for j in range(-1, rows):
        for i in range(-1, cols):
            if (i + j) % 2 == 0:
                x0, y0 = i * square, j * square
                sq = np.array([[x0, y0, 0], [x0 + square, y0, 0], [x0 + square, y0 + square, 0],
                               [x0, y0 + square, 0]], dtype=np.float64)
                black.append(polygon(sq))
    cv2.fillPoly(hi, black, 25, cv2.LINE_8, shift)
    low = cv2.resize(hi.astype(np.float32), (w, h), interpolation=cv2.INTER_AREA)
    if blur > 0:
        low = cv2.GaussianBlur(low, (0, 0), blur)
    if noise > 0:
        low = low + rng.normal(0.0, noise, size=low.shape).astype(np.float32)
    return np.clip(np.round(low), 0, 255).astype(np.uint8)


def render_views(rig: StereoRig | None = None, n: int = 10, *, seed: int = 0, board: tuple[int, int] = BOARD,
                 square: float = SQUARE, supersample: int = 8, blur: float = 0.6, noise: float = 1.5,
                 progress: bool | None = None) -> RenderedViews:
    """Render ``n`` stereo views of a chessboard at random poses (reproducible from ``seed``)."""
    rig = eyebot_rig() if rig is None else rig
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    if supersample < 1:
        raise ValueError(f"supersample must be >= 1, got {supersample}")
    rng = np.random.default_rng(seed)
    poses = _sample_poses(rig, n, rng, board, square)
    obj = board_object_points(board, square).astype(np.float64)
    out = RenderedViews([], [], poses, [], [], tuple(board), float(square))
    size = (rig.width, rig.height)
    with Progress(n, "rendering views", force=progress) as bar:
        for rvec, tvec in poses:
            rv2, tv2 = _right_pose(rig, rvec, tvec)
            out.left.append(_render((rig.M1, rig.D1), rvec, tvec, size, board, square, supersample, rng, blur, noise))
            out.right.append(_render((rig.M2, rig.D2), rv2, tv2, size, board, square, supersample, rng, blur, noise))
            out.corners_left.append(_project(obj, rvec, tvec, rig.M1, rig.D1))
            out.corners_right.append(_project(obj, rv2, tv2, rig.M2, rig.D2))
            bar.update()
    return out


def write_rig(folder: str | os.PathLike[str], rig: StereoRig | None = None, n: int = 10, *, seed: int = 0,
              progress: bool | None = None) -> list[Path]:
    """Write ``left01.png``.. / ``right01.png``.. and the rig's true calibration ``rig_calib.yml``.

    ``folder`` is created (not its parents) after the views are rendered. Returns the written paths.
    Each file is written atomically.
    """
    rig = eyebot_rig() if rig is None else rig
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{folder} exists and is not a folder")
    if not folder.parent.is_dir():
        raise ValueError(f"cannot create {folder}: folder {folder.parent} does not exist")
    views = render_views(rig, n, seed=seed, progress=progress)
    encoded = []
    for i, (a, b) in enumerate(zip(views.left, views.right), start=1):
        for name, img in ((f"left{i:02d}.png", a), (f"right{i:02d}.png", b)):
            ok, buf = cv2.imencode(".png", img)
            if not ok:
                raise ValueError(f"cannot encode {name}")
            encoded.append((folder / name, buf.tobytes()))
    folder.mkdir(exist_ok=True)  # only now that everything is rendered
    written = []
    for path, data in encoded:
        atomic_write_bytes(path, data)
        written.append(path)
    calib_path = folder / "rig_calib.yml"
    write_yaml(rig.calibration(), calib_path)
    written.append(calib_path)
    return written
