"""``eyestereo rectifier`` / ``rectifier.run_all``: the whole toolbox in one run (the thesis's run_all).

End to end on (a) the synthetic rig's true calibration at 352x288 and (b) the real OpenCV stereo
pairs' calibration at 640x480; each run is made once per module. Then the degree-2/4 runs, the
all-or-nothing output folder and every kind of bad input.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.rectify import calib as C
from eyestereo.tools.cli import main as cli
from eyestereo.tools.rectify import rig as G
from eyestereo.tools.rectify.run import OUTPUT_FILES, PLOT_FILES, run_all

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(__file__).resolve().parents[2].parent / "shared"))
DATA = SHARED / "data" / "opencv_stereo_calib"
MAP_KEYS = ("left_x", "left_y", "right_x", "right_y")
# thesis eq. 4.1: p1..p10 multiply 1, x, y, x^2, y^2, xy, x^3, y^3, x^2y, xy^2
EXPONENTS = [(0, 0), (1, 0), (0, 1), (2, 0), (0, 2), (1, 1), (3, 0), (0, 3), (2, 1), (1, 2)]


def run(capsys, *argv) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def opencv_maps(cal: C.StereoCalibration, size: tuple[int, int]) -> dict[str, np.ndarray]:
    """The maps by OpenCV's own functions: an implementation independent of tools/rectify.py."""
    R1, R2, P1, P2, *_ = cv2.stereoRectify(cal.M1, cal.D1, cal.M2, cal.D2, cal.image_size, cal.R,
                                           cal.T.reshape(3, 1), flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1,
                                           newImageSize=size)
    lx, ly = cv2.initUndistortRectifyMap(cal.M1, cal.D1, R1, P1, size, cv2.CV_32FC1)
    rx, ry = cv2.initUndistortRectifyMap(cal.M2, cal.D2, R2, P2, size, cv2.CV_32FC1)
    return dict(zip(MAP_KEYS, (lx, ly, rx, ry)))


def poly_by_hand(c: list[float], w: int, h: int) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    return sum(ck * x**i * y**j for ck, (i, j) in zip(c, EXPONENTS))


def vhdl_codes(text: str) -> dict[str, list[int]]:
    """Coefficient codes from the package text: ``constant LEFT_X_P3 : q3_t := to_signed(-123, Q3_WL);``."""
    codes: dict[str, dict[int, int]] = {}
    for name, i, _kind, val, bkind, bits in re.findall(
            r"constant (LEFT_X|LEFT_Y|RIGHT_X|RIGHT_Y)_P(\d+) : q\d+_t := "
            r"(?:to_(signed|unsigned)\((-?\d+), Q\d+_WL\)|(signed|unsigned)'\(\"([01]+)\"\))", text):
        if bits:
            v = int(bits, 2)
            v -= (1 << len(bits)) if bkind == "signed" and bits[0] == "1" else 0
        else:
            v = int(val)
        codes.setdefault(name.lower(), {})[int(i)] = v
    return {k: [d[i] for i in range(1, 11)] for k, d in codes.items()}


# --------------------------------------------------------------------------------------------------
# One run per data set


@pytest.fixture(scope="module")
def rig_run(tmp_path_factory):
    """``eyestereo rig`` writes the true calibration; ``eyestereo rectifier`` runs on it (352x288)."""
    base = tmp_path_factory.mktemp("rig")
    assert cli.main(["rig", "-o", str(base / "rig"), "--views", "1"]) == 0
    calib = base / "rig" / "rig_calib.yml"
    code = cli.main(["rectifier", str(calib), "-o", str(base / "out"), "--degree", "3", "--max-error", "0.01"])
    assert code == 0
    return calib, base / "out", 0.01


@pytest.fixture(scope="module")
def real_run(tmp_path_factory):
    """The real OpenCV pairs calibrated through the module API, then ``run_all`` at 640x480."""
    if not DATA.is_dir():
        pytest.skip(f"shared calibration images not found at {DATA}")
    base = tmp_path_factory.mktemp("real")
    cal = C.calibrate_stereo(str(DATA / "left*.jpg"), str(DATA / "right*.jpg"), board=(9, 6), square=0.025)
    C.write_yaml(cal, base / "calib.yml")
    res = run_all(base / "calib.yml", base / "out", progress=False)
    return base / "calib.yml", base / "out", res


