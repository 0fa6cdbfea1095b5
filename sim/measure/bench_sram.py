"""SRAM benchmark: long random-traffic runs over many seeds, bandwidth, camera margin, shares, resources.

``python -m eyestereo.sim.measure.bench_sram --out docs/sram.md [--quick]`` runs the SRAM subsystem bench
(:mod:`eyestereo.sim.benches.tb_sram_subsystem`) on GHDL in these configurations, both kinds of part, read
latency 2 (the 100 MHz parts):

1. random traffic from all six masters, many seeds, long runs (the scoreboard and the part's rules
   checked on every access);
2. bandwidth in words per clock: reads in bursts (the fetch port alone), writes (both cameras at 50 M
   words/s each), and a mixed load;
3. the cameras' margin: both cameras at rising word rates while the rectifier fetches without pause and
   the host reads: the highest rate at which no camera FIFO (1024 words, one RAMB16) overflows;
4. the share of SRAM clocks each master gets under the system's load (cameras at 9 M words/s, the
   rectifier at full speed, the rectified writer and the host in the system's proportion);

plus resources (Yosys, Spartan-3E) and the clock estimates, and writes everything to the Markdown file.
Frames are 32x16 pixels: the rates per clock do not depend on the frame size (it only moves addresses).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

from eyestereo.sim.lib.sram_runner import run_sram_bench
from eyestereo.tools.models.sram_arbiter import MASTERS, AddressMap
from eyestereo.tools.reports import markdown_table

W, H = 32, 16
PARAMS = dict(read_latency=2, width=W, height=H, feature_words=64)
KINDS = ("nobl", "pipelined")
CLOCK_MHZ = 100
CAM_RATE = 0.09  # 9 M words/s at 100 MHz


def run(kind: str, name: str, cfg: dict) -> dict:
    t = time.time()
    rep = run_sram_bench("sram_subsystem", "tb_sram_subsystem", cfg, name=f"bench_{name}_{kind}",
                         params=dict(PARAMS, kind=kind))
    rep["wall_s"] = time.time() - t
    return rep


def random_traffic(kinds, seeds, clocks) -> list[dict]:
    out = []
    for kind in kinds:
        for seed in seeds:
            cfg = dict(seed=seed, clocks=clocks, rect_duty=0.15, feat_duty=0.05, host_duty=0.05, feat_max=80,
                       token_after=(seed * 37) % (W * H) if seed % 3 == 0 else None,
                       mode="sequential" if seed % 4 == 1 else "overlapped")
            rep = run(kind, f"random{seed}", cfg)
            out.append(dict(kind=kind, seed=seed, mode=cfg["mode"], clocks=rep["clocks"],
                            reads=rep["sram"]["reads"], writes=rep["sram"]["writes"],
                            fetch_reads=rep["fetch_reads"],
                            host_reads=rep["host_area_reads"] + rep["host_buffer_reads"],
                            frames=sum(rep["frames"].values()), wall_s=rep["wall_s"]))
            print(f"random traffic {kind} seed {seed}: {out[-1]}", flush=True)
    return out


def bandwidth(kinds, clocks, window) -> list[dict]:
    loads = {
        "reads in bursts (fetch port alone, 4-pixel requests)":
            dict(cam_frames=1, cam_rate=0.5, rect=False, feat=False, host_duty=0, fetch_mode="continuous",
                 hold=True, full_mask=1.0),
        "writes (both cameras at 50 M words/s)":
            dict(cam_rate=0.5, cam_fifo=1024, rect=False, feat=False, host_duty=0, fetch=False),
        "mixed (fetch at full speed, cameras 9 M words/s, rectified writer, host)":
            dict(cam_rate=CAM_RATE, cam_fifo=1024, rect_duty=0.14, feat_duty=0.01, feat_max=40, host_duty=0.02,
                 host_read_rate=0.125, fetch_mode="continuous", hold=True, full_mask=1.0),
        "mixed, single random host accesses between the fetches":
            dict(cam_frames=1, cam_rate=0.5, rect=False, feat=False, host_duty=0.1, fetch_mode="continuous",
                 hold=True, full_mask=1.0),
    }
    out = []
    for kind in kinds:
        for label, load in loads.items():
            rep = run(kind, "bw_" + label.split()[0], dict(load, seed=7, clocks=clocks, window=window))
            m = rep["measured"]
            out.append(dict(kind=kind, load=label, total=m["total_per_clock"], reads=m["bus"]["reads"],
                            writes=m["bus"]["writes"], idle=m["bus"]["idle_bus_cycles"],
                            per=m["words_per_clock"], clocks=m["clocks"], wall_s=rep["wall_s"],
                            sim_clocks=rep["clocks"]))
            print(f"bandwidth {kind} {label}: {m['total_per_clock']:.3f}", flush=True)
    return out


SYSTEM = dict(cam_rate=CAM_RATE, cam_fifo=1024, rect_duty=0.14, feat_duty=0.01, feat_max=40, host_duty=0.0,
              host_read_rate=0.125, fetch_mode="continuous", hold=True, full_mask=1.0)


def margin(kinds, rates, clocks, window) -> list[dict]:
    out = []
    for kind in kinds:
        for r in rates:
            try:
                rep = run(kind, f"margin{r}", dict(SYSTEM, cam_rate=r, seed=11, clocks=clocks, window=window,
                                                   allow_overflow=True))
            except (AssertionError, SystemExit) as e:
                out.append(dict(kind=kind, rate=r, failed=str(e)))
                print(f"margin {kind} rate {r}: FAILED {e}", flush=True)
                continue
            m = rep["measured"]
            out.append(dict(kind=kind, rate=r, overflow=any(rep["cam_overflow"]), fill=max(rep["cam_max_fill"]),
                            cams=m["words_per_clock"]["cam0"] + m["words_per_clock"]["cam1"],
                            fetch=m["words_per_clock"]["fetch"], total=m["total_per_clock"],
                            wait_per_word=(rep["waited"]["cam0"] + rep["waited"]["cam1"]) /
                            max(1, rep["moved"]["cam0"] + rep["moved"]["cam1"])))
            print(f"margin {kind} rate {r}: {out[-1]}", flush=True)
    return out


def shares(kinds, clocks, window) -> list[dict]:
    out = []
    for kind in kinds:
        rep = run(kind, "shares", dict(SYSTEM, seed=13, clocks=clocks, window=window))
        m = rep["measured"]
        lat = rep["fetch_latency"]
        out.append(dict(kind=kind, per=m["words_per_clock"], total=m["total_per_clock"],
                        idle=m["bus"]["idle_bus_cycles"], waited=rep["waited"], moved=rep["moved"],
                        fetch_latency=(min(lat), statistics.median(lat), max(lat)) if lat else None,
                        clocks=m["clocks"], fill=rep["cam_max_fill"]))
        print(f"shares {kind}: {out[-1]}", flush=True)
    return out


def latency_idle(kinds) -> list[dict]:
    """The fetch port's latency on an otherwise idle bus (first pixel after the request is taken)."""
    out = []
    for kind in kinds:
        rep = run(kind, "latency", dict(seed=3, clocks=4000, cam_frames=1, cam_rate=0.5, rect=False, feat=False,
                                        host_duty=0.01, fetch_mode="continuous", hold=True, fetch_duty=0.02))
        lat, hl = rep["fetch_latency"], rep["host_latency"]
        out.append(dict(kind=kind, min=min(lat), median=statistics.median(lat), host_min=min(hl),
                        host_median=statistics.median(hl)))
    return out


