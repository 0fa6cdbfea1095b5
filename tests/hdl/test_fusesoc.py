"""FuseSoC accepts the generated cores: it lists them and runs a block's GHDL simulation target."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from eyestereo.hdl.flow.catalog import BLOCKS, jsonable
from eyestereo.hdl.flow.convert import convert
from eyestereo.hdl.flow.fusesoc import block_core, write_cores

FUSESOC = Path(sys.executable).parent / "fusesoc"
needs_fusesoc = pytest.mark.skipif(not FUSESOC.exists() or shutil.which("ghdl") is None,
                                   reason="fusesoc (pip) and GHDL needed")


def _manifest(tmp_path, names):
    blocks = []
    for n in names:
        files = convert(n, tmp_path)
        blocks.append(dict(entity=n, summary=BLOCKS[n].summary, parameters=jsonable(BLOCKS[n].params()),
                           files=[f.name for f in files]))
    return dict(blocks=blocks, package=files[0].name)


def _fusesoc(tmp_path, *args):
    return subprocess.run([str(FUSESOC), "--cores-root", str(tmp_path), *args], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)


def test_block_core_text():
    text = block_core(dict(entity="sobel", summary="Sobel: Ix, Iy", files=["pck_myhdl_011.vhd", "sobel.vhd"],
                           parameters=dict(width=352)), "pck_myhdl_011.vhd", "1.2.3")
    assert text.startswith("CAPI=2:\nname: eyestereo:blocks:sobel:1.2.3\n")
    assert 'description: "Sobel: Ix, Iy [width=352]"' in text  # quoted: YAML would choke on ": "
    assert 'files: ["sobel.vhd"]' in text and 'depend: ["eyestereo:lib:pck_myhdl_011"]' in text
    assert "toplevel: sobel" in text and "tool: ghdl" in text


@needs_fusesoc
def test_fusesoc_lists_the_cores_and_simulates_a_block(tmp_path):
    names = ["line_delay", "stream_to_axis"]
    written = write_cores(tmp_path, _manifest(tmp_path, names), version="0.1.0")
    assert sorted(p.name for p in written) == ["line_delay.core", "pck_myhdl_011.core", "stream_to_axis.core"]
    r = _fusesoc(tmp_path, "core", "list")
    assert r.returncode == 0, r.stderr
    for n in names:
        assert f"eyestereo:blocks:{n}:0.1.0" in r.stdout, r.stdout
    assert "eyestereo:lib:pck_myhdl_011" in r.stdout
    r = _fusesoc(tmp_path, "run", "--build-root", str(tmp_path / "fs"), "--target", "sim",
                 "eyestereo:blocks:stream_to_axis")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    out = r.stdout + r.stderr
    assert "ghdl -r" in out and "stream_to_axis" in out and "Error" not in out, out[-2000:]
    # A broken core is refused (the test can fail): a file that does not exist.
    (tmp_path / "line_delay.core").write_text((tmp_path / "line_delay.core").read_text()
                                              .replace('"line_delay.vhd"', '"missing.vhd"'))
    r = _fusesoc(tmp_path, "run", "--build-root", str(tmp_path / "fs2"), "--target", "sim",
                 "eyestereo:blocks:line_delay")
    assert r.returncode != 0 and "Cannot find missing.vhd" in r.stdout + r.stderr
