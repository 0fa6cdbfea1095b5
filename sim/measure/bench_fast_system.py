"""Benchmark: a full 352x288 frame of the complete front end on the fast harness, beside today's bench (issue 25).

Both benches run the same top (stereo_frontend, 352x288, the synthetic rig's calibration, lists of 255 features),
the same scene (``shift:3``: a random texture moving a pixel per frame, the right view shifted), the OV6630's real
blanking, cameras at 18 and 17.9 MHz, memory 100 MHz, Harris 50 MHz, the overlapped mode, and check every frame
read bit for bit against the numpy chain:

* **today's bench** (:mod:`eyestereo.sim.benches.tb_stereo_frontend`): Python camera models (a wake per bus
  byte), the Python SRAM model (a wake per busy memory clock), cocotbext-axi's AXI4-Lite master with the bus
  checker, the rectified pair and the lists read through the bus;
* **the fast harness** (:mod:`eyestereo.sim.benches.tb_frontend_fast` on
  :mod:`eyestereo.sim.harnesses.frontend_harness`): HDL camera players, the HDL SRAM part (its rules checked in the
  simulator), a lean AXI4-Lite master awake only for its transfers, the pair and the lists read through the SRAM
  part's backdoor.

Measured per run: the build (conversion and the simulator's build), cocotb's time of the test, and per frame read
the wall time between consecutive reads (steady state) and the test's time over the frames read (start-up and the
final drain included). On Verilator (``--frames``) and on GHDL with the LLVM back end (``--ghdl-frames``; today's
bench on GHDL with ``--old-ghdl-frames``, about a quarter of an hour a frame). The table goes to docs/system.md
between its ``fast_system`` markers; every run's report is kept in build/system/fast/ (``--reuse``).

    python -m eyestereo.sim.measure.bench_fast_system [--frames 3] [--ghdl-frames 2] [--old-ghdl-frames 1]
        [--jobs 2] [--reuse] [--out docs/system.md]
"""

from __future__ import annotations

import argparse
import datetime
import json
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from eyestereo.sim.lib.frontend_runs import PUBLIC as OLD_PUBLIC
from eyestereo.sim.lib.runner import ROOT, hdl_revision, run_bench
from eyestereo.tools.io import write_section

RUNS = ROOT / "build" / "system" / "fast"
BEGIN, END = "<!-- fast_system: begin -->", "<!-- fast_system: end -->"
FAST_PUBLIC = ["clk", "rst", "hclk", "hrst", "base_l", "base_r", "wrst_l", "wrst_r", "bus_*", "cam_go", "fifo_clear",
               "cam_l_*", "cam_r_*", "sram_*"]
PARAMS = dict(quantizers="rig:352x288", feature_words=512, max_features=255)
SIM_NAMES = {("verilator", None): "Verilator (MyHDL's Verilog)", ("ghdl", "llvm"): "GHDL, LLVM back end (the VHDL)"}
JOBS = [1]  # runs at a time (main sets it; kept in each report)
GOALS = {"verilator": 60.0, "ghdl": 240.0, "ghdl_ieeefast": 240.0}  # s per full frame (issue 25); the goal beyond them: 30 s on Verilator


def run(kind: str, sim: str, frames: int, reuse: bool, ieee: str = "standard") -> dict:
    """One run: ``kind`` "old" (today's bench) or "fast"; ``ieee`` (GHDL): "standard" or "fast" (the faster
    numeric_std body of sim/lib/ghdl_ieee.py: the same results); its report with wall times added, kept in RUNS."""
    import eyestereo.sim.harnesses.frontend_harness  # noqa: F401  (registers the bench top)

    backend = "llvm" if sim == "ghdl" else None
    tag = f"{kind}_{sim}{'_ieeefast' if ieee == 'fast' else ''}_{frames}"
    kept = RUNS / f"{tag}.json"
    if reuse and kept.is_file():
        return json.loads(kept.read_text())
    RUNS.mkdir(parents=True, exist_ok=True)
    cfg = dict(mode="overlapped", frames=frames, images="shift:3", timing={}, target=200, require_features=True,
               **(dict(ieee="fast") if ieee == "fast" else {}))
    print(f"[fast_system] {tag} ...", flush=True)
    t0 = time.time()
    if kind == "old":
        rep = run_bench("stereo_frontend", "tb_stereo_frontend", cfg, name=f"fast_cmp_{tag}", sim=sim,
                        backend=backend, params=PARAMS, log_file=RUNS / f"{tag}.log",
                        public=OLD_PUBLIC if sim == "verilator" else None)
        rep.pop("last", None)
    else:
        rep = run_bench("frontend_harness", "tb_frontend_fast", cfg, name=f"fast_cmp_{tag}", sim=sim,
                        backend=backend, params=PARAMS, log_file=RUNS / f"{tag}.log",
                        public=FAST_PUBLIC if sim == "verilator" else None)
    rep.update(kind=kind, simulator=SIM_NAMES[(sim, backend)] + (", fast numeric_std" if ieee == "fast" else ""),
               sim_key=sim + ("_ieeefast" if ieee == "fast" else ""), wall_total_s=round(time.time() - t0, 1),
               hdl=hdl_revision(), date=datetime.date.today().isoformat(), jobs=JOBS[0])
    kept.write_text(json.dumps(rep) + "\n")
    print(f"[fast_system] {tag}: {len(rep['frames'])} frames, {rep['wall_total_s']} s", flush=True)
    return rep


