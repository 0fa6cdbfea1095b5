"""Stereo calibration (tools/calib.py) and the synthetic EyeBot rig (tools/rig.py).

Real data: OpenCV's 13 stereo pairs in ../shared/data/opencv_stereo_calib (skipped when absent),
compared with OpenCV's own reference intrinsics shipped beside them. Synthetic data: chessboard
views rendered with the known rig, calibrated, and compared with the rig's truth.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.rectify import calib as C
from eyestereo.tools.rectify import maps as X
from eyestereo.tools.rectify import rig as G

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(__file__).resolve().parents[2].parent / "shared"))
DATA = SHARED / "data" / "opencv_stereo_calib"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"shared calibration images not found at {DATA}")


def ref_matrix(name: str, key: str) -> np.ndarray:
    """Read a matrix from OpenCV's reference files with FileStorage (independent of read_yaml)."""
    fs = cv2.FileStorage(str(DATA / name), cv2.FILE_STORAGE_READ)
    m = fs.getNode(key).mat()
    fs.release()
    return m


@pytest.fixture(scope="module")
def real_calib() -> C.StereoCalibration:
    if not DATA.is_dir():
        pytest.skip(f"shared calibration images not found at {DATA}")
    return C.calibrate_stereo(str(DATA / "left*.jpg"), str(DATA / "right*.jpg"), board=(9, 6), square=0.025)


# --------------------------------------------------------------------------------------------------
# Real data


@needs_data
def test_real_calibration_uses_all_pairs_and_has_small_rms(real_calib):
    print(f"\nreal data: RMS {real_calib.rms:.4f} px (left {real_calib.info['rms_left']:.4f}, "
          f"right {real_calib.info['rms_right']:.4f}), pairs {len(real_calib.info['used'])}")
    assert len(real_calib.info["used"]) == 13 and real_calib.info["skipped"] == []
    # OpenCV's stereo_calib sample reports about 0.4 px on these images
    assert 0.15 < real_calib.rms < 0.5
    assert real_calib.image_size == (640, 480)


@needs_data
def test_real_intrinsics_match_opencv_references(real_calib):
    # left_intrinsics.yml: OpenCV's mono calibration of the left camera with the same 5-coefficient
    # model -> focal lengths within 0.5 %, principal point within 1.5 px
    mono = ref_matrix("left_intrinsics.yml", "camera_matrix")
    assert np.allclose(np.diag(real_calib.M1)[:2], np.diag(mono)[:2], rtol=0.005)
    assert np.abs(real_calib.M1[:2, 2] - mono[:2, 2]).max() < 1.5
    # intrinsics.yml: OpenCV's stereo sample (rational model, no tangential terms, one common focal
    # length) -> a different model, so only within 1 % in focal length and 10 px in principal point
    for ours, key in ((real_calib.M1, "M1"), (real_calib.M2, "M2")):
        ref = ref_matrix("intrinsics.yml", key)
        assert np.allclose(np.diag(ours)[:2], np.diag(ref)[:2], rtol=0.01), key
        assert np.abs(ours[:2, 2] - ref[:2, 2]).max() < 10, key


@needs_data
def test_real_extrinsics_are_a_side_by_side_rig(real_calib):
    angle = np.degrees(np.linalg.norm(cv2.Rodrigues(real_calib.R)[0]))
    t = real_calib.T
    assert angle < 1.0  # nearly parallel cameras
    assert t[0] < 0 and abs(t[0]) > 20 * max(abs(t[1]), abs(t[2]))  # right camera to the right
    assert 0.05 < real_calib.baseline < 0.15  # in metres (square = 0.025)


@needs_data
def test_fix_intrinsics_keeps_per_camera_intrinsics():
    imgs = sorted(DATA.glob("left0[1-5].jpg")), sorted(DATA.glob("right0[1-5].jpg"))
    cal = C.calibrate_stereo(imgs[0], imgs[1], refine=False, judge=False)  # 5 central views: see test_bad_input
    # the stereo step must not touch the mono intrinsics: re-run calibrateCamera independently
    obj = C.board_object_points((9, 6), 0.025)
    pts = cal.info["points_left"]
    _, m1, d1, _, _ = cv2.calibrateCamera([obj] * len(pts), pts, (640, 480), None, None,
                                          criteria=C._CALIB_CRITERIA)
    assert np.allclose(cal.M1, m1, rtol=1e-6) and np.allclose(cal.D1, d1.ravel(), rtol=1e-5, atol=1e-9)


