"""Runs of the complete front end (``tb_stereo_frontend``): what ``eyestereo sim system`` and the system page share.

The command (:mod:`eyestereo.sim.apps.cli_system`) and the measurement page
(:mod:`eyestereo.sim.measure.bench_stereo_frontend`) run the same bench and read its report the same way;
that common part lives here, so neither imports the other's room for it (``measure`` may import ``apps``,
never the reverse: docs/architecture.md).
"""

from __future__ import annotations

from eyestereo.tools.camera import CameraTiming
from eyestereo.tools.models.sram_arbiter import MASTERS

#: The thesis's clocks (MHz) the bench runs the top at.
CLOCKS = {"memory": 100.0, "harris": 50.0, "camera_l": 18.0, "camera_r": 17.9}
#: The blanking of small frames (the camera model's rules: HREF inactive >= 1 PCLK between lines, a VSYNC
#: of >= 1 line): real blanking would make a 48x32 frame mostly blanking.
SHORT_BLANKING = dict(h_blank=64, v_sync=1, v_back=1, v_front=1)
#: What the bench touches in the top (ports and the stage probes): on Verilator only these are public
#: (run_bench's ``public``), the rest is left to Verilator's optimiser (1.3x at 64x48 here).
PUBLIC = ["clk", "rst", "hclk", "hrst", "wrst_*", "cam_*", "bus_*", "sram_*", "rectifier*_busy",
          "frontend_sequencer*_list_done", "sram_subsystem*_cam_held"]


def figures(rep: dict, timing: CameraTiming) -> dict:
    """The figures of one run's report: period, fps, read-out, stage times, SRAM shares, speed."""
    w, h = rep["width"], rep["height"]
    fr = rep["frames"]
    read = [f["read_ns"] - f["frame_ns"] for f in fr]
    out = dict(pixels=w * h, read_out_us=round(sum(read) / len(read) / 1e3, 2),
               frame_clocks=rep["frame_clocks"], camera_frame_us=round(timing.frame_pclk / CLOCKS["camera_l"], 2))
    stages = rep.get("stages", {})
    done = stages.get("list_done_ns") or []
    if rep["mode"] == "sequential":
        # every frame's period: start to the next start; the last frame's, start to its read-out done (the
        # next start would follow at once: a release pulse and a start over the bus)
        periods = [b["start_ns"] - a["start_ns"] for a, b in zip(fr, fr[1:])] + [fr[-1]["read_ns"] - fr[-1]["start_ns"]]
        out["period_from"] = (f"mean of {len(periods)} frames, start to start" if len(periods) > 1 else
                              "start to read-out done")
        out["period_us"] = round(sum(periods) / len(periods) / 1e3, 2)
        out["periods_us"] = [round(p / 1e3, 2) for p in periods]
    elif len(done) > 1:  # the steady state: completed frame to completed frame
        out["period_us"] = round((done[-1] - done[0]) / (len(done) - 1) / 1e3, 2)
        out["period_from"] = f"frame_done to frame_done, {len(done) - 1} intervals"
    else:
        out["period_us"] = round(rep["total_ns"] / rep["frames_done"] / 1e3, 2)
        out["period_from"] = "run time / frames done"
    out["fps"] = round(1e6 / out["period_us"], 2)
    moved = {m: rep["arb"][f"moved_{m}"] for m in MASTERS}
    clocks = rep["arb"]["clocks"]
    out["sram_share"] = {m: round(v / clocks, 4) for m, v in moved.items()}
    out["sram_busy"] = round(sum(moved.values()) / clocks, 4)
    out["stages"] = {k: v for k, v in stages.items() if not k.endswith("_ns")}
    out["frames_done"] = rep["frames_done"]
    out["frames_read"] = len(fr)
    out["bit_exact"] = rep["bit_exact"]
    out["features"] = [f.get("totals") for f in fr]
    if rep.get("wall_s"):
        out["wall_s"] = rep["wall_s"]
        out["sim_ms"] = round(rep["total_ns"] / 1e6, 2)
    if rep.get("sim_seconds"):  # cocotb's time of the test (after the build): memory clocks per second
        out["memory_clocks_per_s"] = round(rep["total_ns"] / 10 / rep["sim_seconds"])
        out["test_s"] = round(rep["sim_seconds"], 1)
    out["simulator"] = rep.get("simulator")
    return out
