"""Measure the stream rectifier (rectify="stream", issue 26) and write docs/memory.md's line-cache section.

* The line cache each calibration needs (:func:`eyestereo.tools.models.line_cache.plan`): the synthetic rig and
  the OpenCV chessboard calibration at 352x288 (CIF cameras, OV6630 timing at 17.73 MHz) and at 640x480
  (OV7670-class VGA timing at 24 MHz, 30 frames/s).
* Full frames of each through the block's HDL (``--sim``, default Verilator; GHDL with ``--sim ghdl``), played by
  two camera models at the cameras' own timing, every beat compared with the rectification model: bit-exact or
  not, overrun pulses, where the first and the last rectified pixel come (in camera line periods after the
  cameras' first line and after their last), the simulator's time.
* Resources and fmax of make synth's runs of the block (``--synth DIR``: a ``resources.json`` of
  ``python -m eyestereo.hdl.flow.synth --block line_cache --block stream_rectifier``).

Run: ``python -m eyestereo.sim.measure.bench_stream_rectifier --out docs/memory.md [--sim verilator] [--synth DIR]``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.camera import CIF_PCLK_HZ, DEFAULT_TIMING, VGA_PCLK_HZ, VGA_TIMING
from eyestereo.tools.models.line_cache import plan
from eyestereo.tools.models.poly_unit import Calibration
from eyestereo.tools.reports import markdown_table, publish

BEGIN, END = "<!-- bench_stream_rectifier: begin -->", "<!-- bench_stream_rectifier: end -->"
CASES = [  # calibration, timing name
    ("rig", "CIF"), ("opencv@352x288", "CIF"), ("rig:640x480", "VGA"), ("opencv", "VGA"),
]
TIMINGS = {"CIF": (DEFAULT_TIMING, CIF_PCLK_HZ), "VGA": (VGA_TIMING, VGA_PCLK_HZ)}


def timing_cfg(name: str) -> dict:
    t, pclk = TIMINGS[name]
    return dict(timing=dict(h_blank=t.h_blank, v_sync=t.v_sync, v_back=t.v_back, v_front=t.v_front),
                pclk_mhz=pclk / 1e6)


def fps(name: str) -> float:
    t, pclk = TIMINGS[name]
    return pclk / ((2 * t.width + t.h_blank) * (t.height + t.v_sync + t.v_back + t.v_front))


def run(spec: str, tname: str, sim: str, frames: int, lines: int) -> dict:
    t0 = time.time()
    rep = run_bench("stream_rectifier", "tb_stream_rectifier",
                    dict(timing_cfg(tname), frames=frames, images="file:chessboard_left01.jpg", skew=1.5),
                    name=f"measure_{spec.replace(':', '_').replace('@', '_')}", params=dict(quantizers=spec, lines=lines),
                    sim=sim)
    rep["wall"] = time.time() - t0
    return rep


def synth_rows(path: Path | None) -> list[list]:
    if path is None or not (path / "resources.json").exists():
        return []
    rows = []
    for r in json.loads((path / "resources.json").read_text()):
        if r["block"] not in ("line_cache", "stream_rectifier"):
            continue
        sm, e, f = r.get("summary", {}), r.get("ecp5", {}), r.get("fmax", {}).get("clk", {})
        rows.append([r["label"], sm.get("LUT", ""), sm.get("RAMB16", ""), sm.get("MULT18X18", ""),
                     f"{e.get('TRELLIS_COMB', '')} / {e.get('TRELLIS_FF', '')} / {e.get('DP16KD', 0)} / "
                     f"{e.get('MULT18X18D', 0)}",
                     f"{f['min']:.1f} / {f['median']:.1f} / {f['max']:.1f}" if f else ""])
    return rows


def report(plans: list, runs: list, syn: list, sim: str) -> str:
    out = ["", "Measured by `python -m eyestereo.sim.measure.bench_stream_rectifier` (generated; do not edit).", "",
           "### Lines each calibration needs", "",
           "`tools/models/line_cache.plan`: the rows each rectified row reads from (and every later row's lowest), "
           "the lines the cameras write while the rectifier (8 memory clocks a stereo pixel at 100 MHz) works on "
           "it, 2 lines of skew between the cameras; L is the next power of two.", ""]
    out += markdown_table(["calibration", "cameras", "span (rows)", "lag (lines)", "needed", "L", "block RAM (kbit, both)",
                           "frame end margin (lines)"],
                          [[p["calibration"], f"{p['source']} {t}", p["span"], p["lag"], p["needed"], p["lines"],
                            p["kbit"], p["frame_margin_lines"]] for p, t in plans])
    out += ["", f"### Full frames through the HDL ({sim})", "",
            "Two camera models play the chessboard image (the left camera's; the right one sees it shifted by 3 px) with the "
            "cameras' timing, the right camera 1.5 lines behind; every beat compared with the rectification model "
            "(`tools/models/rectifier`). First and last: the rectified frame's first and last pixel, in line "
            "periods after the cameras' first line and after their last. External memory reads for "
            "rectification: none (the block has no memory port).", ""]
    out += markdown_table(["calibration", "cameras", "frames/s (the cameras')", "L", "bit-exact", "overrun pulses",
                           "first pixel (lines)", "last pixel after the last line (lines)", "simulation (s)"],
                          [[r["spec"], r["cams"], f"{r['fps']:.1f}", r["lines"], "yes" if r["bit_exact"] else "NO",
                            r["overruns"], f"{r['first_beat_lines'][0]:.1f}", f"{r['end_after_last_line'][0]:.1f}",
                            f"{r['sim_seconds']:.0f}"] for r in runs])
    if syn:
        out += ["", "### Resources and fmax (make synth, ECP5 LFE5U-25F speed 6, seeds 1-4; Spartan-3E counts by Yosys)", ""]
        out += markdown_table(["configuration", "XC3S LUT", "RAMB16", "MULT18X18", "ECP5 cells: LUT4 / FF / DP16KD / MULT18X18D",
                               "fmax clk (min / median / max, MHz)"], syn)
    return "\n".join(out) + "\n\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--sim", default="verilator")
    ap.add_argument("--frames", type=int, default=1)
    ap.add_argument("--synth", type=Path, help="a make synth output folder with the block's resources.json")
    ap.add_argument("--only", action="append", help="only these calibrations (repeatable)")
    ap.add_argument("--reuse", action="store_true", help="take the runs from build/stream_rectifier/runs.json if there")
    a = ap.parse_args(argv)
    plans, runs = [], []
    kept = Path("build/stream_rectifier/runs.json")
    old = {r["spec"]: r for r in json.loads(kept.read_text())} if a.reuse and kept.is_file() else {}
    for spec, tname in CASES:
        cal = Calibration.load(spec)
        t, pclk = TIMINGS[tname]
        p = plan(cal, timing=t, pixel_clock_hz=pclk)
        plans.append((p.as_dict(), tname))
        if a.only and spec not in a.only:
            continue
        if spec in old:
            runs.append(old[spec])
            continue
        rep = run(spec, tname, a.sim, a.frames, p.lines)
        rep.update(spec=spec, cams=f"{cal.source_width}x{cal.source_height} {tname}", fps=fps(tname), lines=p.lines)
        runs.append(rep)
        print(spec, {k: rep[k] for k in ("bit_exact", "overruns", "sim_seconds")}, flush=True)
    kept.parent.mkdir(parents=True, exist_ok=True)
    kept.write_text(json.dumps(runs) + "\n")
    publish(report(plans, runs, synth_rows(a.synth), a.sim), a.out, BEGIN if a.out else None, END if a.out else None)
    return 0 if all(r["bit_exact"] and r["overruns"] == 0 for r in runs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