@needs_data
def test_pairs_without_board_are_skipped_and_reported():
    lefts = [cv2.imread(str(p), cv2.IMREAD_GRAYSCALE) for p in sorted(DATA.glob("left0[1-3].jpg"))]
    rights = [cv2.imread(str(p), cv2.IMREAD_GRAYSCALE) for p in sorted(DATA.glob("right0[1-3].jpg"))]
    blank = np.full((480, 640), 128, np.uint8)
    lines: list[str] = []
    cal = C.calibrate_stereo(lefts + [lefts[0]], rights + [blank], log=lines.append, judge=False)
    assert len(cal.info["used"]) == 3
    assert len(cal.info["skipped"]) == 1 and "right image" in cal.info["skipped"][0][2]
    assert len(lines) == 1 and "skipped" in lines[0]
    with pytest.raises(ValueError, match="only 2 of 3 pairs"):
        C.calibrate_stereo(lefts[:2] + [blank], rights[:3])


def test_calibration_input_errors(tmp_path):
    img = np.zeros((48, 64), np.uint8)
    with pytest.raises(ValueError, match="no left images match"):
        C.calibrate_stereo(str(tmp_path / "nothing*.png"), [img])
    with pytest.raises(ValueError, match="2 left images but 1 right"):
        C.calibrate_stereo([img, img], [img])
    with pytest.raises(ValueError, match="found in both images of only 0 of 3"):
        C.calibrate_stereo([img] * 3, [img + 1] * 3)
    with pytest.raises(ValueError, match="left and right images of a pair are identical"):
        C.calibrate_stereo([img] * 3, [img] * 3)
    with pytest.raises(ValueError, match="but the first image is 64x48"):
        C.calibrate_stereo([img, np.zeros((10, 10), np.uint8)], [img + 1, img + 1])
    (tmp_path / "bad.png").write_bytes(b"not a png")
    with pytest.raises(ValueError, match="cannot read image"):
        C.calibrate_stereo([str(tmp_path / "bad.png")], [img])


@pytest.mark.parametrize("text,expected", [("9x6", (9, 6)), (" 7X5 ", (7, 5))])
def test_parse_board_accepts(text, expected):
    assert C.parse_board(text) == expected


@pytest.mark.parametrize("text", ["9", "9x", "x6", "9*6", "1x6", "6x6", "-9x6", "9x6x2", ""])
def test_parse_board_rejects(text):
    with pytest.raises(ValueError):
        C.parse_board(text)


# --------------------------------------------------------------------------------------------------
# YAML


def sample_calib() -> C.StereoCalibration:
    return G.eyebot_rig().calibration()


def test_yaml_roundtrip_is_exact_and_has_exactly_the_keys(tmp_path):
    cal = sample_calib()
    cal.rms = 0.123456789012345
    path = tmp_path / "calib.yml"
    C.write_yaml(cal, path)
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    keys = list(fs.root().keys())
    shapes = {k: fs.getNode(k).mat().shape for k in ("M1", "D1", "M2", "D2", "R", "T")}
    fs.release()
    assert keys == ["M1", "D1", "M2", "D2", "R", "T", "image_width", "image_height", "rms"]
    assert shapes["T"] == (3, 1) and shapes["D1"] == (1, 5)
    back = C.read_yaml(path)
    for k in ("M1", "D1", "M2", "D2", "R", "T"):
        assert np.array_equal(getattr(back, k), getattr(cal, k)), k
    assert (back.image_width, back.image_height, back.rms) == (352, 288, cal.rms)
    assert [p.name for p in tmp_path.iterdir()] == ["calib.yml"]  # no temporary files left


FOREIGN = """%YAML:1.0
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 501., 240., 0., 0., 1. ]
D1: !!opencv-matrix
   rows: {drows}
   cols: {dcols}
   dt: d
   data: [ {d} ]
M2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 502., 0., 321., 0., 503., 241., 0., 0., 1. ]
D2: [ -0.1, 0.01, 0., 0. ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
T: !!opencv-matrix
   rows: {trows}
   cols: {tcols}
   dt: d
   data: [ -0.06, 0.001, 0.0 ]
image_width: 640
image_height: 480
rms: 0.5
"""


