"""Measure the whole hardware matcher on full frames and its accuracy; write docs/matching.md's section on it.

**Full frames.** Tsukuba, Venus and Motorcycle (:mod:`eyestereo.tools.dense.datasets`, resized to the cameras'
352 x 288), the strongest :data:`CORNERS` Harris corners of each image
(:func:`eyestereo.tools.matching.sparse.detect_corners`; at least 500 per camera inside the border) as the flags,
through ``feature_matcher``'s HDL (sim/benches/tb_feature_matcher.py): the pixels at a beat every 1.5 clocks
on average, the flags 4 rows, 5 pixels and 30 clocks behind (harris_stereo's lead at nms 3 and a crossing),
the list port stalled a fifth of the time; every word compared with the model (the bench fails on any
difference), ``dropped``, ``late`` and ``lost`` 0.

**Accuracy.** On the same corners, the hardware's matches (its bit-true model, which the runs above show equal
to the HDL) against the software matcher's (:func:`eyestereo.tools.matching.sparse.match_features`) with the
same parameters (SAD 9 x 9, t_max 11, disparities 0 .. width / 4 = 88, R = 0, the left-right check), and the
hardware's census cost (80 bits, h_max 15 %, which the software matcher does not have): matches, good, bad
(|error| > 1 px against the ground truth), RMS (:func:`eyestereo.tools.matching.metrics.sparse_scores`).

**Pace.** Frames of more and more corners (:data:`PACE_FRAMES`: Tsukuba's Harris corners, random flags on up to 3 %
of the pixels) at the stream's fastest pace (a beat every clock), on Verilator: is every corner kept, is the
list bit-exact (:func:`pace`)?

Run: ``python -m eyestereo.sim.measure.bench_feature_matcher --out docs/matching.md [--sims verilator,ghdl,icarus]
[--reuse] [--no-pace]`` (each run's report is kept in build/feature_matcher_runs/; ``--reuse`` takes those).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from eyestereo.sim.lib.runner import ghdl_backend, run_bench
from eyestereo.tools.reports import markdown_table, publish

BEGIN, END = "<!-- bench_feature_matcher: begin -->", "<!-- bench_feature_matcher: end -->"
WIDTH, HEIGHT = 352, 288
CORNERS = 520  # the detector's count: 517 .. 531 corners per image inside the border on the three scenes
SCENES = ("tsukuba", "venus", "motorcycle")
D_MAX = WIDTH // 4
COSTS = {"sad": dict(t_max=11), "census": dict(h_max=15)}
PARAMS = dict(window=9, width=WIDTH, height=HEIGHT, border=4, lead=4, queue=32, d_min=0, d_max=D_MAX, rows=0,
              slots=64, corners=1023, max_matches=1023, events=16)
STREAM = dict(idle=0.5, stall=0.2, lag_rows=4, lag_pixels=5, lag_clocks=30, lr_check=True, seed=1)
RUNS = Path("build/feature_matcher_runs")


def run(scene: str, cost: str, sim: str) -> dict:
    t0 = time.time()
    rep = run_bench("feature_matcher", "tb_feature_matcher",
                    dict(frames=[f"dataset:{scene}:{CORNERS}"], **COSTS[cost], **STREAM),
                    name=f"measure_{scene}_{cost}", params=dict(PARAMS, cost=cost), sim=sim)
    rep.update(wall=time.time() - t0, scene=scene, cost=cost,
               sim=f"ghdl ({ghdl_backend()})" if sim == "ghdl" else sim)
    return rep


def kept_or_run(scene: str, cost: str, sim: str, reuse: bool) -> dict:
    f = RUNS / f"{scene}_{cost}_{sim}.json"
    if reuse and f.is_file():
        return json.loads(f.read_text())
    rep = run(scene, cost, sim)
    RUNS.mkdir(parents=True, exist_ok=True)
    f.write_text(json.dumps(rep, indent=2) + "\n")
    return rep


#: The pace study: frames of more and more corners through the matcher at the stream's fastest pace: Tsukuba with
#: 520 Harris corners and with all its corners (the detector's count 2000 finds about 780 per image), then random
#: flags on 1 %, 2 % and 3 % of the pixels (about 1000, 2000, 3000 corners per image; random grey levels).
PACE_FRAMES = ("dataset:tsukuba:520", "dataset:tsukuba:2000", "random:1:0.01", "random:2:0.02", "random:3:0.03")
PACE_PARAMS = dict(PARAMS, corners=4095, max_matches=4095)  # the result table for 3000+ left corners


def pace(spec: str, reuse: bool) -> dict:
    """One frame (``spec``: :func:`eyestereo.sim.lib.corner_frames.frame_case`), SAD, the pixels at a beat every
    clock (a stereo row of 352 in 704 clocks, a frame in 203 k: 2 ms at 100 MHz), the list port never stalled, on
    Verilator; the run's report, or ``kept: False`` when a corner was dropped (the bench's checks failed)."""
    f = RUNS / f"pace_{spec.replace(':', '_')}.json"
    if reuse and f.is_file():
        return json.loads(f.read_text())
    t0 = time.time()
    try:
        rep = run_bench("feature_matcher", "tb_feature_matcher",
                        dict(frames=[spec], **COSTS["sad"], **dict(STREAM, idle=0.0, stall=0.0)),
                        name=f"pace_{spec.replace(':', '_')}", params=dict(PACE_PARAMS, cost="sad"), sim="verilator")
        rep.update(kept=True)
    except (AssertionError, RuntimeError) as e:
        from eyestereo.sim.lib.runner import build_dir_of

        rep = dict(kept=False, error=str(e).splitlines()[0][:200])
        written = build_dir_of("feature_matcher", f"pace_{spec.replace(':', '_')}", "verilator") / "report.json"
        if written.is_file():  # the bench's flags: which part could not keep the corners
            flags = json.loads(written.read_text()).get("flags", {})
            rep["error"] = ", ".join(f"{k} {v}" for k, v in flags.items() if v) or rep["error"]
    rep.update(spec=spec, wall=time.time() - t0)
    RUNS.mkdir(parents=True, exist_ok=True)
    f.write_text(json.dumps(rep, indent=2) + "\n")
    return rep


def accuracy() -> list[list]:
    """Rows (scene, matcher, corners, matches, good, bad, bad %, RMS) on the three scenes."""
    import numpy as np

    from eyestereo.sim.lib.corner_frames import harris_flags
    from eyestereo.tools.dense import datasets
    from eyestereo.tools.matching.metrics import sparse_scores
    from eyestereo.tools.matching.sparse import match_features
    from eyestereo.tools.models.corner_descriptors import corners
    from eyestereo.tools.models.feature_matcher import feature_matcher

    rows = []
    for scene in SCENES:
        pair = datasets.resize(datasets.load(scene), WIDTH, HEIGHT)
        fl = corners(harris_flags(pair.left, CORNERS), PARAMS["border"])
        fr = corners(harris_flags(pair.right, CORNERS), PARAMS["border"])
        sw = match_features(pair.left, pair.right, fl, fr, window=(9, 9), t_max=11, cost="sad", d_min=0,
                            d_max=D_MAX, rows=0, lr_check=True)
        found = [("software (match_features), SAD", np.asarray(sw.left), np.asarray(sw.disparity))]
        for cost in COSTS:
            hw = feature_matcher(pair.left, pair.right, fl, fr, window=9, cost=cost, d_min=0, d_max=D_MAX, rows=0,
                                 lr_check=True, **COSTS[cost])
            m = hw["matches"]
            found.append((f"hardware, {cost}", m[:, :2], m[:, 2]))
        for name, pts, disp in found:
            s = sparse_scores(pts, disp, pair.gt)
            rows.append([scene, name, f"{len(fl)} / {len(fr)}", len(pts), s.good, s.bad, f"{s.bad_percent:.1f}",
                         f"{s.rms:.2f}"])
    return rows


def report(runs: list[dict], acc: list[list], paces: list[dict] | None = None) -> str:
    out = ["", "Measured by `python -m eyestereo.sim.measure.bench_feature_matcher` (generated; do not edit).", "",
           f"The three scenes at {WIDTH} x {HEIGHT}, the strongest {CORNERS} Harris corners per image as the flags, 9 x 9, "
           f"d 0..{D_MAX}, R = 0, the left-right check (SAD: t_max 11, limit 891; census: h_max 15 %, limit 12); the "
           "pixels a beat every 1.5 clocks on average, the flags 4 rows + 5 pixels + 30 clocks behind, the list "
           "port stalled a fifth of the time; every list word compared with the model, no corner dropped.", ""]
    out += markdown_table(["scene", "cost", "simulator", "corners (left / right)", "candidates", "matches",
                           "bit-exact", "list done, clocks after the last flag", "wall (s)"],
                          [[r["scene"], r["cost"], r["sim"], f"{r['corners'][0][0]} / {r['corners'][0][1]}",
                            r["candidates"][0], r["matches"][0], "yes", r["list_latency"][0], f"{r['wall']:.0f}"]
                           for r in runs])
    out += ["", "Accuracy on the same corners: the hardware (its model, equal to the HDL above) against the software "
            "matcher with the same parameters; bad = |d - d_true| > 1 px where the ground truth is known.", ""]
    out += markdown_table(["scene", "matcher", "corners (left / right)", "matches", "good", "bad", "bad %", "RMS px"],
                          acc)
    if paces:
        frame = 2 * WIDTH * HEIGHT
        out += ["", "Pace (Verilator): SAD, more and more corners (Tsukuba's Harris corners, then random flags on 1, 2 "
                "and 3 % of the pixels), the pixels at a beat every clock (a stereo row in "
                f"{2 * WIDTH} clocks, a frame in {frame} clocks: {1e8 / frame:.0f} frames/s at 100 MHz, ten times the "
                "cameras' rate; the front end's rectifier takes about 9 clocks per stereo pixel), the list never "
                "stalled, the result table sized for 4095 left corners.", ""]
        out += markdown_table(["frame", "corners (left / right)", "candidates", "matches",
                               "every corner kept, bit-exact", "list done, clocks after the last flag"],
                              [[p["spec"], f"{p['corners'][0][0]} / {p['corners'][0][1]}" if p["kept"] else "-",
                                p["candidates"][0] if p["kept"] else "-", p["matches"][0] if p["kept"] else "-",
                                "yes" if p["kept"] else f"no ({p['error']}: the engine's `dropped` is its stores, "
                                "event queue or table)" if "dropped" in p["error"] else f"no ({p['error']})",
                                p["list_latency"][0] if p["kept"] else "-"] for p in paces])
    return "\n".join(out) + "\n\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="the page to write the section into (docs/matching.md)")
    ap.add_argument("--sims", default="verilator", help="comma-separated: verilator, icarus, ghdl")
    ap.add_argument("--cases", default=None, help="comma-separated scene_cost (default: every scene and cost)")
    ap.add_argument("--reuse", action="store_true", help=f"take the runs kept in {RUNS} instead of running them again")
    ap.add_argument("--no-pace", action="store_true", help="leave the pace study out")
    args = ap.parse_args(argv)
    sims = [s for s in args.sims.split(",") if s]
    bad = [s for s in sims if s not in ("verilator", "icarus", "ghdl")]
    if bad or not sims:
        ap.error(f"unknown simulator: {', '.join(bad) or '(none given)'}")
    cases = [(s, c) for s in SCENES for c in COSTS]
    if args.cases:
        want = set(args.cases.split(","))
        unknown = want - {f"{s}_{c}" for s, c in cases}
        if unknown:
            ap.error(f"unknown case: {', '.join(sorted(unknown))}")
        cases = [(s, c) for s, c in cases if f"{s}_{c}" in want]
    runs = [kept_or_run(s, c, sim, args.reuse) for sim in sims for s, c in cases]
    paces = [] if args.no_pace else [pace(spec, args.reuse) for spec in PACE_FRAMES]
    publish(report(runs, accuracy(), paces), args.out, BEGIN, END)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
