"""The FFC benchmark's synthetic stereo rig: exact backward maps and their degree-3 polynomials.

A rig like the thesis's (EyeBot M6, 352x288, f ~ 544 px): radial distortion k1 = -0.3, k2 = 0.08 in
normalized coordinates, a small rectifying rotation per camera and a few pixels of principal point
offset, which displace pixels by up to ~25 px. For each camera the backward map rectified pixel ->
source pixel is computed exactly and the degree-3 polynomials (thesis eq. 4.1) are fitted to it by least
squares over all pixels. Used by the FFC benchmark (:mod:`eyestereo.tools.reports.bench_ffc`) and as the
rectification hardware's default calibration (:mod:`eyestereo.tools.rectify.calibrations`).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from eyestereo.tools.rectify.ffc import POLY_NAMES

__all__ = ["fit_poly3", "rig_maps", "synthetic_rig_polynomials"]


def _rotation(rx: float, ry: float, rz: float) -> npt.NDArray[np.float64]:
    """Rotation from angles in degrees about x, then y, then z."""
    ax, ay, az = (math.radians(a) for a in (rx, ry, rz))
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rot_x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    rot_y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rot_z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rot_z @ rot_y @ rot_x


#: Per camera: rotation angles (deg), principal point offset (px), k1, k2.
_RIG = {
    "left": ((0.5, 1.2, 0.8), (3.0, -2.0), -0.30, 0.08),
    "right": ((-0.4, -1.0, -0.6), (-2.5, 3.5), -0.28, 0.10),
}


def rig_maps(width: int = 352, height: int = 288) -> dict[str, npt.NDArray[np.float64]]:
    """Exact backward maps (rectified pixel -> source pixel) of the synthetic rig, ``(H, W)`` each.

    Keys ``left_x, left_y, right_x, right_y``; the focal length scales with the width
    (544 px at 352 columns), so smaller images see the same geometry.
    """
    f = 544.0 * width / 352.0
    cx, cy = (width - 1) / 2.0, (height - 1) / 2.0
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    rays = np.stack([(xs - cx) / f, (ys - cy) / f, np.ones_like(xs)]).reshape(3, -1)
    out = {}
    for side, (angles, (ox, oy), k1, k2) in _RIG.items():
        cam = _rotation(*angles) @ rays
        xn, yn = cam[0] / cam[2], cam[1] / cam[2]
        r2 = xn * xn + yn * yn
        d = 1.0 + k1 * r2 + k2 * r2 * r2
        s = width / 352.0  # offsets scale with the image too
        out[f"{side}_x"] = (f * xn * d + cx + ox * s).reshape(height, width)
        out[f"{side}_y"] = (f * yn * d + cy + oy * s).reshape(height, width)
    return out


def fit_poly3(target: npt.NDArray[np.float64]) -> list[float]:
    """Least-squares degree-3 fit (eq. 4.1 term order) of a ``(H, W)`` map in raw pixel units."""
    height, width = target.shape
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    x, y = xs.ravel(), ys.ravel()
    cols = [np.ones_like(x), x, y, x * x, y * y, x * y, x ** 3, y ** 3, x * x * y, x * y * y]
    a = np.stack(cols, axis=1)
    scale = np.max(np.abs(a), axis=0)  # column scaling keeps the system well conditioned
    sol, *_ = np.linalg.lstsq(a / scale, target.ravel(), rcond=None)
    return [float(v) for v in sol / scale]


def synthetic_rig_polynomials(width: int = 352, height: int = 288) -> dict[str, list[float]]:
    """The four fitted polynomials of the synthetic rig (``poly.json``'s ``polynomials``)."""
    maps = rig_maps(width, height)
    return {name: fit_poly3(maps[name]) for name in POLY_NAMES}
