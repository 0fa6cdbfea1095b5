"""Benchmark of the stereo Harris detector: full real stereo frames on GHDL per share factor, and resources.

``python -m eyestereo.sim.measure.bench_harris_stereo --out docs/harris_stereo.md --shared ../shared/data``

* **sim**: for each share factor, full 352x288 stereo pairs of real images (Middlebury Tsukuba im3/im4 and
  Venus im2/im6, centre crops) through the generated ``harris_stereo`` VHDL in GHDL, left and right with
  different k and 16 different block thresholds each, compared bit for bit with the ``harris_mono`` model
  of each camera (the bench ``tb_harris_stereo``); the bench measures the latency of every specified flag
  and the clocks from the first beat in to the last flag out.
* **synth**: ``make synth``'s flow (GHDL netlist of the VHDL -> Yosys ``synth_xilinx -family xc3se``) on each
  stereo stage and on the whole detector at share 3 (thesis Table 6.4 beside it), and the whole detector
  at shares 1 and 2.

Results are kept in ``build/bench_harris_stereo/*.json`` so the two parts can run apart (``--no-sim``,
``--no-synth``); the page is written from what is there.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import time
from pathlib import Path

import cv2
import numpy as np
from myhdl import Signal, intbv

from eyestereo.hdl.flow.catalog import BENCH_TOPS, BlockSpec, k_port as _k_port, thr_ports as _thr_ports
from eyestereo.hdl.harris.cornerness import cornerness
from eyestereo.hdl.harris.harris_stereo import multipliers
from eyestereo.hdl.harris.harris_window import harris_window
from eyestereo.hdl.harris.nms import nms
from eyestereo.hdl.harris.prethreshold import prethreshold
from eyestereo.hdl.harris.sobel import sobel
from eyestereo.sim.lib.runner import ROOT, hdl_revision, revision_note, run_bench
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.constants import (FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, NMS_DEFAULT, SHARE_FACTORS,
                                       THRESHOLD_BLOCKS)
from eyestereo.tools.io import centre_crop

BUILD = ROOT / "build" / "bench_harris_stereo"
W, H = FRAME_WIDTH, FRAME_HEIGHT
K = [K_CODE_DEFAULT, hm.k_code(0.06)]
THR = [[hm.threshold_code(c) for c in (2e8, 4e8, 1e8, 6e8, 3e8, 1e9, 5e7, 2e8, 8e8, 1e8, 3e8, 4e8, 6e8, 2e8, 1e8, 5e8)],
       [hm.threshold_code(c) for c in (3e8, 1e8, 2e8, 2e8, 5e8, 4e8, 1e8, 3e8, 2e8, 6e8, 1e8, 2e8, 3e8, 4e8, 2e8, 1e8)]]
PAIRS = {"Tsukuba": ("middlebury/tsukuba/im3.png", "middlebury/tsukuba/im4.png"),
         "Venus": ("middlebury/venus/im2.png", "middlebury/venus/im6.png")}
#: What each share factor runs: (pairs back to back, duty).
RUNS = {1: (["Tsukuba"], 1.0), 2: (["Venus"], 1.0), 3: (["Tsukuba"], 1.0)}
#: The stress run of each share factor: a full-size pair of frames cut by a reset token after a left beat
#: (``token_after`` beats in), then a real pair and a random pair back to back, at a duty cycle.
RANDOM = "random:7|random:8"
STRESS = {1: (["Venus", RANDOM], 0.3, 60001), 2: ([RANDOM, "Tsukuba"], 0.7, 120001), 3: (["Tsukuba", RANDOM], 1.0, 150001)}

#: Thesis Table 6.4 (stereo detector, sharing 3, Xilinx ISE on the Spartan-3E 500): LUT, RAMB16, MULT18X18.
TABLE_6_4 = {"sobel_stereo": (374, 2, 0), "harris_window_stereo": (1818, 8, 1), "cornerness_stereo": (266, 0, 2),
             "prethreshold_stereo": (477, 0, 0), "nms_stereo": (538, 2, 0)}
TABLE_6_4_TOTAL = (3473, 12, 3)


def _stereo_stage(name, func, sink, source, hw, control=(), **defaults):
    return BlockSpec(name, f"harris_stereo stage {name}", func, dict(width=W, height=H, stereo=True, **defaults),
                     sink_width=lambda p, s=sink: s, source_width=lambda p, s=source: s, hw_params=hw,
                     control=control)


def register_stages() -> None:
    """The five stages as simulation/synthesis-only top levels (catalogue BENCH_TOPS), share 3, nms 3, 4x4."""
    BENCH_TOPS["sobel_stereo"] = _stereo_stage("sobel_stereo", sobel, 8, sobel_model.WORD.width,
                                               ("width", "height", "share"), share=3)
    BENCH_TOPS["harris_window_stereo"] = _stereo_stage("harris_window_stereo", harris_window,
                                                       sobel_model.WORD.width, window_model.WORD.width,
                                                       ("width", "height", "share"), share=3)
    BENCH_TOPS["cornerness_stereo"] = _stereo_stage("cornerness_stereo", cornerness, window_model.WORD.width,
                                                    corner_model.WORD.width, ("share",),
                                                    control=(("k_left", _k_port), ("k_right", _k_port)), share=3)
    thr = _thr_ports()
    # The stereo prethreshold's address is 2 * block + cam: one bit more than the mono one.
    stereo_addr = ("thr_addr", lambda p: Signal(intbv(0)[len(thr[1][1](p)) + 1:]))
    BENCH_TOPS["prethreshold_stereo"] = _stereo_stage(
        "prethreshold_stereo", prethreshold, corner_model.WORD.width, corner_model.WORD.width,
        ("width", "height", "blocks"), control=(thr[0], stereo_addr, thr[2]), blocks=THRESHOLD_BLOCKS)
    BENCH_TOPS["nms_stereo"] = _stereo_stage("nms_stereo", nms, corner_model.WORD.width, 1,
                                             ("width", "height", "size", "share"), size=NMS_DEFAULT, share=3)


def crop(path: Path) -> np.ndarray:
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise FileNotFoundError(f"cannot read {path}")
    return centre_crop(img, W, H, str(path))


def sim_entry(share: int, rep: dict, names, duty, wall: float) -> dict:
    clocks = rep["last_out"] - rep["first_in"] + 1
    return dict(pairs=names, duty=duty, wall_s=round(wall, 1), **rep, clocks=clocks,
                beats_per_clock=rep["beats_in"] / clocks, revision=hdl_revision(),
                backend=os.environ.get("GHDL_BACKEND", "mcode"), ieee=os.environ.get("GHDL_IEEE", "standard"),
                load=round(os.getloadavg()[0], 1), date=str(datetime.date.today()))


def pair_images(name: str, shared: Path):
    """(left, right) of a pair name of PAIRS (centre crops) or a frame spec ``A|B`` of the bench."""
    if name in PAIRS:
        return tuple(crop(shared / p) for p in PAIRS[name])
    from eyestereo.sim.benches.tb_harris_stereo import stereo_pair

    return stereo_pair(name, W, H)


def _label(name: str) -> str:
    return "random" if name == RANDOM else name


def model_corners(names, shared: Path) -> list[list[int]]:
    """(left, right) corners inside the specified area per pair, by the model (equal to the VHDL's)."""
    from eyestereo.tools.models import harris_stereo as model

    out = []
    for n in names:
        left, right = pair_images(n, shared)
        fl, fr, mask = model.harris_stereo(left, right, K, THR, blocks=THRESHOLD_BLOCKS, nms=NMS_DEFAULT)
        out.append([int((fl.astype(bool) & mask).sum()), int((fr.astype(bool) & mask).sum())])
    return out


def run_sim(shared: Path, shares, stress: bool = False) -> dict:
    """The rate runs (RUNS) of ``shares``, or their stress runs (STRESS, keys ``stress N``)."""
    BUILD.mkdir(parents=True, exist_ok=True)
    out = {}
    for share in shares:
        names, duty, token = STRESS[share] if stress else (*RUNS[share], None)
        frames = []
        for n in names:
            if n not in PAIRS:
                frames.append(n)
                continue
            f = BUILD / f"{n}.npy"
            np.save(f, np.stack(pair_images(n, shared)))
            frames.append(f"npy:{f}")
        cfg = dict(frames=frames, duty=duty, k=K, thresholds=THR, seed=share)
        if token is not None:
            cfg.update(token_after=token, token_cam=1)
        key = f"stress {share}" if stress else share
        t0 = time.perf_counter()
        rep = run_bench("harris_stereo", "tb_harris_stereo", cfg, name=f"bench_{'stress' if stress else 'share'}{share}",
                        params=dict(width=W, height=H, blocks=THRESHOLD_BLOCKS, nms=NMS_DEFAULT, share=share),
                        build_root=ROOT / "build" / "sim")
        wall = time.perf_counter() - t0
        out[key] = sim_entry(share, rep, [_label(n) for n in names], duty, wall)
        out[key].update(corners=model_corners(names, shared), token_after=token, share=share)
        print(f"{key}: {names} bit-exact, {rep['pixels_compared']} flags compared, latency {rep['latency']}, "
              f"{out[key]['clocks']} clocks, {wall:.0f} s", flush=True)
    return out


def run_synth(shares, stages=None) -> dict:
    from eyestereo.hdl.flow.synth import synth_block

    register_stages()
    out = {}
    jobs = [(n, n, {}) for n in TABLE_6_4 if stages is None or n in stages]
    jobs += [(f"harris_stereo share {s}", "harris_stereo", dict(share=s)) for s in shares]
    if stages is None:
        jobs.append(("feature_list", "feature_list", {}))
    for label, name, params in jobs:
        t0 = time.perf_counter()
        r = synth_block(name, BUILD / "synth", label=label, **params)
        out[label] = dict(summary=r["summary"], seconds=round(time.perf_counter() - t0, 1), revision=hdl_revision(),
                          date=str(datetime.date.today()))
        print(f"{label}: {r['summary']}", flush=True)
    return out


def _make_synth_fmax() -> dict:
    """fmax of harris_stereo (share 3) and feature_list from make synth's last run, where it has them."""
    f = ROOT / "build" / "synth" / "resources.json"
    if not f.exists():
        return {}
    out = {}
    for r in json.loads(f.read_text()):
        if r.get("label") in ("harris_stereo", "feature_list") and (r.get("fmax") or {}).get("clk", {}).get("achieved"):
            name = "harris_stereo share 3" if r["label"] == "harris_stereo" else r["label"]
            out[name] = r["fmax"]["clk"]["achieved"]
    return out


def _load(name):
    f = BUILD / f"{name}.json"
    return json.loads(f.read_text()) if f.exists() else None


def render(sim: dict | None, synth: dict | None) -> str:
    lines = ["# Stereo Harris detector: full frames, throughput, latency, resources", "",
             f"Made by `python -m eyestereo.sim.measure.bench_harris_stereo` (`make bench`), {datetime.date.today()}.", "",
             "`harris_stereo` processes both cameras of a stereo stream in one datapath (thesis 6.3): stereo line "
             "delays (both cameras' words in one block RAM, addressed by column and camera), the window's three "
             "products and the cornerness's four on multipliers time-shared over `share` clocks, thresholds and k "
             "per camera. `feature_list` turns its flags into feature words. Block documentation: the docstrings of "
             "`hdl/harris/harris_stereo.py` and `hdl/harris/feature_list.py`; the feature word format: "
             "`eyestereo.tools.models.feature_list`.", ""]
    lines += ["## Design", "",
              "* **Line delays shared by the cameras.** The thesis packs the left and right pixel into one block-RAM "
              "word (serial-to-parallel). Here each line delay is a stereo `line_delay`: 2 x width words addressed "
              "by (column, cam), the left and right words of a column side by side. The block RAMs are the same "
              "(2 x 352 x 8 bits: one RAMB16 for a Sobel delay; 2 x 352 x 36 bits: two for a window delay), and the "
              "datapath stays one camera wide: no pair of Sobel or window adders, no multiplexer between two "
              "halves of a word. The horizontal registers become chains of 2N - 1, read every other one.",
              "* **Multipliers shared over `share` clocks.** Beats come at least `share` clocks apart, so each "
              "product unit holds its operands and runs its products in phases: the window's Ix^2, Iy^2, IxIy on "
              "3 / 2 / 1 multipliers, the cornerness's a*b with k*t, then c*c with (k t >> 8)*t on 2 (4 at share "
              "1). The arithmetic and its formats are the mono blocks', so the codes are the same.",
              "* **Tails at the input's pace.** After a frame, each window stage emits its missing rows itself, "
              "one beat every `share` clocks, so a shared multiplier behind it never sees two beats closer "
              "than `share` clocks.",
              "* **NMS 3x3 with one line delay.** Values are clamped at 0 (no flag changes: a centre must be > 0 and "
              "a neighbour <= 0 loses to it under > and >=), and each row's words carry the flag \"beats the "
              "three pixels above\" (the strict rule for rows above), formed when that row meets the row above at "
              "the line delay's output; one row later the delay returns value and flag together. One 20-bit "
              "stereo line delay (2 RAMB16) instead of two (4).",
              "* **Thresholds and k per camera.** One LUT-RAM of 2 x BX x BY thresholds addressed by (block, cam), "
              "written through `thr_we/thr_cam/thr_addr/thr_data`; `k_left`/`k_right` inputs.",
              "* **Feature lists** (`feature_list`, format in `eyestereo.tools.models.feature_list`): per feature "
              "two 16-bit words, (x | cam << 15) then y; per frame a trailer (0xFFFF, count | overflow << 15) "
              "with `eol`/`eof`; a reset token aborts a list with the queue's reset token; at most "
              "`max_features` per list (the overflow flag says the list was cut); counts per (camera, "
              "threshold block) in two LUT-RAM banks, published at each frame's end with `frame_done`.", ""]
    lines += ["## Full 352x288 stereo frames on GHDL, bit for bit", ""]
    if sim:
        lines += ["Each camera's flags equal the `harris_mono` model of that camera's frame with that camera's k "
                  f"(left code {K[0]}, right {K[1]}) and 16 block thresholds (different per side), on every specified "
                  "pixel; the rate runs below take one pair per share factor at full rate (a beat every `share` "
                  "clocks); the stress runs after them add back-to-back pairs, random pixels, duty cycles and a "
                  "reset token (so do the small-frame regressions, tests/hdl/test_harris_stereo_sim.py, with more "
                  "seeds, NMS sizes and block layouts); the bench also checks that no valid beat has an undefined "
                  "bit and nothing is left over.", "",
                  "| share | stereo pairs (centre 352x288) | flags compared | corners left / right | GHDL back end, numeric_std | wall time (1-min load at the end) | date | HDL revision |",
                  "|---:|---|---:|---|---|---:|---|---|"]
        rate = {k: v for k, v in sim.items() if k.isdigit()}
        stress = {k: v for k, v in sim.items() if k.startswith("stress ")}
        for s, r in sorted(rate.items()):
            fl = ", ".join(f"{a} / {b}" for a, b in r.get("corners", []))
            lines.append(f"| {s} | {' + '.join(r['pairs'])} | {r['pixels_compared']} | {fl} | "
                         f"{r.get('backend', 'mcode')}, {r.get('ieee', 'standard')} | {r['wall_s']:.0f} s "
                         f"({r.get('load', '?')}) | {r.get('date', '?')} | {r.get('revision', '?')} |")
        if stress:
            lines += ["", "Stress runs, full size as well: first a pair of frames cut by a reset token after a left beat "
                      "(so the token also breaks a pixel pair; one token must come out, before any flag of the "
                      "frames after it), then pairs back to back (a real one and one of random pixels), at a duty "
                      "cycle (a beat `share` clocks after the previous one, then each clock with probability `duty`); "
                      "the same checks, every flag of the complete frames compared.", "",
                      "| share | token after beat | then pairs, back to back | duty | flags compared | corners left / right | "
                      "clocks | GHDL back end, numeric_std | wall time (1-min load at the end) | date | HDL revision |",
                      "|---:|---:|---|---:|---:|---|---:|---|---:|---|---|"]
            for _share, r in sorted(stress.items()):
                fl = ", ".join(f"{a} / {b}" for a, b in r.get("corners", []))
                lines.append(f"| {r['share']} | {r['token_after']:,} | {' + '.join(r['pairs'])} | {r['duty']} | "
                             f"{r['pixels_compared']} | {fl} | {r['clocks']:,} | {r.get('backend', 'mcode')}, "
                             f"{r.get('ieee', 'standard')} | {r['wall_s']:.0f} s ({r.get('load', '?')}) | "
                             f"{r.get('date', '?')} | {r.get('revision', '?')} |")
        lines += revision_note((r.get("revision", "?") for r in sim.values()),
                               "python -m eyestereo.sim.measure.vhdl_diff REV harris_stereo:share=N")
        lines += ["", "## Throughput and latency", "",
                  "Measured in the same runs: beats in per clock from the first beat in to the last flag out (one "
                  "pair, so the latency and the frame's tail are included: the limit is one beat per `share` "
                  "clocks, sustained over back-to-back frames), and the latency of every specified "
                  "flag, from the input beat of its camera's pixel (x + 5, y + 4) (nms 3: the beat that completes "
                  "the flag's window) to the flag (x, y): the bench asserts it is the same constant for all of them "
                  "and equals `harris_stereo.latency(nms, share)`.", "",
                  "| share | multipliers | beats per clock (measured) | stereo pixels per clock | at 50 MHz | latency (clocks after pixel (x+5, y+4)) | = |",
                  "|---:|---:|---:|---:|---|---:|---|"]
        for s, r in sorted(rate.items()):
            s = int(s)
            bpc = r["beats_per_clock"]
            fps = 50e6 * bpc / (2 * W * H)
            lat = r["latency"]
            lines.append(f"| {s} | {multipliers(s)} | {bpc:.4f} (limit {1 / s:.4f}) | {bpc / 2:.4f} | "
                         f"{50 * bpc / 2:.2f} M stereo pixels/s, {fps:.0f} stereo frames/s | {lat} | "
                         f"4 lines + 5 pixels of the camera (2 x 1413 beats) + {lat} clocks |")
        l3 = sim.get("3", {}).get("latency")
        if l3 is not None:
            lines += ["", "At share 3 and full rate a flag (x, y) therefore leaves 3 x 2 x (4 x 352 + 5) = 8478 + "
                      f"{l3} clocks after its own pixel (x, y) entered ({(8478 + l3) / 50:.0f} us at 50 MHz).", ""]
    else:
        lines += ["(not run: `--no-sim`)", ""]
    lines += ["## Resources (thesis Table 6.4 beside them)", ""]
    if synth:
        lines += ["`make synth`'s flow on the generated VHDL: GHDL's netlist -> Yosys `synth_xilinx -family xc3se` "
                  "(Spartan-3E cells: LUTs, LUT-RAM counted apart, flip-flops, RAMB16, MULT18X18), each stage "
                  "synthesized on its own at 352x288, share 3, 4x4 blocks, NMS 3x3 (the thesis's configuration), "
                  "then the whole detector. Thesis figures: Xilinx ISE on the Spartan-3E 500 (Table 6.4).", "",
                  "| module | LUT | LUT-RAM | FF | RAMB16 | MULT18X18 | thesis LUT / RAMB16 / MULT |",
                  "|---|---:|---:|---:|---:|---:|---|"]
        tot = [0, 0, 0, 0, 0]
        for n, th in TABLE_6_4.items():
            if n not in synth or "summary" not in synth[n]:
                continue
            s = synth[n]["summary"]
            row = [s.get("LUT", 0), s.get("LUTRAM", 0), s.get("FF", 0), s.get("RAMB16", 0), s.get("MULT18X18", 0)]
            tot = [a + b for a, b in zip(tot, row)]
            lines.append(f"| {n} | " + " | ".join(str(v) for v in row) + f" | {th[0]} / {th[1]} / {th[2]} |")
        lines.append("| **modules summed** | " + " | ".join(f"**{v}**" for v in tot)
                     + f" | **{TABLE_6_4_TOTAL[0]} / {TABLE_6_4_TOTAL[1]} / {TABLE_6_4_TOTAL[2]}** |")
        for label in sorted(k for k in synth if k.startswith("harris_stereo")):
            s = synth[label]["summary"]
            row = [s.get("LUT", 0), s.get("LUTRAM", 0), s.get("FF", 0), s.get("RAMB16", 0), s.get("MULT18X18", 0)]
            th = f"{TABLE_6_4_TOTAL[0]} / {TABLE_6_4_TOTAL[1]} / {TABLE_6_4_TOTAL[2]}" if label.endswith("3") else "-"
            lines.append(f"| {label} (whole, one netlist) | " + " | ".join(str(v) for v in row) + f" | {th} |")
        if "feature_list" in synth:
            s = synth["feature_list"]["summary"]
            row = [s.get("LUT", 0), s.get("LUTRAM", 0), s.get("FF", 0), s.get("RAMB16", 0), s.get("MULT18X18", 0)]
            lines.append("| feature_list (352x288, 4x4 count blocks, FIFO 16) | " + " | ".join(str(v) for v in row)
                         + " | (not in Table 6.4) |")
        lines += [""]
        revs = sorted({v.get("revision", "?") for v in synth.values() if isinstance(v, dict) and "summary" in v})
        lines += [f"HDL revision of these netlists: {', '.join(revs)}.", ""]
        fm = _make_synth_fmax()
        if fm:
            lines += ["fmax from `make synth` (`build/synth/resources.json`: the same flow on the catalogue's default "
                      "configurations, GHDL's netlist through Yosys `synth_ecp5` + nextpnr-ecp5, LFE5U-25F, speed 6; "
                      "the thesis's goal is 50 MHz): " + ", ".join(f"{k} {v:.1f} MHz" for k, v in fm.items()) + ".", ""]
        lines += ["Against Table 6.4, every module is at or under the thesis's LUTs, block RAMs and multipliers; "
                  "the whole detector at share 3 takes the thesis's 12 block RAMs and 3 multipliers (two mono "
                  "detectors: 16 and 14 here, 16 and 16 in the thesis). Share 1 keeps the block RAMs and needs 7 "
                  "multipliers, share 2 four.", ""]
    else:
        lines += ["(not run: `--no-synth`)", ""]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m eyestereo.sim.measure.bench_harris_stereo", description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--shared", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--shares", type=int, nargs="*", default=list(SHARE_FACTORS))
    ap.add_argument("--no-sim", action="store_true")
    ap.add_argument("--no-stress", action="store_true", help="only the rate runs (one real pair per share at full rate)")
    ap.add_argument("--no-rate", action="store_true", help="only the stress runs")
    ap.add_argument("--no-synth", action="store_true")
    ap.add_argument("--stages", nargs="*", default=None, help="synthesize only these stages (default: all five)")
    a = ap.parse_args(argv)
    BUILD.mkdir(parents=True, exist_ok=True)
    if not a.no_sim:
        new = {} if a.no_rate else run_sim(a.shared, a.shares)
        if not a.no_stress:
            new.update(run_sim(a.shared, a.shares, stress=True))
        sim = _load("sim") or {}  # read after the runs: other processes may have added shares meanwhile
        sim.update({str(k): v for k, v in new.items()})
        (BUILD / "sim.json").write_text(json.dumps(sim, indent=1))
    if not a.no_synth:
        new_syn = run_synth(a.shares, a.stages)
        syn = _load("synth") or {}
        syn.update(new_syn)
        (BUILD / "synth.json").write_text(json.dumps(syn, indent=1))
    text = render(_load("sim"), _load("synth"))
    tmp = a.out.with_suffix(".tmp")
    tmp.write_text(text)
    tmp.replace(a.out)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
