"""VHDL package of the quantizers (eyestereo.tools.rectify.vhdl_package) and the ``package`` command.

The package must analyse in GHDL under VHDL-93 (``--std=93c``) and VHDL-2008, and its constants
must be the JSON's formats and codes: checked by parsing the text back and by a GHDL testbench
comparing every constant with a bit string computed here from the JSON.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from eyestereo.tools.cli import main as cli_main
from eyestereo.tools.rectify import ffc, vhdl_package
from eyestereo.tools.reports.bench_ffc import synthetic_rig_polynomials
from eyestereo.tools.fixed import Fmt

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")

W, H = 48, 40


@pytest.fixture(scope="module")
def result():
    return ffc.run_ffc(synthetic_rig_polynomials(W, H), W, H, max_error=0.01)


@pytest.fixture()
def qjson(result, tmp_path):
    path = tmp_path / "quantizers.json"
    ffc.write_quantizers_json(result, path)
    return path


def ghdl(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["ghdl", *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def bits(code: int, wl: int) -> str:
    """Two's complement bit string of a code (written out here, independent of the generator)."""
    return "".join("1" if (code >> i) & 1 else "0" for i in reversed(range(wl)))


def parse_package(text: str) -> tuple[list[Fmt], dict[str, list[int]]]:
    """Formats and coefficient codes read back from the package text."""
    consts = dict(re.findall(r"constant (Q\d+_(?:WL|FL|SIGNED))\s*:\s*\w+ := (\w+|-?\d+);", text))
    subtypes = dict(re.findall(r"subtype q(\d+)_t is (signed|unsigned)\(Q\1_WL - 1 downto 0\);", text))
    fmts = []
    for n in range(1, 27):
        signed = {"true": True, "false": False}[consts[f"Q{n}_SIGNED"]]
        assert subtypes[str(n)] == ("signed" if signed else "unsigned")
        fmts.append(Fmt(signed, int(consts[f"Q{n}_WL"]), int(consts[f"Q{n}_FL"])))
    codes: dict[str, list[int]] = {}
    pat = re.compile(r"constant (\w+)_P(\d+) : q(\d+)_t := (?:to_(un)?signed\((-?\d+), Q\d+_WL\)|"
                     r"(?:un)?signed'\(\"([01]+)\"\));")
    for name, i, q, uns, dec, bitstr in pat.findall(text):
        assert i == q
        f = fmts[int(i) - 1]
        if dec:
            assert (uns == "un") == (not f.signed)
            code = int(dec)
        else:
            assert len(bitstr) == f.wl
            code = int(bitstr, 2)
            if f.signed and code >= 1 << (f.wl - 1):
                code -= 1 << f.wl
        codes.setdefault(name.lower(), []).append(code)
    return fmts, codes


def make_testbench(doc: dict, pkg: str = "stereo_calibration_pkg") -> str:
    lines = ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;", f"use work.{pkg}.all;",
             "entity tb_pkg is", "end entity tb_pkg;", "architecture sim of tb_pkg is", "begin",
             "  process", "  begin"]
    for n, q in enumerate(doc["quantizers"], 1):
        lines.append(f"    assert Q{n}_WL = {q['wl']} and Q{n}_FL = {q['fl']} and "
                     f"Q{n}_SIGNED = {'true' if q['signed'] else 'false'} and q{n}_t'length = {q['wl']} "
                     f"report \"format q{n}\" severity failure;")
    for k, (name, entry) in enumerate(doc["polynomials"].items()):
        for i, code in enumerate(entry["codes"], 1):
            wl = doc["quantizers"][i - 1]["wl"]
            c = f"{name.upper()}_P{i}"
            lines.append(f"    assert std_logic_vector({c}) = \"{bits(code, wl)}\" report \"{c}\" severity failure;")
            lines.append(f"    assert std_logic_vector(P{i}_COEFS({k})) = \"{bits(code, wl)}\" "
                         f"report \"P{i}_COEFS({k})\" severity failure;")
            if abs(code) < 2**31 - 1:
                lines.append(f"    assert to_integer({c}) = {code} report \"{c} value\" severity failure;")
    lines += ["    report \"tb_pkg: all constants match\";", "    wait;", "  end process;", "end architecture sim;"]
    return "\n".join(lines) + "\n"


def check_in_ghdl(pkg_path: Path, doc: dict, work: Path, pkg: str = "stereo_calibration_pkg") -> None:
    tb = work / "tb_pkg.vhd"
    tb.write_text(make_testbench(doc, pkg))
    for std in ("93c", "08"):
        wd = work / f"work{std}"
        wd.mkdir()
        r = ghdl(["-a", f"--std={std}", f"--workdir={wd}", str(pkg_path), str(tb)], work)
        assert r.returncode == 0, f"--std={std}: {r.stderr}"
        r = ghdl(["--elab-run", f"--std={std}", f"--workdir={wd}", "tb_pkg"], work)
        assert r.returncode == 0, f"--std={std}: {r.stdout}{r.stderr}"
        assert "all constants match" in r.stdout + r.stderr