def row(rep: dict) -> dict:
    """The figures of one run: frames, simulated time, build, test, per frame (steady, over the test)."""
    frames = rep["frames"]
    n = len(frames)
    test_s = rep.get("sim_seconds") or 0.0
    steady = [f["wall_s"] for f in frames[1:] if "wall_s" in f]
    sim_ms = (rep.get("total_ns") or rep.get("sim_ns") or 0) / 1e6
    return dict(n=n, sim_ms=sim_ms, build_s=rep["wall_total_s"] - test_s, test_s=test_s,
                per_frame_s=test_s / n if n else None, steady_s=sum(steady) / len(steady) if steady else None,
                clocks_per_s=sim_ms * 1e5 / test_s if test_s else None)


def table(reports: list[dict]) -> list[str]:
    out = [BEGIN, "",
           f"Measured by `python -m eyestereo.sim.measure.bench_fast_system` (generated; do not edit) on "
           f"{reports[0]['date']}, HDL {reports[0]['hdl']}: 352x288, the OV6630's blanking, cameras 18 / 17.9 MHz, "
           "memory 100 MHz, Harris 50 MHz, overlapped, every frame read bit-exact against the numpy chain; "
           f"{reports[0].get('jobs', 1)} run(s) at a time on this 2-core machine (each simulator single-threaded).",
           "",
           "| simulator | bench | frames read | simulated | build | test | per frame (test / frames) | "
           "per frame, steady (read to read) | memory clocks / s |",
           "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for rep in reports:
        r = row(rep)
        bench = "today's (Python cameras, SRAM model, AXI master)" if rep["kind"] == "old" else \
            "fast harness (HDL cameras and SRAM part, backdoor)"
        steady = f"{r['steady_s']:.1f} s" if r["steady_s"] is not None else "-"
        out.append(f"| {rep['simulator']} | {bench} | {r['n']} | {r['sim_ms']:.1f} ms | {r['build_s']:.0f} s | "
                   f"{r['test_s']:.0f} s | **{r['per_frame_s']:.1f} s** | {steady} | {r['clocks_per_s']:,.0f} |")
    out += [""]
    by = {(rep["kind"], rep["sim_key"]): row(rep) for rep in reports}
    for sim, goal in GOALS.items():
        f = by.get(("fast", sim))
        o = by.get(("old", sim.split("_")[0]))
        if f is None:
            continue
        name = {"verilator": "Verilator", "ghdl": "GHDL (LLVM)"}.get(sim, "GHDL (LLVM, fast numeric_std)")
        ratio = (f"; over the whole test (start-up, the cameras' first frame and the final drain included) "
                 f"{f['per_frame_s']:.1f} s a frame read against today's bench's {o['per_frame_s']:.0f} s: "
                 f"{o['per_frame_s'] / f['per_frame_s']:.1f} x") if o else \
            f"; over the whole test (start-up and the final drain included) {f['per_frame_s']:.1f} s a frame read"
        steady = f["steady_s"] if f["steady_s"] is not None else f["per_frame_s"]
        out.append(f"* {name}: a full frame (one frame period, 19.8 ms simulated, from one frame read to the next) "
                   f"in **{steady:.1f} s** on the fast harness{ratio}. The goal {goal:.0f} s a frame: "
                   f"{'met' if steady <= goal else 'NOT met'}"
                   + (f"; the stretch goal 30 s: {'met' if steady <= 30 else 'not met'}" if sim == "verilator" else "")
                   + ".")
    return out + ["", END]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=3, help="frames read per Verilator run (both benches)")
    ap.add_argument("--ghdl-frames", type=int, default=2, help="frames read on GHDL LLVM (fast harness; 0: none)")
    ap.add_argument("--old-ghdl-frames", type=int, default=0,
                    help="frames read on GHDL LLVM by today's bench (0: none; about a quarter of an hour a frame)")
    ap.add_argument("--ghdl-fast-ieee", action="store_true",
                    help="also the fast harness on GHDL against the faster numeric_std body (sim/lib/ghdl_ieee.py)")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once (1: the times are each run's alone)")
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "system.md")
    a = ap.parse_args(argv)
    for name in ("frames", "ghdl_frames", "old_ghdl_frames"):
        if getattr(a, name) < 0:
            ap.error(f"--{name.replace('_', '-')} must be >= 0")
    if a.frames < 1 or a.jobs < 1:
        ap.error("--frames and --jobs must be at least 1")
    if BEGIN not in (a.out.read_text() if a.out.is_file() else ""):
        ap.error(f"{a.out} has no '{BEGIN}' ... '{END}' section to fill")
    JOBS[0] = a.jobs
    jobs = [("old", "verilator", a.frames), ("fast", "verilator", a.frames)]
    if a.ghdl_frames:
        jobs.append(("fast", "ghdl", a.ghdl_frames))
    if a.old_ghdl_frames:
        jobs.append(("old", "ghdl", a.old_ghdl_frames))
    if a.ghdl_fast_ieee and a.ghdl_frames:
        jobs.append(("fast", "ghdl", a.ghdl_frames, "fast"))
    try:
        with ThreadPoolExecutor(a.jobs) as ex:
            reports = list(ex.map(lambda j: run(*j[:3], reuse=a.reuse, ieee=j[3] if len(j) > 3 else "standard"),
                                  jobs))
    except AssertionError as e:
        print(f"bench_fast_system: a run failed: {e}", file=sys.stderr)
        return 1
    lines = table(reports)  # the markers first and last
    write_section(a.out, "\n".join(lines[1:-1]) + "\n", BEGIN, END)
    print("\n".join(table(reports)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
