"""cocotb bench of the complete front end: two camera models, the SRAM model, the host driver on AXI4-Lite.

The two cameras (:class:`~eyestereo.sim.lib.camera.CameraModel`, each with its own PCLK: 18 MHz and 17.9 MHz
by default) play a sequence of stereo frames back to back; the SRAM model checks the part's rules; the
host driver (cocotbext-axi's master with the bus checker) configures mode, k and the block thresholds,
starts the system, waits for frames, takes the rectified pair and the feature lists (``rect_want``,
``feat_want``), reads them through the SRAM window and releases them, frame after frame.

Every rectified pair and every feature list the host reads must equal, bit for bit, the numpy chain
(:func:`eyestereo.tools.models.stereo_frontend.stereo_frontend`) of one stereo pair of the frames the
cameras sent (which pair the system captured depends on the independent clocks: the bench finds it among
the pairs of neighbouring frame indices, and requires the captured frames to move on), and so must the
per-camera totals (FEATURES) and the per-block counts (FCOUNT) of that frame. The model runs with every
parameter the top was built with that changes the result (:func:`model_params`: ``nms``, ``border``,
``max_features``, ``frac`` from the config's ``params``, the block's own defaults for the absent ones), so a
list cut at ``max_features`` (the trailer's overflow flag) is compared like any other. At the end nothing is
left over: no dropped frames, no Harris-clock overflows, ``list_overflows`` (OVERFLOWS: the completed frames
whose list was cut, see :func:`check_list_overflows`) equal to the model's count, the SRAM model saw no
violation, the bus checker no fault. A frame without features is accepted (a flat scene has none); a
configuration with ``require_features`` asks for features in every frame read (in one at least with
``adaptive``: the closed loop may drive a frame to none on its way).

With the ``dense`` option (``params["dense"]``) the host also takes each disparity map (``disp_want``), reads it
from its buffer and releases it; it must equal, bit for bit, the dense model
(:func:`eyestereo.tools.models.stereo_frontend.disparity`) of one of the rectified pairs (the pair the host read
in the same round, or a neighbour: the map can lag its pair), with the settings of the DENSE register
(``dense_settings``, else the reset values); at the end the core's FIFO never overran (``dense_overrun``), the
writer lost no code (``disp_lost``) and completed at least as many maps as were read. ``backdoor_rect`` (SRAM
only): the rectified pairs are taken from the SRAM model's array while the host holds the buffer, not read
through the host port (a word through AXI4-Lite is about 20 memory clocks of Python, the longest part of a small
frame's round); the feature lists and the disparity maps still come through the host port.

The scene (:mod:`eyestereo.sim.lib.frontend_model`): ``images`` (:func:`stereo_frames`: ``random:S``, ``shift:S``,
``files:LEFT,RIGHT``) or ``pair``:
``[left.npy, right.npy]``, each an (height, width) uint8 array at the camera size, the Y of every frame of
that camera (:func:`pair_frames`).

The report gives the frame clocks (FRAME_CLOCKS, the sequencer's measurement), the simulated time of
each stage (capture, rectification, lists complete, host read-out) and the arbiter's per-master counters.
"""

from __future__ import annotations

import inspect
import time

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, Edge, Timer

from eyestereo.sim.lib.axil import AxiLiteHost
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.camera import CameraModel
from eyestereo.sim.lib.frontend_model import (choose_thresholds, frame_digest, match_list_of, match_settings,
                                              model_params, pair_frames, stereo_frames)
from eyestereo.sim.lib.sdram_model import SdramModel
from eyestereo.sim.lib.sram_model import SramModel
from eyestereo.tools.camera import CameraTiming, frame_schedule
from eyestereo.tools.constants import K_CODE_DEFAULT
from eyestereo.tools.host_driver import HostDriver
from eyestereo.tools.models import stereo_frontend as model
from eyestereo.tools.models.feature_list import parse_words
from eyestereo.tools.models.match_engine import parse_list
from eyestereo.tools.models.sram_arbiter import AddressMap, list_words, match_offset
from eyestereo.tools.regmap import ARB_WORDS
from eyestereo.tools.sdram import ULX3S
from eyestereo.tools.sram import SramPart


