"""Bit-true model of :func:`eyestereo.hdl.harris.harris_stereo.harris_stereo`: the mono model, once per camera.

The stereo detector computes, for each camera, exactly what :func:`eyestereo.tools.models.harris_mono.harris_mono`
computes for that camera's frame with that camera's ``k`` and block thresholds; sharing the line
delays and multipliers changes when results come out, never what they are. So this model is the mono
model applied to each side (one definition of the arithmetic), plus the parameter checks and the
stream-level helpers the benches and the command line use.
"""

from __future__ import annotations

import numbers

import numpy as np

from eyestereo.tools.constants import NMS_DEFAULT, SHARE_FACTORS, THRESHOLD_BLOCKS
from eyestereo.tools.models import harris_mono as _mono

#: The share factors (hdl.harris.harris_stereo imports them by this name).


def check_share(share) -> int:
    if (isinstance(share, (bool, np.bool_)) or not isinstance(share, numbers.Integral)
            or int(share) not in SHARE_FACTORS):
        raise ValueError(f"parameter share must be one of {list(SHARE_FACTORS)}, got {type(share).__name__} {share!r}")
    return int(share)


def harris_stereo(left: np.ndarray, right: np.ndarray, k, thresholds, *, blocks=THRESHOLD_BLOCKS,
                  nms: int = NMS_DEFAULT):
    """(left flags, right flags, mask of specified pixels).

    ``k``: one k code for both cameras or a pair (left, right); ``thresholds``: one list of BX*BY codes
    for both or a pair of such lists (left, right).
    """
    left = np.asarray(left)
    right = np.asarray(right)
    if left.shape != right.shape or left.ndim != 2:
        raise ValueError(f"the two frames must be 2-D and of one size, got {left.shape} and {right.shape}")
    kl, kr = k if isinstance(k, (tuple, list)) else (k, k)
    n = blocks[0] * blocks[1]
    thr = thresholds
    if isinstance(thr, (tuple, list)) and len(thr) == 2 and all(isinstance(t, (tuple, list, np.ndarray)) for t in thr):
        tl, tr = thr
    else:
        tl = tr = thr
    if len(tl) != n or len(tr) != n:
        raise ValueError(f"need {n} thresholds per camera, got {len(tl)} and {len(tr)}")
    fl, mask = _mono.harris_mono(left, int(kl), list(tl), blocks=blocks, nms=nms)
    fr, _ = _mono.harris_mono(right, int(kr), list(tr), blocks=blocks, nms=nms)
    return fl, fr, mask