def resources() -> list[dict]:
    """``make synth``'s flow (GHDL netlist -> Yosys xc3se; ECP5 place and route) and the xc3se period estimate."""
    from eyestereo.hdl.flow.sta import estimate
    from eyestereo.hdl.flow.synth import ecp5, prepare, xc3se

    out = []
    for label, name, params in (("sram_controller", "sram_controller", {}),
                                ("sram_controller pipelined", "sram_controller", dict(kind="pipelined")),
                                ("sram_arbiter", "sram_arbiter", {}), ("sram_subsystem", "sram_subsystem", {}),
                                ("sram_subsystem pipelined", "sram_subsystem", dict(kind="pipelined")),
                                ("sram_subsystem 16-bit counters", "sram_subsystem", dict(counter_bits=16)),
                                ("double_buffer", "double_buffer", {})):
        job = prepare(name, Path("build/synth"), label=f"sram_{label}", **params)
        r = xc3se(job)
        try:
            pnr = ecp5(job, freq=CLOCK_MHZ)
        except RuntimeError as e:
            pnr = dict(fmax={}, error=str(e)[:200])
        t = estimate(name, Path("build/synth"), job=job)
        fm = pnr.get("fmax", {}).get("clk", {}).get("achieved")
        out.append(dict(block=label, summary=r["summary"], period=t["period_ns"], fmax=t["fmax_mhz"],
                        levels=t["lut_levels"], ecp5_fmax=fm, ecp5_device=pnr.get("ecp5_device", "LFE5U-25F")))
        print(f"resources {label}: {out[-1]}", flush=True)
    return out


