"""A board's bitstream: the board top converted by MyHDL, Yosys ``synth_ecp5``, nextpnr-ecp5 with the board's pins,
``ecppack`` (make bitstream BOARD=ulx3s-85f).

Steps, in ``<out>/`` (default ``build/board/<board>``):

1. MyHDL's Verilog of the board top (``ulx3s.v``; the ECP5 primitives are instances in it) and its VHDL beside it
   (``vhdl/``: the VHDL stays the product; the board simulation runs the top's VHDL on GHDL), converted in a
   child Python with a fixed string-hash seed (:data:`HASH_SEED`): the same commit gives the same netlist.
2. The LPF: the ports' pins and I/O settings from the board's constraint file (:mod:`eyestereo.tools.board.ulx3s`)
   and one clock constraint, the oscillator's, raised by :data:`MARGIN` (10 %): nextpnr derives every PLL output's
   constraint from it, so each clock is placed and routed for its frequency plus the margin; the cameras' PCLK
   inputs likewise (their 25 MHz plus the margin).
3. Yosys ``synth_ecp5`` (the memories named ``_norw`` marked ``no_rw_check``, and the flip-flops moved into the
   multipliers' and block RAMs' registers, as ``make synth`` does), then nextpnr-ecp5 for the board's device
   (with ``make synth``'s placer options) with each seed of ``--seeds`` (default 1), **without**
   ``--timing-allow-fail``: a seed that misses a constraint fails; the first seed that meets all is packed by
   ``ecppack`` into ``<board>.bit``. Every seed's report is kept (``pnr_report_seed<N>.json``) and the summary
   (``bitstream.json``: utilisation, fmax per clock and seed, the times) is what docs/boards.md shows.

Bad input (an unknown board, a camera mapping that does not parse, a tool missing) is a one-line error and exit
status 1; a failed run leaves no ``.bit``.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from myhdl import Signal, TristateSignal, intbv

from eyestereo.hdl.boards.ulx3s import CLOCKS, ulx3s
from eyestereo.hdl.flow.bram_regs import pack_bram_registers
from eyestereo.hdl.flow.convert import fresh_names
from eyestereo.hdl.flow.dsp_regs import pack_file
from eyestereo.hdl.flow.netlist import mark_no_rw_check
from eyestereo.hdl.flow.synth import NEXTPNR_OPTS, nextpnr_command, tool, yosys
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.tools.board import ulx3s as board_pins
from eyestereo.tools.io import revision, write_section

__all__ = ["BOARDS", "HASH_SEED", "MARGIN", "board_ports", "build", "convert_reproducibly", "main"]

#: The boards ``make bitstream BOARD=...`` knows: name -> (top function, its pin module).
BOARDS = {board_pins.BOARD: (ulx3s, board_pins)}
#: Every clock is constrained this much above its frequency (the project's rule: a clock goal met with 10 % margin).
MARGIN = 1.10
#: The cameras' PCLK (MHz) before the margin: the OV7670 at a 25 MHz XCLK gives at most 25 MHz.
PCLK_MHZ = 25.0


def board_ports() -> dict:
    """Fresh signals for every port of the ULX3S top (names as its function's arguments)."""
    def cam():
        return dict(bus=CameraBus(), xclk=Signal(bool(0)), sioc=Signal(bool(1)),
                    siod=TristateSignal(bool(1)), resetn=Signal(bool(0)), pwdn=Signal(bool(0)))
    cl, cr = cam(), cam()
    return dict(clk_25mhz=Signal(bool(0)), led=Signal(intbv(0)[8:]), btn=Signal(intbv(1)[7:]),
                ftdi_txd=Signal(bool(1)), ftdi_rxd=Signal(bool(1)), sdram_clk=Signal(bool(0)),
                sdram_cke=Signal(bool(0)), sdram_csn=Signal(bool(1)), sdram_wen=Signal(bool(1)),
                sdram_rasn=Signal(bool(1)), sdram_casn=Signal(bool(1)), sdram_a=Signal(intbv(0)[13:]),
                sdram_ba=Signal(intbv(0)[2:]), sdram_dqm=Signal(intbv(3)[2:]), sdram_d=TristateSignal(intbv(0)[16:]),
                gpdi_dp=Signal(intbv(0)[4:]),
                cam_l=cl["bus"], cam_l_xclk=cl["xclk"], cam_l_sioc=cl["sioc"], cam_l_siod=cl["siod"],
                cam_l_resetn=cl["resetn"], cam_l_pwdn=cl["pwdn"],
                cam_r=cr["bus"], cam_r_xclk=cr["xclk"], cam_r_sioc=cr["sioc"], cam_r_siod=cr["siod"],
                cam_r_resetn=cr["resetn"], cam_r_pwdn=cr["pwdn"])


#: The hash seed of the conversion's Python: MyHDL orders some of its output (sensitivity lists, a block's
#: processes) by sets of names, so with Python's random string hashes each run wrote another, equivalent, Verilog,
#: which Yosys and nextpnr place differently (a clock's fmax moved by several MHz between runs of one commit). The
#: flow converts in a child Python with this seed: one commit, one netlist, one bitstream per nextpnr seed.
HASH_SEED = "0"

_CHILD = ("import pickle, sys\n"
          "from pathlib import Path\n"
          "from eyestereo.hdl.flow.bitstream import convert_top\n"
          "a = pickle.load(sys.stdin.buffer)\n"
          "try:\n"
          "    for hdl, where in a['runs']:\n"
          "        convert_top(Path(where), hdl=hdl, **a['params'])\n"
          "except ValueError as e:\n"
          "    print('ValueError: ' + str(e).splitlines()[0], file=sys.stderr)\n"
          "    sys.exit(3)\n")


def convert_reproducibly(out: Path, *, vhdl: bool = True, **params) -> Path:
    """The board top's Verilog (``out/ulx3s.v``) and, with ``vhdl``, VHDL (``out/vhdl/``), converted in a child
    Python whose string hashes are :data:`HASH_SEED`'s; returns the Verilog file. A parameter the top refuses is
    the child's ValueError, raised here."""
    env = dict(os.environ, PYTHONHASHSEED=HASH_SEED)
    runs = [("Verilog", str(out))] + ([("VHDL", str(out / "vhdl"))] if vhdl else [])
    arg = pickle.dumps(dict(params=params, runs=runs))
    r = subprocess.run([sys.executable, "-c", _CHILD], input=arg, capture_output=True, env=env)
    if r.returncode != 0:
        last = (r.stderr.decode(errors="replace").strip().splitlines() or ["(no message)"])[-1]
        if r.returncode == 3 and last.startswith("ValueError: "):
            raise ValueError(last[len("ValueError: "):])
        raise RuntimeError(f"the conversion of the board top failed: {last}")
    return out / "ulx3s.v"


def convert_top(out: Path, *, hdl: str = "Verilog", **params) -> Path:
    """The board top in ``hdl`` under ``out`` (``ulx3s.v`` or ``ulx3s.vhd``); returns the file."""
    out.mkdir(parents=True, exist_ok=True)
    fresh_names()
    top = ulx3s(**board_ports(), **params)
    top.convert(hdl=hdl, path=str(out), name="ulx3s", initial_values=True)
    return out / ("ulx3s.v" if hdl == "Verilog" else "ulx3s.vhd")


#: MyHDL's zero initialisation of a memory (``initial_values=True``): a loop over every word.
_ZERO_INIT = re.compile(r"\ninitial begin: INITIALIZE_(\w+)\n    integer i;\n    for\(i=0; i<\d+; i=i\+1\) begin\n"
                        r"        \w+\[i\] = 0;\n    end\nend\n")


def drop_zero_memory_init(text: str) -> tuple[str, int]:
    """The Verilog without MyHDL's loops that set memories to 0 (the ECP5's block and LUT RAMs are 0 after
    configuration anyway; Yosys's frontend unrolls each loop, which took minutes for the display's 76,800-word
    RAMs); the registers' initial values stay. Returns the text and the loops removed."""
    return _ZERO_INIT.subn("\n", text)


def port_bits(netlist: dict, top: str) -> list[str]:
    """The top's port bits as Yosys names them in the LPF (``led[3]``; a 1-bit port by its name)."""
    ports = netlist["modules"][top]["ports"]
    out = []
    for name, p in ports.items():
        n = len(p["bits"])
        out += [name] if n == 1 else [f"{name}[{i}]" for i in range(n)]
    return out


def _run(cmd: list[str], cwd: Path, what: str) -> None:
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{what} failed (see {cwd}):\n{(r.stdout + r.stderr)[-3000:]}")


def build(board: str, out: Path, *, seeds=(1,), mapping=None, **params) -> dict:
    """The bitstream of ``board`` in ``out``: the steps of the module docstring; returns the summary."""
    if board not in BOARDS:
        raise ValueError(f"unknown board {board!r}; the boards are {', '.join(BOARDS)}")
    pins = BOARDS[board][1]
    mapping = pins.camera_mapping(mapping)
    out = Path(out)
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    t0 = time.perf_counter()
    v = convert_reproducibly(out, **params)
    text, dropped = drop_zero_memory_init(v.read_text())
    text, norw = mark_no_rw_check(text)
    v.write_text(text)
    t_conv = time.perf_counter() - t0
    yosys(f"read_verilog {v.name}; synth_ecp5 -top ulx3s -json ulx3s.json", out, "yosys.log")
    dsp = pack_file(out / "ulx3s.json", "ulx3s")
    bram = pack_file(out / "ulx3s.json", "ulx3s", pack_bram_registers)
    t_syn = time.perf_counter() - t0 - t_conv
    net = json.loads((out / "ulx3s.json").read_text())
    clocks = {"clk_25mhz": CLOCKS["osc"] * MARGIN, "cam_l_pclk": PCLK_MHZ * MARGIN, "cam_r_pclk": PCLK_MHZ * MARGIN}
    (out / f"{board}.lpf").write_text(pins.lpf(port_bits(net, "ulx3s"), mapping=mapping, clocks=clocks))
    runs, chosen = [], None
    for seed in seeds:
        t1 = time.perf_counter()
        tag = f"_seed{seed}"
        cmd = nextpnr_command() + list(pins.DEVICE) + list(NEXTPNR_OPTS) + [
            "--json", "ulx3s.json", "--lpf", f"{board}.lpf", "--textcfg", f"ulx3s{tag}.config", "--seed", str(seed),
            "--report", f"pnr_report{tag}.json", "--log", f"nextpnr{tag}.log", "-q"]
        r = subprocess.run(cmd, cwd=out, capture_output=True, text=True)
        rep_path = out / f"pnr_report{tag}.json"
        rep = json.loads(rep_path.read_text()) if rep_path.exists() else {}
        fmax = {c: v for c, v in rep.get("fmax", {}).items()}
        runs.append(dict(seed=seed, ok=r.returncode == 0, seconds=round(time.perf_counter() - t1, 1), fmax=fmax,
                         utilization=rep.get("utilization", {})))
        if r.returncode != 0 and not rep:
            raise RuntimeError(f"nextpnr-ecp5 failed on seed {seed} (see {out / f'nextpnr{tag}.log'}): "
                               f"{(r.stderr or r.stdout).strip().splitlines()[-1:] or ''}")
        if r.returncode == 0 and chosen is None:
            chosen = seed
    summary = dict(board=board, params={k: str(v) for k, v in params.items()}, seeds=list(seeds), runs=runs,
                   clocks=clocks, margin=MARGIN, memory_inits_dropped=dropped, no_rw_check=norw, dsp_regs=dsp,
                   bram_regs=bram,
                   chosen_seed=chosen, revision=revision(("hdl", "tools")),
                   seconds=dict(convert=round(t_conv, 1), yosys=round(t_syn, 1)))
    if chosen is not None:
        t2 = time.perf_counter()
        _run([tool("yowasp-ecppack"), "--compress", f"ulx3s_seed{chosen}.config", f"{board}.bit"], out, "ecppack")
        summary["seconds"]["ecppack"] = round(time.perf_counter() - t2, 1)
    summary["seconds"]["total"] = round(time.perf_counter() - t0, 1)
    (out / "bitstream.json").write_text(json.dumps(summary, indent=1))
    if chosen is None:
        raise RuntimeError(f"no seed of {list(seeds)} met every clock constraint (see {out}/nextpnr_seed*.log)")
    return summary


#: docs/boards.md's section that ``--doc`` fills.
DOC_MARKERS = ("<!-- bitstream:begin -->", "<!-- bitstream:end -->")
#: nextpnr's clock nets -> the board's clock names (the cameras' PCLK inputs keep theirs).
CLOCK_NAMES = {"mclk": "memory", "tclk": "TMDS", "hclk": "Harris", "pclk": "pixel", "cam_l_pclk": "camera L PCLK",
               "cam_r_pclk": "camera R PCLK"}


def _net(name: str) -> str:
    return re.sub(r"^\$glbnet\$|\$TRELLIS_IO_IN$", "", name)


def doc_section(s: dict) -> str:
    """The section of docs/boards.md: each clock's constraint and fmax per seed (the minimum over the seeds that
    decides), the utilisation of the first seed, the run times."""
    runs = s["runs"]
    nets = sorted({_net(c) for r in runs for c in r["fmax"]}, key=lambda n: list(CLOCK_NAMES).index(n)
                  if n in CLOCK_NAMES else 99)
    seeds = [r["seed"] for r in runs]
    params = "".join(f", {k}={v}" for k, v in s.get("params", {}).items() if k != "mapping")
    lines = [f"Measured by `python -m eyestereo.hdl.flow.bitstream --seeds {','.join(map(str, seeds))} --doc "
             f"docs/boards.md` ({s['board']}{params}, the board top of commit {s.get('revision', 'unknown')}; "
             "the netlist of the bitstream: MyHDL's Verilog of the board top, Yosys "
             "`synth_ecp5`, nextpnr-ecp5 with the board's LPF; every clock constrained "
             f"{round((s['margin'] - 1) * 100)} % above its frequency, so a clock that meets its constraint has the "
             "margin).", "",
             "| clock | MHz | constraint (MHz) | " + " | ".join(f"fmax seed {k}" for k in seeds) + " | min | met |",
             "|---|---:|---:|" + "---:|" * len(seeds) + "---:|---|"]
    for n in nets:
        vals = [next((v for c, v in r["fmax"].items() if _net(c) == n), None) for r in runs]
        got = [v["achieved"] for v in vals if v]
        cons = next(v["constraint"] for v in vals if v)
        lines.append(f"| {CLOCK_NAMES.get(n, n)} (`{n}`) | {cons / s['margin']:.1f} | {cons:.1f} | "
                     + " | ".join(f"{v['achieved']:.1f}" if v else "-" for v in vals)
                     + f" | {min(got):.1f} | {'yes' if min(got) >= cons else 'NO'} |")
    ok = [r for r in runs if r["ok"]]
    lines += ["", f"Seeds that met every clock: {', '.join(str(r['seed']) for r in ok) or 'none'} of "
              f"{', '.join(map(str, seeds))}; the bitstream is packed from seed {s['chosen_seed']}.", ""]
    util = runs[0]["utilization"]
    keep = ("TRELLIS_COMB", "TRELLIS_FF", "TRELLIS_RAMW", "DP16KD", "MULT18X18D", "EHXPLLL", "TRELLIS_IO", "IOLOGIC",
            "SIOLOGIC", "DCCA")
    lines += [f"| resource (seed {runs[0]['seed']}) | used | available | % |", "|---|---:|---:|---:|"]
    for k in keep:
        if k in util:
            u = util[k]
            lines.append(f"| {k} | {u['used']} | {u['available']} | {100 * u['used'] / u['available']:.0f} |")
    t = s["seconds"]
    lines += ["", f"Times on this 2-core machine: conversion {t['convert']} s, Yosys {t['yosys']} s, nextpnr "
              + ", ".join(f"{r['seconds']} s (seed {r['seed']})" for r in runs)
              + (f", ecppack {t['ecppack']} s" if "ecppack" in t else "") + f"; {t['total']} s in all.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m eyestereo.hdl.flow.bitstream",
                                 description="The bitstream of a board design (make bitstream BOARD=...).")
    ap.add_argument("--board", default=board_pins.BOARD, help=f"the board ({', '.join(BOARDS)})")
    ap.add_argument("--out", type=Path, help="output folder (default build/board/<board>)")
    ap.add_argument("--seeds", default="1", help="nextpnr seeds to try in turn, e.g. 1,2,3,4 (default 1)")
    ap.add_argument("--cameras", type=Path, help="the cameras' header mapping, a JSON file (docs/boards.md)")
    ap.add_argument("--matcher", action="store_true",
                    help="with the front end's hardware matcher (the monitor draws the matches; eyestereo board grab "
                         "--matches reads them)")
    ap.add_argument("--doc", type=Path, help="fill this page's bitstream section with the figures (docs/boards.md)")
    ap.add_argument("--from-summary", type=Path, metavar="JSON",
                    help="no build: fill --doc from a kept run's bitstream.json (<out>/bitstream.json)")
    args = ap.parse_args(argv)
    try:
        seeds = [int(s) for s in re.split(r"[ ,]+", args.seeds.strip()) if s]
        if not seeds or any(s < 1 for s in seeds):
            raise ValueError
    except ValueError:
        print(f"error: --seeds {args.seeds!r}: give positive integers, e.g. 1,2,3,4", file=sys.stderr)
        return 1
    out = args.out or Path("build/board") / args.board
    if args.doc is not None:
        text = args.doc.read_text() if args.doc.is_file() else ""
        if DOC_MARKERS[0] not in text or DOC_MARKERS[1] not in text:
            print(f"error: {args.doc}: no '{DOC_MARKERS[0]}' ... '{DOC_MARKERS[1]}' section to fill", file=sys.stderr)
            return 1
    if args.from_summary is not None:
        if args.doc is None:
            print("error: --from-summary fills a page: give --doc", file=sys.stderr)
            return 1
        try:
            s = json.loads(args.from_summary.read_text())
            text = doc_section(s)
        except (OSError, ValueError, KeyError) as e:
            print(f"error: {args.from_summary}: not a bitstream summary ({e})", file=sys.stderr)
            return 1
        write_section(args.doc, text, *DOC_MARKERS)
        return 0
    try:
        s = build(args.board, out, seeds=seeds, mapping=args.cameras, **({"matcher": True} if args.matcher else {}))
    except (ValueError, RuntimeError) as e:
        print(f"error: {str(e).splitlines()[0]}", file=sys.stderr)
        summary = out / "bitstream.json"
        if args.doc is not None and summary.is_file():  # the figures of a run that missed a clock are shown too
            write_section(args.doc, doc_section(json.loads(summary.read_text())), *DOC_MARKERS)
        return 1
    if args.doc is not None:
        write_section(args.doc, doc_section(s), *DOC_MARKERS)
    for r in s["runs"]:
        print(f"seed {r['seed']}: {'met' if r['ok'] else 'FAILED'} in {r['seconds']} s: " + ", ".join(
            f"{c} {v['achieved']:.1f}/{v['constraint']:.1f} MHz" for c, v in sorted(r["fmax"].items())))
    print(f"{out / (args.board + '.bit')} ({s['seconds']['total']} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
