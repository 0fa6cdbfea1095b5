"""A synthetic EyeBot-M6-like stereo rig with known parameters, and chessboard views rendered with it.

The EyeBot M6 (thesis 3.1) carries two 352x288 cameras, focal length 4.9 mm at 9 um pixels
(f = 4.9 / 0.009 = 544.4 px), 66 mm apart. :func:`eyebot_rig` builds such a rig with lens distortion
(barrel, k1 about -0.3, plus a little tangential distortion) and a small misalignment: the right
camera is turned by about 1.4 degrees relative to the left one, the baseline is slightly off the x axis
and both principal points are several pixels off the image centre. Its exact backward maps
(:func:`eyestereo.tools.rectify.maps.ground_truth_maps`) move pixels by up to about 25 px, like the
"none" row of the thesis's Table 4.1 (docs/toolbox.md gives the figure).

:func:`render_views` draws a 9x6-inner-corner chessboard at random but sensible poses, wholly visible
in both cameras: every square and the white paper around the board are polygons whose edges (split in
8 segments, so the lens bends them) are projected with ``cv2.projectPoints`` (distortion included);
each pixel gets the exact area of the polygons over it (``supersample=k``: the old fillPoly at k times
the resolution, area-averaged down), then the image is blurred a little
(Gaussian, sigma 0.6 px) and given mild noise (sigma 1.5 grey levels). The result is a list of grey
uint8 image pairs plus the true corner positions, so calibration and maps can be checked against
ground truth. ``layout="cover"`` spreads the boards over the whole field of view of both cameras
(corners, edges, several depths and tilts) instead of the middle of the image; :func:`coverage_masks`
gives the rectified pixels whose source some board covered.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from eyestereo.tools.io import Outputs
from eyestereo.tools.rectify.calib import StereoCalibration, board_object_points, write_yaml
from eyestereo.tools.progress import progress_bar

__all__ = [
    "BOARD",
    "COVER_TARGETS",
    "LAYOUTS",
    "SQUARE",
    "RenderedViews",
    "StereoRig",
    "coverage_masks",
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


class StereoRig(StereoCalibration):
    """True parameters of a stereo rig: a :class:`~eyestereo.tools.rectify.calib.StereoCalibration` (same
    arrays, same meaning) with rms 0, built from the image size first; ``width``/``height`` name that size."""

    def __init__(self, width: int, height: int, M1: np.ndarray, D1: np.ndarray, M2: np.ndarray,
                 D2: np.ndarray, R: np.ndarray, T: np.ndarray) -> None:
        super().__init__(M1, D1, M2, D2, R, T, width, height, 0.0)

    @property
    def width(self) -> int:
        return self.image_width

    @property
    def height(self) -> int:
        return self.image_height

    def calibration(self) -> StereoCalibration:
        """The rig's truth as a plain calibration record (rms = 0)."""
        return StereoCalibration(self.M1, self.D1, self.M2, self.D2, self.R, self.T, self.width, self.height, 0.0)


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


def _pose_ok(rig: StereoRig, rvec: np.ndarray, tvec: np.ndarray, outline: np.ndarray,
             margin_px: float) -> bool:
    """Whether the paper ``outline`` lies wholly inside both images, ``margin_px`` from the border."""
    w, h = rig.width, rig.height
    for (rv, tv), M, D in (((rvec, tvec), rig.M1, rig.D1), (_right_pose(rig, rvec, tvec), rig.M2, rig.D2)):
        pts = _project(outline, rv, tv, M, D)
        if (pts[:, 0].min() < margin_px or pts[:, 1].min() < margin_px or pts[:, 0].max() > w - 1 - margin_px
                or pts[:, 1].max() > h - 1 - margin_px):
            return False
    return True


def _board_rotation(rng: np.random.Generator, tilt: float, spin: float) -> np.ndarray:
    t = rng.uniform(-tilt, tilt, size=2)  # about x and y
    s = rng.uniform(-spin, spin)  # in-plane
    return cv2.Rodrigues(np.array([t[0], t[1], 0.0]))[0] @ cv2.Rodrigues(np.array([0.0, 0.0, s]))[0]