# ------------------------------------------------------------------------------------------------------
def report(res: dict) -> str:
    amap = AddressMap()
    L = ["# The SRAM subsystem: controller, arbiter, frame buffers", "",
         "Generated by `python -m eyestereo.sim.measure.bench_sram` (GHDL, cocotb, the SRAM model of "
         "`sim/lib/sram_model.py`); do not edit by hand. Design and interfaces: `hdl/interfaces/sram_bus.py` (pins, word "
         "port, host port), `hdl/memory/sram_controller.py`, `hdl/memory/sram_arbiter.py`, `hdl/memory/frame_buffers.py`, "
         "`hdl/interfaces/fetch_port.py`, `hdl/interfaces/queue.py`; the part and its rules: `tools/sram.py`.", ""]
    L += ["## What is in it", "",
          "- **The part** (`tools/sram.py`, cocotb wrapper `sim/lib/sram_model.py`): the board's 18-Mbit SRAM, 1M x 18 "
          "(16 DQ lines used), as either kind of 100 MHz part: a standard pipelined SyncBurst (CY7C1382D / "
          "IS61LPS102418-class: a single write started with ADSC# takes its data with the address, reads come "
          "`read_latency` clocks later, so the bus needs an idle cycle when it turns round) or a NoBL/ZBT part "
          "(CY7C1372D / IS61NLP102418-class: write data `read_latency` clocks after its address, like read data: "
          "no turnaround). Read latency 1..3. Checked on every edge: defined inputs, single accesses only (no "
          "burst-continue cycles), byte enables, write data in exactly the right cycle, no bus contention, the "
          "turnaround, OE# during read data; reads return the stored word with the part's coherency. A broken "
          "rule fails the test with the rule, the edge and the time.",
          "- **`sram_controller`**: the pins (all outputs from flip-flops, read data registered on entry: I/O-block "
          "registers) and an in-order word port with tags; on a pipelined part it holds a write back while a read "
          "taken in the last read_latency + 1 clocks could still be on the bus. Timing diagrams in "
          "`hdl/interfaces/sram_bus.py`.",
          "- **`sram_arbiter`**: six masters, each a port of its own kind: two camera writers (queue read ports "
          "of the cameras' async FIFOs), the rectifier's pixel fetch port (slave side, `hdl/interfaces/fetch_port.py`), the "
          "rectified-image writer (the stereo image stream, left and right pixel of each (x, y) packed into one "
          "word), the feature-list writer (queue read port) and the host port (reads and writes, byte "
          "enables). Writers collect bursts of 8 words in LUT-RAM FIFOs. The writers of the streams that cannot "
          "wait (both cameras, the rectified stream) are urgent and take turns first; the feature writer, the "
          "fetch port and the host take turns round robin in the gaps; every turn moves at least one word, so "
          "no master starves. Per-master counters of words moved and clocks waited, frame counters and buffer "
          "states on a status port.",
          "- **Frame buffers** (`hdl/memory/frame_buffers.py`): two buffers per producer, FREE / WRITING / FULL / READING; "
          "a frame is FULL once its last word is issued (the controller is in order), a consumer takes the "
          "newest FULL frame and holds it until it releases it, so nobody reads a half-written frame. The same "
          "handshake (`FrameControl`) runs the system's *sequential* mode (arm each camera for one frame, "
          "take, rectify, release, read out, repeat) and its *overlapped* mode (cameras run, each consumer "
          "takes the newest frame whenever it is free: double buffering).",
          "- **`sram_subsystem`**: the arbiter on the controller, what the complete system instantiates.", ""]
    L += ["## Address map (352x288 frames, 8192-word feature lists)", "",
          "One word per pixel, row by row from each buffer's base (`AddressMap`, "
          "`eyestereo.tools.models.sram_arbiter`); camera words are Y in bits 7..0 and the pixel's chroma "
          "sample in 15..8, rectified words the left pixel in 7..0 and the right one in 15..8 (both images of "
          "a pair in one word: half the writes and half the host's reads).", "", amap.table(), "",
          f"Camera and rectified double buffers take {6 * amap.frame:,} words, the feature lists "
          f"{2 * amap.feature_words:,}; {amap.words - amap.host_base:,} words "
          f"({100 * (amap.words - amap.host_base) / amap.words:.0f} %) are left for the host.", ""]
    for key, section in (("random", _random_section), ("bandwidth", _bandwidth_section),
                         ("margin", _margin_section), ("shares", _shares_section), ("latency", _latency_section),
                         ("resources", _resources_section), ("speed", _speed_section)):
        if res.get(key):
            L += section(res[key])
    return "\n".join(L) + "\n"


