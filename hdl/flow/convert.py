"""Conversion of catalogue blocks to VHDL/Verilog, the manifests, and the GHDL / Icarus checks.

``python -m eyestereo.hdl.flow.convert [--out build/vhdl]`` is what ``make vhdl`` runs;
``python -m eyestereo.hdl.flow.convert --hdl verilog [--out build/verilog]`` is ``make verilog``.
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

from eyestereo.hdl.flow.catalog import BLOCKS, get, jsonable

# --std=93c is GHDL's relaxed VHDL-93: strict 93 rejects the "array(0 to N-1)" memory declarations
# MyHDL writes, which vendor VHDL-93 tools accept.
GHDL_STDS = ("93c", "08")

_VPORT = re.compile(r"^\s*(input|output|inout)\s+(?:wire\s+|reg\s+)?(signed\s+)?(\[[^\]]+\]\s*)?(\w+)\s*;", re.M)
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


def fresh_names() -> None:
    """Forget the block names MyHDL has handed out in this process. MyHDL makes each instance name unique over the
    whole process by appending ``_0``, ``_1``, ... to it, every repeat again: in a test worker that has converted the
    front end a dozen times, nested blocks' names passed GHDL's 1023-character limit (issue 26). Each conversion is
    its own design, so its names need only be unique within it.

    The per-block call counters (``en_reg0``, ``en_reg1``, ...) are reset too: MyHDL resets them only after an
    elaboration that completes, so one that raised half-way (a refused parameter) or a MyHDL ``Simulation`` left
    them counting, and the next conversion's names depended on what ran before it in the process."""
    import myhdl
    import myhdl._block as mb

    mb._name_set.clear()
    mb._inst_name_set.clear()
    for deco in myhdl._simulator._blocks:
        deco.calls = 0


def convert(name: str, path: Path, *, hdl: str = "VHDL", entity: str | None = None, timescale: str | None = None,
            **params) -> list[Path]:
    """Convert one block (fresh instance) into ``path``; returns the files written (package first).

    Every signal and memory gets its initial value (``initial_values=True``): a simulation starts
    from the state a real FPGA starts from (flip-flops and block RAM at 0 after configuration), so no
    output is ever undefined, and synthesis keeps the values as the registers' and RAMs' INIT.
    ``timescale``: the Verilog's `` `timescale`` (MyHDL's default 1ns/10ps when None).
    """
    spec = get(name)
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    fresh_names()
    inst, _, _ = spec.elaborate(**params)
    entity = entity or spec.name
    with warnings.catch_warnings():
        # Unread outputs of shared sub-blocks (e.g. a line delay's flags) are expected; keep logs readable.
        warnings.simplefilter("ignore")
        extra = dict(timescale=timescale) if (timescale and hdl.lower() == "verilog") else {}
        inst.convert(hdl=hdl, name=entity, path=str(path), initial_values=True, **extra)
    models = []
    for fname, text in (spec.sources(hdl.lower()) if spec.sources else {}).items():
        (path / fname).write_text(text)
        models.append(path / fname)
    if hdl == "VHDL":
        vhd = path / f"{entity}.vhd"
        vhd.write_text(vhdl93_literals(vhd.read_text()))
        return sorted(path.glob("pck_myhdl_*.vhd")) + models + [vhd]
    return models + [path / f"{entity}.v"]


def vhdl_ports(vhd: Path) -> list[dict]:
    """Ports of the entity in a generated VHDL file: name, direction, type."""
    text = Path(vhd).read_text()
    m = re.search(r"\bentity\s+\w+\s+is\s+port\s*\((.*?)\);\s*end\s+entity", text, re.S | re.I)
    if not m:
        raise ValueError(f"no entity port list found in {vhd}")
    return [dict(name=n, dir=d, type=t.strip()) for n, d, t in _PORT.findall(m.group(1))]


def verilog_ports(v: Path) -> list[dict]:
    """Ports of the module in a generated Verilog file: name, direction, type (e.g. ``signed [19:0]``)."""
    return [dict(name=n, dir=d, type=((sg or "") + (rng or "")).strip() or "1 bit")
            for d, sg, rng, n in _VPORT.findall(Path(v).read_text())]


def check_verilog(files: list[Path], top: str, workdir: Path) -> None:
    """Compile files with Icarus Verilog (-g2012, top ``top``); raise RuntimeError with its messages on failure."""
    if shutil.which("iverilog") is None:
        raise RuntimeError("iverilog not found: install it (Debian: apt-get install iverilog)")
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = ["iverilog", "-g2012", "-s", top, "-o", str(workdir / f"{top}.vvp")] + [str(f) for f in files]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"Icarus Verilog rejected {[f.name for f in files]}:\n{r.stdout}{r.stderr}")


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

    Also writes a FuseSoC core per block (:mod:`eyestereo.hdl.flow.fusesoc`).
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
    from eyestereo.hdl.flow.fusesoc import write_cores

    manifest["cores"] = [p.name for p in write_cores(out, manifest)]
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def make_verilog(out: Path) -> dict:
    """The twin of :func:`make_vhdl`: every block's default configuration as MyHDL's Verilog in ``out``.

    Each module is compiled by Icarus Verilog, and its arithmetic checked for operands of mixed
    signedness (:func:`eyestereo.hdl.flow.vlint.mixed_signedness`), which is where MyHDL's Verilog back end
    and its VHDL back end part ways; ``manifest.json`` lists modules, parameters and ports.
    """
    from eyestereo.hdl.flow.vlint import mixed_signedness

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    manifest = {"blocks": [], "iverilog": "-g2012"}
    problems = []
    for name, spec in BLOCKS.items():
        with tempfile.TemporaryDirectory() as tmp:
            (written,) = convert(name, Path(tmp), hdl="Verilog")
            shutil.copy(written, out / written.name)
        v = out / f"{spec.name}.v"
        with tempfile.TemporaryDirectory() as tmp:
            check_verilog([v], spec.name, Path(tmp))
        problems += [f"{v.name}: {p}" for p in mixed_signedness(v.read_text())]
        manifest["blocks"].append(dict(entity=spec.name, summary=spec.summary, parameters=jsonable(spec.params()),
                                       ports=verilog_ports(v), files=[v.name]))
    if problems:
        raise RuntimeError("operands of mixed signedness in the Verilog (Verilog would compute them unsigned):\n"
                           + "\n".join(problems))
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Convert every eyestereo block to VHDL (checked with GHDL) or "
                                             "Verilog (checked with Icarus Verilog).")
    ap.add_argument("--hdl", default="vhdl", choices=("vhdl", "verilog"))
    ap.add_argument("--out", default=None, type=Path, help="default build/vhdl or build/verilog")
    args = ap.parse_args(argv)
    args.out = args.out or Path("build") / args.hdl
    try:
        m = make_vhdl(args.out) if args.hdl == "vhdl" else make_verilog(args.out)
    except (RuntimeError, ValueError) as e:
        print(f"make {args.hdl}: {e}", file=sys.stderr)
        return 1
    if args.hdl == "verilog":
        for b in m["blocks"]:
            print(f"{args.out}/{b['entity']}.v  ({len(b['ports'])} ports)")
        print("compiled with Icarus Verilog -g2012, no operands of mixed signedness: OK")
        return 0
    for b in m["blocks"]:
        print(f"{args.out}/{b['entity']}.vhd  ({len(b['ports'])} ports)  {b['entity']}.core")
    print(f"analysed with GHDL --std={' and --std='.join(GHDL_STDS)}: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
