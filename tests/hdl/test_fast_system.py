"""The fast whole-system harness (issue 25): its HDL test models, the fast bench, the soak's regressions.

* the HDL SRAM part against the Python part model, pin for pin, with and without broken rules (GHDL; Verilator and
  Icarus in ``make test-sims``);
* the complete front end on the harness, bit-exact, on GHDL (the VHDL) and Verilator;
* the three defects the soak found, each a short soak with the faults that showed it (GHDL): a broken camera frame
  in the sequential mode (the camera's arm was used up: the system waited for ever), a Harris-domain reset (the
  lists of the cut frame never came: busy for ever), a camera starting late (its older buffered frame was paired
  after a newer one);
* the soak's plans, scripts and coverage report (pure Python), and the bad parameters.
"""

from __future__ import annotations

import random
import shutil

import numpy as np
import pytest

import eyestereo.sim.harnesses.frontend_harness  # noqa: F401  (registers the bench tops)
from eyestereo.sim.lib.runner import run_bench, verilator_root

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
SMALL = dict(quantizers="rig:48x32", feature_words=512, max_features=255)
SHORT = dict(h_blank=64, v_sync=1, v_back=1, v_front=1)
PUBLIC = ["clk", "rst", "hclk", "hrst", "base_l", "base_r", "wrst_l", "wrst_r", "bus_*", "cam_go", "fifo_clear",
          "cam_l_*", "cam_r_*", "sram_*"]


# ---- the SRAM part ------------------------------------------------------------------------------------------
@needs_ghdl
@pytest.mark.sim
@pytest.mark.parametrize("rl", [1, 2, 3])
def test_sram_part_matches_the_python_part(request, rl):
    """Every read word and every broken rule (count, rules, first edge) as tools.sram.SramChip gives them."""
    rep = run_bench("sram_part_tb", "tb_sram_part", dict(cycles=2500, fault_rate=0.05, seed=rl),
                    name=request.node.name, params=dict(read_latency=rl))
    assert rep["compared"] > 600 and rep["violations"] > 20
    assert set(rep["rules"]) == {"single accesses only", "byte writes", "write data in the right cycle",
                                 "no bus contention", "output enable"}


@needs_ghdl
@pytest.mark.sim
def test_sram_part_clean_traffic_breaks_no_rule(request):
    rep = run_bench("sram_part_tb", "tb_sram_part", dict(cycles=2000, fault_rate=0.0, seed=9),
                    name=request.node.name, params=dict(read_latency=2))
    assert rep["violations"] == 0 and rep["compared"] > 600


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["verilator", "icarus"])
def test_sram_part_on_the_verilog_simulators(request, sim):
    if sim == "icarus" and shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog not installed")
    if sim == "verilator" and verilator_root() is None:
        pytest.skip("Verilator not installed")
    rep = run_bench("sram_part_tb", "tb_sram_part", dict(cycles=2500, fault_rate=0.05, seed=4),
                    name=request.node.name, params=dict(read_latency=2), sim=sim)
    assert rep["compared"] > 600 and rep["violations"] > 20


# ---- the fast front end -----------------------------------------------------------------------------------
@needs_ghdl
@pytest.mark.sim
def test_fast_frontend_bit_exact_on_ghdl(request):
    """The VHDL of the top with the VHDL test models: two sequential frames, every word as the numpy chain."""
    rep = run_bench("frontend_harness", "tb_frontend_fast",
                    dict(mode="sequential", frames=2, images="shift:3", timing=SHORT, target=40),
                    name=request.node.name, params=SMALL)
    assert rep["bit_exact"] and len(rep["frames"]) == 2 and all(f["features"] > 0 for f in rep["frames"])
    assert rep["sram"]["violations"] == 0 and rep["sram"]["writes"] > 2 * 48 * 32


@pytest.mark.othersims
def test_fast_frontend_bit_exact_on_verilator(request):
    if verilator_root() is None:
        pytest.skip("Verilator not installed")
    rep = run_bench("frontend_harness", "tb_frontend_fast",
                    dict(mode="overlapped", frames=4, images="shift:3", timing=SHORT, target=40),
                    name=request.node.name, params=SMALL, sim="verilator", public=PUBLIC)
    assert rep["bit_exact"] and len(rep["frames"]) == 4


# ---- the soak's regressions (GHDL) ------------------------------------------------------------------------
def _soak(request, **cfg) -> dict:
    base = dict(timing=SHORT, target=40, camera_fault_rate=0.0, host_fault_rate=0.0, seed=5)
    return run_bench("frontend_harness", "tb_frontend_soak", dict(base, **cfg), name=request.node.name, params=SMALL)


