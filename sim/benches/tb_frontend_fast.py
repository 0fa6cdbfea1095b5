"""cocotb bench of the complete front end at speed: cameras and SRAM as HDL test models, Python waking per frame.

The top is :mod:`eyestereo.sim.harnesses.frontend_harness` (stereo_frontend, two camera players, the SRAM part
with its rule checks). Before the cameras start, the bench writes each camera's whole script (the frames of
``images`` or ``pair`` played back to back, :func:`~eyestereo.tools.camera.frame_schedule`, at the clocks of
``cam_l_mhz`` / ``cam_r_mhz``); the host driver then configures the registers on a lean AXI4-Lite master
(:class:`~eyestereo.sim.lib.fast_system.LeanAxiLite`, awake only during its transfers), starts the system and,
frame after frame, polls STATUS (a timer between polls), takes the rectified pair and the feature lists through
the frame handshake (``rect_want``, ``feat_want``, the held bits, the releases: the registers, as a host does)
and reads them with the SRAM part's backdoor (:class:`~eyestereo.sim.lib.fast_system.Backdoor`) instead of the
bus (the bus read-out is what :mod:`eyestereo.sim.benches.tb_stereo_frontend` tests).

Every pair and list read must equal, bit for bit, the numpy chain of one stereo pair of the frames sent (found
as in tb_stereo_frontend, moving on); so must FEATURES and FCOUNT. At the end: no dropped frames, no Harris
overflows, the SRAM part saw no broken rule and served reads and writes, nothing left over. The report gives
each frame's simulated and wall times (the wall time of a frame: from the previous frame's read to this one's).
"""

from __future__ import annotations

import time

import cocotb
import numpy as np
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.fast_system import FastTB, sram_rules
from eyestereo.sim.lib.frontend_model import choose_thresholds, frame_digest, pair_frames, stereo_frames
from eyestereo.tools.constants import K_CODE_DEFAULT
from eyestereo.tools.models import stereo_frontend as model
from eyestereo.tools.models.feature_list import parse_words