# The page's measured sections: each renders its entry of the results (skipped when missing or empty).
def _random_section(rt: list[dict]) -> list[str]:
    rows = []
    for kind in KINDS:
        rs = [r for r in rt if r["kind"] == kind]
        if rs:
            rows.append([kind, len(rs), f"{min(r['seed'] for r in rs)}..{max(r['seed'] for r in rs)}",
                         f"{sum(r['clocks'] for r in rs):,}", f"{sum(r['fetch_reads'] + r['host_reads'] for r in rs):,}",
                         f"{sum(r['writes'] for r in rs):,}", sum(r["frames"] for r in rs), "all passed"])
    return ["## Random traffic against the SRAM model", "",
            "All six masters at once (cameras at 9 M words/s, the rectified stream with a reset token in some "
            "runs, feature lists up to 80 words into 64-word buffers, fetch passes, the host's random reads and "
            "writes and its buffer reads), overlapped and sequential mode. Every read is checked against the "
            "last word written (fetch and host buffer reads against the frames the writers were given, "
            "rebuilt from the SRAM's write log: a read of a half-written frame fails), every write lands "
            "where its frame says, the part's rules hold on every edge, the counters match.", ""] + markdown_table(
        ["part", "runs", "seeds", "clocks", "reads checked", "writes checked", "frames", "result"], rows,
        "lrlrrrrl") + [""]


def _bandwidth_section(bw: list[dict]) -> list[str]:
    rows = [[b["load"], b["kind"]] + [f"{v:.3f}" for v in (
        b["total"], b["reads"], b["writes"], b["idle"], b["per"]["cam0"] + b["per"]["cam1"], b["per"]["fetch"],
        b["per"]["rect"], b["per"]["host"])] for b in bw]
    return ["## Bandwidth (words per clock, 1.0 = 100 M words/s)", "",
            "Measured at the SRAM's pins over the second half of each run, read latency 2.", ""] + markdown_table(
        ["load", "part", "words/clock", "reads", "writes", "idle bus cycles", "cameras", "fetch", "rectified", "host"],
        rows, "ll" + "r" * 8) + [
        "", "A NoBL part turns the bus round for free; a pipelined SyncBurst part loses three clocks each "
        "time writes follow reads (one idle bus cycle for tCHZ, and a write's data goes with its "
        "address), which is why writers collect bursts of 8 words.", ""]


def _sustained(m: dict) -> bool:
    """A camera rate the SRAM keeps up with: no overflow, the FIFO nearly empty, every word written."""
    return "failed" not in m and not m["overflow"] and m["fill"] <= 64 and m["cams"] >= 0.98 * 2 * m["rate"]


