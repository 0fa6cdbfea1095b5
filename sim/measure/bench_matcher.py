"""Measure the hardware matcher's engine on full frames and write docs/matching.md's "Match engine" section.

Each case is a Middlebury pair (Tsukuba im3 / im4, Venus im2 / im6; the centre 352 x 288, the cameras'
size), the strongest 500 Harris corners of each image (:func:`eyestereo.tools.matching.sparse.detect_corners`)
and their 9 x 9 descriptors (SAD: the grey levels, t_max 11, limit 891; census: 80 bits, h_max 15 %,
limit 12), disparities 0..64, the same row (R = 0), the left-right check, through ``match_engine``'s HDL
(sim/benches/tb_match_engine.py): the corners of a row come every ``ROW_CLOCKS`` clocks (the front end's
pace: rectification at 9.2 memory clocks per stereo pixel, docs/system.md), the list port's ``ready`` low a
fifth of the time, every list word compared with the model (the bench fails on any difference).

The pace study (Verilator): the same frames with the rows coming faster, ``ROW_CLOCKS`` halved until the
engine's ``dropped`` flag rises; the fastest row time it kept up with, and the frame rate that allows at
100 MHz (``1e8 / (row clocks * 288)``).

Run: ``python -m eyestereo.sim.measure.bench_matcher --out docs/matching.md [--sims verilator,ghdl,icarus]
[--reuse]`` (each run's report is kept in build/matcher_runs/; ``--reuse`` takes those).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from eyestereo.sim.lib.runner import ghdl_backend, run_bench
from eyestereo.tools.reports import markdown_table, publish

BEGIN, END = "<!-- bench_matcher: begin -->", "<!-- bench_matcher: end -->"
WIDTH, HEIGHT = 352, 288
ROW_CLOCKS = 3240  # 352 stereo pixels x 9.2 memory clocks
CORNERS = 500
PAIRS = {"tsukuba": ("tsukuba", "im3.png", "im4.png"), "venus": ("venus", "im2.png", "im6.png")}
COSTS = {"sad": dict(cost="sad", limit=11 * 81), "census": dict(cost="census", limit=12)}
PARAMS = dict(window=9, width=WIDTH, height=HEIGHT, d_min=0, d_max=64, rows=0, slots=64, corners=1023,
              max_matches=1023, events=16)
RUNS = Path("build/matcher_runs")


def data_dir() -> Path:
    """The Middlebury folder: the shared data set next to the checkout."""
    return Path(__file__).resolve().parents[2].parent / "shared" / "data" / "middlebury"


def spec(pair: str) -> str:
    folder, left, right = PAIRS[pair]
    d = data_dir() / folder
    return f"pair:{d / left}:{d / right}:{CORNERS}"


def run(pair: str, cost: str, sim: str, row_clocks: int = ROW_CLOCKS, *, allow_dropped: bool = False) -> dict:
    c = COSTS[cost]
    params = dict(PARAMS, cost=c["cost"])
    t0 = time.time()
    rep = run_bench("match_engine", "tb_match_engine",
                    dict(frames=[spec(pair)], limit=c["limit"], lr_check=True, row_clocks=row_clocks, stall=0.2,
                         seed=1, budget=200_000, allow_dropped=allow_dropped),
                    name=f"measure_{pair}_{cost}_{row_clocks}", params=params, sim=sim)
    rep.update(wall=time.time() - t0, pair=pair, cost=cost, row_clocks=row_clocks,
               sim=f"ghdl ({ghdl_backend()})" if sim == "ghdl" else sim)
    return rep


def kept_or_run(pair: str, cost: str, sim: str, reuse: bool) -> dict:
    f = RUNS / f"{pair}_{cost}_{sim}.json"
    if reuse and f.is_file():
        return json.loads(f.read_text())
    rep = run(pair, cost, sim)
    RUNS.mkdir(parents=True, exist_ok=True)
    f.write_text(json.dumps(rep, indent=2) + "\n")
    return rep


def pace(pair: str, cost: str, reuse: bool) -> dict:
    """The fastest row time (halving from ROW_CLOCKS) at which the engine kept every corner, on Verilator."""
    f = RUNS / f"{pair}_{cost}_pace.json"
    if reuse and f.is_file():
        return json.loads(f.read_text())
    kept, rc = None, ROW_CLOCKS
    while rc >= 8:
        rep = run(pair, cost, "verilator", rc, allow_dropped=True)
        if rep["dropped"]:
            break
        kept, rc = rc, rc // 2
    out = dict(pair=pair, cost=cost, kept=kept, dropped_at=rc)
    RUNS.mkdir(parents=True, exist_ok=True)
    f.write_text(json.dumps(out, indent=2) + "\n")
    return out


def report(runs: list[dict], paces: list[dict]) -> str:
    rows = [[r["pair"], r["cost"], r["sim"], f"{r['corners'][0][0]} / {r['corners'][0][1]}", r["candidates"][0],
             r["matches"][0], "yes", r["list_latency"][0], f"{r['wall']:.0f}"] for r in runs]
    out = ["", "Measured by `python -m eyestereo.sim.measure.bench_matcher` (generated; do not edit).", "",
           f"The centre {WIDTH} x {HEIGHT} of each pair, the strongest {CORNERS} Harris corners per image, 9 x 9 "
           "descriptors (SAD: limit 891 = 11 x 81; census: 80 bits, limit 12 = 15 %), d 0..64, R = 0, left-right "
           f"check; a row's corners every {ROW_CLOCKS} clocks, the list port stalled a fifth of the time; every "
           "word compared with the model.", ""]
    out += markdown_table(["pair", "cost", "simulator", "corners (left / right)", "candidates", "matches",
                           "bit-exact", "list done, clocks after the last row end", "wall (s)"], rows)
    if paces:
        out += ["", "Pace (Verilator): the rows brought faster, the row time halved until `dropped` rose.", ""]
        out += markdown_table(["pair", "cost", "fastest row time kept (clocks)", "dropped at (clocks)",
                               "frames/s at 100 MHz (288 rows)"],
                              [[p["pair"], p["cost"], p["kept"], p["dropped_at"],
                                f"{1e8 / (p['kept'] * HEIGHT):.0f}" if p["kept"] else "-"] for p in paces])
    return "\n".join(out) + "\n\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="the page to write the section into (docs/matching.md)")
    ap.add_argument("--sims", default="verilator", help="comma-separated: verilator, icarus, ghdl")
    ap.add_argument("--no-pace", action="store_true", help="leave the pace study out")
    ap.add_argument("--reuse", action="store_true", help=f"take the runs kept in {RUNS} instead of running them again")
    args = ap.parse_args(argv)
    sims = [s for s in args.sims.split(",") if s]
    bad = [s for s in sims if s not in ("verilator", "icarus", "ghdl")]
    if bad or not sims:
        ap.error(f"unknown simulator: {', '.join(bad) or '(none given)'}")
    runs = [kept_or_run(p, c, s, args.reuse) for p in PAIRS for c in COSTS for s in sims]
    paces = [] if args.no_pace else [pace(p, c, args.reuse) for p in PAIRS for c in COSTS]
    publish(report(runs, paces), args.out, BEGIN, END)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
