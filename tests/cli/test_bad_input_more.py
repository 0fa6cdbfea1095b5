"""More bad input on the command line, one test per class of defect (issue 30, "smaller classes";
docs/bad_input.md).

As in ``test_bad_input.py`` (whose helpers are copied here): every refusal asserts the exit status,
the one-line message (the whole of stderr) and that no file was created or changed; the library
functions behind the commands refuse the same input with a one-line ValueError.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.cli import main as cli
from eyestereo.tools.rectify import calib as C
from eyestereo.tools.rectify import calibrations as Q
from eyestereo.tools.rectify import lut as L
from eyestereo.tools.rectify import maps as X
from eyestereo.tools.rectify import polyfit as P
from eyestereo.tools.rectify import rig as G

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="ghdl not installed")


def snapshot(folder: Path) -> dict[str, tuple[str, int]]:
    """Every file and folder below ``folder`` (hidden ones too): content hash and mode."""
    return {str(p.relative_to(folder)): (hashlib.sha1(p.read_bytes()).hexdigest() if p.is_file() else "dir",
                                         p.stat().st_mode & 0o7777) for p in sorted(folder.rglob("*"))}


def run(capfd, *argv) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capfd.readouterr()
    return code, out, err


def refused(capfd, folder: Path, status: int, pieces, *argv) -> str:
    """Run ``argv``; assert the status, one ``eyestereo: error:`` line holding every piece, and ``folder``
    unchanged; the line."""
    before = snapshot(folder)
    code, _, err = run(capfd, *argv)
    one = err.startswith("eyestereo: error: ") and err.count("\n") == 1 and err.endswith("\n")
    pieces = [pieces] if isinstance(pieces, str) else pieces
    assert code == status and one and all(p in err for p in pieces), (argv, code, err)
    assert snapshot(folder) == before, argv
    return err


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """The synthetic rig's calibration (352x288 cameras), its maps at 48x36, a camera image."""
    d = tmp_path_factory.mktemp("world")
    cal = G.eyebot_rig().calibration()
    C.write_yaml(cal, d / "calib.yml")
    X.save_maps(X.compute_maps(cal, size=(48, 36)), d / "maps.npz")
    cv2.imwrite(str(d / "cam.png"), np.full((288, 352), 128, np.uint8))
    return d


@pytest.fixture
def box(world, tmp_path):
    """A fresh copy of the world to run in (its snapshot is what must not change)."""
    shutil.copytree(world, tmp_path / "w")
    return tmp_path / "w"


# --------------------------------------------------------------------------------------------------
# 1. lut --prefix: only prefixes that give usable C names


@pytest.mark.parametrize("prefix, piece", [
    ("int", "prefix 'int' is a C keyword; give a name such as int_lut"),
    ("static", "prefix 'static' is a C keyword"),
    ("for", "prefix 'for' is a C keyword"),
    ("_Bool", "prefix '_Bool' starts with '_': the names made of it (_Bool_left_x, _BOOL_WIDTH) are reserved for "
              "the C compiler and library"),
    ("__x", "prefix '__x' starts with '_'"),
    ("_X", "prefix '_X' starts with '_'"),
    ("int8", "prefix 'int8' would define INT8_WIDTH, a standard C macro (<stdint.h>, <limits.h>)"),
    ("size", "would define SIZE_WIDTH"),
    ("1abc", "prefix must be a C identifier (a letter, then letters, digits or _), got '1abc'"),
    ("my-lut", "prefix must be a C identifier"),
    ("lut\n", "prefix must be a C identifier"),
    ("a" * 50, "has 50 characters; at most 49"),
])
def test_lut_refuses_prefixes_that_give_no_usable_c_names(capfd, box, prefix, piece):
    """A keyword, a reserved ``_`` name, a clash with a standard macro (``int8`` -> ``INT8_WIDTH``, which
    the header's own ``<stdint.h>`` defines under -std=c2x) or no identifier at all: exit 2 from argparse,
    and a ValueError from the writer for library users."""
    refused(capfd, box, 2, ["argument --prefix: ", piece], "lut", box / "maps.npz", "--prefix", prefix, "-o",
            box / "lut.h")
    with pytest.raises(ValueError, match="prefix") as info:
        L.create_c_lut(X.load_maps(box / "maps.npz"), box / "lib.h", prefix=prefix)
    assert "\n" not in str(info.value) and not (box / "lib.h").exists()