def _margin_section(mg: list[dict]) -> list[str]:
    rows = []
    for m in mg:
        rate = [m["kind"], f"{m['rate'] * CLOCK_MHZ:.0f}", f"{m['rate'] / CAM_RATE:.1f}"]
        if "failed" in m:
            rows.append(rate + ["-", f"no (bench failed: {m['failed'][:60]})", "", "", ""])
        else:
            rows.append(rate + [m["fill"], "yes" if _sustained(m) else "no", f"{m['cams']:.3f}", f"{m['fetch']:.3f}",
                                f"{m['wait_per_word']:.2f}"])
    L = ["## Camera margin", "",
         "Both cameras at the same word rate while the rectifier fetches without pause, the rectified "
         "writer runs and the host reads the rectified images at 12.5 M words/s; camera FIFO (the async "
         "FIFO's read side) 1024 words. Camera writers are urgent, so their rate takes bandwidth from the "
         "rectifier and the host, not the other way round. A rate is *sustained* when the cameras' words are written as fast as they come "
         "and the FIFO stays nearly empty (at most 64 words): a FIFO that keeps filling overflows in a "
         "longer run.", ""] + markdown_table(
        ["part", "camera rate (M words/s each)", "x 9 M", "max FIFO fill", "sustained", "cameras (words/clock)",
         "fetch (words/clock)", "camera wait per word (clocks)"], rows, "lrrrlrrr") + [""]
    for kind in KINDS:
        ok = [m["rate"] for m in mg if m["kind"] == kind and _sustained(m)]
        bad = [m["rate"] for m in mg if m["kind"] == kind and not _sustained(m)]
        if ok:
            L.append(f"- {kind}: sustained up to {max(ok) * CLOCK_MHZ:.0f} M words/s per camera, "
                     f"{max(ok) / CAM_RATE:.1f} times the cameras' 9 M words/s" +
                     (f"; not at {min(bad) * CLOCK_MHZ:.0f} M words/s." if bad else " (the highest rate tried)."))
    return L + [""]


def _shares_section(sh: list[dict]) -> list[str]:
    L = ["## Share of the SRAM's clocks under the system's load", "",
         "Cameras at 9 M words/s each, the rectifier fetching without pause (4 pixels per request), the "
         "rectified writer at about an eighth of the fetch rate (one packed word per 8 reads: 4 pixels "
         "per camera), feature lists, the host reading the rectified images at 12.5 M words/s. Inputs of "
         "the complete system's frame-rate measurement.", ""]
    L += markdown_table(["part", *MASTERS, "idle / turnaround", "total words/clock"], [
        [s["kind"], *(f"{100 * s['per'][m]:.1f} %" for m in MASTERS), f"{100 * (1 - s['total']):.1f} %",
         f"{s['total']:.3f}"] for s in sh])
    L += [""] + markdown_table(["part", *(f"clocks waited per word: {m}" if i == 0 else m for i, m in enumerate(MASTERS)),
                                "fetch latency min / median / max"], [
        [s["kind"], *(f"{s['waited'][m] / max(1, s['moved'][m]):.2f}" for m in MASTERS),
         "{} / {:.0f} / {}".format(*s["fetch_latency"]) if s["fetch_latency"] else "-"] for s in sh])
    for s in sh:
        f = s["per"]["fetch"]
        if f > 0:
            ms = 8 * AddressMap().frame / (f * CLOCK_MHZ * 1e3)
            L += ["", f"- {s['kind']}: at {f:.3f} fetch words per clock one stereo frame's 8 x 101,376 reads "
                  f"take {ms:.1f} ms ({1000 / ms:.0f} frames/s for the rectifier alone; derived, not "
                  f"simulated at 352x288)."]
    return L + [""]


def _latency_section(li: list[dict]) -> list[str]:
    return ["Latency on a quiet bus, from the clock a request is taken to the clock its data comes back: fetch "
            "(first pixel) " + ", ".join(f"{x['kind']} {x['min']} (median {x['median']:.0f})" for x in li) +
            "; host read " + ", ".join(f"{x['kind']} {x['host_min']} (median {x['host_median']:.0f})" for x in li) +
            " clocks.", ""]


