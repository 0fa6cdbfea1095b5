"""GHDL regressions of the camera path: camera_stream, async_fifo, camera_interface, camera_pair.

Every case plays camera models (their own PCLK, period and phase in ps) or a stream into the block, runs
the bit-true, clock-accurate model on the same schedule, clocks, reader stalls and resets, and compares
every word taken, in order (tests/hdl benches in sim/tb_camera_*.py). Small frames (24x8, short blanking)
for the many cases, one full 352x288 frame.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.camera import CameraTiming
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

pytestmark = pytest.mark.sim

CAM = dict(width=24, height=8, order="YUYV", vsync_active=1, href_active=1)
BLANK = dict(h_blank=8, v_sync=1, v_back=1, v_front=1)
TIMING = CameraTiming(**CAM, **BLANK)
FRAMES = ["random:1", "random:2", "random:3"]


def ps(mhz: float) -> int:
    """An even period in ps for a frequency in MHz."""
    return 2 * round(1e6 / mhz / 2)


def _run(block, bench, cfg, request, params, sim=None):
    kw = {}
    sig = inspect.signature(run_bench).parameters
    if "harness" in sig:
        kw["harness"] = False  # multi-clock benches drive their ports themselves
    if sim is not None:
        if "sim" not in sig:
            return _run_icarus(block, bench, cfg, request.node.name, params)
        kw["sim"] = sim
    return run_bench(block, bench, cfg, name=request.node.name, params=params, **kw)


def _run_icarus(block, bench, cfg, name, params):
    """The Verilog conversion on Icarus, for a runner without ``sim=`` (the same bench, the same checks)."""
    import json
    import os
    import shutil

    from cocotb_tools.runner import get_results, get_runner

    from eyestereo.hdl.flow.convert import convert
    from eyestereo.sim.lib.runner import BUILD, SIM_DIR, slug

    if shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog not installed")
    d = BUILD / slug(block) / (slug(name) + ".icarus")
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    sources = convert(block, d, hdl="Verilog", **params)
    runner = get_runner("icarus")
    runner.build(sources=[str(p) for p in sources], hdl_toplevel=block, build_dir=d, always=True,
                 timescale=("1ns", "1ps"))
    env = {"EYESTEREO_TB": json.dumps(dict(cfg, block=block, params=params, report=str(d / "report.json"))),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    n, failed = get_results(runner.test(hdl_toplevel=block, hdl_toplevel_lang="verilog", build_dir=d, test_dir=d,
                                        test_module=f"eyestereo.sim.benches.{bench}", extra_env=env))
    assert n > 0 and failed == 0, f"{failed} of {n} cocotb tests failed on Icarus (see {d})"
    return json.loads((d / "report.json").read_text())


def camera(prefix="cam", mhz=18.0, phase=41000, frames=FRAMES, **kw):
    return dict(prefix=prefix, pclk=[ps(mhz), phase], frames=list(frames), **kw)


def run_ci(request, cameras, *, rclk_mhz=100.0, rphase=3000, depth=16, params=None, rresets=(), block=None):
    p = dict(CAM, depth=depth, **(params or {}))
    cfg = dict(timing=BLANK, rclk=[ps(rclk_mhz), rphase], rresets=[list(r) for r in rresets], cameras=cameras)
    block = block or ("camera_pair" if len(cameras) == 2 else "camera_interface")
    rep = _run(block, "tb_camera_interface", cfg, request, p)
    assert len(rep["sides"]) == len(cameras)
    return rep


def line_start(frame: int, line: int, t: CameraTiming = TIMING, preroll: int = 8) -> int:
    """PCLK edge of the first byte of a line (in a schedule played from sample 0 after the preroll)."""
    return preroll + frame * t.frame_pclk + t.first_line_pclk + line * t.line_pclk


def rclk_edge(pclk_edge: int, pclk: ClockSpec, rclk: ClockSpec) -> int:
    return rclk.first_after(pclk.time(pclk_edge))


# --- clock ratios and phases -------------------------------------------------------------------------
@pytest.mark.parametrize("cam_mhz,sys_mhz", [(18, 100), (18, 50), (27, 100)], ids=["18-100", "18-50", "27-100"])
def test_clock_ratios(request, cam_mhz, sys_mhz):
    rep = run_ci(request, [camera(mhz=cam_mhz)], rclk_mhz=sys_mhz)
    s = rep["sides"][0]
    assert s["frames"] == [0, 1, 2] and s["dropped"] == 0 and s["words"] == 3 * 24 * 8


@pytest.mark.parametrize("depth,intact", [(32, True), (16, False)])
def test_camera_faster_than_the_system_clock(request, depth, intact):
    """PCLK 75 MHz (37.5 M words/s during a line) into 30 MHz: each 24-pixel line piles up ~5 words and
    the 8-PCLK blanking drains ~3, so the level climbs through the frame to ~20 entries: 32 hold it, 16
    do not (every frame overflows, is aborted and counted)."""
    rep = run_ci(request, [camera(mhz=75, phase=9000)], rclk_mhz=30, rphase=11000, depth=depth)
    s = rep["sides"][0]
    if intact:
        assert s["frames"] == [0, 1, 2] and s["dropped"] == 0
    else:
        assert s["frames"] == [] and s["dropped"] == 3 and len(s["aborted"]) == 3


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_phase_and_frequency_offset(request, seed):
    rng = np.random.default_rng(seed)
    cam_p = ps(18 * (1 + rng.uniform(-0.01, 0.01)))
    sys_p = ps(100 * (1 + rng.uniform(-0.002, 0.002)))
    order = ["YUYV", "YVYU", "UYVY", "VYUY"][seed % 4]
    cfg_cam = dict(prefix="cam", pclk=[cam_p, cam_p // 2 + int(rng.integers(cam_p))], frames=FRAMES)
    rep = run_ci(request, [cfg_cam], rclk_mhz=1e6 / sys_p, rphase=int(rng.integers(sys_p)),
                 params=dict(order=order, vsync_active=seed % 2, href_active=(seed // 2) % 2))
    s = rep["sides"][0]
    assert s["frames"] == [0, 1, 2] and s["dropped"] == 0


def test_two_cameras_with_independent_clocks(request):
    left = camera("cam_l", mhz=17.9, phase=30011, frames=["random:1", "random:2", "random:3"])
    right = camera("cam_r", mhz=18.3, phase=51234, frames=["random:4", "random:5", "random:6"], start=300)
    rep = run_ci(request, [left, right], rphase=7777)
    l, r = rep["sides"]
    assert l["frames"] == [0, 1, 2] and r["frames"] == [1, 2]  # the right one starts inside frame 0
    assert l["dropped"] == r["dropped"] == 0


# --- start, resets, overflow ---------------------------------------------------------------------------
@pytest.mark.parametrize("start,first", [(TIMING.line_pclk // 2, 0), (TIMING.first_line_pclk + 5, 1),
                                         (TIMING.first_line_pclk + 3 * TIMING.line_pclk + 50, 1)],
                         ids=["in-vsync", "in-first-line", "in-blanking"])
def test_start_in_the_middle_of_a_frame(request, start, first):
    rep = run_ci(request, [camera(start=start)])
    s = rep["sides"][0]
    assert s["frames"] == list(range(first, 3)) and s["dropped"] == 0 and s["aborted"] == []


def test_write_domain_reset_alone(request):
    mid = line_start(1, 3) + 10
    rep = run_ci(request, [camera(wresets=[[mid, mid + 3]])])
    s = rep["sides"][0]
    assert s["frames"] == [0, 2] and s["dropped"] == 1 and [a[0] for a in s["aborted"]] == [1]


def test_read_domain_reset_alone(request):
    p18, r100 = ClockSpec(ps(18), 41000), ClockSpec(ps(100), 3000)
    k = rclk_edge(line_start(1, 3) + 10, p18, r100)
    rep = run_ci(request, [camera()], rresets=[(k, k + 4)])
    s = rep["sides"][0]
    assert s["frames"] == [0, 2] and s["dropped"] == 0 and [c[0] for c in s["cut_by_rrst"]] == [1]


@pytest.mark.parametrize("frames_hit", [1, 2])
def test_overflow_drops_and_counts_the_broken_frame(request, frames_hit):
    """The reader stalls inside frame 1 (and on into frame 2) long enough to overflow 16 entries: the
    frame(s) come out cut, with a reset token, are counted, and the next frame is whole."""
    p18, r100 = ClockSpec(ps(18), 41000), ClockSpec(ps(100), 3000)
    s0 = rclk_edge(line_start(1, 2), p18, r100)
    s1 = rclk_edge(line_start(1 + frames_hit - 1, 6), p18, r100)
    frames = FRAMES + ["random:4"]
    rep = run_ci(request, [camera(frames=frames, stalls=[[s0, s1]])])
    s = rep["sides"][0]
    assert s["dropped"] == frames_hit
    assert s["frames"] == [f for f in range(4) if not 1 <= f <= frames_hit]
    assert s["aborted"] and s["aborted"][0][0] == 1 and s["lost"] >= 1


def test_full_cif_frame(request):
    """One 352x288 frame of a real colour image, 18 MHz into 100 MHz (short vertical blanking)."""
    p = dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, order="YUYV", vsync_active=1, href_active=1, depth=1024)
    cfg = dict(timing=dict(h_blank=192, v_sync=1, v_back=1, v_front=1), rclk=[ps(100), 3000],
               cameras=[camera(frames=["file:tsukuba_im3.png"])])
    rep = _run("camera_interface", "tb_camera_interface", cfg, request, p)
    s = rep["sides"][0]
    assert s["frames"] == [0] and s["words"] == FRAME_WIDTH * FRAME_HEIGHT and s["edges_equal"] == s["words"]


# --- camera_stream alone ---------------------------------------------------------------------------
@pytest.mark.parametrize("order,vs,hr", [("YUYV", 1, 1), ("YVYU", 0, 1), ("UYVY", 1, 0), ("VYUY", 0, 0)])
def test_camera_stream_orders_polarities_faults(request, order, vs, hr):
    params = dict(CAM, order=order, vsync_active=vs, href_active=hr, luma=True)
    faults = {"1": {"line_bytes": {"2": 13}}, "2": {"lines": 5}, "3": {"line_bytes": {"7": 50}}}
    cfg = dict(timing=BLANK, pclk=[ps(18), 30000], frames=FRAMES + ["random:4", "random:5"], faults=faults,
               start=TIMING.line_pclk // 3, resets=[[line_start(4, 2) + 7, line_start(4, 2) + 9]])
    rep = _run("camera_stream", "tb_camera_stream", cfg, request, params)
    assert rep["frames"] == [0] and [a[0] for a in rep["aborted"]] == [1, 2, 3]


# --- async_fifo alone --------------------------------------------------------------------------------
@pytest.mark.parametrize("data_width,depth,wmhz,rmhz,extra", [
    (8, 4, 50, 80, dict(duty=1.0)),  # back-to-back words, a faster reader
    (36, 16, 100, 37, dict(duty=0.3, seed=5)),  # a slower reader that keeps up on average
    (16, 16, 100, 40, dict(duty=1.0, gap=20, tokens={"1": 9})),  # a token from the source; frames 3, 4 overflow
    (16, 8, 33, 71, dict(duty=0.7, seed=9, stalls=[[60, 200]], wresets=[[120, 123]], rresets=[[400, 402]])),
], ids=["w8-fast-reader", "w36-slow-reader", "w16-overflow-token", "w16-stall-resets"])
def test_async_fifo(request, data_width, depth, wmhz, rmhz, extra):
    cfg = dict(params=dict(data_width=data_width, depth=depth), wclk=[ps(wmhz), 5000], rclk=[ps(rmhz), 1234],
               width=6, height=3, frames=5, **extra)
    rep = _run("async_fifo", "tb_async_fifo", cfg, request, cfg["params"])
    assert rep["words"] > 0 and rep["frames"] and len(rep["frames"]) + rep["dropped"] <= 5
    if "tokens" in extra:
        assert rep["frames"] == [0, 2] and rep["dropped"] == 3 and rep["tokens"] == 3


# --- the Verilog conversion on Icarus (make test) and Verilator (make test-sims) ----------------------------
VERILOG_SIMS = ["icarus", pytest.param("verilator", marks=pytest.mark.othersims)]


@pytest.mark.parametrize("sim", VERILOG_SIMS)
def test_verilog_camera_interface_overflow_and_reset(request, sim):
    """The same bench on the Verilog conversion: an overflow (stall) and a read-domain reset."""
    p18, r100 = ClockSpec(ps(18), 41000), ClockSpec(ps(100), 3000)
    s0, s1 = rclk_edge(line_start(0, 2), p18, r100), rclk_edge(line_start(0, 6), p18, r100)
    k = rclk_edge(line_start(2, 3) + 10, p18, r100)
    cfg = dict(timing=BLANK, rclk=[r100.period, r100.phase], rresets=[[k, k + 4]],
               cameras=[camera(frames=FRAMES + ["random:4"], stalls=[[s0, s1]])])
    rep = _run("camera_interface", "tb_camera_interface", cfg, request, dict(CAM, depth=16), sim=sim)
    s = rep["sides"][0]
    assert s["frames"] == [1, 3] and s["dropped"] == 1 and [c[0] for c in s["cut_by_rrst"]] == [2]


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_verilog_two_cameras_with_independent_clocks(request, sim):
    """camera_pair (two pixel clocks and the system clock) on the Verilog conversion."""
    left = camera("cam_l", mhz=17.9, phase=30011, frames=["random:1", "random:2", "random:3"])
    right = camera("cam_r", mhz=18.3, phase=51234, frames=["random:4", "random:5", "random:6"], start=300)
    cfg = dict(timing=BLANK, rclk=[ps(100), 7777], rresets=[], cameras=[left, right])
    rep = _run("camera_pair", "tb_camera_interface", cfg, request, dict(CAM, depth=16), sim=sim)
    l, r = rep["sides"]
    assert l["frames"] == [0, 1, 2] and r["frames"] == [1, 2]  # the right one starts inside frame 0
    assert l["dropped"] == r["dropped"] == 0


@pytest.mark.parametrize("sim", VERILOG_SIMS)
def test_verilog_camera_stream_and_fifo(request, sim):
    params = dict(CAM, order="VYUY", vsync_active=0, href_active=1, luma=True)
    cfg = dict(timing=BLANK, pclk=[ps(18), 30000], frames=FRAMES, faults={"1": {"line_bytes": {"2": 13}}})
    rep = _run("camera_stream", "tb_camera_stream", cfg, request, params, sim=sim)
    assert rep["frames"] == [0, 2] and [a[0] for a in rep["aborted"]] == [1]
    cfg = dict(params=dict(data_width=16, depth=16), wclk=[ps(100), 5000], rclk=[ps(40), 1234], width=6,
               height=3, frames=5, duty=1.0, gap=20, tokens={"1": 9})
    rep = _run("async_fifo", "tb_async_fifo", cfg, request, cfg["params"], sim=sim)
    assert rep["frames"] == [0, 2] and rep["dropped"] == 3
