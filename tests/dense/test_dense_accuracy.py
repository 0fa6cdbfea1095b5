"""The accuracy tools (tools/dense): measures by hand, the ground truth's occlusion mask, the holes' background
interpolation, resizing, the accuracy CLI (bad input: one line, exit 2; a small run writes its section), the
pictures (files, layout, colours, sizes, a bad folder refused)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.dense import accuracy, datasets, metrics, pictures

PICTURES = Path(__file__).resolve().parents[2] / "docs" / "img" / "dense"

needs_data = pytest.mark.skipif(not (datasets.data_dir() / "middlebury" / "tsukuba" / "im3.png").is_file(),
                                reason="Middlebury pairs not in the shared data folder")


def test_visible_mask_by_hand():
    gt = np.full((1, 20), 2.0)
    gt[0, 10:] = 6.0  # a near surface from x = 10: it lands on right columns 4.., over the background's 6..9
    gt[0, 15] = np.nan
    vis = metrics.visible_mask(gt)[0]
    expected = np.ones(20, bool)
    expected[:2] = False      # x - 2 < 0: outside the right image
    expected[6:10] = False    # background hidden by the near surface
    expected[15] = False      # unknown
    assert vis.tolist() == expected.tolist()


def test_scores_by_hand():
    gt = np.full((2, 5), 5.0)
    gt[1, 4] = np.nan
    est = np.array([[5.0, 6.5, 8.0, 10.0, np.nan], [5.0, 5.0, 5.0, 2.5, 9.0]])
    vis = np.ones_like(gt, bool)
    s = metrics.scores(est, gt, visible=vis)
    # 9 known pixels, 8 with an estimate; errors 0, 1.5, 3, 5, 0, 0, 0, 2.5
    assert s["bad1_noc"] == pytest.approx(100 * 4 / 8) and s["bad2_noc"] == pytest.approx(100 * 3 / 8)
    assert s["bad4_all"] == pytest.approx(100 * 1 / 8)
    assert s["density"] == pytest.approx(100 * 8 / 9)
    assert s["bad2_filled"] == pytest.approx(100 * 4 / 9)
    assert s["rms"] == pytest.approx(np.sqrt((1.5 ** 2 + 9 + 25 + 2.5 ** 2) / 8))
    vis[0, :3] = False
    assert metrics.scores(est, gt, visible=vis)["bad2_noc"] == pytest.approx(100 * 2 / 5)
    with pytest.raises(ValueError, match="differ in size"):
        metrics.scores(est[:, :4], gt)
    with pytest.raises(ValueError, match="negative"):
        metrics.visible_mask(-gt)


def test_fill_background_by_hand():
    nan = np.nan
    row = np.array([[nan, 3.0, nan, nan, 7.0, nan, 5.0, nan]])
    # ends: the nearest valid value; between 3 and 7: the smaller, 3; between 7 and 5: 5
    assert metrics.fill_background(row).tolist() == [[3.0, 3.0, 3.0, 3.0, 7.0, 5.0, 5.0, 5.0]]
    assert np.isnan(row[0, 0])  # the input is left alone
    grid = np.array([[nan, nan, nan],
                     [2.0, nan, 4.0],
                     [nan, nan, nan],
                     [nan, 6.0, nan],
                     [nan, nan, nan]])
    # rows 1 and 3 filled along the row; the empty rows from their columns: row 0 from row 1 (top end),
    # row 2 the smaller of rows 1 and 3, row 4 from row 3 (bottom end)
    assert metrics.fill_background(grid).tolist() == [[2.0, 2.0, 4.0], [2.0, 2.0, 4.0], [2.0, 2.0, 4.0],
                                                      [6.0, 6.0, 6.0], [6.0, 6.0, 6.0]]
    assert np.isnan(metrics.fill_background(np.full((2, 3), nan))).all()
    with pytest.raises(ValueError, match="2-D"):
        metrics.fill_background(np.zeros(4))


def test_bad2_interpolated_by_hand():
    nan = np.nan
    gt = np.array([[4.0, 4.0, 4.0, 9.0, 9.0, 9.0]] * 2)
    est = np.array([[4.0, nan, nan, 9.0, nan, 9.0],    # holes in the background: filled right
                    [nan, 4.0, 4.0, nan, 9.0, 9.0]])   # x = 3 filled with 4 (the farther side), truth 9: bad
    s = metrics.scores(est, gt, visible=np.ones_like(gt, bool))
    assert s["bad2_noc"] == 0.0
    assert s["bad2_filled"] == pytest.approx(100 * 5 / 12)   # the five holes
    assert s["bad2_interp"] == pytest.approx(100 * 1 / 12)
    vis = np.ones_like(gt, bool)
    vis[1, 3] = False  # the one bad filled pixel left out of noc
    assert metrics.scores(est, gt, visible=vis)["bad2_interp"] == 0.0
    assert metrics.scores(np.full_like(gt, nan), gt, visible=np.ones_like(gt, bool))["bad2_interp"] == 100.0


def test_resize_scales_disparities_with_the_width():
    rng = np.random.default_rng(0)
    img = rng.integers(0, 256, (40, 80), dtype=np.uint8)
    gt = np.full((40, 80), 8.0)
    gt[:, :5] = np.nan
    small = datasets.resize(datasets.Pair("x", img, img, gt), 40, 30)
    assert small.left.shape == (30, 40) and small.size == "40x30"
    assert np.nanmax(small.gt) == 4.0 and np.isnan(small.gt[:, 0]).all()
    assert datasets.disparity_range(small) == 64
    assert datasets.disparity_range(datasets.Pair("y", img, img, gt * 10)) == 96
    with pytest.raises(ValueError, match="at least 8x8"):
        datasets.resize(small, 4, 30)
    with pytest.raises(ValueError, match="unknown pair 'kitti'"):
        datasets.load("kitti")


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "eyestereo.tools.dense.accuracy", *map(str, args)],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("args", [("--pairs", "kitti"), ("--sizes", "huge"), ("--pairs", ","),
                                  ("--bogus",)])
def test_cli_bad_input_one_line(args):
    r = run_cli(*args)
    assert r.returncode == 2 and r.stdout == ""
    assert len(r.stderr.strip().splitlines()) == 1 and "error:" in r.stderr


def test_cli_pictures_refused_one_line(tmp_path):
    r = run_cli("--pictures", tmp_path / "pics", "--out", tmp_path / "dense.md")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "--pictures" in r.stderr
    (tmp_path / "a_file").write_text("x")
    r = run_cli("--pictures", tmp_path / "a_file")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "is a file" in r.stderr


def test_cli_page_without_markers(tmp_path):
    page = tmp_path / "dense.md"
    page.write_text("# no section here\n")
    r = run_cli("--out", page, "--no-cuts")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "dense_accuracy" in r.stderr
    r = run_cli("--out", tmp_path / "missing.md")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


@needs_data
def test_cli_writes_its_section(tmp_path):
    page = tmp_path / "dense.md"
    page.write_text(f"# intro\n\n{accuracy.BEGIN}\nstale-section-xyz\n{accuracy.END}\ntail\n")
    assert accuracy.main(["--out", str(page), "--pairs", "tsukuba", "--sizes", "cif", "--no-cuts"]) == 0
    text = page.read_text()
    assert "stale-section-xyz" not in text and text.endswith(f"{accuracy.END}\ntail\n")
    assert "### tsukuba 352x288, D = 64" in text and "| bit-true model |" in text and "| OpenCV StereoBM |" in text
    row = next(line for line in text.splitlines() if line.startswith("| tsukuba | 352x288 |"))
    ours, sgbm = (float(c) for c in row.split("|")[3:5])
    assert ours <= sgbm + 2  # the goal on this pair


def synthetic_pair() -> datasets.Pair:
    """A random texture and its copy 5 px to the left; ground truth 5 px, unknown in the first 3 columns."""
    rng = np.random.default_rng(1)
    left = cv2.GaussianBlur(rng.integers(0, 256, (64, 96), dtype=np.uint8), (3, 3), 0)
    right = np.roll(left, -5, axis=1)
    gt = np.full(left.shape, 5.0)
    gt[:, :3] = np.nan
    return datasets.Pair("synthetic", left, right, gt)


def test_picture_writer(tmp_path):
    pair = synthetic_pair()
    paths = accuracy.write_pictures(tmp_path / "pics", [pair], disparities=16)
    assert paths == [tmp_path / "pics" / "synthetic.png"]
    data = paths[0].read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) < 300_000
    img = cv2.imread(str(paths[0]))  # BGR
    h, w = pair.left.shape
    panels = 5  # left image, ground truth, ours, SGBM, BM
    assert img.shape == (pictures.LABEL_HEIGHT + h + pictures.GAP + pictures.STRIP_HEIGHT,
                         pictures.GAP + panels * (w + pictures.GAP), 3)
    # the ground truth panel: unknown columns black, the rest 5 px = the top of the scale (vmax = 5):
    # OpenCV's turbo colour of level 255
    x0, y = pictures.GAP + (w + pictures.GAP), pictures.LABEL_HEIGHT + h // 2
    top = cv2.applyColorMap(np.array([[255]], np.uint8), cv2.COLORMAP_TURBO)[0, 0]
    assert img[y, x0:x0 + 3].tolist() == [[0, 0, 0]] * 3
    assert img[y, x0 + 3:x0 + w].tolist() == [top.tolist()] * (w - 3)
    # the left image panel is the image in 128 grey levels (within half a step of 255 / 127)
    left_panel = img[pictures.LABEL_HEIGHT:pictures.LABEL_HEIGHT + h, pictures.GAP:pictures.GAP + w, 1]
    assert np.abs(left_panel.astype(int) - pair.left).max() <= 1
    # the same maps give the same bytes
    assert accuracy.write_pictures(tmp_path / "again", [pair], disparities=16)[0].read_bytes() == data


def test_picture_folder_refused_one_line(tmp_path):
    (tmp_path / "a_file").write_text("x")
    for bad, why in ((tmp_path / "a_file", "is a file"), (tmp_path / "no" / "such", "neither does its parent")):
        with pytest.raises(ValueError, match=why) as e:
            accuracy.write_pictures(bad, [synthetic_pair()], disparities=16)
        assert "\n" not in str(e.value)
    assert not (tmp_path / "no").exists()


def test_committed_pictures_are_small():
    files = sorted(PICTURES.glob("*.png"))
    assert [f.stem for f in files] == sorted(datasets.PAIRS)
    assert all(f.stat().st_size < 300_000 for f in files)


@needs_data
def test_committed_pictures_are_the_modules(tmp_path):
    assert accuracy.main(["--pictures", str(tmp_path), "--pairs", "tsukuba"]) == 0
    made, committed = (cv2.imread(str(p / "tsukuba.png")) for p in (tmp_path, PICTURES))
    assert made is not None and committed is not None and np.array_equal(made, committed)