def _resources_section(rs: list[dict]) -> list[str]:
    rows = []
    for r in rs:
        s = r["summary"]
        dev = r.get("ecp5_device", "")
        rows.append([r["block"], s["LUT"], s["LUTRAM"], s["FF"], s["RAMB16"], s["MULT18X18"], s["carry"], r["levels"],
                     f"{r['period']} ns ({r['fmax']} MHz)", f"{r['ecp5_fmax']:.1f} MHz" if r.get("ecp5_fmax") else "-",
                     "LFE5U-85F CABGA756" if "85k" in dev else ("LFE5U-25F CABGA381" if dev else "")])
    return ["## Resources and clock", "",
            "`make synth`'s flow: the VHDL synthesized by GHDL, then Yosys `synth_xilinx -family xc3se` (the "
            "thesis's Spartan-3E); default parameters (352x288, 32-bit counters, NoBL) unless the row says "
            "otherwise. *Est. period*: the longest register-to-register path of that Spartan-3E netlist with "
            "the XC3S500E -4 data-sheet cell delays and 0.7 ns per net (`hdl/flow/sta.py`; no place and route "
            "exists for the Spartan-3E here, so this is an estimate). *ECP5*: nextpnr-ecp5 place and route of "
            "the same GHDL netlist, speed grade 6, the clock constrained at 100 MHz (the SRAM's), on the "
            "device named (blocks with more port bits than the LFE5U-25F's package has pins go on the 85k "
            "part): a real timing figure, of another family.", ""] + markdown_table(
        ["block", "LUT", "LUT-RAM", "FF", "RAMB16", "MULT18X18", "carry cells", "LUT levels", "est. period (S3E-4)",
         "ECP5 fmax", "ECP5 device"], rows, "l" + "r" * 9 + "l") + [
        "", "The arbiter alone has its word port on pins as well (far-apart I/O on the 85k device), which "
        "costs it in the place and route; inside the subsystem that port is internal. The 32-bit counters "
        "(12 counters of words moved and clocks waited, and the clock counter) are about 230 of the "
        "arbiter's LUTs (`counter_bits=16`: the row above).", ""]


def _speed_section(sp: float) -> list[str]:
    return [f"Simulation speed (GHDL mcode, cocotb, the SRAM model and six agents in Python): about "
            f"{sp:,.0f} clocks per second.", ""]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Measure the SRAM subsystem and write docs/sram.md.")
    ap.add_argument("--out", default="docs/sram.md", type=Path)
    ap.add_argument("--quick", action="store_true", help="few seeds and short runs (a smoke test)")
    ap.add_argument("--json", type=Path, help="also write the raw results here")
    ap.add_argument("--from-json", type=Path, help="only render the Markdown from raw results written earlier")
    args = ap.parse_args(argv)
    if args.from_json:
        args.out.write_text(report(json.loads(args.from_json.read_text())))
        print(f"wrote {args.out}")
        return 0
    q = args.quick
    res: dict = {}
    t0 = time.time()
    def save():
        if args.json:
            args.json.write_text(json.dumps(res, indent=1, default=str))

    try:
        res["random"] = random_traffic(KINDS, range(1, 3 if q else 13), 6000 if q else 30000)
        clocks = sum(r["clocks"] for r in res["random"])
        res["speed"] = clocks / sum(r["wall_s"] for r in res["random"])
        save()
        res["bandwidth"] = bandwidth(KINDS, 6000 if q else 24000, 3000 if q else 12000)
        save()
        res["margin"] = margin(KINDS, [0.09, 0.27] if q else [0.09, 0.18, 0.27, 0.36, 0.4, 0.44, 0.48, 0.5],
                               6000 if q else 30000, 3000 if q else 10000)
        save()
        res["shares"] = shares(KINDS, 8000 if q else 40000, 4000 if q else 10000)
        res["latency"] = latency_idle(KINDS)
        save()
        res["resources"] = resources()
        save()
    except (AssertionError, RuntimeError, ValueError, SystemExit) as e:
        print(f"bench_sram: {e}", file=sys.stderr)
        return 1
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(report(res))
    tmp.replace(args.out)
    save()
    print(f"wrote {args.out} in {time.time() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