def test_lut_keeps_ordinary_prefixes(capfd, box):
    for prefix in ("eyestereo_lut", "rl", "Lut2", "int_lut", "x_", "integer", "a" * 49):
        code, _, err = run(capfd, "lut", box / "maps.npz", "--prefix", prefix, "-o", box / "lut.h")
        assert code == 0 and err == "", (prefix, err)
        assert f"static const int16_t {prefix}_left_x[{prefix.upper()}_HEIGHT" in (box / "lut.h").read_text()


# --------------------------------------------------------------------------------------------------
# 2. Maps with infinite entries: refused wherever maps come in; NaN keeps marking "no source pixel"


def _maps_with(box: Path, name: str, edits: dict[str, list[tuple[int, int, float]]], **extra) -> Path:
    """``box/maps.npz`` with ``edits`` (map -> [(y, x, value)]) as ``box/name``."""
    maps = X.load_maps(box / "maps.npz")
    arrays = {k: getattr(maps, k).copy() for k in X.MAP_KEYS}
    for k, entries in edits.items():
        for y, x, v in entries:
            arrays[k][y, x] = v
    np.savez(box / name, **arrays, **{"K": maps.K, "image_size": np.array(maps.source_size), **extra})
    return box / name


@pytest.mark.parametrize("argv", [
    ["fit", "{m}", "-o", "{d}/p.json"],
    ["lut", "{m}", "-o", "{d}/l.h"],
    ["warp", "{d}/cam.png", "{m}", "--side", "left", "-o", "{d}/w.png"],
])
def test_maps_with_infinite_entries_are_refused(capfd, box, argv):
    """+-inf is no coordinate and no "no source" mark: fit used to fit the other pixels without a word,
    lut to write INVALID codes and warp black pixels for it."""
    bad = _maps_with(box, "inf.npz", {"left_x": [(2, 4, np.inf), (5, 1, -np.inf), (7, 7, np.inf)],
                                      "right_y": [(0, 3, np.inf)], "left_y": [(1, 1, np.nan)]})
    want = (f"{bad}: map left_x holds 3 infinite entries (the first at x=4, y=2), map right_y holds 1 infinite "
            f"entry (the first at x=3, y=0): a map entry is a source coordinate, or NaN for a pixel without a "
            f"source")
    line = refused(capfd, box, 1, want, *(a.format(d=box, m=bad) for a in argv))
    assert line == f"eyestereo: error: {want}\n"


def test_map_libraries_refuse_infinite_entries_and_keep_nan(capfd, box):
    maps = X.load_maps(box / "maps.npz")
    right_x = maps.right_x.copy()
    maps.right_x[3, 2] = -np.inf  # set after Maps checked its arrays
    for call in (lambda: P.fit(maps, 3), lambda: L.create_c_lut(maps, box / "lib.h")):
        with pytest.raises(ValueError, match=r"^map right_x holds 1 infinite entry \(the first at x=2, y=3\)"):
            call()
    assert not (box / "lib.h").exists()
    with pytest.raises(ValueError, match="^map right_x holds 1 infinite entry"):
        X.Maps(maps.left_x, maps.left_y, maps.right_x, maps.right_y)
    maps.right_x[:] = right_x
    # NaN still means "no source pixel": fitted around, written as INVALID
    nan = _maps_with(box, "nan.npz", {"left_x": [(2, 4, np.nan), (3, 3, np.nan)]})
    code, _, err = run(capfd, "fit", nan, "-o", box / "p.json")
    assert code == 0, err
    assert json.loads((box / "p.json").read_text())["report"]["pixels"] == 48 * 36 - 2
    code, _, err = run(capfd, "lut", nan, "-o", box / "l.h")
    assert code == 0 and ",-32768," in (box / "l.h").read_text(), err
    # the matrices of a maps file must be finite
    k_nan = _maps_with(box, "k.npz", {}, K=np.full((3, 3), np.nan))
    refused(capfd, box, 1, f"{k_nan}: K must hold finite numbers", "fit", k_nan, "-o", box / "p2.json")


# --------------------------------------------------------------------------------------------------
# 3. Calibration specs: sides within the rectifier hardware's 2..4096, checked before anything is built


