"""cocotb bench: the fault soak of the complete front end (issue 25), on the fast harness.

The top is :mod:`eyestereo.sim.harnesses.frontend_harness`. The cameras play a long scripted sequence of distinct
frames (a random scene moving a pixel per frame, the right view shifted) with the camera faults of
:mod:`eyestereo.sim.lib.soak` at ``camera_fault_rate`` per camera frame; the host reads ``frames`` frames, and
after a frame it injects a host fault with probability ``host_fault_rate`` (a pause before releasing the
buffers, a rewrite of k and the thresholds while a frame runs, a mode change, a reset of one clock domain).

Every frame read is identified and checked: its rectified pair, through the SRAM part's backdoor, must equal the
rectification model of one left camera frame (the low bytes) and one right camera frame (the high bytes) that
were sent whole (never one a fault broke), the pair moving on; its feature list must equal the model's list of
that pair with the Harris settings in effect (or, for the two frames read after a settings write, the old ones
or neither: the write lands in a frame in flight; for the frame read after a Harris-domain reset, neither). Each
wait has a deadline (the watchdog: a hang fails the run with the state it hung in). At the end: DROPPED per
camera equals the broken frames played (within the camera resets' bound), OVERFLOWS.harris_overflows within
the Harris resets' bound, the SRAM part saw no broken rule, every register access answered OKAY.

The report lists every fault injected (kind, where, when), each frame read, and per fault kind the count and
the longest recovery (camera frames from the end of the fault to the next frame read); with ``coverage`` the
functional coverage (:mod:`eyestereo.sim.lib.soak_coverage`) is written beside it.
"""

from __future__ import annotations

import random
import time

import cocotb
import numpy as np
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, Timer

from eyestereo.sim.lib import soak_coverage as cov
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.fast_system import FastTB, sram_rules
from eyestereo.sim.lib.frontend_model import choose_thresholds, stereo_frames
from eyestereo.sim.lib.soak import BREAKING, CAMERA_FAULTS, FAULTS, HOST_FAULTS, camera_runs, plan_cameras, \
    settings_pair
from eyestereo.tools.constants import K_CODE_DEFAULT
from eyestereo.tools.models import rectifier as rect_model
from eyestereo.tools.models import stereo_frontend as model

RECOVERY_LIMIT = 4.0  # camera frames from the end of a fault to the next frame read


class Soak:
    """The soak's bookkeeping: the frames sent, their models, the faults, the settings in effect."""

    def __init__(self, tb: FastTB, frames, thr: int):
        self.tb, self.frames = tb, frames
        self.rect = {}
        self.lists = {}
        self.settings = settings_pair(thr, K_CODE_DEFAULT)
        self.cur, self.prev = 0, 0
        self.reads_since_write = 99
        self.harris_reset_pending = False
        self.events: list[dict] = []
        self.mixed = self.cut = 0

    def rect_of(self, i: int):
        if i not in self.rect:
            tb = self.tb
            self.rect[i] = rect_model.rectifier(tb.cal, model.grey(self.frames[i][0]), model.grey(self.frames[i][1]),
                                                tb.mp["frac"])
        return self.rect[i]

    def identify(self, img: np.ndarray, side: int, last: int) -> int | None:
        n = len(self.frames)
        for i in list(range(max(0, last), n)) + list(range(0, max(0, last))):
            if np.array_equal(self.rect_of(i)[side], img):
                return i
        return None

    def list_of(self, i: int, j: int, s: int) -> list[int]:
        key = (i, j, s)
        if key not in self.lists:
            st = self.settings[s]
            self.lists[key] = model.stereo_frontend(self.tb.cal, self.frames[i][0], self.frames[j][1], st["k"],
                                                    ([st["thr"]] * 16, [st["thr"]] * 16), **self.tb.mp)["list_words"]
        return self.lists[key]

    def event(self, kind: str, **kw) -> dict:
        e = dict(kind=kind, t_ns=get_sim_time(unit="ns"), **kw)
        self.events.append(e)
        return e


