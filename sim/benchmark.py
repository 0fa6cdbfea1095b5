"""``make bench``: throughput, latency, simulation speed and synthesis resources, written to docs.

Every figure is measured here, on this machine, by running the GHDL benches and Yosys:

* pixels per clock: two 352x288 frames back to back at 100 % input duty; output beats of the second
  frame divided by the clocks between the last beats of the first and second frame (1.0 = the block
  keeps up with one pixel per clock).
* latency: clocks from the input beat that completes an output pixel's window (input pixel
  (x + r, y + r)) to that output beat, over every pixel of both frames that has such an input beat.
* simulation speed: simulated clock cycles per wall-clock second of the whole bench run (conversion,
  GHDL elaboration, cocotb start-up included) and of the simulation alone (cocotb's own timing).
Resources and fmax are ``make synth``'s (:mod:`eyestereo.hdl.synth`): it writes its own section of
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
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from eyestereo.hdl import synth
from eyestereo.sim.runner import BUILD, ROOT, run_bench, slug

W, H = 352, 288
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
     ["window:" + i for i in IMAGES], dict(k=10)),
    ("prethreshold 4x4", "prethreshold", "tb_prethreshold", dict(width=W, height=H, blocks=(4, 4)), 0,
     ["corner:10:" + i for i in IMAGES], dict(thresholds=dict(enumerate(THR16)))),
    ("nms 3x3", "nms", "tb_nms", dict(width=W, height=H, size=3), 1,
     ["rcorner:1:-50:50", "rcorner:2:-50:50"]),
    ("nms 5x5", "nms", "tb_nms", dict(width=W, height=H, size=5), 2,
     ["rcorner:1:-50:50", "rcorner:2:-50:50"]),
    ("harris_mono (4x4, nms 3x3)", "harris_mono", "tb_harris_mono", dict(width=W, height=H, blocks=(4, 4), nms=3),
     4, IMAGES, dict(k=10, thresholds=THR16)),
    ("harris_mono (1x1, nms 5x5)", "harris_mono", "tb_harris_mono", dict(width=W, height=H, blocks=(1, 1), nms=5),
     5, IMAGES, dict(k=10, thresholds=[40])),
]


NOTES = """
* The simulation speed of the bigger designs is GHDL's (mcode back end) evaluation of MyHDL's many
  small processes, not cocotb's: the Sobel bench runs at about 11 k clocks/s, harris_mono at 2.5 k.
"""


def _sim_seconds(build_dir: Path) -> float | None:
    """Real time cocotb spent in the test itself (from its results file)."""
    for f in build_dir.glob("*.xml"):
        for tc in ET.parse(f).getroot().iter("testcase"):
            return float(tc.get("time", "nan"))
    return None


def measure(case) -> dict:
    name, block, bench, params, radius, frames = case[:6]
    extra = case[6] if len(case) > 6 else {}
    t0 = time.perf_counter()
    rep = run_bench(block, bench, dict(extra, frames=frames, duty=1.0, timing=True), name=f"bench_{slug(name)}",
                    params=params)
    wall = time.perf_counter() - t0
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
    sim_s = _sim_seconds(BUILD / slug(block) / slug(f"bench_{slug(name)}"))
    return dict(name=name, block=block, ppc=float(ppc), lat_min=int(lat.min()), lat_max=int(lat.max()),
                lead_lines=radius, lead_pixels=radius, cycles=rep["cycles"], wall=wall, sim=sim_s,
                compared=rep["pixels_compared"])


def _version(cmd: list[str]) -> str:
    try:
        return subprocess.run(cmd, capture_output=True, text=True).stdout.splitlines()[0].strip()
    except (OSError, IndexError):
        return "?"


def report(results: list[dict]) -> str:
    import cocotb
    import myhdl

    cpu = "?"
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    out = ["# Benchmarks", "",
           f"Measured by `make bench` ({Path(__file__).name}) on {datetime.date.today()}: {cpu}, "
           f"{platform.python_implementation()} {platform.python_version()}, {_version(['ghdl', '--version'])}, "
           f"cocotb {cocotb.__version__}, MyHDL {myhdl.__version__}.", "",
           "## Throughput, latency, simulation speed (352x288, two frames back to back, 100 % input duty)", "",
           "| block | pixels / clock | latency (clocks) | window lead | clocks simulated | sim speed, whole run "
           "(clk/s) | sim speed, simulation only (clk/s) | pixels compared bit-exact |",
           "|---|---:|---:|---|---:|---:|---:|---:|"]
    for r in results:
        lat = str(r["lat_min"]) if r["lat_min"] == r["lat_max"] else f"{r['lat_min']}..{r['lat_max']}"
        n = r["lead_lines"]
        lead = f"{n} line{'s' if n > 1 else ''} + {n} px" if n else "-"
        sim = f"{r['cycles'] / r['sim']:.0f}" if r["sim"] else "?"
        out.append(f"| {r['name']} | {r['ppc']:.4f} | {lat} | {lead} | {r['cycles']} | "
                   f"{r['cycles'] / r['wall']:.0f} | {sim} | {r['compared']} |")
    out += ["", "Latency counts clocks from the input beat of pixel (x + r, y + r), the last one the window "
            "centred on (x, y) needs, to the output beat of (x, y); the output stream therefore runs "
            "r lines + r pixels + that many clocks behind the input. For the line delay it is input "
            "beat to output beat.", ""]
    return "\n".join(out)


def synth_section(doc: Path) -> str:
    """The section make synth wrote into ``doc`` (markers included), or a pointer to make synth."""
    old = doc.read_text() if doc.exists() else ""
    i, j = old.find(synth.DOC_BEGIN), old.find(synth.DOC_END)
    if i >= 0 and j > i:
        return old[i:j + len(synth.DOC_END)] + "\n"
    return f"{synth.DOC_BEGIN}\nResources and fmax: run `make synth`.\n{synth.DOC_END}\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Measure throughput, latency, sim speed and resources.")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.md")
    args = ap.parse_args(argv)
    results = []
    for case in CASES:
        print(f"benchmark: {case[0]} ...", flush=True)
        results.append(measure(case))
    text = report(results) + NOTES + "\n" + synth_section(args.out)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    (BUILD.parent / "bench.json").write_text(json.dumps(dict(results=results), indent=2))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
