"""Synthetic corner test pattern (in the spirit of thesis Fig. 7.4): shapes with known sub-pixel corners.

Squares and rectangles (right-angle corners) at random sub-pixel positions and rotations, on a grid of
cells so no two shapes interfere, drawn with 16x supersampling (exact area coverage up to 1/256 pixel),
optionally blurred. Pixel (i, j) covers [j - 0.5, j + 0.5] x [i - 0.5, i + 0.5], so true corner
coordinates are in the same 0-based pixel convention as the detector's (x, y).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

SUPERSAMPLE = 16


@dataclass
class Pattern:
    image: np.ndarray  # uint8, (height, width)
    corners: np.ndarray  # (n, 2) float64, true (x, y) of every shape vertex


def corner_pattern(width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, *, seed: int = 0, cells=(5, 4),
                   blur: float = 0.0, rotate: bool = True, contrast: tuple[int, int] = (50, 200)) -> Pattern:
    """A pattern of one quadrilateral per grid cell; returns the image and its true corners."""
    if width < 40 or height < 40:
        raise ValueError(f"corner pattern needs at least 40x40 pixels, got {width}x{height}")
    rng = np.random.default_rng(seed)
    s = SUPERSAMPLE
    bg, fg = contrast
    hi = np.full((height * s, width * s), bg, dtype=np.uint8)
    cw, ch = width / cells[0], height / cells[1]
    corners = []
    for cy in range(cells[1]):
        for cx in range(cells[0]):
            half_w = rng.uniform(0.22, 0.32) * min(cw, ch)
            half_h = half_w * rng.uniform(0.6, 1.0)
            theta = rng.uniform(0, np.pi / 2) if rotate else 0.0
            centre = np.array([(cx + 0.5) * cw + rng.uniform(-2, 2), (cy + 0.5) * ch + rng.uniform(-2, 2)])
            rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
            box = np.array([[-half_w, -half_h], [half_w, -half_h], [half_w, half_h], [-half_w, half_h]])
            pts = box @ rot.T + centre
            corners.extend(pts.tolist())
            # Pixel-centre convention: low-res x maps to high-res (x + 0.5) * s - 0.5; cv2 fillPoly with
            # 8 fractional bits places the polygon to 1/256 of a high-res pixel.
            frac = 8
            hp = np.round(((pts + 0.5) * s - 0.5) * (1 << frac)).astype(np.int32)
            cv2.fillPoly(hi, [hp], int(fg), lineType=cv2.LINE_8, shift=frac)
    img = cv2.resize(hi.astype(np.float32), (width, height), interpolation=cv2.INTER_AREA)
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    return Pattern(np.clip(np.round(img), 0, 255).astype(np.uint8), np.array(corners, dtype=np.float64))


def match_corners(true_xy: np.ndarray, found_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each true corner, the distance to the nearest found one, and that found one's index."""
    t = np.asarray(true_xy, np.float64).reshape(-1, 2)
    f = np.asarray(found_xy, np.float64).reshape(-1, 2)
    if len(f) == 0:
        return np.full(len(t), np.inf), np.full(len(t), -1)
    d = np.hypot(t[:, None, 0] - f[None, :, 0], t[:, None, 1] - f[None, :, 1])
    idx = d.argmin(1)
    return d[np.arange(len(t)), idx], idx


def checkerboard_pattern(width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, *, seed: int = 0, square: float = 24.0,
                         blur: float = 0.0, rotate: bool = True, contrast: tuple[int, int] = (50, 200),
                         margin: int = 6) -> Pattern:
    """A rotated checkerboard at a random sub-pixel offset; corners are its X-junctions.

    Junction corners are symmetric, so a corner detector has no systematic offset there (unlike the
    L-corners of :func:`corner_pattern`, where Harris's maximum sits about a pixel inside the shape).
    Only junctions at least ``margin`` pixels inside the image are listed.
    """
    if width < 40 or height < 40:
        raise ValueError(f"checkerboard pattern needs at least 40x40 pixels, got {width}x{height}")
    rng = np.random.default_rng(seed)
    s = 8
    theta = rng.uniform(0, np.pi / 2) if rotate else 0.0
    origin = np.array([width / 2, height / 2]) + rng.uniform(-square / 2, square / 2, 2)
    c, si = np.cos(theta), np.sin(theta)
    ys, xs = np.mgrid[0:height * s, 0:width * s].astype(np.float64)
    x = (xs + 0.5) / s - 0.5 - origin[0]
    y = (ys + 0.5) / s - 0.5 - origin[1]
    u = (c * x + si * y) / square
    v = (-si * x + c * y) / square
    parity = (np.floor(u) + np.floor(v)).astype(np.int64) & 1
    bg, fg = contrast
    hi = np.where(parity == 1, fg, bg).astype(np.float32)
    img = cv2.resize(hi, (width, height), interpolation=cv2.INTER_AREA)
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    n = int(np.hypot(width, height) / square) + 2
    i, j = np.mgrid[-n:n + 1, -n:n + 1]
    pts = np.stack([i.ravel(), j.ravel()], 1) * square
    xy = np.stack([c * pts[:, 0] - si * pts[:, 1], si * pts[:, 0] + c * pts[:, 1]], 1) + origin
    inside = ((xy[:, 0] >= margin) & (xy[:, 0] <= width - 1 - margin)
              & (xy[:, 1] >= margin) & (xy[:, 1] <= height - 1 - margin))
    return Pattern(np.clip(np.round(img), 0, 255).astype(np.uint8), xy[inside])