def check_outputs(calib_path: Path, out: Path, size: tuple[int, int], bound: float, fit_bound: float) -> None:
    w, h = size
    cal = C.read_yaml(calib_path)
    # every file, nothing else (no temporary files either), nothing beside the folder
    assert tree(out) == sorted([*OUTPUT_FILES, "plots", *(f"plots/{p}" for p in PLOT_FILES)])
    assert not [p for p in out.parent.iterdir() if p.name.startswith(".")]
    for p in PLOT_FILES:
        assert (out / "plots" / p).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    umask = os.umask(0o022)
    os.umask(umask)
    for p in out.rglob("*"):  # modes of a plain write (mkstemp alone would give 0600 / 0700)
        assert p.stat().st_mode & 0o777 == (0o777 if p.is_dir() else 0o666) & ~umask, p
    assert out.stat().st_mode & 0o777 == 0o777 & ~umask
    # maps.npz: four float (h, w) arrays, matching OpenCV's independent construction
    ref = opencv_maps(cal, size)
    with np.load(out / "maps.npz") as z:
        maps = {k: z[k] for k in MAP_KEYS}
    for k in MAP_KEYS:
        assert maps[k].shape == (h, w) and maps[k].dtype.kind == "f", k
        assert np.abs(maps[k] - ref[k]).max() < 0.15, k  # OpenCV's rougher principal point (docs: < 0.09)
    # poly.json: degree 3, and the polynomials, evaluated here by hand, follow the maps
    poly = json.loads((out / "poly.json").read_text())
    assert (poly["width"], poly["height"], poly["degree"]) == (w, h, 3)
    for k in MAP_KEYS:
        resid = np.abs(poly_by_hand(poly["polynomials"][k], w, h) - maps[k])
        assert resid.mean() < fit_bound, (k, resid.mean())
    # quantizers.json: 26 merged quantizers; the codes are those of the polynomials and of the package
    q = json.loads((out / "quantizers.json").read_text())
    assert [x["name"] for x in q["quantizers"]] == [f"q{i}" for i in range(1, 27)]
    assert (q["width"], q["height"], q["max_error"], q["measure"]) == (w, h, bound, "mse")
    assert q["total_bits"] == sum(x["wl"] for x in q["quantizers"])
    for k in MAP_KEYS:
        codes = q["polynomials"][k]["codes"]
        for c, x, p in zip(codes, q["quantizers"][:10], poly["polynomials"][k]):
            lo, hi = (-(1 << (x["wl"] - 1)), (1 << (x["wl"] - 1)) - 1) if x["signed"] else (0, (1 << x["wl"]) - 1)
            assert lo <= c <= hi
            assert c == int(np.floor(p * 2.0 ** x["fl"]))  # floor rounding of the coefficient
    vhd = (out / "stereo_calibration_pkg.vhd").read_text()
    assert vhdl_codes(vhd) == {k: q["polynomials"][k]["codes"] for k in MAP_KEYS}
    assert f"IMAGE_WIDTH  : integer := {w};" in vhd and f"IMAGE_HEIGHT : integer := {h};" in vhd
    for i, x in enumerate(q["quantizers"], 1):
        assert f"constant Q{i}_WL     : integer := {x['wl']};" in vhd
    if shutil.which("ghdl"):
        work = out.parent / "ghdl"
        work.mkdir(exist_ok=True)
        r = subprocess.run(["ghdl", "-a", "--std=08", f"--workdir={work}", str(out / "stereo_calibration_pkg.vhd")],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
    # report.txt: the size, the achieved errors (those of quantizers.json) within the bound, the bits
    rep = (out / "report.txt").read_text()
    assert f"rectified images: {w}x{h}" in rep
    achieved = {m[0]: (float(m[1]), float(m[2])) for m in
                re.findall(r"^\s+(left_x|left_y|right_x|right_y)\s+(\S+) <= (\S+)\s", rep, re.M)}
    assert sorted(achieved) == sorted(MAP_KEYS), rep
    for k, (e, b) in achieved.items():
        assert b == bound and 0 < e <= bound
        assert e == pytest.approx(q["errors"]["merged"][k], rel=1e-5)
    assert f"total {q['total_bits']} bits" in rep
    assert "degree 3" in rep and "none" in rep and "timings (s):" in rep
    assert len(rep.splitlines()) < 40  # short


def test_rig_run_is_complete_and_consistent(rig_run):
    calib, out, bound = rig_run
    check_outputs(calib, out, (352, 288), bound, fit_bound=0.05)
    print("\n" + (out / "report.txt").read_text().splitlines()[-1])


def test_real_run_is_complete_and_consistent(real_run):
    calib, out, res = real_run
    check_outputs(calib, out, (640, 480), 0.01, fit_bound=0.5)
    assert res["ffc"] is not None and res["width"] == 640 and set(res["files"]) == set(
        [*OUTPUT_FILES, *(f"plots/{p}" for p in PLOT_FILES)])
    print(f"\nreal 640x480 run: {res['timings']['total']:.1f} s "
          f"({', '.join(f'{k} {v:.2f}' for k, v in res['timings'].items())})")


def test_other_degrees_write_no_ffc_and_say_why(rig_run, tmp_path):
    calib, _, _ = rig_run
    for degree in (2, 4):
        out = tmp_path / f"d{degree}"
        res = run_all(calib, out, degree=degree, progress=False)
        assert tree(out) == sorted(["maps.npz", "poly.json", "report.txt", "plots",
                                    *(f"plots/{p}" for p in PLOT_FILES)])
        assert res["ffc"] is None
        assert json.loads((out / "poly.json").read_text())["degree"] == degree
        rep = (out / "report.txt").read_text()
        assert "need degree 3" in rep and f"degree {degree}" in rep


def test_size_option_rectifies_to_another_size(rig_run, tmp_path, capsys):
    calib, _, _ = rig_run
    code, out, err = run(capsys, "rectifier", calib, "-o", tmp_path / "half", "--size", "176x144", "--degree", "2")
    assert code == 0, err
    with np.load(tmp_path / "half" / "maps.npz") as z:
        assert z["left_x"].shape == (144, 176)
        # the rectified image is scaled, the camera image is not: sources still span the 352x288 image
        assert z["left_x"].max() > 300
    assert "rectified images: 176x144" in (tmp_path / "half" / "report.txt").read_text()


def test_an_earlier_run_is_replaced_only_on_success(rig_run, tmp_path, capsys):
    calib, done, _ = rig_run
    out = tmp_path / "out"
    shutil.copytree(done, out)
    before = snapshot(out)
    # a failing run leaves the earlier output untouched
    code, _, err = run(capsys, "rectifier", calib, "-o", out, "--max-error", "1e-12", "--high", "2")
    assert code == 1 and err.count("\n") == 1 and "cannot be met" in err
    assert snapshot(out) == before
    # a successful degree-4 run replaces it as a whole: no stale quantizers.json or package
    code, _, err = run(capsys, "rectifier", calib, "-o", out, "--degree", "4")
    assert code == 0, err
    assert "quantizers.json" not in tree(out) and json.loads((out / "poly.json").read_text())["degree"] == 4
    assert "note: no FFC" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no hidden leftovers


def test_progress_bar_when_asked(rig_run, tmp_path, capsys):
    calib, _, _ = rig_run
    run_all(calib, tmp_path / "o", degree=2, progress=True)
    err = capsys.readouterr().err
    assert "rectifier: plots" in err and "rectifier: report" in err and "/5 [" in err  # tqdm, one step each


# --------------------------------------------------------------------------------------------------
# Bad input: one line, non-zero exit, no output folder (or the old one untouched)


@pytest.fixture
def bad_inputs(tmp_path):
    C.write_yaml(G.eyebot_rig().calibration(), tmp_path / "calib.yml")
    (tmp_path / "corrupt.yml").write_text("%YAML:1.0\nM1: [ 1, 2\n")
    (tmp_path / "nokey.yml").write_text((tmp_path / "calib.yml").read_text().replace("R:", "Rx:"))
    (tmp_path / "keep").mkdir()
    (tmp_path / "keep" / "notes.txt").write_text("mine")
    (tmp_path / "afile").write_text("x")
    return tmp_path


BAD = {
    "missing calib": (["{d}/none.yml", "-o", "{d}/out"], 1, "does not exist"),
    "corrupt yaml": (["{d}/corrupt.yml", "-o", "{d}/out"], 1, "corrupt.yml"),
    "yaml without R": (["{d}/nokey.yml", "-o", "{d}/out"], 1, "key 'R' is missing"),
    "unreachable bound": (["{d}/calib.yml", "-o", "{d}/out", "--max-error", "1e-12", "--high", "2"], 1,
                          "cannot be met with up to H=2"),
    "foreign files in OUTDIR": (["{d}/calib.yml", "-o", "{d}/keep"], 1, "notes.txt"),
    "OUTDIR is a file": (["{d}/calib.yml", "-o", "{d}/afile"], 1, "not a folder"),
    "OUTDIR parent missing": (["{d}/calib.yml", "-o", "{d}/a/b"], 1, "does not exist"),
    "OUTDIR is ..": (["{d}/calib.yml", "-o", "{d}/keep/.."], 1, "must be named"),
    "bad degree": (["{d}/calib.yml", "-o", "{d}/out", "--degree", "5"], 2, "invalid choice"),
    "bad bound": (["{d}/calib.yml", "-o", "{d}/out", "--max-error", "-1"], 2, "positive"),
    "bad size": (["{d}/calib.yml", "-o", "{d}/out", "--size", "0x3"], 2, "size must be WxH"),
    "missing -o": (["{d}/calib.yml"], 2, "required"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_gives_one_line_and_no_output(bad_inputs, capsys, case):
    argv, status, piece = BAD[case]
    before = snapshot(bad_inputs)
    names = tree(bad_inputs)
    code, out, err = run(capsys, "rectifier", *(a.format(d=bad_inputs) for a in argv))
    assert code == status
    assert err.startswith("eyestereo: error: ") and err.count("\n") == 1 and "Traceback" not in err, err
    assert piece in err, err
    assert tree(bad_inputs) == names and snapshot(bad_inputs) == before  # no OUTDIR, no hidden folder


def test_api_refuses_bad_arguments_before_writing(tmp_path):
    C.write_yaml(G.eyebot_rig().calibration(), tmp_path / "calib.yml")
    for kw, piece in (({"degree": 5}, "degree"), ({"method": "lut"}, "method"),
                      ({"method": "opencv", "focal": "min"}, "focal"), ({"measure": "rms"}, "measure")):
        with pytest.raises(ValueError, match=piece):
            run_all(tmp_path / "calib.yml", tmp_path / "out", progress=False, **kw)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["calib.yml"]
