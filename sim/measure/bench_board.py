"""The board simulation measured: the ULX3S top with its parts' models (tests/boards/test_board_sim.py's run) on a
simulator, its figures into docs/boards.md's ``boardsim`` section.

    python -m eyestereo.sim.measure.bench_board --out docs/boards.md [--sim ghdl] [--backend mcode|llvm]

Figures: what the run showed (features read over the serial line, HDMI frames decoded, pairs the display copied,
requests on the serial line) and what it cost (simulated time, wall time of the test, simulated memory clocks a
second).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import eyestereo.sim.harnesses.board_harness  # noqa: F401  (registers the bench top)
from eyestereo.hdl.boards.ulx3s import board_clocks
from eyestereo.sim.lib.runner import hdl_revision, run_bench
from eyestereo.tools.io import write_section

#: The run of tests/boards/test_board_sim.py (kept equal by tests/boards/test_board_sim.py importing them).
PARAMS = dict(quantizers="rig:32x24", mode="sim-64x48", clocks_per_bit=8, sccb_table=((0x11, 0x00), (0x40, 0xD0)),
              sccb_hz=400e3, matcher=True, match_rows=1)
CONFIG = dict(frames=400, target=12, k=10, monitor_frames=2, cam_mhz=12.5, scene="match:7", match=dict(t_max=40),
              timing=dict(h_blank=64, v_sync=2, v_back=4, v_front=2))
MARKERS = ("<!-- boardsim:begin -->", "<!-- boardsim:end -->")


def section(rep: dict, sim: str, wall: float) -> str:
    sim_ms = rep["sim_time_ns"] / 1e6
    mem_mhz = board_clocks(matcher=PARAMS.get("matcher", False), memory_mhz=PARAMS.get("memory_mhz"))["mem"]
    clocks = rep["sim_time_ns"] * mem_mhz / 1e3
    return "\n".join([
        f"Measured by `python -m eyestereo.sim.measure.bench_board` ({sim}; the board top of commit {hdl_revision()}, the small "
        "configuration above):", "",
        "| figure | value |", "|---|---:|",
        f"| features the host read over the serial line (= the model's) | {rep['features']} |",
        f"| matches the host read (= the feature matcher model's); their segments' pixels on the monitor | "
        f"{rep.get('matches')}; {rep.get('segment_pixels')} |",
        f"| threshold code (chosen with the model for about {CONFIG['target']} features per camera) | "
        f"{rep['threshold']} |",
        f"| FRAMES when the host took its pair | {rep['frames_at_grab']} |",
        f"| whole HDMI frames decoded (the last compared with the model's picture) | {rep['hdmi_frames']} |",
        f"| pairs the display copied | {rep['copies']} |",
        f"| requests on the serial line | {rep['requests']} |",
        f"| DROPPED (left, right) after the run; FRAMES | {', '.join(map(str, rep['dropped']))}; {rep['frames']} |",
        f"| memory clock | {mem_mhz:g} MHz |",
        f"| simulated time | {sim_ms:.2f} ms ({clocks / 1e3:.0f} k memory clocks) |",
        f"| wall time of the run | {wall:.0f} s ({clocks / wall / 1e3:.1f} k memory clocks/s) |", ""]) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m eyestereo.sim.measure.bench_board", description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/boards.md"), help="the page whose boardsim section to fill")
    ap.add_argument("--sim", default="ghdl", choices=("ghdl",), help="simulator (the harness's models are VHDL)")
    ap.add_argument("--backend", choices=("mcode", "llvm"), help="GHDL's back end (default $GHDL_BACKEND or mcode)")
    args = ap.parse_args(argv)
    text = args.out.read_text() if args.out.is_file() else ""
    if MARKERS[0] not in text or MARKERS[1] not in text:
        print(f"error: {args.out}: no '{MARKERS[0]}' ... '{MARKERS[1]}' section to fill", file=sys.stderr)
        return 1
    t0 = time.perf_counter()
    rep = run_bench("board_harness", "tb_board", dict(CONFIG), name="bench_board", params=dict(PARAMS), sim=args.sim,
                    backend=args.backend)
    wall = time.perf_counter() - t0
    write_section(args.out, section(rep, f"{args.sim} {args.backend or ''}".strip(), wall), *MARKERS)
    print(section(rep, args.sim, wall))
    return 0


if __name__ == "__main__":
    sys.exit(main())
