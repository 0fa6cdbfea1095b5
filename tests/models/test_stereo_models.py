"""The stereo Harris and feature-list models: per-camera parameters, the feature word layout, counts."""

import numpy as np
import pytest

from eyestereo.tools.models import feature_list as fl
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.models import harris_stereo as hs


def test_each_camera_gets_its_own_k_and_thresholds():
    rng = np.random.default_rng(5)
    left, right = rng.integers(0, 256, (2, 30, 40))
    tl, tr = [0, 5, 100, -3], [40, 0, 7, 9]
    a_l, a_r, mask = hs.harris_stereo(left, right, (10, 30), (tl, tr), blocks=(2, 2), nms=3)
    assert (a_l == hm.harris_mono(left, 10, tl, blocks=(2, 2), nms=3)[0]).all()
    assert (a_r == hm.harris_mono(right, 30, tr, blocks=(2, 2), nms=3)[0]).all()
    b_l, b_r, _ = hs.harris_stereo(left, right, (30, 10), (tr, tl), blocks=(2, 2), nms=3)
    assert ((a_l != b_l) & mask).any() and ((a_r != b_r) & mask).any()  # the sides are not mixed up


def test_stereo_model_refuses_frames_of_two_sizes():
    with pytest.raises(ValueError, match="of one size"):
        hs.harris_stereo(np.zeros((9, 9)), np.zeros((9, 10)), 10, [0], blocks=(1, 1))
    with pytest.raises(ValueError, match="need 4 thresholds per camera"):
        hs.harris_stereo(np.zeros((9, 9)), np.zeros((9, 9)), 10, [0], blocks=(2, 2))


def test_feature_word_fits_the_16_bit_queue():
    assert fl.FEATURE.width == 32 and fl.TRAILER.width == 32
    assert fl.FEATURE.bits("x") == (15, 0) and fl.FEATURE.bits("cam") == (16, 15) and fl.FEATURE.bits("y") == (32, 16)
    w = int(fl.FEATURE.pack(x=351, cam=1, y=287))
    assert w & 0xFFFF == 351 | 0x8000 and w >> 16 == 287


def test_feature_list_against_a_plain_loop():
    rng = np.random.default_rng(1)
    h, w, border, blocks = 20, 30, 3, (3, 2)
    left, right = (rng.random((2, h, w)) < 0.1).astype(int)
    res = fl.feature_list(left, right, blocks=blocks, border=border, max_features=10 ** 4)
    feats, counts = [], np.zeros((2, 6), int)
    for y in range(border, h - border):
        for x in range(border, w - border):
            for cam, f in enumerate((left, right)):
                if f[y, x]:
                    feats.append((x, y, cam))
                    bx = max(i for i in range(3) if i * w // 3 <= x)
                    by = max(i for i in range(2) if i * h // 2 <= y)
                    counts[cam, by * 3 + bx] += 1
    assert res["features"] == feats and (res["counts"] == counts).all() and not res["overflow"]
    lists = fl.parse_words(res["words"])
    assert len(lists) == 1 and lists[0]["features"] == feats and lists[0]["count"] == len(feats)
    cut = fl.feature_list(left, right, blocks=blocks, border=border, max_features=5)
    assert cut["overflow"] and cut["features"] == feats[:5] and (cut["counts"] == counts).all()
    assert fl.parse_words(cut["words"])[0]["overflow"] is True


def test_empty_frame_gives_a_trailer_alone():
    z = np.zeros((9, 9), int)
    res = fl.feature_list(z, z, blocks=(1, 1), border=3)
    assert res["words"] == [(0xFFFF, False, False), (0, True, True)]


def test_system_model_defaults_are_the_tops():
    """The system model's defaults (max_features above all: the list's cut) are the top's, read from its
    signature: a bench or a caller leaving one out gets what the hardware builds by default."""
    import inspect

    from eyestereo.hdl.system.stereo_frontend import stereo_frontend as top
    from eyestereo.tools.models import stereo_frontend as sf

    hw = inspect.signature(top).parameters
    sw = inspect.signature(sf.stereo_frontend).parameters
    assert sw["max_features"].default == hw["max_features"].default
    for name in ("nms", "border", "frac"):
        assert sw[name].default == hw[name].default, name