@needs_ghdl
def test_package_analyses_and_matches_json(qjson, tmp_path):
    out = tmp_path / "stereo_calibration_pkg.vhd"
    text = vhdl_package.write_package(qjson, out)
    assert out.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["quantizers.json", "stereo_calibration_pkg.vhd"]
    doc = json.loads(qjson.read_text())
    fmts, codes = parse_package(text)
    assert fmts == [Fmt(q["signed"], q["wl"], q["fl"]) for q in doc["quantizers"]]
    assert codes == {n: e["codes"] for n, e in doc["polynomials"].items()}
    assert "use ieee.numeric_std.all;" in text and "package stereo_calibration_pkg is" in text
    check_in_ghdl(out, doc, tmp_path)


def test_package_from_result_equals_package_from_json(result, qjson, tmp_path):
    a = vhdl_package.package_text(result)
    b = vhdl_package.write_package(qjson, tmp_path / "p.vhd")
    assert a == b


@needs_ghdl
def test_package_wide_and_negative_codes(tmp_path):
    """Codes beyond a 32-bit VHDL integer become bit strings; one polynomial; another name.

    (A quantizers.json must hold the four polynomials; the package writer itself takes any set.)"""
    quants = [{"name": f"q{n}", "signed": n % 2 == 1, "wl": 12, "fl": 3} for n in range(1, 27)]
    quants[0] = {"name": "q1", "signed": True, "wl": 40, "fl": 10}
    quants[1] = {"name": "q2", "signed": False, "wl": 36, "fl": -2}
    quants[2] = {"name": "q3", "signed": True, "wl": 33, "fl": 40}
    codes = [-(2**39), 2**36 - 1, 2**31 - 1, 5, -3, 7, -2048, 0, 2047, 4095]  # odd q: signed
    doc = {"width": 8, "height": 6, "degree": 3, "quantizers": quants,
           "polynomials": {"cam": {"codes": codes}}}
    path = tmp_path / "q.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ffc.FFCError, match="must hold the four left_x, left_y, right_x, right_y; it lacks"):
        vhdl_package.write_package(path, tmp_path / "x.vhd")
    out = tmp_path / "pkg.vhd"
    text = vhdl_package.write_package(doc, out, name="rig_b_pkg")
    fmts, back = parse_package(text)
    assert back == {"cam": codes}
    assert "signed'(\"1" + "0" * 39 + "\")" in text and "unsigned'(\"" + "1" * 36 + "\")" in text
    check_in_ghdl(out, doc, tmp_path, "rig_b_pkg")


@pytest.mark.parametrize("name", ["", "1pkg", "my__pkg", "pkg_", "entity", "a-b", "package"])
def test_package_name_must_be_an_identifier(result, name):
    with pytest.raises(ffc.FFCError, match="not a valid VHDL identifier"):
        vhdl_package.package_text(result, name)


def run_cli(argv, capsys):
    code = cli_main.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_package(qjson, tmp_path, capsys):
    out = tmp_path / "pkg.vhd"
    code, stdout, err = run_cli(["package", qjson, "-o", out, "--name", "cal_pkg"], capsys)
    assert code == 0 and err == ""
    assert "package cal_pkg is" in out.read_text()


@pytest.mark.parametrize("case, message", [
    ("missing", "does not exist"),
    ("badjson", "not valid JSON"),
    ("count", "must list 26 formats"),
    ("order", "entry 3 must be named 'q3'"),
    ("code", "does not fit q2"),
    ("name", "not a valid VHDL identifier"),
])
def test_cli_package_bad_input(qjson, tmp_path, capsys, case, message):
    doc = json.loads(qjson.read_text())
    src = tmp_path / "in.json"
    extra: list[str] = []
    if case == "badjson":
        src.write_text("{]")
    elif case == "count":
        doc["quantizers"].pop()
    elif case == "order":
        doc["quantizers"][2]["name"] = "q4"
    elif case == "code":
        f = doc["quantizers"][1]
        doc["polynomials"]["left_y"]["codes"][1] = 1 << f["wl"]
    elif case == "name":
        extra = ["--name", "signal"]
    if case not in ("missing", "badjson"):
        src.write_text(json.dumps(doc))
    out = tmp_path / "pkg.vhd"
    code, stdout, err = run_cli(["package", src, "-o", out, *extra], capsys)
    assert code != 0
    assert err.startswith("eyestereo: error: ") and err.count("\n") == 1 and message in err
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