@pytest.mark.parametrize("dshape,tshape", [((1, 5), (3, 1)), ((5, 1), (1, 3)), ((1, 8), (3, 1)),
                                           ((14, 1), (1, 3))])
def test_read_yaml_accepts_files_made_elsewhere(tmp_path, dshape, tshape):
    n = dshape[0] * dshape[1]
    d = [0.1 * (i + 1) * (-1) ** i for i in range(n)]
    if n == 14:
        d[12] = d[13] = 0.0
    text = FOREIGN.format(drows=dshape[0], dcols=dshape[1], d=", ".join(map(str, d)), trows=tshape[0],
                          tcols=tshape[1])
    path = tmp_path / "other.yml"
    path.write_text(text)
    cal = C.read_yaml(path)
    assert np.allclose(cal.D1, d) and cal.D1.shape == (n,)
    assert np.allclose(cal.D2, [-0.1, 0.01, 0, 0])
    assert np.allclose(cal.T, [-0.06, 0.001, 0.0]) and cal.T.shape == (3,)
    assert cal.M2[1, 1] == 503 and cal.image_size == (640, 480) and cal.rms == 0.5


BAD_YAML = {
    "missing key": (lambda t: t.replace("rms: 0.5\n", ""), "key 'rms' is missing"),
    "garbage": (lambda t: "\x00\x01 this is : not [ yaml", "not an OpenCV YAML"),
    "bad D length": (lambda t: t.replace("D2: [ -0.1, 0.01, 0., 0. ]", "D2: [ -0.1, 0.01, 0. ]"), "D2 must have"),
    "R not rotation": (lambda t: t.replace("[ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]",
                                           "[ 2., 0., 0., 0., 1., 0., 0., 0., 1. ]"), "R is not a rotation"),
    "M text": (lambda t: t.replace("image_width: 640", "image_width: wide"), "image_width"),
    "M not camera": (lambda t: t.replace("500., 0., 320.", "-500., 0., 320."), "M1 is not a camera matrix"),
    "T wrong size": (lambda t: t.replace("[ -0.06, 0.001, 0.0 ]", "[ -0.06, 0.001 ]"), "'T' is a malformed matrix"),
    "T two values": (lambda t: t.replace("rows: 3\n   cols: 1\n   dt: d\n   data: [ -0.06, 0.001, 0.0 ]",
                                         "rows: 2\n   cols: 1\n   dt: d\n   data: [ -0.06, 0.001 ]"),
                     "T must have 3 elements"),
}


@pytest.mark.parametrize("case", sorted(BAD_YAML))
def test_read_yaml_rejects_bad_files_with_one_line(tmp_path, case):
    edit, message = BAD_YAML[case]
    good = FOREIGN.format(drows=1, dcols=5, d="0.1, -0.2, 0, 0, 0", trows=3, tcols=1)
    path = tmp_path / "bad.yml"
    path.write_text(edit(good))
    with pytest.raises(ValueError, match=message) as info:
        C.read_yaml(path)
    assert "\n" not in str(info.value)


