"""The fault soak (``make soak``, issue 25): the front end for many frames under faults; docs/reliability.md's table.

Runs :mod:`eyestereo.sim.benches.tb_frontend_soak` on the fast harness
(:mod:`eyestereo.sim.harnesses.frontend_harness`, Verilator: MyHDL's Verilog of the top with the HDL camera
players and SRAM part) for each run of :data:`PLAN` (``--quick``: :data:`QUICK`), ``--jobs`` at a time: small
frames (48x32 and 96x72, short blanking) in both starting modes and three camera clock ratios, and full 352x288
frames with the OV6630's blanking. Every run injects the camera and host faults of :data:`eyestereo.sim.lib.soak.FAULTS`
and checks every rule written there; a run that fails stops the soak with its message (exit 1) and nothing is
written. Then the runs' functional coverage is merged (:mod:`eyestereo.sim.lib.soak_coverage`) and docs/reliability.md's
soak section is rewritten: the faults and their expected behaviour, the runs, each fault kind's count and
recovery, the coverage and its holes with their reasons.

    python -m eyestereo.sim.measure.soak [--quick] [--jobs 2] [--out docs/reliability.md] [--reuse]
"""

from __future__ import annotations

import argparse
import datetime
import json
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from eyestereo.sim.lib.runner import ROOT, hdl_revision, run_bench
from eyestereo.tools.io import write_section

BUILD = ROOT / "build" / "soak"
BEGIN, END = "<!-- soak: begin -->", "<!-- soak: end -->"
SHORT = dict(h_blank=64, v_sync=1, v_back=1, v_front=1)
PUBLIC = ["clk", "rst", "hclk", "hrst", "base_l", "base_r", "wrst_l", "wrst_r", "bus_*", "cam_go", "fifo_clear",
          "cam_l_*", "cam_r_*", "sram_*"]
#: The soak's runs: name, frame size, the mode it starts in (mode changes switch it), frames read, the cameras'
#: clocks (MHz), the fault plan's seed. Small runs at 0.12 camera faults per camera frame and 0.2 host faults per
#: frame; the full ones the same.
PLAN = (
    dict(name="small_ovl_near", size="48x32", mode="overlapped", frames=400, mhz=(18.0, 17.9), seed=11),
    dict(name="small_seq_near", size="48x32", mode="sequential", frames=300, mhz=(18.0, 17.9), seed=12),
    dict(name="small_ovl_equal", size="48x32", mode="overlapped", frames=200, mhz=(18.0, 18.0), seed=13),
    dict(name="small_seq_far", size="48x32", mode="sequential", frames=200, mhz=(18.0, 15.0), seed=14),
    dict(name="medium_ovl_near", size="96x72", mode="overlapped", frames=100, mhz=(18.0, 17.9), seed=15),
    dict(name="full_ovl_near", size="352x288", mode="overlapped", frames=20, mhz=(18.0, 17.9), seed=16),
    dict(name="full_seq_near", size="352x288", mode="sequential", frames=12, mhz=(18.0, 17.9), seed=17),
)
QUICK = (
    dict(name="quick_ovl", size="48x32", mode="overlapped", frames=60, mhz=(18.0, 17.9), seed=21),
    dict(name="quick_seq", size="48x32", mode="sequential", frames=60, mhz=(18.0, 15.0), seed=22),
)
CAMERA_RATE, HOST_RATE = 0.12, 0.2


def run_one(r: dict, reuse: bool = False) -> dict:
    """One soak run on Verilator; its report (kept in build/soak/<name>.json, with its coverage file)."""
    import shutil

    import eyestereo.sim.harnesses.frontend_harness  # noqa: F401  (registers the bench top)

    kept = BUILD / f"{r['name']}.json"
    if reuse and kept.is_file():
        return json.loads(kept.read_text())
    full = r["size"] == "352x288"
    cfg = dict(mode=r["mode"], frames=r["frames"], timing={} if full else SHORT, target=200 if full else 40,
               cam_l_mhz=r["mhz"][0], cam_r_mhz=r["mhz"][1], seed=r["seed"], camera_fault_rate=CAMERA_RATE,
               host_fault_rate=HOST_RATE)
    BUILD.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    print(f"[soak] {r['name']}: {r['frames']} frames at {r['size']} ...", flush=True)
    rep = run_bench("frontend_harness", "tb_frontend_soak", cfg, name=f"soak_{r['name']}", sim="verilator",
                    params=dict(quantizers=f"rig:{r['size']}", feature_words=512, max_features=255),
                    log_file=BUILD / f"{r['name']}.log", public=PUBLIC)
    rep["run"] = dict(r, wall_total_s=round(time.time() - t0, 1), hdl=hdl_revision())
    from eyestereo.sim.lib.runner import build_dir_of

    shutil.copy2(build_dir_of("frontend_harness", f"soak_{r['name']}", "verilator") / "coverage.yml",
                 BUILD / f"{r['name']}.coverage.yml")
    kept.write_text(json.dumps(rep) + "\n")
    print(f"[soak] {r['name']}: {rep['frames_read']} frames read, all checks passed, {rep['run']['wall_total_s']} s",
          flush=True)
    return rep


