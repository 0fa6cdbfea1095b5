"""Benchmark of the coordinate warper: ``python -m eyestereo.sim.measure.bench_warper``.

Measured here, by running the GHDL bench (:mod:`eyestereo.sim.benches.tb_coordinate_warper` on the harness of
:mod:`eyestereo.sim.harnesses.warper_harness`) and Yosys:

* **full frames**, every pair compared bit for bit with the model: the synthetic rig (352x288) with a
  consumer that takes each pair at once (combinational and registered), after random delays and in
  long bursts; seeded rigs at 352x288 (the larger spreads leave the camera image more); the shared
  OpenCV chessboard calibration at its own 640x480;
* **throughput**: clocks per pair between the first and the last take of a frame (4.0 = the unit never
  stops), and the clocks from ``start`` to ``done``;
* **simulation speed**: simulated clocks per second of the bench run (conversion, elaboration and the
  FFC of an uncached calibration excluded);
* **the netlist** that is measured (GHDL's synthesis of the VHDL, :mod:`eyestereo.sim.lib.netlist`) on Icarus
  Verilog: the same bench, one full frame of the default calibration;
* **resources** and **fmax**: :func:`eyestereo.hdl.flow.synth.synth_block` (that netlist through Yosys
  ``synth_xilinx -family xc3se``; ``nextpnr-ecp5`` for fmax) beside the thesis's Table 4.4.

Writes the section between ``<!-- warper-bench:begin -->`` and ``<!-- warper-bench:end -->`` of
``docs/rectifier.md`` (``--no-write``: print only; ``--quick``: the default calibration only).
GHDL's back end: ``$GHDL_BACKEND`` (``llvm`` if ``ghdl-llvm`` is installed), else mcode.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import sys
import time
from pathlib import Path

import eyestereo.sim.harnesses.warper_harness  # noqa: F401  (registers the bench top)
from eyestereo.hdl.flow import synth
from eyestereo.sim.lib.runner import BUILD, ROOT, run_bench, slug
from eyestereo.tools.rectify import calibrations
from eyestereo.tools.reports import markdown_table, publish

TOP = "coordinate_warper_tb"
BEGIN, END = "<!-- warper-bench:begin -->", "<!-- warper-bench:end -->"

#: label, calibration spec, consumer configuration
FULL = [
    ("synthetic rig, consumer at once", "rig", dict(ack_p=256)),
    ("synthetic rig, registered one-clock pulses", "rig", dict(ack_p=256, ack_reg=True)),
    ("synthetic rig, random consumer (p = 1/2 per clock)", "rig", dict(ack_p=128)),
    ("synthetic rig, bursts without acknowledgement", "rig", dict(ack_p=256, burst=True)),
    ("seeded rig 1 (spread 1)", "seed:1", dict(ack_p=256)),
    ("seeded rig 2 (spread 2)", "seed:2:2", dict(ack_p=256)),
    ("seeded rig 3 (spread 3)", "seed:3:3", dict(ack_p=256)),
    ("seeded rig 4 (spread 4), random consumer", "seed:4:4", dict(ack_p=100, ack_reg=True)),
    ("OpenCV chessboard calibration, 640x480", "opencv", dict(ack_p=256)),
]

#: Thesis Table 4.4 (Xilinx ISE, post place and route): MULT18X18, LUTs.
THESIS = {"calculation unit": (9, 262), "coordinate warper (without the unit)": (0, 99)}


def _backend() -> str:
    """GHDL's code generator: ``$GHDL_BACKEND`` (the Debian ``ghdl`` wrapper honours it), else mcode."""
    return os.environ.get("GHDL_BACKEND", "mcode")


def full_frame(label: str, spec: str, consumer: dict) -> dict:
    calibrations.load(spec)  # build (and cache) the calibration outside the timed run
    t0 = time.perf_counter()
    rep = run_bench(TOP, "tb_coordinate_warper", dict(consumer, frames=1, seed=1), name=f"bench_{slug(label)}",
                    params=dict(quantizers=spec, batch=32))
    wall = time.perf_counter() - t0
    sim_s = None
    for f in Path(rep.get("build_dir", BUILD / TOP / slug(f"bench_{slug(label)}"))).glob("*.xml"):
        m = re.search(r'<testcase [^>]*time="([0-9.]+)"', f.read_text())
        sim_s = float(m.group(1)) if m else None
    return dict(label=label, spec=spec, consumer=consumer, wall=wall, sim=sim_s, **rep)


def netlist_frame(spec: str = "rig") -> dict:
    """One full frame of the bench on GHDL's netlist of the VHDL (harness and warper), in Icarus Verilog:
    the netlist whose resources are measured below, shown bit-exact."""
    from eyestereo.sim.lib.netlist import run_netlist_bench

    if shutil.which("iverilog") is None:
        return dict(skipped="iverilog not installed")
    t0 = time.perf_counter()
    rep = run_netlist_bench(TOP, "tb_coordinate_warper", dict(frames=1, seed=1, ack_p=256),
                            name=f"bench_netlist_{slug(spec)}", params=dict(quantizers=spec, batch=32))
    return dict(rep, wall=time.perf_counter() - t0)


def resources() -> list[dict]:
    out = []
    for label, block, params in [("poly_unit", "poly_unit", {}),
                                 ("coordinate_warper", "coordinate_warper", {}),
                                 ("poly_unit, run-time coefficients", "poly_unit", dict(coefficients="register")),
                                 ("coordinate_warper, OpenCV 640x480", "coordinate_warper", dict(quantizers="opencv"))]:
        print(f"bench_warper: synthesizing {label} ...", flush=True)
        try:
            out.append(synth.synth_block(block, BUILD.parent / "synth_warper", label=label, pnr=True, **params))
        except FileNotFoundError as exc:
            print(f"skipped {label}: {exc}", file=sys.stderr)
    return out