@cocotb.test()
async def frames_bit_exact(dut):
    cfg = load_config()
    tb = FastTB(dut, cfg)
    w, h, mp, cal, drv = tb.w, tb.h, tb.mp, tb.cal, tb.drv
    mode = cfg.get("mode", "sequential")
    n_host = cfg.get("frames", 2)
    n_cam = cfg.get("camera_frames", 3 * n_host + 3)
    if cfg.get("pair") is not None:
        frames = pair_frames(cfg["pair"], n_cam, w, h)
    else:
        frames = stereo_frames(cfg.get("images") or "shift:3", n_cam, w, h)
    digests = [(frame_digest(a), frame_digest(b)) for a, b in frames]
    k = K_CODE_DEFAULT
    thr = cfg["threshold"] if cfg.get("threshold") is not None else \
        choose_thresholds(cal, frames, k, cfg.get("target", 40), mp)
    t_wall0 = time.time()
    await tb.start(frames)
    await drv.check_id()
    assert await drv.geometry() == (w, h)
    await drv.configure(mode=mode, continuous=mode == "overlapped", k_left=k, k_right=k,
                        thresholds_left=[thr] * 16, thresholds_right=[thr] * 16)
    await ClockCycles(dut.clk, 50)  # the thresholds cross into the Harris clock
    dut.cam_go.value = 1

    expected = {}

    def model_of(i, j):
        key = (digests[i][0], digests[j][1])
        if key not in expected:
            expected[key] = model.stereo_frontend(cal, frames[i][0], frames[j][1], k, ([thr] * 16, [thr] * 16), **mp)
        return expected[key]

    def find(pred, last):
        hits = [(i, j) for i in range(n_cam) for j in range(max(0, i - 1), min(n_cam, i + 2)) if pred(model_of(i, j))]
        assert hits, "no stereo pair of the frames sent gives what the host read"
        return ([p for p in hits if p > last] or hits)[0]

    poll = cfg.get("poll_clocks", 2000)
    timeout = int(6 * tb.camera_ns() / 10) + 40 * w * h
    results, last_rect, last_list = [], (-1, -1), (-1, -1)
    t_run0 = time.time()
    wall_prev = t_run0
    if mode == "overlapped":
        await drv.start()
    for n in range(n_host):
        t0 = get_sim_time(unit="ns")
        if mode == "sequential":
            await drv.start()
        await drv.wait_frame(after=n, timeout_clocks=timeout, poll_clocks=poll)
        t_frame = get_sim_time(unit="ns")
        await drv.set(rect_want=1, feat_want=1)
        deadline = get_sim_time(unit="ns") + max(3 * tb.camera_ns(), 2e6)
        while not ((st := await drv.status())["rect_held"] and st["feat_held"]):
            assert get_sim_time(unit="ns") < deadline, f"frame {n}: the host never got the pair and lists ({st})"
            await tb.bus.wait(poll // 4)
        await drv.set(rect_want=0, feat_want=0)
        tot = await drv.read("FEATURES")
        counts = await drv.feature_counts()
        rect = (await tb.backdoor.read(tb.amap.rectified(st["rect_buf"]), w * h)).reshape(h, w)
        lw = (await tb.backdoor.read(tb.amap.features(st["feat_buf"]), tb.amap.feature_words)).tolist()
        await drv.pulse("rect_release", "feat_release")
        ends = [i for i in range(0, len(lw), 2) if lw[i] == 0xFFFF]
        assert ends, f"frame {n}: no list trailer in the {len(lw)} words of the feature buffer"
        lw = lw[:ends[0] + 2]
        pr = find(lambda m, rect=rect: np.array_equal(m["rect_words"], rect), last_rect)
        pl = find(lambda m, lw=lw: m["list_words"] == lw, last_list)

        def counts_ok(m, counts=counts, tot=tot):
            c = m["list"]["counts"]
            return [int(x) for x in c[0]] == counts[0] and [int(x) for x in c[1]] == counts[1] and \
                int(m["list"]["totals"][0]) == tot & 0xFFFF and int(m["list"]["totals"][1]) == tot >> 16

        find(counts_ok, (-1, -1))
        lst = parse_words([(d, False, False) for d in lw[:-1]] + [(lw[-1], True, True)])[0]
        now = time.time()
        results.append(dict(frame=n, rect_pair=pr, list_pair=pl, features=len(lst["features"]),
                            overflow=bool(lst["overflow"]), start_ns=t0, frame_ns=t_frame,
                            read_ns=get_sim_time(unit="ns"), wall_s=round(now - wall_prev, 2)))
        wall_prev = now
        last_rect, last_list = pr, pl
        dut._log.info(f"frame {n}: done {t_frame / 1e6:.3f} ms (simulated), pair {pr}, {len(lst['features'])} "
                      f"features, wall {results[-1]['wall_s']} s")
    if mode == "overlapped":
        await drv.stop()
    for _ in range(max(100, timeout // 1000)):
        if not (await drv.status())["busy"]:
            break
        await tb.bus.wait(1000)
    else:
        raise AssertionError("the system stays busy after stop")
    st = await drv.status()
    assert st["dropped_left"] == st["dropped_right"] == 0, st
    assert st["harris_overflows"] == 0, st
    await Timer(100, unit="ns")
    sram = sram_rules(dut)
    assert sram["violations"] == 0, f"the SRAM part saw {sram['violations']} broken rules, first {sram['first']}"
    assert sram["reads"] > 0 and sram["writes"] > 0, sram
    if cfg.get("require_features", True):
        assert all(r["features"] > 0 for r in results), [r["features"] for r in results]
    write_report(cfg, dict(mode=mode, width=w, height=h, threshold=thr, frames=results, bit_exact=True,
                           frames_done=st["frames"], frame_clocks=st["frame_clocks"], sram=sram,
                           host_transfers=tb.bus.transfers, backdoor_words=tb.backdoor.words_read,
                           sim_ns=get_sim_time(unit="ns"), wall_run_s=round(time.time() - t_run0, 2),
                           wall_s=round(time.time() - t_wall0, 2), camera_frame_pclk=tb.timing.frame_pclk))