def section(reports: list[dict], cov_lines: list[str], holes: list, quick: bool) -> list[str]:
    """docs/reliability.md's soak section."""
    from eyestereo.sim.lib.soak import FAULTS

    small = sum(r["frames_read"] for r in reports if r["width"] * r["height"] < 352 * 288)
    full = sum(r["frames_read"] for r in reports if r["width"] * r["height"] >= 352 * 288)
    out = [BEGIN, "",
           f"Measured by `python -m eyestereo.sim.measure.soak{' --quick' if quick else ''}` (generated; do not edit) "
           f"on {datetime.date.today().isoformat()}, HDL {_revisions(reports)}: the fast harness on Verilator, "
           f"{small} small frames and {full} full 352x288 frames read, every one bit-exact, no hang.", "",
           "### The faults and what the system must do (written before the soak ran: `sim/lib/soak.py`)", "",
           "| fault | by | injected | expected (checked by the soak bench) |", "|---|---|---|---|"]
    out += [f"| `{k}` | {who} | {what} | {exp} |" for k, (who, what, exp) in FAULTS.items()]
    out += ["", "Every frame read: its rectified pair equal to the rectification model of one left and one right "
            "camera frame sent whole (never one a fault broke), both moving on; its feature list the model's with the "
            "settings in effect. Every wait has a deadline (5.5 camera frames): a hang fails the run.", "",
            "### The runs", "",
            "| run | size | starts in | camera clocks (MHz) | frames read | exact / old or mixed settings / cut | "
            "camera frames played (L, R) | DROPPED (got; expected) | harris_overflows, lists_lost (resets) | "
            "SRAM rules broken | simulated | wall |",
            "|---|---|---|---|---:|---|---|---|---|---:|---:|---:|"]
    for r in reports:
        run = r["run"]
        v = r["verdicts"]
        old = v.get("old settings", 0) + v.get("mixed settings", 0)
        out.append(f"| {run['name']} | {r['width']}x{r['height']} | {run['mode']} | "
                   f"{run['mhz'][0]} / {run['mhz'][1]} | "
                   f"{r['frames_read']} | {v.get('exact', 0)} / {old} / {v.get('cut by the Harris reset', 0)} | "
                   f"{r['camera_frames_played'][0]}, {r['camera_frames_played'][1]} | "
                   f"{r['dropped'][0]}, {r['dropped'][1]}; {_bounds(r['dropped_expected'])} | "
                   f"{r['harris_overflows']}, {r['lists_lost']} ({r['resets']['harris']}) | "
                   f"{r['sram']['violations']} | {r['sim_ns'] / 1e6:.1f} ms | {run['wall_total_s']} s |")
    kinds: dict[str, dict] = {}
    for r in reports:
        for k, row in r["faults"].items():
            t = kinds.setdefault(k, dict(count=0, isolated=0, worst=0.0, worst_any=0.0))
            t["count"] += row["count"]
            t["isolated"] += row["isolated"]
            t["worst"] = max(t["worst"], row["worst"])
            t["worst_any"] = max(t["worst_any"], row["worst_any"])
    out += ["", "### Each fault kind over all runs", "",
            "Recovery: camera frames from the end of the fault to the next frame read; *isolated* faults are those "
            "with no other fault before that frame (the bench requires them within 4 frames).", "",
            "| fault | injected | isolated | worst recovery, isolated (frames) | worst with other faults around |",
            "|---|---:|---:|---:|---:|"]
    for k in FAULTS:
        t = kinds.get(k, dict(count=0, isolated=0, worst=0.0, worst_any=0.0))
        out.append(f"| `{k}` | {t['count']} | {t['isolated']} | {t['worst']:.2f} | {t['worst_any']:.2f} |")
    out += ["", "### Functional coverage (cocotb-coverage, merged over the runs)", "",
            "The plan: `sim/lib/soak_coverage.py`. Merged database: build/soak/coverage.yml.", ""] + cov_lines
    out += ["", f"Holes ({len(holes)}), each with its reason:", ""]
    out += [f"* `{cp}` {b}: {reason}" for cp, b, reason in holes] or ["* none"]
    return out + ["", END]


def _revisions(reports: list[dict]) -> str:
    """The HDL revision(s) the runs measured (recorded by each run; today's for a run kept without one)."""
    return ", ".join(sorted({r["run"].get("hdl") or hdl_revision() for r in reports}))


def _bounds(b) -> str:
    return ", ".join(f"{side} {lo}" if lo == hi else f"{side} {lo}..{hi}" for side, (lo, hi) in zip("LR", b))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the two short runs of QUICK instead of PLAN")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "reliability.md")
    ap.add_argument("--reuse", action="store_true", help="take the runs kept in build/soak/")
    a = ap.parse_args(argv)
    if a.jobs < 1:
        ap.error(f"--jobs must be at least 1, got {a.jobs}")
    if BEGIN not in (a.out.read_text() if a.out.is_file() else ""):
        ap.error(f"{a.out} has no '{BEGIN}' ... '{END}' section to fill")
    plan = QUICK if a.quick else PLAN
    from eyestereo.sim.lib import soak_coverage as cov

    try:
        with ThreadPoolExecutor(a.jobs) as ex:
            reports = list(ex.map(lambda r: run_one(r, a.reuse), sorted(plan, key=lambda r: -_cost(r))))
    except AssertionError as e:
        print(f"soak: a run failed: {e}", file=sys.stderr)
        return 1
    order = [r["name"] for r in plan]
    reports.sort(key=lambda rep: order.index(rep["run"]["name"]))
    merged = cov.merge([BUILD / f"{r['name']}.coverage.yml" for r in plan], BUILD / "coverage.yml")
    lines, holes = cov.report(merged)
    text = section(reports, lines, holes, a.quick)  # the markers first and last
    write_section(a.out, "\n".join(text[1:-1]) + "\n", BEGIN, END)
    print(f"soak: {sum(r['frames_read'] for r in reports)} frames read in {len(reports)} runs, all bit-exact; "
          f"{len(holes)} coverage holes; {a.out} written")
    return 0


def _cost(r: dict) -> float:
    w, h = (int(v) for v in r["size"].split("x"))
    return r["frames"] * (w * h if w * h > 10_000 else 4 * w * h + 20_000)


if __name__ == "__main__":
    sys.exit(main())