def test_read_yaml_missing_file(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        C.read_yaml(tmp_path / "none.yml")


def test_write_yaml_refuses_a_missing_folder(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        C.write_yaml(sample_calib(), tmp_path / "no_such_dir" / "calib.yml")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------------------------------
# The synthetic rig


def test_rig_has_the_eyebot_geometry():
    rig = G.eyebot_rig()
    assert (rig.width, rig.height) == (352, 288)
    assert abs(rig.M1[1, 1] - 4.9e-3 / 9e-6) < 1e-9  # f = 4.9 mm / 9 um
    assert abs(np.linalg.norm(rig.T) - 0.066) < 0.001
    assert 0.5 < np.degrees(np.linalg.norm(cv2.Rodrigues(rig.R)[0])) < 3  # a small misalignment
    # the exact maps move pixels by up to about 25 px, like Table 4.1's "none" row (25.83)
    gt = X.ground_truth_maps(rig)
    yy, xx = np.mgrid[0:288, 0:352]
    disp = max(np.hypot(gt.left_x - xx, gt.left_y - yy).max(), np.hypot(gt.right_x - xx, gt.right_y - yy).max())
    print(f"\nrig: max displacement of the exact maps from identity {disp:.2f} px")
    assert 20 < disp < 30


@pytest.fixture(scope="module")
def synthetic():
    rig = G.eyebot_rig()
    views = G.render_views(rig, 10, seed=1)
    cal = C.calibrate_stereo(views.left, views.right, board=views.board, square=views.square)
    return rig, views, cal


def test_rendered_views_are_sensible(synthetic):
    rig, views, _ = synthetic
    assert len(views.left) == len(views.right) == 10
    for img in views.left + views.right:
        assert img.shape == (288, 352) and img.dtype == np.uint8
        assert img.min() < 60 and img.max() > 180  # black squares and white paper
    for c in views.corners_left + views.corners_right:
        assert c.shape == (54, 2)
        assert c[:, 0].min() > 0 and c[:, 0].max() < 351 and c[:, 1].min() > 0 and c[:, 1].max() < 287


def test_rendered_corners_are_found_where_they_were_drawn(synthetic):
    _, views, _ = synthetic
    errs = []
    for img, truth in zip(views.left + views.right, views.corners_left + views.corners_right):
        found = C.find_corners(img, views.board)
        assert found is not None
        found = found.reshape(-1, 2)
        if np.linalg.norm(found[0] - truth[0]) > np.linalg.norm(found[0] - truth[-1]):
            found = found[::-1]  # detected from the other end of the symmetric grid
        errs.append(found - truth)
    e = np.concatenate(errs)
    rms = float(np.sqrt((e**2).sum(axis=1).mean()))
    sub = []
    for img, truth in zip(views.left + views.right, views.corners_left + views.corners_right):
        found = C.find_corners(img, views.board, refine="subpix").reshape(-1, 2)
        if np.linalg.norm(found[0] - truth[0]) > np.linalg.norm(found[0] - truth[-1]):
            found = found[::-1]
        sub.append(found - truth)
    rms_sub = float(np.sqrt((np.concatenate(sub) ** 2).sum(axis=1).mean()))
    print(f"\nrendered corners: rms error {rms:.4f} px, max {np.abs(e).max():.4f} px, mean {e.mean(axis=0)}; "
          f"cornerSubPix alone {rms_sub:.4f} px")
    assert abs(e.mean(axis=0)).max() < 0.005  # no bias (no pixel-convention offset)
    assert rms < 0.02  # saddle fit (cornerSubPix alone: about 0.05 px)
    assert 0.02 < rms_sub < 0.08
    with pytest.raises(ValueError, match="refine"):
        C.find_corners(views.left[0], views.board, refine="harris")


def test_exact_area_renderer():
    sq = np.array([[10.3, 5.2], [20.7, 5.9], [19.1, 17.4], [9.6, 16.1]])
    cov = G._area_coverage([sq], (40, 30))
    x, y = sq[:, 0], sq[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert cov.sum() == pytest.approx(area, rel=1e-12) and cov.min() >= 0 and cov.max() <= 1 + 1e-12
    # pixel (i, j) covers [j - 0.5, j + 0.5] x [i - 0.5, i + 0.5]
    cell = G._area_coverage([np.array([[2.0, 3.0], [3.0, 3.0], [3.0, 4.0], [2.0, 4.0]])], (6, 6))
    assert cell[3, 2] == pytest.approx(0.25) and cell[3, 3] == pytest.approx(0.25)
    assert cell[4, 2] == pytest.approx(0.25) and cell[4, 3] == pytest.approx(0.25) and cell.sum() == pytest.approx(1)


def test_synthetic_calibration_recovers_the_truth(synthetic):
    rig, views, cal = synthetic
    print(f"\nsynthetic: RMS {cal.rms:.4f} px, f {cal.M1[0, 0]:.2f}/{cal.M1[1, 1]:.2f} "
          f"(true {rig.M1[0, 0]:.2f}/{rig.M1[1, 1]:.2f}), T {cal.T} (true {rig.T})")
    assert cal.rms < 0.1
    assert np.allclose(np.diag(cal.M1)[:2], np.diag(rig.M1)[:2], rtol=0.003)
    assert np.allclose(np.diag(cal.M2)[:2], np.diag(rig.M2)[:2], rtol=0.003)
    assert np.abs(cal.M1[:2, 2] - rig.M1[:2, 2]).max() < 3
    assert np.abs(cal.M2[:2, 2] - rig.M2[:2, 2]).max() < 3
    assert np.linalg.norm(cal.T - rig.T) < 0.001  # 1 mm of 66
    assert np.degrees(np.linalg.norm(cv2.Rodrigues(cal.R @ rig.R.T)[0])) < 0.15


def covered(views: G.RenderedViews, maps: X.Maps) -> dict[str, np.ndarray]:
    """Rectified pixels whose source lies inside the area some board covered (convex hull of its corners)."""
    masks = {}
    for side, corners in (("left", views.corners_left), ("right", views.corners_right)):
        src = np.zeros((288, 352), np.uint8)
        for c in corners:
            cv2.fillConvexPoly(src, cv2.convexHull(c.astype(np.float32)).astype(np.int32), 1)
        mx, my = maps.side(side)
        inside = (mx >= 0) & (mx <= 351) & (my >= 0) & (my <= 287)
        xi = np.clip(np.round(mx), 0, 351).astype(int)
        yi = np.clip(np.round(my), 0, 287).astype(int)
        masks[side] = inside & (src[yi, xi] > 0)
    return masks


def test_synthetic_calibration_recovers_the_maps(synthetic):
    rig, views, cal = synthetic
    est = X.compute_maps(cal)
    gt = X.ground_truth_maps(rig)
    masks = covered(views, est)
    frac = np.mean([m.mean() for m in masks.values()])
    # 1. lens model: the maps agree with the true cameras up to the choice of rectified frame
    up_to_frame = X.compare_up_to_frame(est, rig.calibration(), masks)
    # 2. stereo: true projections of the board corners land on the same rectified row
    dy = np.concatenate([X.row_alignment(est, cal, a, b) for a, b in zip(views.corners_left, views.corners_right)])
    # 3. plain difference: includes the rectified frame, which moves with the estimated baseline
    #    direction and focal lengths (a 0.3 mm error in T_z alone turns it by 4.5 mrad)
    plain = X.map_difference(gt, est, masks)
    print(f"\nsynthetic maps over the board-covered {frac:.0%} of the image: up to frame mean "
          f"{up_to_frame['mean']:.4f} max {up_to_frame['max']:.4f} px; vertical disparity mean "
          f"{np.abs(dy).mean():.4f} max {np.abs(dy).max():.4f} px; plain mean {plain['mean']:.3f} "
          f"max {plain['max']:.3f} px")
    assert frac > 0.25
    assert up_to_frame["mean"] < 0.02 and up_to_frame["max"] < 0.1
    assert np.abs(dy).mean() < 0.02 and np.abs(dy).max() < 0.1
    assert plain["max"] < 3


def test_compare_up_to_frame_detects_lens_errors(synthetic):
    rig, views, _ = synthetic
    truth = rig.calibration()
    wrong = rig.calibration()
    wrong.D1 = wrong.D1 + np.array([0.02, 0, 0, 0, 0])  # k1 off by 0.02: ~0.9 px at the corners
    maps = X.compute_maps(wrong)
    res = X.compare_up_to_frame(maps, truth)
    assert res["left_mean"] > 0.05 and res["left_max"] > 0.3 and res["right_max"] < 1e-4
    exact = X.compare_up_to_frame(X.compute_maps(truth), truth)
    assert exact["max"] < 1e-6


def test_write_rig(tmp_path):
    written = G.write_rig(tmp_path, n=3, seed=5)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted(["left01.png", "left02.png", "left03.png", "right01.png", "right02.png",
                            "right03.png", "rig_calib.yml"])
    assert len(written) == 7
    cal = C.read_yaml(tmp_path / "rig_calib.yml")
    assert np.array_equal(cal.M1, G.eyebot_rig().M1) and cal.rms == 0
    img = cv2.imread(str(tmp_path / "left02.png"), cv2.IMREAD_UNCHANGED)
    assert img.shape == (288, 352) and img.dtype == np.uint8
