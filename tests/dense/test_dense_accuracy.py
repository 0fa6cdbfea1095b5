"""The accuracy tools (tools/dense): measures by hand, the ground truth's occlusion mask, resizing, the
accuracy CLI (bad input: one line, exit 2; a small run writes its section)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from eyestereo.tools.dense import accuracy, datasets, metrics

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