def report(frames: list[dict], icarus: dict | None, res: list[dict], backend: str) -> str:
    lines = [f"Measured by `python -m eyestereo.sim.measure.bench_warper` on GHDL ({backend} back end); every pair of every "
             "frame compared with the bit-true model (all fields). Clocks per pair: between the first and the last "
             "take of the frame; frame: clocks from `start` to `done`.", ""]
    lines += markdown_table(
        ["frame", "calibration", "pairs compared", "out of range L / R", "clocks per pair", "frame clocks",
         "sim speed (clk/s)"],
        [[f["label"], f"`{f['spec']}` {f['width']}x{f['height']}", f"{f['pairs']:,}",
          f"{100 * f['oor_l'] / f['pairs']:.1f} % / {100 * f['oor_r'] / f['pairs']:.1f} %", f"{f['clocks_per_pair']:.4f}",
          f"{f['frame_clocks'][0]:,}", f"{f['frame_clocks'][0] / f['sim']:.0f}" if f.get("sim") else "?"]
         for f in frames], "ll" + "r" * 5) + [""]
    at_once = [f for f in frames if f["consumer"].get("ack_p") == 256 and not f["consumer"].get("burst")]
    if at_once:
        cpp = sorted({round(f["clocks_per_pair"], 6) for f in at_once})
        lines.append(f"With a consumer that takes every pair at once: **{', '.join(f'{c:g}' for c in cpp)} clocks per "
                     "pair** (goal 4.0): the unit never stops; a frame takes 4 x width x height + 10 clocks.")
    if icarus:
        if "skipped" in icarus:
            lines.append(f"Netlist: skipped ({icarus['skipped']}).")
        else:
            lines.append(f"GHDL's netlist of the VHDL (harness and warper; the netlist whose resources follow), in "
                         f"Icarus Verilog: one full frame of the synthetic rig, {icarus['pairs']:,} pairs bit-exact, "
                         f"{icarus['clocks_per_pair']:.4f} clocks per pair ({icarus['wall']:.0f} s).")
    lines += ["", "Resources of GHDL's netlist of the VHDL (`eyestereo.hdl.flow.synth`: `ghdl synth`, repaired, Yosys "
              "`synth_xilinx -family xc3se`; LUT = 4-input LUTs, carry cells not counted) and fmax of the same "
              "netlist placed and routed on an ECP5 (`nextpnr-ecp5`; the Spartan-3E has no open place and route: "
              "the figure says how deep the logic is, the thesis's goal is 100 MHz):", ""]
    thesis = {"poly_unit": "calculation unit: 9 / 262",
              "coordinate_warper": "calculation unit + warper: 9 / 262 + 99 = 361"}
    lines += markdown_table(
        ["block", "LUT", "FF", "LUT-RAM", "MULT18X18", "fmax ECP5 (MHz)", "thesis Table 4.4 (ISE, post-PAR): MULT / LUT"],
        [[r["label"], *(r["summary"][k] for k in ("LUT", "FF", "LUTRAM", "MULT18X18")),
          ", ".join(f"{v['achieved']:.1f}" for v in (r.get("fmax") or {}).values()) or "-", thesis.get(r["label"], "-")]
         for r in res], "l" + "r" * 5 + "l")
    by = {r["label"]: r["summary"] for r in res}
    if "poly_unit" in by and "coordinate_warper" in by:
        u, w = by["poly_unit"]["LUT"], by["coordinate_warper"]["LUT"]
        lines += ["", f"Against the thesis: the unit alone {u} LUTs ({100 * (u / 262 - 1):+.0f} % against its 262), "
                  f"the whole warper with its unit {w} LUTs ({100 * (w / 361 - 1):+.0f} % against 262 + 99). MyHDL "
                  "flattens the warper and its unit into one netlist, so the warper's own share is not separable "
                  "(Yosys optimizes the unit inside the warper, whose inputs come from counters, differently from "
                  "the unit on its own). Multipliers beyond 9: operands above 18 bits, below."]
    wide = []
    for spec in ("rig", "opencv"):
        try:
            doc = calibrations.load(spec)
        except FileNotFoundError:
            continue
        ops = ", ".join(f"{w['product']} operand {w['operand']} ({'s' if w['signed'] else 'u'}fix[{w['wl']},{w['fl']}], "
                        f"{w['signed_bits']} signed bits)" for w in doc["wide_multiplier_inputs"]) or "none"
        wide.append(f"`{spec}`: {ops}")
    lines += ["", "Multiplier operands above 18 signed bits (each costs a second MULT18X18): " + "; ".join(wide) + "."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Full frames, throughput and resources of the coordinate warper.")
    ap.add_argument("--doc", type=Path, default=ROOT / "docs" / "rectifier.md")
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--quick", action="store_true", help="only the default calibration, consumer at once")
    args = ap.parse_args(argv)
    backend = _backend()
    frames = []
    for label, spec, consumer in (FULL[:1] if args.quick else FULL):
        print(f"bench_warper: {label} ...", flush=True)
        try:
            frames.append(full_frame(label, spec, consumer))
        except FileNotFoundError as exc:
            print(f"skipped {label}: {exc}", file=sys.stderr)
    print("bench_warper: the netlist on Icarus ...", flush=True)
    icarus = None if args.quick else netlist_frame()
    publish(report(frames, icarus, resources(), backend), None if args.no_write else args.doc, BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