@needs_ghdl
@pytest.mark.sim
def test_soak_broken_camera_frames_in_the_sequential_mode(request):
    """A camera frame broken while the camera was armed gives its arm back: the next frame is captured (before,
    the sequential mode waited for ever); DROPPED counts every broken frame."""
    rep = _soak(request, mode="sequential", frames=5, camera_frames=24,
                camera_faults_at=[["r", 2, "short_line"], ["l", 3, "short_frame"], ["r", 4, "long_line"],
                                  ["l", 5, "short_line"], ["r", 6, "short_frame"]])
    assert rep["frames_read"] == 5 and rep["verdicts"] == {"exact": 5}
    assert rep["dropped"] == [2, 3]


@needs_ghdl
@pytest.mark.sim
def test_soak_harris_resets_do_not_hang(request):
    """Harris-domain resets while frames run: the sequencer's list watchdog gives a cut frame's lists up (LOST),
    the host starts again (before, busy stayed high for ever), the thresholds are sent again (before, every later
    frame was thresholded at 0) and the next frames are bit-exact."""
    rep = _soak(request, mode="sequential", frames=6, camera_frames=28, threshold=256,
                host_faults_at={"0": "reset_harris", "1": "reset_harris", "2": "reset_harris"})
    assert rep["frames_read"] == 6 and rep["resets"]["harris"] == 3
    assert rep["lists_lost"] <= 3 and rep["verdicts"].get("exact", 0) >= 3
    # the thresholds came back after each reset (threshold_replay): the last frames' lists are the model's with
    # code 256, not with 0 (a list thresholded at 0 holds several times the features)
    assert all(r["verdict"] == "exact" for r in rep["reads"][-2:]) and all(0 < r["features"] < 60
                                                                          for r in rep["reads"][-2:])


@needs_ghdl
@pytest.mark.sim
def test_soak_late_camera_never_pairs_an_older_frame(request):
    """A camera that stops for a frame or two: the pair taken after it is never older than the one before (before,
    the older of two FULL camera buffers was still offered after the newer was taken)."""
    rep = _soak(request, mode="overlapped", frames=8, camera_frames=30,
                camera_faults_at=[["l", 3, "late_start"], ["r", 5, "late_start"], ["l", 8, "late_start"],
                                  ["r", 10, "late_start"]])
    assert rep["frames_read"] == 8 and rep["verdicts"] == {"exact": 8}
    pairs = [r["pair"] for r in rep["reads"]]
    assert all(b[0] > a[0] and b[1] > a[1] for a, b in zip(pairs, pairs[1:])), pairs


# ---- plans, scripts, coverage, bad input (no simulator) ----------------------------------------------------
def test_script_lines_pack_a_line_and_split_long_runs():
    from eyestereo.sim.lib.fast_system import MAX_RUN, script_lines
    from eyestereo.sim.lib.harness_files import RUN_KINDS, RUN_SHIFT

    lines = [int(v) for v in script_lines([("vsync", 3), ("line", np.array([1, 2, 3, 4])), ("stop", MAX_RUN + 5)])]
    assert lines[0] == RUN_KINDS["vsync"] << RUN_SHIFT | 3
    assert lines[1] == RUN_KINDS["line"] << RUN_SHIFT | 4
    assert lines[2:4] == [1 + 2 * 256 + 3 * 65536, 4]  # three bytes a word, the first in the low bits
    assert lines[4:] == [RUN_KINDS["stop"] << RUN_SHIFT | MAX_RUN, RUN_KINDS["stop"] << RUN_SHIFT | 5]


@pytest.mark.parametrize("runs, msg", [([("blink", 3)], "unknown run kind"),
                                       ([("line", np.array([1, 256]))], "0..255")])
def test_script_lines_refuse_bad_runs(runs, msg):
    from eyestereo.sim.lib.fast_system import script_lines

    with pytest.raises(ValueError, match=msg):
        script_lines(runs)


def test_write_script_leaves_no_half_file(tmp_path):
    from eyestereo.sim.lib.fast_system import write_script

    f = tmp_path / "cam_l.txt"
    f.write_text("the user's old script\n")
    with pytest.raises(ValueError):
        write_script(f, [("idle", 4), ("nope", 1)])
    assert f.read_text() == "the user's old script\n" and sorted(p.name for p in tmp_path.iterdir()) == ["cam_l.txt"]


def test_camera_runs_keep_each_fault_s_length():
    """mid_frame keeps the frame's length (blanking instead of VSYNC and lines), pclk_stop adds only its stop,
    late_start puts its stop before the frame; the starts follow."""
    from eyestereo.sim.lib.soak import CameraPlan, camera_runs
    from eyestereo.tools.camera import CameraTiming, schedule_length

    t = CameraTiming(width=8, height=4, **SHORT)
    frames = [np.zeros((4, 8), np.int64) + i for i in range(3)]
    plain, starts = camera_runs(frames, t, CameraPlan())
    assert starts == [0, t.frame_pclk, 2 * t.frame_pclk] and schedule_length(plain) == 3 * t.frame_pclk
    for kind, d, extra in (("mid_frame", dict(lines=2), 0), ("pclk_stop", dict(line=1, at=3, n=17), 17),
                           ("late_start", dict(n=99), 99)):
        runs, starts = camera_runs(frames, t, CameraPlan({1: (kind, d)}))
        assert schedule_length(runs) == 3 * t.frame_pclk + extra, kind
        assert starts == [0, t.frame_pclk, 2 * t.frame_pclk + extra], kind
    runs, _ = camera_runs(frames, t, CameraPlan({1: ("mid_frame", dict(lines=2))}))
    assert sum(1 for k, _ in runs if k == "vsync") == 2 and sum(1 for k, _ in runs if k == "line") == 3 * 4 - 2


