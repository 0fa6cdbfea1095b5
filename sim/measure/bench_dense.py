"""Measure the dense-disparity blocks on full frames and write docs/dense.md's "Full frames" section.

Each case is a Tsukuba pair (the centre 352 x 288 of im3 / im4, the cameras' size) through a block's HDL
(``sgm`` on the census model's words, or the whole ``dense_stereo`` chain on the grey pair; ``census`` and
``median3`` on their own, a table of their own) with D = 64, 4
paths, PU = 4 unless the case says otherwise, fed at about 1.2 x the block's pixel spacing with random idle
gaps (sim/benches/tb_sgm.py), every code compared with the bit-true model. Reported: bit-exact (the bench
fails otherwise), the pixels and valid codes, the pixel spacing, the clocks from the frame's first input to
its last output, what the spacing allows at 100 MHz (frames per second: ``1e8 / (spacing * width *
height)``), the lag of a row's codes after its last input pixel, the simulator and its wall time.

Run: ``python -m eyestereo.sim.measure.bench_dense --out docs/dense.md [--sims verilator,icarus,ghdl]
[--cases sgm,dense_stereo,census,median3] [--reuse]`` (each run's report is kept in build/dense_runs/; ``--reuse`` takes those).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from eyestereo.hdl.dense.sgm import spacing
from eyestereo.sim.lib.runner import ghdl_backend, run_bench
from eyestereo.tools.reports import markdown_table, publish

BEGIN, END = "<!-- bench_dense: begin -->", "<!-- bench_dense: end -->"
DATA = Path("/work/shared/data/middlebury/tsukuba")
WIDTH, HEIGHT = 352, 288
CLOCK_HZ = 100e6
HW = dict(window=5, disparities=64, pu=4, paths=4, path_bits=7, sum_shift=1, frac_bits=4, fifo=256,
          width=WIDTH, height=HEIGHT)
RUNS = Path("build/dense_runs")  # each run's report, for --reuse
CASES = {"sgm": ("sgm", {}), "dense_stereo": ("dense_stereo", dict(median=True, fifo=None)),
         "sgm_pu8": ("sgm", dict(pu=8)),
         # the two blocks around sgm, on their own: census on the grey pair (both cameras' words), median3 on
         # the full frame's codes of the model's census + SGM (no median), at 0.7 beats per clock
         "census": ("census", {}), "median3": ("median3", {})}
SMALL = ("census", "median3")


def data_dir() -> Path:
    """The Tsukuba pair's folder (the shared data set next to the checkout, or the one this machine has)."""
    here = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "middlebury" / "tsukuba"
    return here if here.is_dir() else DATA


def codes_file() -> Path:
    """The model's disparity codes (census + SGM, no median) of the Tsukuba pair's centre, for median3."""
    import cv2
    import numpy as np

    from eyestereo.tools.io import centre_crop
    from eyestereo.tools.models.dense_stereo import dense_stereo

    f = RUNS / f"tsukuba_codes_{WIDTH}x{HEIGHT}.npy"
    if not f.is_file():
        grey = [centre_crop(cv2.imread(str(data_dir() / n), cv2.IMREAD_GRAYSCALE), WIDTH, HEIGHT, n)
                for n in ("im3.png", "im4.png")]
        RUNS.mkdir(parents=True, exist_ok=True)
        np.save(f, dense_stereo(*grey, disparities=HW["disparities"], median=False))
    return f


def run_small(case: str, sim: str) -> dict:
    """census or median3 on one full frame (their benches: tb_census, tb_median3)."""
    t0 = time.time()
    if case == "census":
        pair = [f"image:{data_dir() / 'im3.png'}", f"image:{data_dir() / 'im4.png'}"]
        rep = run_bench("census", "tb_census", dict(frames=[pair], duty=0.7, seed=1), name="measure_census",
                        params=dict(window=HW["window"], width=WIDTH, height=HEIGHT, stereo=True), sim=sim)
    else:
        rep = run_bench("median3", "tb_median3", dict(frames=[f"npy:{codes_file().resolve()}"], duty=0.7, seed=1),
                        name="measure_median3", params=dict(width=WIDTH, height=HEIGHT), sim=sim)
    rep.update(wall=time.time() - t0, case=case, sim=f"ghdl ({ghdl_backend()})" if sim == "ghdl" else sim)
    RUNS.mkdir(parents=True, exist_ok=True)
    (RUNS / f"{case}_{sim}.json").write_text(json.dumps(rep, indent=2) + "\n")
    return rep