@pytest.mark.parametrize("spec", ["rig:100000x100000", "rig:4097x288", "seed:1@352x5000", "seed:2:1@1x10",
                                  "rig:" + "9" * 5000 + "x2", "rig:0x0"])
def test_calibration_spec_sizes_are_bounded(spec, monkeypatch, tmp_path):
    """``rig:100000x100000`` used to end in a MemoryError, ``seed:1@352x5000`` to build a calibration the
    hardware cannot take (its fetch port and counters stop at 4096)."""
    monkeypatch.setenv("EYESTEREO_CACHE", str(tmp_path / "cache"))
    with pytest.raises(ValueError) as info:
        Q.load(spec)
    text = str(info.value)
    assert text.startswith("bad size '") and "\n" not in text
    assert text.endswith("': want WxH with 2..4096 pixels a side (the rectifier hardware's frame limit)")
    assert not (tmp_path / "cache").exists()


def test_calibration_spec_sizes_at_the_limits():
    assert Q._parse("rig:4096x2") == ("rig", dict(width=4096, height=2))
    assert Q._parse("seed:3:0.5@2x4096") == ("seed", dict(seed=3, spread=0.5, width=2, height=4096))


# --------------------------------------------------------------------------------------------------
# 4. rectifier --vhdl: --frac, and everything that can be checked before the toolbox's run


@needs_ghdl
@pytest.mark.sim
def test_rectifier_vhdl_names_the_bound_and_takes_frac(capfd, box):
    """A tight bound gives q24 more fraction bits than the interpolation takes (8): one line naming the
    bound and suggesting --frac, nothing written and nothing printed on stdout; --frac 8 makes it."""
    argv = ["rectifier", box / "calib.yml", "--size", "40x24", "--max-error", "1e-6", "-o", box / "rect", "--vhdl"]
    before = snapshot(box)
    code, out, err = run(capfd, *argv)
    assert code == 1 and out == "" and snapshot(box) == before, (code, out, err)
    assert err == ("eyestereo: error: --max-error 1e-06 (mse) gives the rectifier's coordinates 11 fraction bits "
                   "(q24's); its interpolation takes at most 8: give --frac 8 (or fewer) or a looser --max-error; "
                   "nothing written\n")
    code, out, err = run(capfd, *argv, "--frac", "8")
    assert code == 0, err
    assert json.loads((box / "rect" / "vhdl" / "rectifier.json").read_text())["frac"] == 8
    assert f"-> {box / 'rect'}/vhdl/" in out


@pytest.mark.parametrize("extra, piece", [
    (["--vhdl", "--frac", "9"], "argument --frac: --frac must lie in 0..8, got 9"),
    (["--vhdl", "--frac", "x"], "argument --frac: not an integer: 'x'"),
    (["--frac", "5"], "argument --frac: only with --vhdl"),
    (["--vhdl", "--degree", "2"], "argument --vhdl: the rectifier's VHDL needs --degree 3, got --degree 2"),
])
def test_rectifier_vhdl_checks_its_options_before_the_run(capfd, box, monkeypatch, extra, piece):
    from eyestereo.tools.rectify import run as R

    monkeypatch.setattr(R, "run_all", lambda *a, **k: pytest.fail("the toolbox ran"))
    refused(capfd, box, 2, piece, "rectifier", box / "calib.yml", "-o", box / "rect", *extra)


@needs_ghdl
def test_rectifier_vhdl_checks_ghdl_and_the_calibration_before_the_run(capfd, box, monkeypatch):
    from eyestereo.tools.rectify import run as R

    monkeypatch.setattr(R, "run_all", lambda *a, **k: pytest.fail("the toolbox ran"))
    refused(capfd, box, 1, f"calibration file {box / 'nothere.yml'} does not exist", "rectifier",
            box / "nothere.yml", "-o", box / "rect", "--vhdl")
    cal = C.read_yaml(box / "calib.yml")
    cal.image_width = 5000
    C.write_yaml(cal, box / "wide.yml")
    refused(capfd, box, 1, "wide.yml: camera images of 5000x288; the rectifier's fetch port takes 2..4096 pixels a "
            "side", "rectifier", box / "wide.yml", "-o", box / "rect", "--vhdl")
    monkeypatch.setattr(shutil, "which", lambda name: None)
    refused(capfd, box, 1, "ghdl not found: install GHDL", "rectifier", box / "calib.yml", "-o", box / "rect",
            "--vhdl")
