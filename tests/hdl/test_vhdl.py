"""make vhdl: every block's default configuration converts, analyses in GHDL (93c and 08), has a manifest."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from myhdl import ResetSignal, Signal
from myhdl._Signal import _Signal

from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, make_vhdl, vhdl_ports
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.interfaces.stream import ImageStream

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")


def _port_names(ports: dict) -> list[str]:
    """HDL port names of a block's ports: a bundle as ``<arg>_<field>`` (its declared fields; an undeclared
    bundle such as BufferSide: its Signal attributes)."""
    names = []
    for n, port in ports.items():
        if isinstance(port, _Signal):
            names.append(n)
        else:
            fields = (port.fields() if hasattr(port, "fields")
                      else [k for k, v in vars(port).items() if isinstance(v, _Signal)])
            names += [f"{n}_{f}" for f in fields]
    return names


@needs_ghdl
def test_make_vhdl_writes_and_analyses_every_block(tmp_path):
    m = make_vhdl(tmp_path)  # raises if GHDL rejects anything
    files = sorted(p.name for p in tmp_path.iterdir())
    assert len([f for f in files if f.startswith("pck_myhdl_") and f.endswith(".vhd")]) == 1
    assert {b["entity"] for b in m["blocks"]} == set(BLOCKS)
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    assert manifest == json.loads(json.dumps(m))
    for b in manifest["blocks"]:
        assert (tmp_path / f"{b['entity']}.vhd").exists()
        assert b["files"][0] == manifest["package"]
        # every block: the entity's ports are the catalogue's ports, bundles expanded by their declarations
        _, all_ports, _ = BLOCKS[b["entity"]].elaborate()
        assert sorted(p["name"] for p in b["ports"]) == sorted(_port_names(all_ports)), b["entity"]
        if BLOCKS[b["entity"]].build is not None:  # own port lists: tests/hdl/test_camera_params.py
            continue
        names = [p["name"] for p in b["ports"]]
        spec = BLOCKS[b["entity"]]
        _, ports, _ = spec.elaborate()
        control = [n for n in ports if n not in ("clk", "rst", "sink", "source")]  # in the block's call order
        # MyHDL lists plain signal ports (clk, rst, control) before the flattened stream interfaces.
        assert names == ["clk", "rst"] + control + [f"sink_{f}" for f in ports["sink"].fields()] + \
            [f"source_{f}" for f in ports["source"].fields()]
        dirs = {p["name"]: p["dir"] for p in b["ports"]}
        assert dirs[f"sink_{ports['sink'].fields()[0]}"] == "in"
        assert dirs[f"source_{ports['source'].fields()[0]}"] == "out"
        assert b["files"][0] == manifest["package"]
        assert b["parameters"]["width"] == 352 and b["parameters"]["height"] == 288
    assert sorted(manifest["cores"]) == sorted([f"{b}.core" for b in BLOCKS] + ["pck_myhdl_011.core"])
    fusesoc = Path(sys.executable).parent / "fusesoc"
    if fusesoc.exists():  # FuseSoC accepts every generated core (tests/hdl/test_fusesoc.py runs one)
        r = subprocess.run([str(fusesoc), "--cores-root", str(tmp_path), "core", "list"], capture_output=True,
                           text=True, cwd=tmp_path)
        assert r.returncode == 0 and all(f"eyestereo:blocks:{b}:" in r.stdout for b in BLOCKS), r.stdout + r.stderr
    sobel = next(b for b in manifest["blocks"] if b["entity"] == "sobel")
    widths = {p["name"]: p["type"] for p in sobel["ports"]}
    assert widths["sink_data"] == "unsigned(7 downto 0)"
    assert widths["source_data"] == "unsigned(17 downto 0)"
    # Analysed again here, file by file in dependency order, under both standards.
    for std in GHDL_STDS:
        analyse([tmp_path / manifest["package"]] + [tmp_path / f"{b}.vhd" for b in BLOCKS], std, tmp_path / std)


@needs_ghdl
def test_analysis_catches_broken_vhdl(tmp_path):
    bad = tmp_path / "bad.vhd"
    bad.write_text("entity bad is port (a : in bit) end entity;\n")  # missing ';'
    with pytest.raises(RuntimeError, match="GHDL --std=08 rejected"):
        analyse([bad], "08", tmp_path / "w")


@needs_ghdl
def test_stereo_stream_has_cam_ports(tmp_path):
    clk, rst = Signal(bool(0)), ResetSignal(0, active=1, isasync=False)
    inst = line_delay(clk, rst, ImageStream(8, stereo=True), ImageStream(8, stereo=True), width=16, height=4)
    inst.convert(hdl="VHDL", name="ld_stereo", path=str(tmp_path))
    names = [p["name"] for p in vhdl_ports(tmp_path / "ld_stereo.vhd")]
    assert "sink_cam" in names and "source_cam" in names
    analyse(sorted(tmp_path.glob("pck_myhdl_*.vhd")) + [tmp_path / "ld_stereo.vhd"], "08", tmp_path / "w")


def test_vhdl_ports_parser_reads_directions():
    text = ("entity x is\n    port (\n        a: in std_logic;\n        b: out unsigned(3 downto 0)\n    );\n"
            "end entity x;\n")
    import pathlib
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = pathlib.Path(d) / "x.vhd"
        p.write_text(text)
        assert vhdl_ports(p) == [dict(name="a", dir="in", type="std_logic"),
                                 dict(name="b", dir="out", type="unsigned(3 downto 0)")]
