"""The lens model of OpenCV's calibration (0 to 14 distortion coefficients), forward and inverse.

Its own module so that the calibration's judge (:mod:`eyestereo.tools.rectify.judge`, called by
:mod:`~eyestereo.tools.rectify.calib`) and the maps (:mod:`~eyestereo.tools.rectify.maps`, which import the
calibration) can both use it without an import circle. Plain numpy.
"""

from __future__ import annotations

import numpy as np

__all__ = ["distort", "undistort"]


def _dist_coeffs(d: np.ndarray) -> np.ndarray:
    d = np.asarray(d, dtype=np.float64).ravel()
    if d.size not in (0, 4, 5, 8, 12, 14):
        raise ValueError(f"distortion vector must have 0, 4, 5, 8, 12 or 14 coefficients, got {d.size}")
    out = np.zeros(14)
    out[: d.size] = d
    return out


def _tilt_matrix(tau_x: float, tau_y: float) -> np.ndarray:
    """OpenCV's tilted-sensor projection matrix (``computeTiltProjectionMatrix``)."""
    cx, sx, cy, sy = np.cos(tau_x), np.sin(tau_x), np.cos(tau_y), np.sin(tau_y)
    rot_x = np.array([[1, 0, 0], [0, cx, sx], [0, -sx, cx]])
    rot_y = np.array([[cy, 0, -sy], [0, 1, 0], [sy, 0, cy]])
    rot_xy = rot_y @ rot_x
    proj_z = np.array([[rot_xy[2, 2], 0, -rot_xy[0, 2]], [0, rot_xy[2, 2], -rot_xy[1, 2]], [0, 0, 1]])
    return proj_z @ rot_xy


def distort(x: np.ndarray, y: np.ndarray, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Apply the lens model to normalised ideal coordinates ``(x, y)`` (any equal shapes)."""
    k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4, tx, ty = _dist_coeffs(dist)
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    r2 = x * x + y * y
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    if k4 or k5 or k6:
        radial = radial / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
    xy2 = 2 * x * y
    xd = x * radial + p1 * xy2 + p2 * (r2 + 2 * x * x) + r2 * (s1 + s2 * r2)
    yd = y * radial + p1 * (r2 + 2 * y * y) + p2 * xy2 + r2 * (s3 + s4 * r2)
    if tx or ty:
        m = _tilt_matrix(tx, ty)
        w = m[2, 0] * xd + m[2, 1] * yd + m[2, 2]
        w = np.where(w != 0, w, 1.0)
        xd, yd = (m[0, 0] * xd + m[0, 1] * yd + m[0, 2]) / w, (m[1, 0] * xd + m[1, 1] * yd + m[1, 2]) / w
    return xd, yd


def undistort(xd: np.ndarray, yd: np.ndarray, dist: np.ndarray, *, iterations: int = 50,
              tol: float = 1e-14) -> tuple[np.ndarray, np.ndarray]:
    """Invert :func:`distort` by Newton iteration (Jacobian by central differences).

    Converges to ``|distort(x, y) - (xd, yd)| < tol`` (normalised units) for any point inside the
    region where the lens model is monotonic; raises ValueError if it does not.
    """
    xd = np.asarray(xd, dtype=np.float64)
    yd = np.asarray(yd, dtype=np.float64)
    x, y = xd.copy(), yd.copy()
    h = 1e-6
    for _ in range(iterations):
        fx, fy = distort(x, y, dist)
        ex, ey = fx - xd, fy - yd
        if max(np.abs(ex).max(initial=0), np.abs(ey).max(initial=0)) < tol:
            return x, y
        ax, ay = distort(x + h, y, dist)
        bx, by = distort(x - h, y, dist)
        cx, cy = distort(x, y + h, dist)
        dx, dy = distort(x, y - h, dist)
        j11, j21 = (ax - bx) / (2 * h), (ay - by) / (2 * h)
        j12, j22 = (cx - dx) / (2 * h), (cy - dy) / (2 * h)
        det = j11 * j22 - j12 * j21
        det = np.where(np.abs(det) > 1e-12, det, 1e-12)
        x = x - (j22 * ex - j12 * ey) / det
        y = y - (-j21 * ex + j11 * ey) / det
    fx, fy = distort(x, y, dist)
    if max(np.abs(fx - xd).max(initial=0), np.abs(fy - yd).max(initial=0)) > 1e-9:
        raise ValueError("cannot undistort: the lens model is not invertible at these points")
    return x, y
