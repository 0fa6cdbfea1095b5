"""Conversion of catalogue blocks to VHDL/Verilog, the manifest, and the GHDL analysis check.

``python -m eyestereo.hdl.convert [--out build/vhdl]`` is what ``make vhdl`` runs.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

from eyestereo.hdl.catalog import BLOCKS, get, jsonable

# --std=93c is GHDL's relaxed VHDL-93: strict 93 rejects the "array(0 to N-1)" memory declarations
# MyHDL writes, which vendor VHDL-93 tools accept.
GHDL_STDS = ("93c", "08")

_PORT = re.compile(r"^\s*(\w+)\s*:\s*(in|out|inout)\s+([^;]+?);?\s*$", re.M)


# MyHDL writes initial values as VHDL-2008 sized bit strings (``12X"0"``), which VHDL-93 rejects.
_SIZED_LITERAL = re.compile(r'\b(\d+)X"([0-9A-Fa-f]+)"')


def _plain_literal(m: re.Match) -> str:
    n, value = int(m.group(1)), int(m.group(2), 16)
    if value >> n:
        raise ValueError(f"initial value {m.group(0)} does not fit {n} bits")
    return '"' + format(value, f"0{n}b") + '"'


def vhdl93_literals(text: str) -> str:
    """``N X"hex"`` literals rewritten as N-character bit strings (valid in VHDL-93 and VHDL-2008)."""
    return _SIZED_LITERAL.sub(_plain_literal, text)


def convert(name: str, path: Path, *, hdl: str = "VHDL", entity: str | None = None, **params) -> list[Path]:
    """Convert one block (fresh instance) into ``path``; returns the files written (package first).

    Every signal and memory gets its initial value (``initial_values=True``): a simulation starts
    from the state a real FPGA starts from (flip-flops and block RAM at 0 after configuration), so no
    output is ever undefined, and synthesis keeps the values as the registers' and RAMs' INIT.
    """
    spec = get(name)
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    inst, _, _ = spec.elaborate(**params)
    entity = entity or spec.name
    with warnings.catch_warnings():
        # Unread outputs of shared sub-blocks (e.g. a line delay's flags) are expected; keep logs readable.
        warnings.simplefilter("ignore")
        inst.convert(hdl=hdl, name=entity, path=str(path), initial_values=True)
    if hdl == "VHDL":
        vhd = path / f"{entity}.vhd"
        vhd.write_text(vhdl93_literals(vhd.read_text()))
        return sorted(path.glob("pck_myhdl_*.vhd")) + [vhd]
    return [path / f"{entity}.v"]


def vhdl_ports(vhd: Path) -> list[dict]:
    """Ports of the entity in a generated VHDL file: name, direction, type."""
    text = Path(vhd).read_text()
    m = re.search(r"\bentity\s+\w+\s+is\s+port\s*\((.*?)\);\s*end\s+entity", text, re.S | re.I)
    if not m:
        raise ValueError(f"no entity port list found in {vhd}")
    return [dict(name=n, dir=d, type=t.strip()) for n, d, t in _PORT.findall(m.group(1))]


def analyse(files: list[Path], std: str, workdir: Path) -> None:
    """Analyse files with GHDL; raise RuntimeError with GHDL's messages on failure."""
    if shutil.which("ghdl") is None:
        raise RuntimeError("ghdl not found: install it (Debian: apt-get install ghdl)")
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = ["ghdl", "-a", f"--std={std}", f"--workdir={workdir}"] + [str(f) for f in files]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"GHDL --std={std} rejected {[f.name for f in files]}:\n{r.stdout}{r.stderr}")


def make_vhdl(out: Path) -> dict:
    """Write the default configuration of every block to ``out`` with its manifest, then analyse it.

    Also writes a FuseSoC core per block (:mod:`eyestereo.hdl.fusesoc`).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    manifest = {"blocks": [], "package": None, "ghdl_std": list(GHDL_STDS)}
    files: list[Path] = []
    for name, spec in BLOCKS.items():
        with tempfile.TemporaryDirectory() as tmp:
            written = convert(name, Path(tmp))
            for f in written:
                shutil.copy(f, out / f.name)
        vhd = out / f"{spec.name}.vhd"
        pck = out / written[0].name
        manifest["package"] = pck.name
        files.append(vhd)
        manifest["blocks"].append(dict(entity=spec.name, summary=spec.summary,
                                       parameters=jsonable(spec.params()),
                                       ports=vhdl_ports(vhd), files=[pck.name, vhd.name]))
    for std in GHDL_STDS:
        with tempfile.TemporaryDirectory() as tmp:
            analyse([out / manifest["package"]] + files, std, Path(tmp))
    from eyestereo.hdl.fusesoc import write_cores

    manifest["cores"] = [p.name for p in write_cores(out, manifest)]
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Convert every eyestereo block to VHDL and check it with GHDL.")
    ap.add_argument("--out", default="build/vhdl", type=Path)
    args = ap.parse_args(argv)
    try:
        m = make_vhdl(args.out)
    except (RuntimeError, ValueError) as e:
        print(f"make vhdl: {e}", file=sys.stderr)
        return 1
    for b in m["blocks"]:
        print(f"{args.out}/{b['entity']}.vhd  ({len(b['ports'])} ports)  {b['entity']}.core")
    print(f"analysed with GHDL --std={' and --std='.join(GHDL_STDS)}: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
