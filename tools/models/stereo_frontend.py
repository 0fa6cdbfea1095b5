"""Bit-true model of :func:`eyestereo.hdl.system.stereo_frontend.stereo_frontend`: the whole front end in numpy.

camera words (what the camera models send) -> their Y (what the fetch port reads from the camera
buffers) -> the rectification model (:mod:`eyestereo.tools.models.rectifier`) -> the stereo Harris
model (:mod:`eyestereo.tools.models.harris_stereo`) -> the feature-list model
(:mod:`eyestereo.tools.models.feature_list`). No arithmetic of its own: every step is the existing
model. With the ``dense`` option, the disparity map of the rectified pair
(:mod:`eyestereo.tools.models.dense_stereo`). Also the words the host reads back: the rectified pair packed as
:data:`~eyestereo.tools.models.sram_arbiter.RECT_WORD` and the list words in the feature buffer.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.constants import NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.models import dense_stereo as dense_model
from eyestereo.tools.models import feature_list as fl_model
from eyestereo.tools.models import harris_stereo as hs_model
from eyestereo.tools.models import rectifier as rect_model
from eyestereo.tools.models.harris_mono import radius
from eyestereo.tools.models.poly_unit import DEFAULT_FRAC, Calibration
from eyestereo.tools.models.sram_arbiter import CAMERA_WORD, RECT_WORD

__all__ = ["BLOCKS", "grey", "stereo_frontend", "rect_words", "list_words", "disparity"]

#: Threshold and count blocks per camera (the register map's 16 thresholds per camera).
BLOCKS = THRESHOLD_BLOCKS


def grey(words) -> np.ndarray:
    """The Y plane (uint8) of a frame of camera words."""
    return CAMERA_WORD.unpack(np.asarray(words, dtype=np.int64))["y"].astype(np.uint8)


def rect_words(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """The rectified buffer's words (row by row): left pixel in bits 7..0, right in 15..8."""
    return RECT_WORD.pack(left=np.asarray(left, np.int64), right=np.asarray(right, np.int64)).astype(np.int64)


def list_words(words) -> list[int]:
    """The data of the feature buffer's words (as the host reads them) from the model's queue words."""
    return [int(d) for d, _, _ in words]


def stereo_frontend(cal: Calibration, left_words, right_words, k, thresholds, *, nms: int = NMS_DEFAULT,
                    border: int | None = None, max_features: int = 1023,
                    frac: int | None = DEFAULT_FRAC, dense: dict | None = None) -> dict:
    """One stereo frame through the whole chain.

    ``left_words``/``right_words``: camera words (height x width); ``k``: a code or (left, right);
    ``thresholds``: 16 codes or (left 16, right 16). Returns ``rectified`` (left, right), ``rect_words``,
    ``flags`` (left, right, mask), ``list`` (the feature_list model's dict) and ``list_words``.

    ``nms``, ``border``, ``max_features``, ``frac``: the top's parameters of those names, with its defaults
    (tests/models/test_stereo_models.py checks them against its signature); a top built otherwise is
    modelled only with the same values (the bench's ``model_params``): ``max_features`` cuts the list.

    ``dense``: None (the option off) or the dense core's settings (keyword arguments of
    :func:`eyestereo.tools.models.dense_stereo.dense_stereo`: ``disparities``, ``paths``, the DENSE register's
    ``p1``, ``p2``, ``uniqueness``, ``lr_check``, ``subpixel``): adds ``disparity``, the codes the disparity buffer
    holds (row by row). Computed only when asked (the sgm model takes seconds at CIF): :func:`disparity`.
    """
    gl, gr = grey(left_words), grey(right_words)
    rl, rr = rect_model.rectifier(cal, gl, gr, frac)
    fl, fr, mask = hs_model.harris_stereo(rl, rr, k, thresholds, blocks=BLOCKS, nms=nms)
    border = radius(nms) if border is None else int(border)
    lst = fl_model.feature_list(fl, fr, blocks=BLOCKS, border=border, max_features=max_features)
    out = dict(rectified=(rl, rr), rect_words=rect_words(rl, rr), flags=(fl, fr, mask), list=lst,
               list_words=list_words(lst["words"]))
    if dense is not None:
        out["disparity"] = disparity(rl, rr, dense)
    return out


def disparity(left, right, dense: dict) -> np.ndarray:
    """The disparity buffer's words (int64, row by row) of a rectified pair: the dense option's codes."""
    return dense_model.dense_stereo(left, right, **dense).astype(np.int64)