def run(case: str, sim: str) -> dict:
    if case in SMALL:
        return run_small(case, sim)
    block, extra = CASES[case]
    params = dict(HW, **extra)
    sp = spacing(params["disparities"], params["pu"])
    pair = [f"image:{data_dir() / 'im3.png'}", f"image:{data_dir() / 'im4.png'}"]
    t0 = time.time()
    rep = run_bench(block, "tb_sgm", dict(frames=[pair], seed=1, pixel_clocks=1.2 * sp), name=f"measure_{case}",
                    params=params, sim=sim)
    rep.update(wall=time.time() - t0, case=case, sim=f"ghdl ({ghdl_backend()})" if sim == "ghdl" else sim,
               pu=params["pu"])
    RUNS.mkdir(parents=True, exist_ok=True)
    (RUNS / f"{case}_{sim}.json").write_text(json.dumps(rep, indent=2) + "\n")
    return rep


def kept(case: str, sim: str) -> dict | None:
    """A run's report from an earlier run of this script (--reuse), or None."""
    f = RUNS / f"{case}_{sim}.json"
    return json.loads(f.read_text()) if f.is_file() else None


def report(runs: list[dict]) -> str:
    small = [r for r in runs if r["case"] in SMALL]
    runs = [r for r in runs if r["case"] not in SMALL]
    rows = []
    for r in runs:
        sp = r["spacing"]
        rows.append([r["case"], r["sim"], r["pu"], "yes", r["pixels_compared"], r["valid_codes"], sp,
                     r["last_out"] - r["first_in"], f"{CLOCK_HZ / (sp * WIDTH * HEIGHT):.1f}",
                     f"{r['row_latency_min']} .. {r['row_latency_max']}", f"{r['wall']:.0f}"])
    out = ["", "Measured by `python -m eyestereo.sim.measure.bench_dense` (generated; do not edit).", "",
           f"Tsukuba's centre {WIDTH} x {HEIGHT}, D = 64, 4 paths, census 5 x 5, default settings; input at about "
           "1.2 x the pixel spacing with random gaps; every code compared with the bit-true model (the bench "
           "fails on any difference).", ""]
    out += markdown_table(["case", "simulator", "PU", "bit-exact", "pixels", "valid codes", "clocks / pixel",
                           "clocks, first input to last code", "fps the spacing allows at 100 MHz",
                           "row lag (clocks after its last pixel)", "wall (s)"], rows)
    if small:
        out += ["", f"The blocks around sgm on their own, the same {WIDTH} x {HEIGHT} frame: census on the grey "
                "pair (both cameras' words compared), median3 on the model's codes of census + SGM without the "
                "median; input at 0.7 beats per clock with random gaps; every output compared with the model, "
                "and the latency of every pixel whose window is complete.", ""]
        out += markdown_table(["case", "simulator", "bit-exact", "words compared", "latency (clocks)",
                               "pixels with the latency checked", "wall (s)"],
                              [[r["case"], r["sim"], "yes", r["pixels_compared"], r["latency"], r["latency_checked"],
                                f"{r['wall']:.0f}"] for r in small])
    return "\n".join(out) + "\n\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="the page to write the section into (docs/dense.md)")
    ap.add_argument("--sims", default="verilator", help="comma-separated: verilator, icarus, ghdl")
    ap.add_argument("--cases", default="sgm,dense_stereo", help=f"comma-separated of {', '.join(CASES)}")
    ap.add_argument("--reuse", action="store_true", help=f"take the runs kept in {RUNS} instead of running them again")
    args = ap.parse_args(argv)
    sims = [s for s in args.sims.split(",") if s]
    cases = [c for c in args.cases.split(",") if c]
    bad = [c for c in cases if c not in CASES] + [s for s in sims if s not in ("verilator", "icarus", "ghdl")]
    if bad or not sims or not cases:
        ap.error(f"unknown case or simulator: {', '.join(bad) or '(none given)'}")
    runs = [(args.reuse and kept(c, s)) or run(c, s) for c in cases for s in sims]
    publish(report(runs), args.out, BEGIN, END)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
