"""``eyestereo evaluate`` / ``eyestereo sweep`` (tools/cli/matching.py, tools/matching/evaluate.py): end to end and
every kind of bad input; the ground truth scores only."""

from __future__ import annotations

import os
import argparse
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

import eyestereo.tools
from eyestereo.tools.cli import main as cli
from eyestereo.tools.cli import matching as E
from eyestereo.tools.matching import evaluate as V

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(eyestereo.tools.__file__).resolve().parents[1].parent / "shared"))
DATA = SHARED / "data" / "middlebury"
needs_middlebury = pytest.mark.skipif(not (DATA / "tsukuba" / "im3.png").is_file(),
                                      reason=f"Middlebury images not found at {DATA}")


def run(capsys, *argv) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def dots(h, w, seed, dot=2):
    rng = np.random.default_rng(seed)
    cells = rng.integers(30, 221, size=(-(-h // dot), -(-w // dot)))
    return np.kron(cells, np.ones((dot, dot), np.int64))[:h, :w].astype(np.uint8)


@pytest.fixture
def synthetic(tmp_path):
    """A random-dot pair shifted by 6 px and its ground truth (PGM, x4, a 0 = unknown stripe)."""
    h, w, d = 64, 96, 6
    base = dots(h, w + d, 2)
    cv2.imwrite(str(tmp_path / "L.png"), base[:, :w])
    cv2.imwrite(str(tmp_path / "R.png"), base[:, d:d + w])
    gt = np.full((h, w), 4 * d, np.uint8)
    gt[:, :10] = 0
    cv2.imwrite(str(tmp_path / "gt.pgm"), gt)
    return tmp_path


def only_inputs(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_evaluate_synthetic_pair_is_perfect(synthetic, capsys):
    j = synthetic / "out.json"
    code, out, err = run(capsys, "evaluate", synthetic / "L.png", synthetic / "R.png", synthetic / "gt.pgm",
                         "--scale", 4, "--json", j, "--corners", 150)
    assert code == 0, err
    doc = json.loads(j.read_text())
    assert {"matches", "good", "bad", "bad_percent", "rms", "seconds"} <= set(doc)
    assert doc["bad"] == 0 and doc["rms"] == 0.0 and doc["bad_percent"] == 0.0
    assert doc["good"] == doc["evaluated"] > 50 and doc["matches"] == doc["evaluated"] + doc["unknown"]
    assert doc["params"]["d_max"] == 96 // 4              # from the image width, not from the ground truth
    assert doc["params"]["cost"] == "ncc" and doc["params"]["lr_check"] is True
    assert 0 < doc["seconds"] < 1 and "bad 0.00 %" in out


@needs_middlebury
def test_evaluate_tsukuba_end_to_end(tmp_path, capsys):
    j, o = tmp_path / "t.json", tmp_path / "png"
    code, out, err = run(capsys, "evaluate", DATA / "tsukuba" / "im3.png", DATA / "tsukuba" / "im4.png",
                         DATA / "tsukuba" / "disp3.pgm", "--scale", 16, "--json", j, "-o", o, "--dense")
    assert code == 0, err
    doc = json.loads(j.read_text())
    assert 450 <= doc["left_corners"] <= 550
    assert doc["good"] + doc["bad"] == doc["evaluated"] and doc["matches"] >= doc["evaluated"] > 200
    assert doc["bad_percent"] == pytest.approx(100 * doc["bad"] / doc["evaluated"], abs=1e-4)
    assert doc["bad_percent"] < 10 and doc["rms"] < 1.5
    assert doc["params"]["d_max"] == 384 // 4 and doc["params"]["window"] == [11, 11]
    assert doc["params"]["ncc_min"] == 0.75 and doc["good"] >= 150
    assert doc["dense"]["evaluated"] > 80000 and doc["dense"]["bad_percent"] > doc["bad_percent"]
    for name in ("matches.png", "disparity.png", "dense.png"):
        img = cv2.imread(str(o / name))
        assert img is not None and img.shape[1] > 384
    assert only_inputs(o) == ["dense.png", "disparity.png", "matches.png"]


def test_sweep_t_max_is_monotone(synthetic, capsys):
    j, p = synthetic / "sweep.json", synthetic / "sweep.png"
    code, out, err = run(capsys, "sweep", synthetic / "L.png", synthetic / "R.png", synthetic / "gt.pgm",
                         "--scale", 4, "--vary", "t_max", "--values", "0.5:3:0.5", "--json", j, "--plot", p,
                         "--corners", 150, "--cost", "sad", "--no-lr-check")
    assert code == 0, err
    rows = json.loads(j.read_text())["rows"]
    assert [r["value"] for r in rows] == [0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    m = [r["matches"] for r in rows]
    assert m == sorted(m) and all(r["bad"] == 0 for r in rows)
    assert cv2.imread(str(p)) is not None
    code, out, err = run(capsys, "sweep", synthetic / "L.png", synthetic / "R.png", synthetic / "gt.pgm",
                         "--scale", 4, "--vary", "window", "--values", "3,5x7,9")
    assert code == 0, err
    assert "5x7" in out and len(out.strip().splitlines()) == 4


def test_register_adds_both_commands():
    parser = argparse.ArgumentParser(prog="eyestereo")
    E.register(parser.add_subparsers(dest="command", required=True))
    a = parser.parse_args(["evaluate", "l.png", "r.png", "gt.pgm", "--scale", "16", "--json", "x.json"])
    assert a.func is E.cmd_evaluate and a.scale == 16 and a.window == (11, 11) and a.t_max == 11
    assert a.cost == "ncc" and a.ncc_min == 0.75 and a.lr_check is True and a.max_disparity is None
    b = parser.parse_args(["sweep", "l", "r", "g", "--vary", "split", "--values", "1,9", "--window", "5x7",
                           "--no-lr-check"])
    assert b.func is E.cmd_sweep and b.window == (5, 7) and b.lr_check is False


def test_the_ground_truth_does_not_change_the_matches(synthetic, tmp_path, capsys):
    """Scoring against a different ground truth gives the same matches: nothing is read from it."""
    import cv2 as _cv2

    other = tmp_path / "gt_other.pgm"
    _cv2.imwrite(str(other), np.full((64, 96), 200, np.uint8))   # disparity 50: all wrong, and a larger range
    docs = []
    for gt in (synthetic / "gt.pgm", other):
        j = tmp_path / f"{gt.stem}.json"
        code, out, err = run(capsys, "evaluate", synthetic / "L.png", synthetic / "R.png", gt, "--scale", 4,
                             "--json", j, "--corners", 150)
        assert code == 0, err
        docs.append(json.loads(j.read_text()))
    assert docs[0]["params"] == docs[1]["params"] and docs[0]["matches"] == docs[1]["matches"]
    assert docs[0]["bad"] == 0 and docs[1]["good"] == 0


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyestereo: error: "), err
    return lines[0]


def test_runtime_errors_exit_1_and_write_nothing(synthetic, capsys):
    L, R, G = synthetic / "L.png", synthetic / "R.png", synthetic / "gt.pgm"
    small = synthetic / "small.png"
    cv2.imwrite(str(small), dots(60, 90, 1))
    bad_gt = synthetic / "gt_small.pgm"
    cv2.imwrite(str(bad_gt), np.full((60, 90), 8, np.uint8))
    before = only_inputs(synthetic)
    j = synthetic / "x.json"
    cases = [
        ((L, small, G), "differ in size"),
        ((L, R, bad_gt), "ground truth is 90x60 but the images are 96x64"),
        ((L, synthetic / "none.png", G), "does not exist"),
        ((L, R, G, "--threshold", 524287), "no corners"),
        ((L, R, G, "--json", synthetic / "no" / "x.json"), "does not exist"),
        ((L, R, G, "--cost", "ncc", "--split", "9"), "split correlation is defined for the SAD and SSD costs only"),
    ]
    for args, msg in cases:
        code, out, err = run(capsys, "evaluate", *args, "--json", j) if "--json" not in args else \
            run(capsys, "evaluate", *args)
        assert code == 1, (args, err)
        assert msg in one_error_line(err)
    (synthetic / "junk.png").write_bytes(b"garbage")
    code, out, err = run(capsys, "evaluate", L, synthetic / "junk.png", G, "--json", j, "-o", synthetic / "o")
    assert code == 1 and "cannot read right image" in one_error_line(err) and "junk.png" in err
    assert only_inputs(synthetic) == sorted(before + ["junk.png"])


def test_usage_errors_exit_2(synthetic, capsys):
    L, R, G = synthetic / "L.png", synthetic / "R.png", synthetic / "gt.pgm"
    for argv in [("evaluate", L, R), ("evaluate", L, R, G, "--window", "4"), ("evaluate", L, R, G, "--t-max", "-1"),
                 ("evaluate", L, R, G, "--split", "3"), ("evaluate", L, R, G, "--scale", "0"),
                 ("sweep", L, R, G, "--vary", "t_max", "--values", "a,b"),
                 ("sweep", L, R, G, "--vary", "window", "--values", "4x4"),
                 ("sweep", L, R, G, "--vary", "nothing", "--values", "1")]:
        code, out, err = run(capsys, *argv)
        assert code == 2, (argv, err)
        one_error_line(err)


def test_parse_values():
    assert V.parse_values("ncc_min", "0.7:0.8:0.05") == [0.7, 0.75, 0.8]
    assert V.parse_values("t_max", "9:13:2") == [9.0, 11.0, 13.0]
    assert V.parse_values("window", "5x7, 9") == [(5, 7), (9, 9)]
    assert V.parse_values("split", "1,5,9") == [1, 5, 9]
    assert V.parse_values("rows", "0:2") == [0, 1, 2]
    with pytest.raises(ValueError, match="split"):
        V.parse_values("split", "3")
    with pytest.raises(ValueError, match="positive step"):
        V.parse_values("t_max", "5:1")