def test_camera_plans_are_seeded_and_forced_faults_land():
    from eyestereo.sim.lib.soak import plan_cameras
    from eyestereo.tools.camera import CameraTiming

    t = CameraTiming(width=48, height=32, **SHORT)
    a = plan_cameras(200, 0.2, t, random.Random(3))
    b = plan_cameras(200, 0.2, t, random.Random(3))
    assert a[0].faults == b[0].faults and a[1].faults == b[1].faults and len(a[0].faults) + len(a[1].faults) > 20
    for plan in a:
        frames = sorted(plan.faults)
        assert all(y - x >= 2 for x, y in zip(frames, frames[1:])) and min(frames) >= 2
    forced = plan_cameras(10, 0.0, t, random.Random(1), forced=[("r", 4, "late_start")])
    assert not forced[0].faults and forced[1].faults[4][0] == "late_start"
    with pytest.raises(ValueError, match="camera 'l' or 'r'"):
        plan_cameras(10, 0.0, t, random.Random(1), forced=[("x", 4, "late_start")])
    with pytest.raises(ValueError, match="not a camera fault"):
        plan_cameras(10, 0.0, t, random.Random(1), forced=[("l", 4, "reset_harris")])


def test_coverage_report_names_every_hole_with_a_reason(tmp_path):
    """Two runs' databases merged: a bin hit in either counts; an unreached bin is a hole with its reason."""
    import yaml

    from eyestereo.sim.lib import soak_coverage as cov

    def db(hits):
        return {"soak": {"size": 2, "coverage": 1, "cover_percentage": 50.0, "type": "<class 'CoverItem'>"},
                "soak.fault.mode": {"type": "<class 'CoverPoint'>", "size": 2, "coverage": sum(hits.values()) > 0,
                                    "cover_percentage": 50.0, "weight": 1, "at_least": 1,
                                    "bins:_hits": dict(hits)}}
    files = []
    for i, hits in enumerate(({"sequential": 3, "overlapped": 0}, {"sequential": 0, "overlapped": 0})):
        files.append(tmp_path / f"r{i}.yml")
        files[-1].write_text(yaml.dump(db(hits)))
    lines, holes = cov.report(cov.merge(files, tmp_path / "merged.yml"))
    assert any("`soak.fault.mode` | 2 | 1 |" in ln for ln in lines)
    assert holes == [("soak.fault.mode", "overlapped", "not reached (no reason known: a hole to close)")]
    assert cov.HOLE_REASONS[("SRAM", "write")] and cov.clock_ratio(18.0, 17.9) == "near"
    assert cov.clock_ratio(18.0, 15.0) == "far" and cov.clock_ratio(18.0, 18.0) == "equal"
    with pytest.raises(ValueError, match="no coverage files"):
        cov.merge([], tmp_path / "none.yml")


@pytest.mark.parametrize("params, msg", [(dict(kind="pipelined"), "NoBL SRAM"), (dict(memory="sdram"), "NoBL SRAM"),
                                         (dict(read_latency=4), "read latency must be 1..3")])
def test_the_harness_refuses_a_part_it_does_not_model(params, msg):
    from eyestereo.hdl.flow.catalog import get

    with pytest.raises(ValueError, match=msg):
        get("frontend_harness").elaborate(**dict(SMALL, **params))


@pytest.mark.parametrize("bad", [0, -5, 1 << 25, 2.5, True])
def test_the_list_watchdog_s_timeout_is_checked(bad):
    from myhdl import Signal, intbv

    from eyestereo.hdl.flow.catalog import fresh_ports
    from eyestereo.hdl.memory.frame_buffers import FrameControl
    from eyestereo.hdl.system.frontend_sequencer import frontend_sequencer

    def bit():
        return Signal(bool(0))

    ports = fresh_ports(frontend_sequencer, mode=bit(), continuous=bit(), start=bit(), stop=bit(), ctl=FrameControl(),
                        rect_start=bit(), rect_busy=bit(), list_done=bit(), list_overflow=bit(), busy=bit(),
                        frames=Signal(intbv(0)[32:]), frame_clocks=Signal(intbv(0)[32:]),
                        list_overflows=Signal(intbv(0)[16:]))
    with pytest.raises(ValueError, match="list_timeout must be None or an int"):
        frontend_sequencer(**ports, list_timeout=bad)