async def _host_reads(drv, tb, rect: np.ndarray, rect_buf: int, rng: random.Random) -> None:
    """What a host reads besides the frames (the coverage of the register map), and a few words of the rectified
    pair through the bus, compared with what the backdoor gave (the same words; the buffer is still held)."""
    await drv.read("FEATURES")
    await drv.feature_counts()
    await drv.arbiter()
    await drv.read_thresholds("THR_LEFT")
    await drv.read_thresholds("THR_RIGHT")
    for reg in ("K_LEFT", "K_RIGHT", "CTRL", "GEOMETRY"):
        await drv.read(reg)
    a = rng.randrange(rect.size - 4)
    got = await drv.read_sram_words(tb.amap.rectified(rect_buf) + a, 4)
    assert got == rect.reshape(-1)[a:a + 4].tolist(), \
        f"the bus reads {got} at word {a} of the rectified pair, the backdoor {rect.reshape(-1)[a:a + 4].tolist()}"


async def pulse_reset(sig, clk_period_ps: int, after_ns: float, cycles: int = 8) -> None:
    await Timer(int(after_ns), unit="ns")
    sig.value = 1
    await Timer(cycles * clk_period_ps, unit="ps")
    sig.value = 0


@cocotb.test()
async def soak(dut):
    cfg = load_config()
    tb = FastTB(dut, cfg)
    w, h, drv, timing = tb.w, tb.h, tb.drv, tb.timing
    rng = random.Random(cfg.get("seed", 1))
    mode = cfg.get("mode", "overlapped")
    n_host = int(cfg["frames"])
    cam_rate, host_rate = float(cfg.get("camera_fault_rate", 0.1)), float(cfg.get("host_fault_rate", 0.2))
    cam_kinds = tuple(cfg.get("camera_faults", CAMERA_FAULTS))
    host_kinds = tuple(cfg.get("host_faults", HOST_FAULTS))
    for k in cam_kinds + host_kinds:
        if k not in FAULTS:
            raise ValueError(f"unknown fault kind {k!r}: {', '.join(FAULTS)}")
    # camera frames: a frame read takes up to ~3 camera frames (sequential, faults), the late starts more
    n_cam = int(cfg.get("camera_frames") or 4 * n_host + 12)
    frames = stereo_frames(f"shift:{cfg.get('scene_seed', 3)}", n_cam, w, h)
    thr = cfg["threshold"] if cfg.get("threshold") is not None else \
        choose_thresholds(tb.cal, frames, K_CODE_DEFAULT, cfg.get("target", 40), tb.mp)
    plans = plan_cameras(n_cam, cam_rate if cam_kinds else 0.0, timing, rng, kinds=cam_kinds or CAMERA_FAULTS,
                         forced=cfg.get("camera_faults_at", ()))
    host_at = {int(k): v for k, v in cfg.get("host_faults_at", {}).items()}  # host frame -> fault kind (forced)
    for k in host_at.values():
        if k not in HOST_FAULTS:
            raise ValueError(f"host_faults_at: {k!r} is not a host fault ({', '.join(HOST_FAULTS)})")
    lead = int(timing.frame_pclk * cfg.get("late_right", 0.0))
    (runs_l, starts_l), (runs_r, starts_r) = (camera_runs([f[0] for f in frames], timing, plans[0]),
                                              camera_runs([f[1] for f in frames], timing, plans[1], lead=lead))
    sk = Soak(tb, frames, thr)
    periods = [2 * int(round(1e6 / mhz / 2)) for mhz in tb.mhz]  # ps
    cam_ns = tb.camera_ns()
    cov.sample_run(f"{w}x{h}", cov.clock_ratio(*tb.mhz))
    tb.bus.on_access = lambda a, op: cov.sample_register(cov.register_of(a), op)
    modes = [(0.0, mode)]  # (time, mode from then on): the mode a camera fault met
    await tb.start(runs=(runs_l, runs_r))
    await drv.check_id()
    assert await drv.geometry() == (w, h)
    s0 = sk.settings[0]
    await drv.configure(mode=mode, continuous=mode == "overlapped", k_left=s0["k"], k_right=s0["k"],
                        thresholds_left=[s0["thr"]] * 16, thresholds_right=[s0["thr"]] * 16)
    await ClockCycles(dut.clk, 50)
    dut.cam_go.value = 1
    t_go = get_sim_time(unit="ns")
    wall0 = time.time()
    poll = cfg.get("poll_clocks", 2000)
    # every wait's deadline (the watchdog): a late start (2 frames), a broken frame after it, a whole frame and its
    # rectification, with margin
    settle = 5.5
    deadline_clocks = int(settle * cam_ns / 10) + 40 * w * h

    def recent(now: float) -> str:
        """The faults of the last few camera frames before ``now`` (for a hang's message)."""
        out = [e for e in sk.events if e["t_ns"] > now - 12 * cam_ns]
        for c, (plan, starts, per) in enumerate(((plans[0], starts_l, periods[0]), (plans[1], starts_r, periods[1]))):
            out += [dict(camera="lr"[c], frame=f, kind=k, t_ns=round(t_go + starts[f] * per / 1e3))
                    for f, (k, _) in plan.faults.items() if now - 12 * cam_ns < t_go + starts[f] * per / 1e3 < now]
        played = [int(dut.cam_l_samples.value), int(dut.cam_r_samples.value)]
        at = [sum(1 for x in st if x <= p) - 1 for st, p in ((starts_l, played[0]), (starts_r, played[1]))]
        out.sort(key=lambda e: e["t_ns"])
        return f"faults in the last 12 camera frames: {out}; the cameras at frames {at}"
    async def until_idle(what: str) -> None:
        """Wait until busy falls after a stop (the watchdog: ``settle`` camera frames)."""
        dl = get_sim_time(unit="ns") + settle * cam_ns
        while (st := await drv.status())["busy"]:
            assert get_sim_time(unit="ns") < dl, f"hang: busy stays high after {what}: {st}; " \
                f"{recent(get_sim_time(unit='ns'))}"
            await tb.bus.wait(poll)

    if mode == "overlapped":
        await drv.start()
    reads, last = [], (-1, -1)
    pending_write = False
    restarts = 0  # sequential starts given again after the list watchdog gave a frame up
    resets = dict(cam_l=0, cam_r=0, harris=0)
    for n in range(n_host):
        if mode == "sequential":
            await drv.start()
        if pending_write:  # the settings change while this frame runs
            sk.prev, sk.cur = sk.cur, 1 - sk.cur
            st = sk.settings[sk.cur]
            await drv.configure(mode=mode, continuous=mode == "overlapped", k_left=st["k"], k_right=st["k"],
                                thresholds_left=[st["thr"]] * 16, thresholds_right=[st["thr"]] * 16)
            sk.reads_since_write = 0
            pending_write = False
        before = await drv.read("FRAMES")
        lost0 = await drv.read("LOST")
        dl = get_sim_time(unit="ns") + deadline_clocks * 10
        while await drv.read("FRAMES") == before:
            if mode == "sequential" and await drv.read("LOST") != lost0 and not (await drv.status())["busy"]:
                # the list watchdog gave this frame up (a Harris reset cut it): the start is over, start again
                lost0 = await drv.read("LOST")
                restarts += 1
                await drv.start()
            if get_sim_time(unit="ns") > dl:
                raise AssertionError(f"hang: frame {n} never came (FRAMES stays {before}); status "
                                     f"{await drv.status()}; {recent(get_sim_time(unit='ns'))}")
            await tb.bus.wait(poll)
        await drv.set(rect_want=1, feat_want=1)
        dl = get_sim_time(unit="ns") + settle * cam_ns
        while not ((stt := await drv.status())["rect_held"] and stt["feat_held"]):
            assert get_sim_time(unit="ns") < dl, f"hang: frame {n}: the host never got the pair and lists ({stt}); " \
                f"{recent(get_sim_time(unit='ns'))}"
            await tb.bus.wait(poll // 4)
        await drv.set(rect_want=0, feat_want=0)
        t_read = get_sim_time(unit="ns")
        rect = (await tb.backdoor.read(tb.amap.rectified(stt["rect_buf"]), w * h)).reshape(h, w)
        lw = (await tb.backdoor.read(tb.amap.features(stt["feat_buf"]), tb.amap.feature_words)).tolist()
        host_fault = rng.choice(host_kinds) if host_kinds and rng.random() < host_rate else None
        host_fault = host_at.get(n, host_fault)
        if host_fault == "host_pause":
            pause = rng.uniform(1.0, 3.0) * cam_ns
            sk.event("host_pause", frames=round(pause / cam_ns, 2), mode=mode, end_ns=get_sim_time(unit="ns") + pause)
            cov.sample_pause(pause / cam_ns)
            await Timer(int(pause), unit="ns")
        if n % 10 == 0:  # now and then the registers a host reads besides, and a few words through the bus
            await _host_reads(drv, tb, rect, stt["rect_buf"], rng)
        await drv.pulse("rect_release", "feat_release")
        for level in (int(dut.cam_l_fifo_max.value), int(dut.cam_r_fifo_max.value)):
            cov.sample_fifo(level)
        dut.fifo_clear.value = n % 2 == 0
        # identify: the left frame from the low bytes, the right from the high bytes
        i = sk.identify(rect & 0xFF, 0, last[0])
        j = sk.identify(rect >> 8, 1, last[1])
        assert i is not None and j is not None, \
            f"frame {n}: the rectified pair read is the model of no camera frame sent (left {i}, right {j})"
        for side, f, plan in (("left", i, plans[0]), ("right", j, plans[1])):
            assert f not in plan.broken(), f"frame {n}: the {side} camera frame {f} was broken ({plan.faults[f]}) " \
                                           "but was read"
        # a camera buffer is taken once and a rectified pair read once: both frames move on
        assert i > last[0] and j > last[1], f"frame {n}: pair {(i, j)} after {last}"
        ends = [a for a in range(0, len(lw), 2) if lw[a] == 0xFFFF]
        assert ends, f"frame {n}: no list trailer in the feature buffer"
        lw = lw[:ends[0] + 2]
        verdict = "exact"
        if lw != sk.list_of(i, j, sk.cur):
            if sk.reads_since_write < 2 and lw == sk.list_of(i, j, sk.prev):
                verdict = "old settings"
            elif sk.reads_since_write < 2:
                verdict = "mixed settings"
                sk.mixed += 1
            elif sk.harris_reset_pending:
                verdict = "cut by the Harris reset"
                sk.cut += 1
            else:
                raise AssertionError(f"frame {n}: the list of pair {(i, j)} ({len(lw)} words) is not the model's "
                                     f"({len(sk.list_of(i, j, sk.cur))} words) with the settings in effect; "
                                     f"first words {lw[:6]}, the model's {sk.list_of(i, j, sk.cur)[:6]}; status "
                                     f"{await drv.status()}; {recent(get_sim_time(unit='ns'))}")
        sk.reads_since_write += 1
        sk.harris_reset_pending = False
        reads.append(dict(n=n, pair=[i, j], mode=mode, t_ns=t_read, verdict=verdict,
                          features=(len(lw) - 2) // 2))
        last = (i, j)
        if n % 50 == 0 or n == n_host - 1:
            dut._log.info(f"frame {n}: pair {(i, j)} {verdict}, {t_read / 1e6:.2f} ms simulated, "
                          f"wall {time.time() - wall0:.1f} s, {len(sk.events)} host faults")
        # the host's faults for the next frame
        if host_fault == "settings_write":
            sk.event("settings_write", mode=mode, to=1 - sk.cur)
            pending_write = True
        elif host_fault == "mode_change":
            await drv.stop()
            await until_idle("mode change")
            new = "sequential" if mode == "overlapped" else "overlapped"
            sk.event("mode_change", mode=mode, to=new)
            mode = new
            modes.append((get_sim_time(unit="ns"), mode))
            await drv.configure(mode=mode, continuous=mode == "overlapped")
            if mode == "overlapped":
                await drv.start()
        elif host_fault in ("reset_camera", "reset_harris"):
            after = rng.uniform(0, cam_ns)
            if host_fault == "reset_camera":
                side = rng.choice("lr")
                resets[f"cam_{side}"] += 1
                sk.event("reset_camera", mode=mode, camera=side, at_ns=get_sim_time(unit="ns") + after)
                cocotb.start_soon(pulse_reset(getattr(dut, f"wrst_{side}"), periods["lr".index(side)], after))
            else:
                resets["harris"] += 1
                sk.harris_reset_pending = True
                sk.event("reset_harris", mode=mode, at_ns=get_sim_time(unit="ns") + after)
                cocotb.start_soon(pulse_reset(dut.hrst, int(round(1e6 / cfg.get("harris_mhz", 50.0))), after))
    if mode == "overlapped":
        await drv.stop()
    await until_idle("the final stop")
    stt = await drv.status()
    t_end = get_sim_time(unit="ns")
    # the camera faults played: a frame whose schedule began before the end (its samples from go on)
    played = [int(dut.cam_l_samples.value), int(dut.cam_r_samples.value)]
    cam_faults, dropped_want = [], []
    for c, (plan, starts) in enumerate(((plans[0], starts_l), (plans[1], starts_r))):
        started = [f for f in plan.faults if starts[f] < played[c]]
        whole = [f for f in started if f + 1 < len(starts) and starts[f + 1] <= played[c]]
        lo = sum(1 for f in whole if plan.faults[f][0] in BREAKING)
        hi = sum(1 for f in started if plan.faults[f][0] in BREAKING) + resets["cam_" + "lr"[c]]
        dropped_want.append((lo, hi))
        for f in started:
            kind, d = plan.faults[f]
            t0 = t_go + starts[f] * periods[c] / 1e3
            t1 = t_go + (starts[f + 1] if f + 1 < len(starts) else played[c]) * periods[c] / 1e3
            cam_faults.append(dict(kind=kind, camera="lr"[c], frame=f, t_ns=t0, end_ns=t1, **d))
    got_dropped = (stt["dropped_left"], stt["dropped_right"])
    for c in range(2):
        lo, hi = dropped_want[c]
        assert lo <= got_dropped[c] <= hi, f"DROPPED of camera {'lr'[c]}: {got_dropped[c]}, the faults give {lo}..{hi}"
    assert 0 <= stt["harris_overflows"] <= resets["harris"], \
        f"harris_overflows {stt['harris_overflows']} with {resets['harris']} Harris resets"
    assert 0 <= stt["lists_lost"] <= resets["harris"], \
        f"lists_lost {stt['lists_lost']} with {resets['harris']} Harris resets (the list watchdog gives up only those)"
    await Timer(100, unit="ns")
    sram = sram_rules(dut)
    assert sram["violations"] == 0, f"the SRAM part saw {sram['violations']} broken rules, first {sram['first']}"
    # recovery: camera frames from each fault's end to the next frame read
    done = [r["t_ns"] for r in reads]
    faults = cam_faults + sk.events
    table = {}
    starts = sorted(f.get("at_ns", f["t_ns"]) for f in faults)
    for f in faults:
        t0 = f.get("at_ns", f["t_ns"])
        end = f.get("end_ns", t0)
        nxt = [t for t in done if t > end]
        rec = (nxt[0] - end) / cam_ns if nxt else None
        f["recovery_frames"] = None if rec is None else round(rec, 2)
        # isolated: no other fault begins between this one's start and the frame read after it (else the
        # recovery is the sum of several)
        f["isolated"] = bool(nxt) and sum(1 for t in starts if t0 <= t <= nxt[0]) == 1
        row = table.setdefault(f["kind"], dict(count=0, recovered=0, isolated=0, worst=0.0, worst_any=0.0))
        row["count"] += 1
        if rec is not None:
            row["recovered"] += 1
            row["worst_any"] = max(row["worst_any"], round(rec, 2))
            if f["isolated"]:
                row["isolated"] += 1
                row["worst"] = max(row["worst"], round(rec, 2))
    late = [f for f in faults if f["isolated"] and f["recovery_frames"] > RECOVERY_LIMIT]
    for f in faults:  # coverage: each fault in the mode it met
        t0 = f.get("at_ns", f["t_ns"])
        cov.sample_fault(f["kind"], f.get("mode") or [m for t, m in modes if t <= t0][-1])
        if f["kind"] == "pclk_stop":
            cov.sample_stop(f["n"])
        elif f["kind"] == "late_start":
            cov.sample_late(f["n"] / timing.frame_pclk)
    cov.export("coverage.yml")
    assert not late, f"{len(late)} isolated faults took longer than {RECOVERY_LIMIT} frames to recover: {late[:3]}"
    frames_played = [sum(1 for x in st if x <= p) for st, p in ((starts_l, played[0]), (starts_r, played[1]))]
    write_report(cfg, dict(frames_read=len(reads), width=w, height=h, camera_samples_played=played,
                           camera_frames_played=frames_played,
                           frames_done=stt["frames"], dropped=list(got_dropped), dropped_expected=dropped_want,
                           harris_overflows=stt["harris_overflows"], lists_lost=stt["lists_lost"], resets=resets,
                           restarts=restarts, mixed=sk.mixed, cut=sk.cut,
                           faults=table, sram=sram, sim_ns=t_end, wall_s=round(time.time() - wall0, 1),
                           verdicts={v: sum(r["verdict"] == v for r in reads) for v in {r["verdict"] for r in reads}},
                           reads=reads, fault_events=faults, host_transfers=tb.bus.transfers))