@cocotb.test()
async def frames_bit_exact(dut):
    cfg = load_config()
    from eyestereo.hdl.rectify.calibration import calibration_param

    cal = calibration_param(cfg["params"]["quantizers"], None, None)
    w, h = cal.width, cal.height
    mp = model_params(cfg["params"])  # what the top was built with, for the model
    mode = cfg.get("mode", "sequential")
    n_host = cfg.get("frames", 3)
    # sequential: each frame lets a few camera frames pass (arming, read-out): enough for every one
    n_cam = cfg.get("camera_frames", 5 * n_host + 4)
    dense = bool(cfg["params"].get("dense", False))
    msets = match_settings(cfg)
    amap = AddressMap(w, h, cfg["params"].get("feature_words") or
                      list_words(mp["max_features"], msets["max_matches"] if msets else None),
                      cameras=cfg["params"].get("rectify", "fetch") != "stream", dense=dense)
    dsets = dense_settings(cfg)
    if cfg.get("pair") is not None:
        if cfg.get("images") is not None:
            raise ValueError("give the scene as images or as pair, not both")
        frames = pair_frames(cfg["pair"], n_cam, w, h)
    else:
        frames = stereo_frames(cfg.get("images") or "random:1", n_cam, w, h)
    digests = [(frame_digest(a), frame_digest(b)) for a, b in frames]
    k = K_CODE_DEFAULT  # k = 0.04, the thesis's (and the K registers' reset)
    thr = cfg["threshold"] if cfg.get("threshold") is not None else \
        choose_thresholds(cal, frames, k, cfg.get("target", 40), mp)

    # clocks: memory 100 MHz, Harris 50 MHz (or as configured), cameras on their own
    Clock(dut.clk, 10, unit="ns").start()
    Clock(dut.hclk, int(round(1e3 / cfg.get("harris_mhz", 50.0) * 1000)), unit="ps").start()
    for r in ("rst", "hrst", "wrst_l", "wrst_r"):
        getattr(dut, r).value = 1
    timing = CameraTiming(width=w, height=h, **cfg.get("timing", dict(h_blank=64, v_sync=1, v_back=1, v_front=1)))
    cams = []
    for side, mhz, phase in (("l", cfg.get("cam_l_mhz", 18.0), 40_000), ("r", cfg.get("cam_r_mhz", 17.9), 61_000)):
        period = 2 * int(round(1e6 / mhz / 2))
        cams.append(CameraModel(dut, f"cam_{side}", timing, period, max(phase, period // 2)))
    bus = AxiLiteHost(dut, "bus", dut.clk, dut.rst)
    bus.pauses(cfg.get("pause", 0.0), cfg.get("seed", 1))
    await ClockCycles(dut.clk, 6)
    for r in ("rst", "hrst", "wrst_l", "wrst_r"):
        getattr(dut, r).value = 0
    if cfg["params"].get("memory", "sram") == "sdram":  # the SDR SDRAM's rules on its pins (issue 26)
        sram = SdramModel(dut, dut.clk, cfg["params"].get("sdram_part", ULX3S), prefix="sram", period_ns=10.0,
                          cas_latency=2)
    else:
        part = SramPart(cfg["params"].get("kind", "nobl"), cfg["params"].get("read_latency", 2))
        sram = SramModel(dut, dut.clk, part)
    sram.start()
    drv = HostDriver(bus)
    await drv.check_id()
    assert await drv.geometry() == (w, h)
    await drv.configure(mode=mode, continuous=bool(cfg.get("continuous", mode == "overlapped")), k_left=k,
                        k_right=k, thresholds_left=[thr] * 16, thresholds_right=[thr] * 16)
    assert await drv.read_thresholds("THR_LEFT") == [thr] * 16
    if dense and cfg.get("dense_settings"):
        await drv.set(**cfg["dense_settings"])
    if msets:
        await drv.set(match_limit=msets["limit"], match_uniqueness=msets["uniqueness"],
                      match_lr_check=int(msets["lr_check"]))
    await ClockCycles(dut.clk, 50)  # the thresholds cross into the Harris clock

    for cam, idx in zip(cams, (0, 1)):
        await cocotb.start(cam.start_clock())
        cocotb.start_soon(cam.play(frame_schedule([f[idx] for f in frames], timing)))

    # stage times: the converted top keeps the blocks' signals by name (a probe, not a port)
    events = []

    async def watch(sig, label):
        while True:
            await Edge(sig)
            events.append((label, int(sig.value), get_sim_time(unit="ns")))

    def probe(*patterns):
        # MyHDL numbers instances per process and per level (rectifier0, rectifier0_0, ...; the naming differs
        # with the configuration): try the first few of each form
        for pattern in patterns:
            for i in range(4):
                for j in range(4):
                    try:
                        return getattr(dut, pattern.format(i=i, j=j))
                    except AttributeError:
                        pass
        return None

    for patterns, label in ((("rectifier{i}_busy", "rectifier{i}_{j}_busy"), "rect_busy"),
                            (("frontend_sequencer{i}_list_done", "frontend_sequencer{i}_{j}_list_done"), "list_done"),
                            (("sram_subsystem{i}_sram_arbiter{j}_ctl_cam_held",
                              "sram_subsystem{i}_{j}_sram_arbiter{i}_{j}_ctl_cam_held",
                              "sram_subsystem{i}_0_sram_arbiter{j}_0_ctl_cam_held"), "cam_held")):
        sig = probe(*patterns)
        if sig is not None:
            cocotb.start_soon(watch(sig, label))
        else:
            dut._log.warning(f"no probe for {label}: its stage time is left out")

    expected = {}  # (i, j, thresholds) -> model outputs, computed on demand
    cur = ([thr] * 16, [thr] * 16)  # the thresholds the system runs with
    adaptive = cfg.get("adaptive")  # target features per block: the host closes the loop (thesis 7.2)
    if adaptive is not None:
        from eyestereo.tools.matching.adaptive import SecantController

        ctrls = [SecantController(adaptive, init=thr) for _ in range(2)]

    def model_of(i, j):
        key = (digests[i][0], digests[j][1], tuple(cur[0]), tuple(cur[1]))
        if key not in expected:
            expected[key] = model.stereo_frontend(cal, frames[i][0], frames[j][1], k, (list(cur[0]), list(cur[1])),
                                                  **mp)
        return expected[key]

    disparities = {}  # (digest of the rectified pair) -> the dense model's codes

    def disparity_of(m):
        key = frame_digest(m["rect_words"])
        if key not in disparities:
            disparities[key] = model.disparity(*m["rectified"], dsets)
        return disparities[key]

    def find(pred, last, diff=None):
        hits = [(i, j) for i in range(n_cam) for j in range(max(0, i - 1), min(n_cam, i + 2)) if pred(model_of(i, j))]
        if not hits and diff is not None:
            best = min((diff(model_of(i, j)), (i, j)) for i in range(n_cam) for j in range(n_cam))
            raise AssertionError(f"no stereo pair of the frames sent gives what the host read; nearest {best}")
        assert hits, "no stereo pair of the frames sent gives what the host read"
        hits = [p for p in hits if p > last] or hits
        return hits[0]

    if cfg.get("speed_us"):  # a speed measurement only: the system capturing, no comparison
        await drv.start()
        if cfg.get("speed_skip_us"):  # past the cameras' first VSYNC and back porch: into the active lines
            await Timer(int(cfg["speed_skip_us"]), unit="us")
        t0, w0 = get_sim_time(unit="ns"), time.time()
        await Timer(int(cfg["speed_us"]), unit="us")
        wall = time.time() - w0
        sim_us = (get_sim_time(unit="ns") - t0) / 1e3
        write_report(cfg, dict(mode=mode, width=w, height=h, speed=True, sim_us=sim_us, wall_s=round(wall, 2),
                               memory_clocks_per_s=round(sim_us * 100 / wall, 1)))
        return
    results, last_rect, last_list, last_disp = [], (-1, -1), (-1, -1), (-1, -1)
    # a frame: up to two camera frames to the pair held, the rectification, the host's read-out before it
    # (memory clocks; the camera's frame period in PCLK of 1/18 us, the memory clock 100 MHz)
    timeout = max(5_000_000, int(6 * timing.frame_pclk * 100 / 17.9) + 40 * w * h)
    t_start = get_sim_time(unit="ns")
    wall0 = time.time()
    if mode == "overlapped":
        await drv.start()
    read = cfg.get("read", "all")
    if read not in ("all", "matches") or (read == "matches" and not msets):
        raise ValueError(f"read={read!r}: 'all' (the pair and the lists) or 'matches' (the matcher option's list only)")
    matches_of = {}  # (digest of the rectified pair) -> the matcher model's list

    def match_model(m):
        key = (frame_digest(m["rect_words"]), tuple(cur[0]), tuple(cur[1]))
        if key not in matches_of:
            matches_of[key] = match_list_of(m, mp, msets)
        return matches_of[key]

    for n in range(n_host):
        t0 = get_sim_time(unit="ns")
        if mode == "sequential":
            await drv.start()
        await drv.wait_frame(after=n, timeout_clocks=timeout, poll_clocks=200)
        t_frame = get_sim_time(unit="ns")
        if read == "matches":  # the host wants no image and no feature: the list buffer's matches alone
            await drv.set(feat_want=1)
            cam_ns = timing.frame_pclk * 1e3 / min(cfg.get("cam_l_mhz", 18.0), cfg.get("cam_r_mhz", 17.9))
            deadline = get_sim_time(unit="ns") + max(3 * cam_ns, 2e6)
            while not (st := await drv.status())["feat_held"]:
                if get_sim_time(unit="ns") > deadline:
                    raise AssertionError(f"frame {n}: the host never got the lists ({st})")
                await bus.wait(50)
            await drv.set(feat_want=0)
            t_held = get_sim_time(unit="ns")
            mw = await drv.read_match_list(amap.features(st["feat_buf"]) + match_offset(mp["max_features"]))
            t_read = get_sim_time(unit="ns")
            await drv.pulse("feat_release")
            pl = find(lambda m, mw=mw: [int(d) for d, _, _ in match_model(m)["words"]] == mw, last_list)
            want, ml = match_model(model_of(*pl)), model_of(*pl)["list"]
            got = parse_list(mw)  # the hardware's matches, for the picture
            last = dict(matches=got["matches"].tolist(), dy=got["dy"].tolist())
            dut._log.info(f"frame {n}: done {t_frame / 1e6:.3f} ms, {got['count']} matches read in "
                          f"{(t_read - t_held) / 1e3:.1f} us (simulated), wall {time.time() - wall0:.1f} s")
            # features and overflow: the model's list of the pair the matches belong to (not read: the report's
            # list_overflows rule needs them)
            results.append(dict(frame=n, list_pair=pl, features=len(ml["features"]), overflow=bool(ml["overflow"]),
                                model_totals=[int(v) for v in ml["totals"]], model_overflow=bool(ml["overflow"]),
                                matches=int(want["count"]), candidates=int(want["candidates"]), match_words=len(mw),
                                start_ns=t0, frame_ns=t_frame, held_ns=t_held, read_ns=t_read))
            last_list = pl
            continue
        await drv.set(rect_want=1, feat_want=1)
        # a pair comes within a camera frame or two (overlapped: the writer may be filling the free buffer); wait
        # three camera frames of the slowest camera (at least 2 ms, the bound before VGA), polling every 50 clocks
        cam_ns = timing.frame_pclk * 1e3 / min(cfg.get("cam_l_mhz", 18.0), cfg.get("cam_r_mhz", 17.9))
        deadline = get_sim_time(unit="ns") + max(3 * cam_ns, 2e6)
        while True:
            st = await drv.status()
            if st["rect_held"] and st["feat_held"]:
                break
            if get_sim_time(unit="ns") > deadline:
                raise AssertionError(f"frame {n}: the host never got the rectified pair and the lists ({st})")
            await bus.wait(50)
        await drv.set(rect_want=0, feat_want=0)
        tot = await drv.read("FEATURES")
        counts = await drv.feature_counts()
        if cfg.get("backdoor_rect"):
            if not isinstance(sram, SramModel):
                raise ValueError("backdoor_rect: only with the SRAM model (memory=sram)")
            base = amap.rectified(st["rect_buf"])
            rect = np.array([sram.chip.word(base + a) for a in range(w * h)], np.int64).reshape(h, w)
        else:
            rect = np.array(await drv.read_sram_words(amap.rectified(st["rect_buf"]), w * h),
                            np.int64).reshape(h, w)
        fbase = amap.features(st["feat_buf"])
        lw, i = [], 0
        while True:  # the list up to its trailer
            a, b = await drv.read_sram_words(fbase + i, 2)
            lw += [a, b]
            i += 2
            if a == 0xFFFF or i >= amap.feature_words:
                break
        if msets:  # the matcher option: the frame's match list at its fixed word of the same buffer
            t_m = get_sim_time(unit="ns")
            mw = await drv.read_match_list(fbase + match_offset(mp["max_features"]))
            t_m = get_sim_time(unit="ns") - t_m
        t_read = get_sim_time(unit="ns")
        dut._log.info(f"frame {n}: started {t0 / 1e6:.3f} ms, done {t_frame / 1e6:.3f} ms, read {t_read / 1e6:.3f} ms "
                      f"(simulated), wall {time.time() - wall0:.1f} s")
        await drv.pulse("rect_release", "feat_release")
        # find() calls the predicates at once; the defaults bind this frame's words to them all the same
        pr = find(lambda m, rect=rect: np.array_equal(m["rect_words"], rect), last_rect,
                  lambda m, rect=rect: (int(np.sum(m["rect_words"] != rect)),
                                        np.argwhere(m["rect_words"] != rect)[:4].tolist()))
        pl = find(lambda m, lw=lw: m["list_words"] == lw, last_list)
        lst = parse_words([(d, False, False) for d in lw[:-1]] + [(lw[-1], True, True)])[0]
        last = dict(rect=rect.tolist(), features=[list(f) for f in lst["features"]])
        ml = model_of(*pl)["list"]  # the model's list of that pair: equal to what the host read
        if msets:
            want = match_list_of(model_of(*pl), mp, msets)
            assert mw == [int(d) for d, _, _ in want["words"]], \
                f"frame {n}: the match list read ({len(mw)} words) is not the model's ({len(want['words'])} words, " \
                f"{want['count']} matches): first words {mw[:6]} / {[int(d) for d, _, _ in want['words'][:6]]}"
            got = parse_list(mw)  # the hardware's matches (equal to the model's), for the picture
            last["matches"] = got["matches"].tolist()
            last["dy"] = got["dy"].tolist()
            results_match = dict(matches=int(want["count"]), candidates=int(want["candidates"]),
                                 match_words=len(mw), match_read_ns=t_m)
        results.append(dict(frame=n, rect_pair=pr, list_pair=pl, features=len(lst["features"]),
                            overflow=bool(lst["overflow"]), model_totals=[int(v) for v in ml["totals"]],
                            model_overflow=bool(ml["overflow"]), start_ns=t0, frame_ns=t_frame, read_ns=t_read))
        if msets:
            results[-1].update(results_match)
        last_rect, last_list = pr, pl
        # the totals and per-block counts belong to the last complete frame: the list's pair, or a later
        # one in the overlapped mode (the system goes on meanwhile): it must be one of the frames sent
        def counts_ok(m, counts=counts, tot=tot):
            c = m["list"]["counts"]
            return [int(x) for x in c[0]] == counts[0] and [int(x) for x in c[1]] == counts[1] and \
                int(m["list"]["totals"][0]) == tot & 0xFFFF and int(m["list"]["totals"][1]) == tot >> 16
        find(counts_ok, (-1, -1))
        results[-1].update(totals=[tot & 0xFFFF, tot >> 16], thresholds=[list(map(int, c)) for c in cur])
        if dense:
            pd, got = await take_disparity(drv, amap, w, h, deadline_ns=3 * cam_ns, pr=pr, last=last_disp,
                                           n_cam=n_cam, model_of=model_of, disparity_of=disparity_of)
            last_disp = pd
            last["disparity"] = got.tolist()
            results[-1].update(disp_pair=pd, disp_ns=get_sim_time(unit="ns"))
        if adaptive is not None:  # the next frame's thresholds from this frame's block counts
            cur = tuple([int(v) for v in c.update(np.array(cnt))] for c, cnt in zip(ctrls, counts))
            await drv.configure(mode=mode, thresholds_left=cur[0], thresholds_right=cur[1])
    if mode == "overlapped":
        await drv.stop()
    # stop ends continuous operation after the frame in progress: up to a camera frame and its rectification
    for _ in range(max(1000, timeout // 1000)):
        if not (await drv.status())["busy"]:
            break
        await bus.wait(100 if w * h < 10_000 else 1000)
    else:
        raise AssertionError("the system stays busy after stop")
    st = await drv.status()
    arb = await drv.arbiter()
    assert st["dropped_left"] == st["dropped_right"] == 0, st
    assert st["harris_overflows"] == 0, st
    if msets:
        assert st["match_dropped"] == st["match_late"] == st["match_lost"] == 0, st
    if dense:
        assert st["dense_overrun"] == 0 and st["disp_lost"] == 0, st
        assert st["disp_frames"] >= len(results), st
    ovf = check_list_overflows(st, results, [model_of(i, j)["list"]["overflow"] for i in range(n_cam)
                                             for j in range(max(0, i - 1), min(n_cam, i + 2))]
                               if st["frames"] > len(results) and adaptive is None else None)
    sdram = None
    if isinstance(sram, SdramModel):
        sram.finish()
        assert not sram.violations, f"{len(sram.violations)} SDRAM rules broken, first: {sram.violations[:3]}"
        assert sram.stats.late_refreshes == 0, f"{sram.stats.late_refreshes} refreshes late"
        sdram = dict(refreshes=sram.stats.refreshes, late_refreshes=sram.stats.late_refreshes)
    else:
        assert sram.error is None, sram.error
    bus.checker.check()
    if cfg.get("require_features"):
        # the configuration asks for features (a frame without any tests little); the closed loop may drive
        # one frame to none on its way
        assert all(r["features"] > 0 for r in results) if adaptive is None else \
            any(r["features"] for r in results), [r["features"] for r in results]
    write_report(cfg, dict(mode=mode, width=w, height=h, threshold=thr, frames=results, bit_exact=True,
                           model_params=mp, list_overflows=ovf, sdram=sdram, dense=dsets,
                           disp_frames=st["disp_frames"] if dense else None,
                           frame_clocks=st["frame_clocks"], frames_done=st["frames"], arb=arb,
                           arb_words=list(ARB_WORDS), total_ns=get_sim_time(unit="ns") - t_start,
                           camera_frame_pclk=timing.frame_pclk, axi=bus.checker.counts, last=last,
                           stages=stage_times(events, [r["start_ns"] for r in results])))


def dense_settings(cfg: dict) -> dict | None:
    """The dense model's keyword arguments for the top of ``cfg`` (None without the option): its
    ``disparities`` and ``paths`` (or the block's defaults), the DENSE register's reset values updated by
    ``dense_settings`` (what the bench writes), the top's fixed window and median."""
    if not cfg["params"].get("dense", False):
        return None
    from eyestereo.hdl.system.stereo_frontend import stereo_frontend as top
    from eyestereo.tools.regmap import REGMAP

    sig = inspect.signature(top).parameters
    out = {n: cfg["params"].get(n, sig[n].default) for n in ("disparities", "paths")}
    out.update({f.name: f.reset for f in REGMAP["DENSE"].fields})
    out.update(cfg.get("dense_settings") or {})
    for flag in ("lr_check", "subpixel"):
        out[flag] = bool(out[flag])
    return out


async def take_disparity(drv, amap, w: int, h: int, *, deadline_ns: float, pr, last, n_cam: int, model_of,
                         disparity_of):
    """Take the newest disparity map, read it and give it back (the host driver's ``take_disparity``); the stereo
    pair (i, j) whose model it equals, searched from the rectified pair ``pr`` of the same round outwards (a map
    may lag its pair or, the system going on, lead it), and moving on from ``last``. Returns the pair and the
    codes read (height x width)."""
    got = np.array(await drv.take_disparity(amap, timeout_clocks=int(max(deadline_ns, 2e6) / 10)),
                   np.int64).reshape(h, w)
    pairs = sorted(((i, j) for i in range(n_cam) for j in range(max(0, i - 1), min(n_cam, i + 2))),
                   key=lambda p: (abs(p[0] - pr[0]) + abs(p[1] - pr[1]), p))
    for p in pairs:
        if p >= last and np.array_equal(disparity_of(model_of(*p)), got):
            return p, got
    want = disparity_of(model_of(*pr))
    bad = np.argwhere(want != got)
    raise AssertionError(f"the disparity map read equals the model of no stereo pair sent; against the pair "
                         f"{pr} of the rectified images read: {len(bad)} codes differ, first {bad[:4].tolist()}")


def check_list_overflows(st: dict, results: list[dict], candidates: list[bool] | None) -> dict:
    """Check OVERFLOWS.list_overflows against the model; returns what was checked (for the report).

    What the counter counts (hdl/system/frontend_sequencer.py, register map OVERFLOWS): the frames the system
    *completed* since reset (feature_list's ``frame_done``, the FRAMES register) whose list was cut
    (feature_list's ``overflow``: more than ``max_features`` features, or one finding the list FIFO full,
    which the model never does). The frames the host read are known: their lists were compared with the
    model's, trailer and overflow flag included. When the system completed more (overlapped, continuous:
    it goes on while the host reads), the others' pairs are not known: ``candidates``, the model's flag of
    every stereo pair the bench considers, gives their count when all agree (a still scene), else the
    counter is only bounded by the read frames' count and that plus the unread frames."""
    done, got = int(st["frames"]), int(st["list_overflows"])
    read = sum(1 for r in results if r["overflow"])
    unread = done - len(results)
    assert unread >= 0, f"the host read {len(results)} frames, the system completed {done}"
    if unread == 0:
        rule, lo, hi = "the frames read", read, read
    elif candidates and len(set(map(bool, candidates))) == 1:
        n = read + unread * bool(candidates[0])
        rule, lo, hi = "the frames read and every candidate pair alike", n, n
    else:
        rule, lo, hi = "bounded: the unread frames' pairs are not known", read, read + unread
    assert lo <= got <= hi, (f"list_overflows {got}: the model's lists of the {done} completed frames give "
                             f"{lo if lo == hi else f'{lo}..{hi}'} ({rule}; {read} of the {len(results)} read)", st)
    return dict(counted=got, expected=[lo, hi], rule=rule, frames_done=done, frames_read=len(results))


def stage_times(events, starts) -> dict:
    """Mean stage times (us) from the probes: capture (start to the pair held; sequential), rectification
    (the rectifier's busy), lists (the rectifier's end to the feature list's frame_done)."""
    def rises(label, level=1):
        return [t for n, v, t in events if n == label and v == level]

    rb, rf, ld, ch = rises("rect_busy"), rises("rect_busy", 0), rises("list_done"), rises("cam_held")
    rect = [f - r for r, f in zip(rb, [x for x in rf if x > rb[0]])] if rb else []
    lists = []
    for f in rf:
        nxt = [t for t in ld if t > f]
        if nxt:
            lists.append(nxt[0] - f)
    capture = []
    for s0 in starts:
        nxt = [t for t in ch if t > s0]
        if nxt:
            capture.append(nxt[0] - s0)

    def mean(v):
        return round(sum(v) / len(v) / 1e3, 2) if v else None

    return dict(capture_us=mean(capture), rectify_us=mean(rect), lists_after_rectifier_us=mean(lists),
                rectified_frames=len(rect), list_done_ns=ld, rect_start_ns=rb)