def _draw_poses(n: int, max_tries: int, why: str, propose) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` poses from ``propose(i)`` (a pose for view ``i``, or None to draw again), a RuntimeError
    ``why`` after ``max_tries`` draws."""
    poses: list[tuple[np.ndarray, np.ndarray]] = []
    for _ in range(max_tries):
        if len(poses) == n:
            break
        pose = propose(len(poses))
        if pose is not None:
            poses.append(pose)
    if len(poses) < n:
        raise RuntimeError(why)
    return poses


def _aim(M: np.ndarray, px: np.ndarray, z: float, rb: np.ndarray, board: tuple[int, int],
         square: float) -> np.ndarray:
    """The translation that puts the centre of the board (rotated by ``rb``) at depth ``z`` on the ray of
    pixel ``px`` of the camera with matrix ``M``."""
    cols, rows = board
    centre = np.array([(cols - 1) / 2 * square, (rows - 1) / 2 * square, 0.0])
    return z * (np.linalg.inv(M) @ np.array([px[0], px[1], 1.0])) - rb @ centre


def _sample_poses(rig: StereoRig, n: int, rng: np.random.Generator, board: tuple[int, int], square: float,
                  margin_px: float = 6.0) -> list[tuple[np.ndarray, np.ndarray]]:
    outline = _paper_outline(board, square, 0.5 * square)
    w, h = rig.width, rig.height

    def propose(_i):
        rb = _board_rotation(rng, 0.55, 0.35)  # tilted up to ~31 degrees, turned up to ~20 degrees
        z = rng.uniform(0.32, 0.55)
        # aim the board centre at a random pixel of the left image
        px = np.array([rng.uniform(0.2, 0.8) * w, rng.uniform(0.2, 0.8) * h])
        tvec = _aim(rig.M1, px, z, rb, board, square)
        rvec = cv2.Rodrigues(rb)[0].ravel()
        return (rvec, tvec) if _pose_ok(rig, rvec, tvec, outline, margin_px) else None

    return _draw_poses(n, 20000, "cannot place the board in view of both cameras", propose)


#: Targets of the "cover" layout, in this order: (camera 0 = left / 1 = right, x, y as fractions of
#: the image). Each view's board must cover its target point (the convex hull of its inner corners
#: contains it). A stereo pair cannot cover the left camera's left edge or the right camera's right
#: edge (the other camera does not see that far), so the corners are targeted in the camera that can
#: reach them: the left camera's right-hand corners, the right camera's left-hand ones.
COVER_TARGETS = ((0, 0.85, 0.15), (1, 0.15, 0.85), (0, 0.85, 0.85), (1, 0.15, 0.15), (0, 0.5, 0.5),
                 (0, 0.5, 0.15), (1, 0.5, 0.85), (0, 0.85, 0.5), (1, 0.15, 0.5))
LAYOUTS = ("random", "cover")
COVER_FAR = 1.0  # farthest board of the "cover" layout, metres (the nearest: 0.32)
COVER_MIN_SPACING = 11.0  # closer corners (px) are redrawn: findChessboardCorners gets unreliable
COVER_PAPER = 0.75  # white paper around the squares, in squares (0.5 for "random"; thinner misleads
#                     findChessboardCorners at an outer corner of far boards now and then)


def _sample_cover_poses(rig: StereoRig, n: int, rng: np.random.Generator, board: tuple[int, int],
                        square: float, margin_px: float = 6.0, paper: float | None = None
                        ) -> list[tuple[np.ndarray, np.ndarray]]:
    """Poses that spread over the whole field of view: view ``i`` covers ``COVER_TARGETS[i % 9]``
    (corners, edge midpoints, centre), at 0.32..1.0 m, tilted by up to 34 degrees about x and y and
    turned by up to 20 degrees in the image plane; the paper wholly visible in both cameras; corners
    at least ``COVER_MIN_SPACING`` px apart."""
    cols, rows = board
    outline = _paper_outline(board, square, (COVER_PAPER if paper is None else paper) * square)
    obj = board_object_points(board, square).astype(np.float64)
    w, h = rig.width, rig.height

    def propose(i):
        cam, fx, fy = COVER_TARGETS[i % len(COVER_TARGETS)]
        target = (fx * (w - 1), fy * (h - 1))
        rb = _board_rotation(rng, 0.6, 0.35)
        z = rng.uniform(0.32, COVER_FAR)
        half = 0.5 * cols * square * rig.M1[0, 0] / z  # half the board's width in pixels
        px = np.array([fx * w, fy * h]) + rng.uniform(-half, half, size=2)
        M = rig.M1 if cam == 0 else rig.M2
        tvec = _aim(M, px, z, rb, board, square)
        if cam == 1:  # placed in the right camera's frame: X_left = R^T (X_right - T)
            rb, tvec = rig.R.T @ rb, rig.R.T @ (tvec - rig.T)
        rvec = cv2.Rodrigues(rb)[0].ravel()
        if not _pose_ok(rig, rvec, tvec, outline, margin_px):
            return None
        rv, tv = (rvec, tvec) if cam == 0 else _right_pose(rig, rvec, tvec)
        pts = _project(obj, rv, tv, M, rig.D1 if cam == 0 else rig.D2)
        hull = cv2.convexHull(pts.astype(np.float32))
        if cv2.pointPolygonTest(hull, (float(target[0]), float(target[1])), False) < 0:
            return None
        grid = pts.reshape(rows, cols, 2)
        spacing = min(np.linalg.norm(np.diff(grid, axis=0), axis=2).min(),
                      np.linalg.norm(np.diff(grid, axis=1), axis=2).min())
        if spacing < COVER_MIN_SPACING:  # too small to be found reliably
            return None
        return rvec, tvec

    return _draw_poses(n, 200000, "cannot place the board to cover the field of view of both cameras", propose)


def _area_coverage(polys: list[np.ndarray], size: tuple[int, int]) -> np.ndarray:
    """Exact area coverage (0..1) of each pixel by non-overlapping polygons ((k, 2) float vertices).

    Pixel ``(i, j)`` covers ``[j - 0.5, j + 0.5] x [i - 0.5, i + 0.5]`` (OpenCV's convention: centres at
    integers). Every edge is cut where it crosses a pixel row or column; each piece adds its signed
    trapezoid area to an accumulation buffer, whose running sum along the rows is the covered area
    (the scanline accumulation of anti-aliasing font rasterisers). Exact up to rounding.
    """
    w, h = size
    acc = np.zeros((h, w + 2), np.float64)
    a = np.concatenate(polys) + 0.5  # pixel j covers [j, j + 1) in these coordinates
    b = np.concatenate([np.roll(p, -1, axis=0) for p in polys]) + 0.5
    d = b - a
    n = len(a)
    ts, segs = [np.zeros(n), np.ones(n)], [np.arange(n), np.arange(n)]
    for k in (0, 1):  # where each edge crosses an integer x (k = 0) or y (k = 1)
        lo = np.floor(np.minimum(a[:, k], b[:, k])) + 1
        hi = np.ceil(np.maximum(a[:, k], b[:, k])) - 1
        cnt = np.maximum(hi - lo + 1, 0).astype(int)
        seg = np.repeat(np.arange(n), cnt)
        first = np.repeat(np.cumsum(cnt) - cnt, cnt)
        v = lo[seg] + (np.arange(cnt.sum()) - first)
        ts.append((v - a[seg, k]) / d[seg, k])
        segs.append(seg)
    t, s = np.concatenate(ts), np.concatenate(segs)
    order = np.lexsort((t, s))
    t, s = t[order], s[order]
    same = (s[1:] == s[:-1]) & (t[1:] > t[:-1])
    t0, t1, s = t[:-1][same], t[1:][same], s[:-1][same]
    p0, p1 = a[s] + t0[:, None] * d[s], a[s] + t1[:, None] * d[s]
    mid = 0.5 * (p0 + p1)  # each piece lies within one pixel
    col, row = np.floor(mid[:, 0]).astype(int), np.floor(mid[:, 1]).astype(int)
    dy, frac = p1[:, 1] - p0[:, 1], mid[:, 0] - col
    ok = (row >= 0) & (row < h) & (col >= 0) & (col < w)
    np.add.at(acc, (row[ok], col[ok]), dy[ok] * (1 - frac[ok]))
    np.add.at(acc, (row[ok], col[ok] + 1), dy[ok] * frac[ok])
    return np.abs(np.cumsum(acc, axis=1)[:, :w])


def _render(rig_side: tuple[np.ndarray, np.ndarray], rvec: np.ndarray, tvec: np.ndarray, size: tuple[int, int],
            board: tuple[int, int], square: float, supersample: int | None, rng: np.random.Generator,
            blur: float, noise: float, paper: float = 0.5) -> np.ndarray:
    M, D = rig_side
    w, h = size
    cols, rows = board
    segs = 8
    t = np.linspace(0.0, 1.0, segs, endpoint=False)

    def outline(corners: np.ndarray) -> np.ndarray:
        # corners (4, 3) in the board frame -> projected, edge-subdivided polygon (pixels)
        pts = np.concatenate([a + t[:, None] * (b - a) for a, b in zip(corners, np.roll(corners, -1, axis=0))])
        return _project(pts, rvec, tvec, M, D)

    squares = []
    for j in range(-1, rows):
        for i in range(-1, cols):
            if (i + j) % 2 == 0:
                x0, y0 = i * square, j * square
                squares.append(outline(np.array([[x0, y0, 0], [x0 + square, y0, 0], [x0 + square, y0 + square, 0],
                                                 [x0, y0 + square, 0]], dtype=np.float64)))
    sheet = outline(_paper_outline(board, square, paper * square))
    if supersample is None:  # exact pixel areas
        low = (80.0 + (215.0 - 80.0) * _area_coverage([sheet], size)
               + (25.0 - 215.0) * _area_coverage(squares, size)).astype(np.float32)
    else:  # filled at supersample x the resolution, area-averaged down
        s = supersample
        shift = 8
        hi = np.full((h * s, w * s), 80, np.uint8)  # background

        def fixed(p: np.ndarray) -> np.ndarray:
            # high-resolution pixel (k, l) is centred on low-resolution (l + 0.5) / s - 0.5
            return np.round(((p + 0.5) * s - 0.5) * (1 << shift)).astype(np.int32).reshape(-1, 1, 2)

        cv2.fillPoly(hi, [fixed(sheet)], 215, cv2.LINE_8, shift)
        cv2.fillPoly(hi, [fixed(q) for q in squares], 25, cv2.LINE_8, shift)
        low = cv2.resize(hi.astype(np.float32), (w, h), interpolation=cv2.INTER_AREA)
    if blur > 0:
        low = cv2.GaussianBlur(low, (0, 0), blur)
    if noise > 0:
        low = low + rng.normal(0.0, noise, size=low.shape).astype(np.float32)
    return np.clip(np.round(low), 0, 255).astype(np.uint8)


def render_views(rig: StereoRig | None = None, n: int = 10, *, seed: int = 0, board: tuple[int, int] = BOARD,
                 square: float = SQUARE, supersample: int | None = None, blur: float = 0.6, noise: float = 1.5,
                 layout: str = "random", progress: bool | None = None) -> RenderedViews:
    """Render ``n`` stereo views of a chessboard (reproducible from ``seed``).

    ``layout="random"`` (default): poses 0.32..0.55 m away with the board centre aimed at the middle
    60 % of the left image, paper margin 0.5 squares. ``layout="cover"``: poses spread over the whole
    field of view of both cameras, corners included, at 0.32..1.0 m, paper margin 0.75 squares (see
    :data:`COVER_TARGETS`); about 27 views cover the reachable field.
    """
    rig = eyebot_rig() if rig is None else rig
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    if supersample is not None and supersample < 1:
        raise ValueError(f"supersample must be >= 1, got {supersample}")
    if layout not in LAYOUTS:
        raise ValueError(f"layout must be 'random' or 'cover', got {layout!r}")
    rng = np.random.default_rng(seed)
    sampler = _sample_poses if layout == "random" else _sample_cover_poses
    poses = sampler(rig, n, rng, board, square)
    paper = 0.5 if layout == "random" else COVER_PAPER
    obj = board_object_points(board, square).astype(np.float64)
    out = RenderedViews([], [], poses, [], [], tuple(board), float(square))
    size = (rig.width, rig.height)
    with progress_bar(n, "rendering views", force=progress) as bar:
        for rvec, tvec in poses:
            rv2, tv2 = _right_pose(rig, rvec, tvec)
            out.left.append(_render((rig.M1, rig.D1), rvec, tvec, size, board, square, supersample, rng, blur, noise,
                                     paper))
            out.right.append(_render((rig.M2, rig.D2), rv2, tv2, size, board, square, supersample, rng, blur, noise,
                                      paper))
            out.corners_left.append(_project(obj, rvec, tvec, rig.M1, rig.D1))
            out.corners_right.append(_project(obj, rv2, tv2, rig.M2, rig.D2))
            bar.update()
    return out


#: Names :func:`write_rig` writes into its folder (an existing folder may hold only these).
RIG_FILES = r"(left|right)\d{2,}\.png|rig_calib\.yml"


def write_rig(folder: str | os.PathLike[str], rig: StereoRig | None = None, n: int = 10, *, seed: int = 0,
              layout: str = "random", progress: bool | None = None) -> list[Path]:
    """Write ``left01.png``.. / ``right01.png``.. and the rig's true calibration ``rig_calib.yml``.

    ``folder`` is written all or nothing (:class:`eyestereo.tools.io.Outputs`): created if missing
    (its parent must exist), or, if it exists, replaced as a whole, which it must allow by holding
    nothing but an earlier rig's files (:data:`RIG_FILES`). Returns the written paths.
    """
    rig = eyebot_rig() if rig is None else rig
    folder = Path(folder)
    with Outputs() as out:
        tmp = out.folder(folder, RIG_FILES)
        views = render_views(rig, n, seed=seed, layout=layout, progress=progress)
        written = []
        for i, (a, b) in enumerate(zip(views.left, views.right), start=1):
            for name, img in ((f"left{i:02d}.png", a), (f"right{i:02d}.png", b)):
                ok, buf = cv2.imencode(".png", img)
                if not ok:
                    raise ValueError(f"cannot encode {name}")
                (tmp / name).write_bytes(buf.tobytes())
                written.append(folder / name)
        write_yaml(rig.calibration(), tmp / "rig_calib.yml")
        written.append(folder / "rig_calib.yml")
    return written


def coverage_masks(views: RenderedViews, maps: Any, size: tuple[int, int] | None = None) -> dict[str, np.ndarray]:
    """Rectified pixels whose source lies where some rendered board was (per side, boolean (h, w)).

    "Where a board was" is the union over the views of the convex hull of the board's true inner
    corners in that camera's image; ``maps`` (a :class:`~eyestereo.tools.rectify.maps.Maps`) says where each
    rectified pixel's source is. ``size``: the camera image size (default: the maps' source size).
    """
    size = size or maps.source_size
    if size is None:
        raise ValueError("coverage_masks needs the camera image size")
    w, h = size
    masks = {}
    for side, corners in (("left", views.corners_left), ("right", views.corners_right)):
        src = np.zeros((h, w), np.uint8)
        for c in corners:
            cv2.fillConvexPoly(src, cv2.convexHull(np.asarray(c, np.float32)).astype(np.int32), 1)
        mx, my = maps.side(side)
        inside = np.isfinite(mx) & np.isfinite(my) & (mx >= 0) & (mx <= w - 1) & (my >= 0) & (my <= h - 1)
        xi = np.clip(np.round(np.nan_to_num(mx)), 0, w - 1).astype(int)
        yi = np.clip(np.round(np.nan_to_num(my)), 0, h - 1).astype(int)
        masks[side] = inside & (src[yi, xi] > 0)
    return masks
