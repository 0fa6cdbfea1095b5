"""Scenes for the front end's benches: a rectified stereo pair as the calibrated rig's cameras would see it.

The front end rectifies what its cameras deliver. A rectified pair (Middlebury's) fed to the cameras as it is comes
out of the rig's rectification warped (its lens model and its misalignment applied to images that have neither),
and its rows no longer line up: a matcher then finds few matches. :func:`camera_views` undoes the rectification
instead: camera pixel (u, v) gets the rectified image at the point the rig's maps send to (u, v), so that the
front end's rectification gives the pair back (up to two bilinear resamplings).
"""

from __future__ import annotations

import numpy as np

__all__ = ["camera_views"]


def camera_views(cal, left: np.ndarray, right: np.ndarray, *, iterations: int = 20) -> list[np.ndarray]:
    """The two camera images (uint8, the calibration's source size) whose rectification by ``cal`` (a
    :class:`~eyestereo.tools.models.poly_unit.Calibration`) is the rectified pair ``left``, ``right`` (uint8, the
    calibration's rectified size).

    The maps are the coordinate warper's (rectified pixel -> camera coordinate, its fixed-point codes); each
    camera pixel's rectified point is found by fixed-point iteration ``p <- p - (map(p) - q)`` from ``p = q`` (the
    maps are near the identity: a lens and a degree of rotation), then the pair is sampled there (bilinear, edges
    repeated)."""
    import cv2

    from eyestereo.tools.models.coordinate_warper import coordinate_warper
    from eyestereo.tools.models.poly_unit import resolve_frac

    for name, img in (("left", left), ("right", right)):
        if np.shape(img) != (cal.height, cal.width):
            raise ValueError(f"the {name} image must be {cal.width}x{cal.height} (the rectified size), got shape "
                             f"{np.shape(img)}")
    frac = resolve_frac(cal, None)
    cw = coordinate_warper(cal, frac)
    v, u = np.mgrid[0:cal.source_height, 0:cal.source_width].astype(np.float32)
    out = []
    for img, kx, ky in ((left, "xl", "yl"), (right, "xr", "yr")):
        mx = (cw[kx] / 2.0 ** frac).astype(np.float32)
        my = (cw[ky] / 2.0 ** frac).astype(np.float32)
        px, py = u.copy(), v.copy()
        for _ in range(iterations):
            px -= cv2.remap(mx, px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE) - u
            py -= cv2.remap(my, px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE) - v
        view = cv2.remap(np.asarray(img, np.float32), px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        out.append(np.clip(np.rint(view), 0, 255).astype(np.uint8))
    return out
