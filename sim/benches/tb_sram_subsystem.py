"""cocotb bench: sram_subsystem (arbiter + controller) with traffic on all six ports against the SRAM model,
or sdram_subsystem (arbiter + bridge + SDRAM controller) against the SDRAM model.

Agents (:mod:`eyestereo.sim.lib.sram_agents`) drive both cameras at their rate through FIFO models, the
rectified stereo stream, feature lists, the rectifier's fetch requests and the host's random accesses
at once; the bench plays the system's controller on the frame handshake, in the overlapped (double
buffered) or the sequential mode. The SRAM model checks the part's rules on every edge and logs every
access. Checks, online and after the run:

* every read returns the last word written to its address: fetch responses and the host's buffer reads
  against the frames the writers were given (rebuilt from the SRAM's write log: a read that meets a
  frame not completely written, or being overwritten, fails), the host's own area against its writes;
* every writer's words land in order, frame by frame from a buffer's base, matching the frames sent;
* the fetch reads hit exactly the addresses of the requests, in order;
* no camera FIFO overflows, the rectified writer loses no word;
* the arbiter's counters (status port) equal the words the bench saw moved, its published-frame counts
  the complete frames in the SRAM;
* nothing is left over: every agent idle, the SRAM model idle.

The memory is the config's ``memory`` (``"sram"`` or ``"sdram"``; default from the block's name). On the
SDRAM the part is the block's ``part`` parameter (the model reads the same spec, so a shortened power-up
wait is checked as such); the model starts before the reset ends (it checks the power-up sequence), every
access is logged as the SRAM's is, and the same checks run on those logs; besides them, no rule of the
part broken (:class:`~eyestereo.tools.sdram.SdramChip`, every edge) and no refresh late. The SRAM-only
bus figures (drive and idle cycles) are left out there.

The report (``report.json``) carries the measurements the benchmark script turns into docs/sram.md.
"""

from __future__ import annotations

import copy
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sdram_model import SdramModel
from eyestereo.sim.lib.sram_agents import CameraSource, FeatureSource, FetchMaster, HostMaster, Pin, StereoSource
from eyestereo.sim.lib.sram_model import SramModel, read_int
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.sram_arbiter import MASTERS, STAT, WRITERS, AddressMap, BufferHistory, fetch_addresses
from eyestereo.tools.sdram import ULX3S
from eyestereo.tools.sram import SramPart

PERIOD_NS = 10


class Controller:
    """The system's controller on the frame handshake (FrameControl ports ``ctl_*``), in ``mode``
    "overlapped" (cameras run, every consumer takes the newest frame when free) or "sequential" (arm the
    cameras for one frame each, run the fetch pass, then let the host read the results, repeat)."""

    def __init__(self, dut, mode, amap: AddressMap, fetch: FetchMaster, host: HostMaster, stat):
        self.dut = dut
        self.mode = mode
        self.amap = amap
        self.fetch, self.host = fetch, host
        names = ("cam_run", "cam_arm", "cam_want", "cam_release", "rect_want", "rect_release", "feat_want",
                 "feat_release")
        self.pin = {n: Pin(getattr(dut, f"ctl_{n}")) for n in names}
        self.stat_addr = Pin(dut.stat_addr)
        self.stat_data = dut.stat_data
        self.held = dict(cam=False, rect=False, feat=False)
        self.job = None          # the host's consumer job: ("rect"|"feat", phase)
        self.takes = dict(cam=0, rect=0, feat=0)
        self.arms = 0
        self.armed_wait = False
        self.stopped = False
        self.stat_query = None
        self.released = False
        self.early_release = False
        self.hold = False  # continuous fetching: keep the first pair until the end of the run
        self.fetching = True  # False: nobody takes camera pairs (no fetch traffic)
        self.wanting = False  # sequential: cam_want raised, the pair not taken yet

    def start(self):
        if self.mode == "overlapped":
            self.pin["cam_run"].set(3)
            self.pin["cam_want"].set(int(self.fetching))
            self.pin["rect_want"].set(1)
            self.pin["feat_want"].set(1)
        else:
            self.pin["cam_run"].set(0)

    def sample(self, clock):
        d = self.dut
        for n in ("cam_release", "rect_release", "feat_release", "cam_arm"):
            self.pin[n].set(0)
        cam_held = read_int(d.ctl_cam_held)
        if cam_held and not self.held["cam"]:
            self.released = False
            bufs = read_int(d.ctl_cam_buf)
            self.fetch.held = True
            self.fetch.start_pass((bufs & 1, bufs >> 1))
            self.takes["cam"] += 1
            self.wanting = False
            if self.mode == "sequential" or self.early_release:
                self.pin["cam_want"].set(0)
        self.held["cam"] = bool(cam_held)
        for k in ("rect", "feat"):
            h = read_int(getattr(d, f"ctl_{k}_held"))
            if h and not self.held[k]:
                self.takes[k] += 1
                if self.mode == "sequential":
                    self.pin[f"{k}_want"].set(0)
                buf = read_int(getattr(d, f"ctl_{k}_buf"))
                self._queue_job(k, buf)
            self.held[k] = bool(h)
        # the fetch pass
        if self.fetch.held:
            done = self.fetch.done_pass if self.fetch.mode == "frame" else (
                self.fetch.count >= self.fetch.min_requests and (self.stopped or (
                    not self.hold and (read_int(d.ctl_avail) & 3) == 3)))
            self.fetch.done_pass = done
            if self.early_release and self.held["cam"] and not self.released:
                # a consumer bug on purpose: release while still reading; the bench must then catch
                # reads of frames being overwritten
                self.pin["cam_release"].set(1)
                self.released = True
            if done and self.fetch.idle:
                self.fetch.held = False
                if not self.released:
                    self.pin["cam_release"].set(1)
                    self.released = True
                if self.mode == "sequential":
                    self.pin["rect_want"].set(1)
                    self.pin["feat_want"].set(1)
                elif self.early_release:
                    self.pin["cam_want"].set(int(self.fetching))
        # the host's consumer jobs
        if self.stat_query is not None:
            kind, buf, phase = self.stat_query
            if phase < 3:
                self.stat_query = (kind, buf, phase + 1)
            else:
                n = read_int(self.stat_data) & 0x7FFFFFFF
                base = self.amap.features(buf)
                self.host.read_buffer(range(base, base + n))
                self.job = ("feat", buf)
                self.stat_query = None
        if self.job is not None and self.host.idle and self.stat_query is None:
            kind = self.job[0]
            self.pin[f"{kind}_release"].set(1)
            self.job = None
        if self.job is None and self.stat_query is None and self.pending:
            self._start_job(*self.pending.pop(0))
        # sequential mode: arm both cameras when nothing is captured or held
        if self.mode == "sequential" and not self.stopped:
            avail = read_int(d.ctl_avail)
            # (the pair is taken a couple of clocks after cam_want: not held yet is not free yet)
            if not self.armed_wait and not self.wanting and not self.held["cam"] and not self.fetch.held:
                self.pin["cam_arm"].set(3)
                self.arms += 1
                self.armed_wait = True
            elif self.armed_wait and (avail & 3) == 3:
                self.pin["cam_want"].set(1)
                self.armed_wait = False
                self.wanting = True

    pending: list = []

    def _queue_job(self, kind, buf):
        self.pending = self.pending + [(kind, buf)]

    def _start_job(self, kind, buf):
        if kind == "rect":
            base = self.amap.rectified(buf)
            self.host.read_buffer(range(base, base + self.amap.frame))
            self.job = ("rect", buf)
        else:
            self.stat_addr.set(20 + buf)
            self.stat_query = ("feat", buf, 1)

    def stop(self):
        """The end of the run: take no new camera pair (finish the pass in progress)."""
        self.stopped = True
        self.pin["cam_want"].set(0)

    @property
    def idle(self) -> bool:
        return self.job is None and self.stat_query is None and not self.pending and not self.fetch.held


async def read_stat(dut, clk) -> dict[int, int]:
    out = {}
    for a in STAT:
        dut.stat_addr.value = a
        await ClockCycles(clk, 3)
        out[a] = read_int(dut.stat_data)
    return out


@cocotb.test()
async def subsystem_traffic(dut):
    cfg = load_config()
    p = cfg["params"]
    memory = cfg.get("memory", "sdram" if cfg.get("block") == "sdram_subsystem" else "sram")
    if memory not in ("sram", "sdram"):
        raise ValueError(f"config memory must be 'sram' or 'sdram', got {memory!r}")
    sdram = memory == "sdram"
    w, h = p.get("width", FRAME_WIDTH), p.get("height", FRAME_HEIGHT)
    amap = AddressMap(w, h, p.get("feature_words", 8192))
    seed = cfg.get("seed", 1)
    clk = dut.clk
    Clock(clk, PERIOD_NS, unit="ns").start()
    for name in ("cam0_valid", "cam1_valid", "fetch_req_valid", "rect_valid", "feat_valid", "host_req_valid",
                 "ctl_cam_run", "ctl_cam_arm", "ctl_cam_want", "ctl_cam_release", "ctl_rect_want",
                 "ctl_rect_release", "ctl_feat_want", "ctl_feat_release", "stat_addr"):
        getattr(dut, name).value = 0
    dut.rst.value = 1
    if sdram:
        # the model watches from the controller's first edge in reset: the whole power-up sequence
        # model_part: a board whose part differs from the one the block was built for (the negative tests)
        model = SdramModel(dut, clk, cfg.get("model_part", p.get("part", ULX3S)), prefix="sdram", period_ns=PERIOD_NS,
                           cas_latency=p.get("cas_latency", 2), record=True)
        await ClockCycles(clk, 2)
        model.start()
        await ClockCycles(clk, 1)
        dut.rst.value = 0
        # as the front end, start no traffic before the power-up sequence (the rectified stream has no
        # back-pressure: its words would be lost while the part cannot be written)
        ck = model.part.clocks(1000.0 / PERIOD_NS)
        for _ in range(ck.powerup + (model.part.init_refreshes + 2) * (ck.rfc + ck.rp) + 100):
            await RisingEdge(clk)
            if model.chip.ready:
                break
        assert model.chip.ready, f"the SDRAM's power-up sequence not complete {ck.powerup} clocks after reset"
        edge_now = model.edge_now
    else:
        await ClockCycles(clk, 3)
        dut.rst.value = 0
        await RisingEdge(clk)
        model = SramModel(dut, clk, SramPart(p.get("kind", "nobl"), p.get("read_latency", 2)), log=True)
        model.start()
        edge_now = model._edge_number

    cams = [CameraSource(dut, f"cam{c}", random.Random(seed * 10 + c), width=w, height=h,
                         rate=cfg.get("cam_rate", 0.09), depth=cfg.get("cam_fifo", 64),
                         hblank=cfg.get("hblank", 0), vblank=cfg.get("vblank", 0)) for c in (0, 1)]
    for c in cams:
        c.limit = cfg.get("cam_frames")
    stereo = StereoSource(dut, "rect", random.Random(seed * 10 + 2), width=w, height=h,
                          duty=cfg.get("rect_duty", 0.1), frames=cfg.get("rect_frames"),
                          token_after=cfg.get("token_after"))
    feats = FeatureSource(dut, "feat", random.Random(seed * 10 + 3), duty=cfg.get("feat_duty", 0.05),
                          max_len=cfg.get("feat_max", 40), lists=cfg.get("feat_lists"))
    fetch = FetchMaster(dut, "fetch", random.Random(seed * 10 + 4), width=w, height=h,
                        duty=cfg.get("fetch_duty", 1.0), mode=cfg.get("fetch_mode", "frame"),
                        full_mask=cfg.get("full_mask", 0.8))
    host = HostMaster(dut, "host", random.Random(seed * 10 + 5), area=(amap.host_base, amap.words),
                      duty=cfg.get("host_duty", 0.05))
    host.job_rate = cfg.get("host_read_rate", 1.0)
    ctl = Controller(dut, cfg.get("mode", "overlapped"), amap, fetch, host, None)
    ctl.early_release = bool(cfg.get("early_release"))
    ctl.hold = bool(cfg.get("hold"))
    ctl.fetching = cfg.get("fetch", True)
    for a, on in (("cam", cfg.get("cams", True)), ("rect", cfg.get("rect", True)), ("feat", cfg.get("feat", True))):
        if not on:
            if a == "cam":
                for c in cams:
                    c.enabled = False
            elif a == "rect":
                stereo.enabled = False
            else:
                feats.enabled = False
    ctl.start()
    agents = [*cams, stereo, feats, fetch, host]

    clocks = cfg.get("clocks", 20000)
    window = cfg.get("window", 0)  # measurements over the clocks window..clocks (after a warm-up)
    clock = 0
    fetch_held_clocks = 0
    snap = {}
    draining = False
    drain_limit = clocks + cfg.get("drain", 20000 + 20 * w * h)
    while True:
        await RisingEdge(clk)
        for a in agents:
            a.sample(clock)
        ctl.sample(clock)
        if fetch.held:
            fetch_held_clocks += 1
        if cfg.get("debug") and clock >= cfg["debug"]:
            def g(n):
                return read_int(getattr(dut, "sram_arbiter0_" + n))
            print("DBG", clock, *[f"{n}={g(n)}" for n in cfg.get("debug_signals", [])], "pend", len(fetch.pending),
                  "held", fetch.held, ctl.held)
        clock += 1
        if clock in (window, clocks) and not draining:
            snap[clock] = dict(edge=edge_now(), stats=copy.deepcopy(vars(model.chip.stats)),
                               cam_fill=[c.max_fill for c in cams], held=fetch_held_clocks)
        if clock == clocks and not draining:
            draining = True
            for c in cams:
                c.stop()
            stereo.enabled = False
            feats.enabled = False
            host.duty = 0.0
            ctl.stop()
        for a in agents:
            a.drive(clock)
        if draining and all(a.idle for a in (*cams, stereo, feats, host, fetch)) and ctl.idle \
                and not (fetch.held or ctl.held["cam"] and fetch.mode == "frame" and not fetch.done_pass):
            break
        assert clock < drain_limit, (f"not drained after {clock} clocks: cameras "
                                     f"{[len(c.fifo) for c in cams]} words waiting, stereo "
                                     f"{len(stereo.beats)} beats, features {len(feats.words)} words, fetch "
                                     f"{len(fetch.pending)} responses, host {len(host.expect)} responses")
        if not cfg.get("allow_overflow"):
            for c in cams:
                assert not c.overflows, f"camera FIFO overflow at clock {c.overflows[0]} (depth {c.depth})"
    for name in ("cam0_valid", "cam1_valid", "fetch_req_valid", "rect_valid", "feat_valid", "host_req_valid"):
        getattr(dut, name).value = 0
    # let the writers flush their last words and the pipeline empty
    await ClockCycles(clk, 64)
    assert model.chip.idle, (f"the {memory.upper()} model still has {model.chip.pending()}; last writes "
                             f"{[(e, hex(a), hex(d)) for e, a, d in model.chip.write_log[-6:]]}, clock {clock}; "
                             f"{sum(1 for e, a, d in model.chip.write_log if a in (4 * amap.frame, 5 * amap.frame))} "
                             f"base writes of {len(model.chip.write_log)}; {stereo.sent[-1][:3]}, {len(stereo.sent)}")
    stat = await read_stat(dut, clk)
    assert all(v is not None for v in stat.values()), f"undefined status words: {stat}"
    if sdram:
        model.finish()
        assert not model.violations, f"{len(model.violations)} SDRAM rules broken: {model.violations[:4]}"
        assert model.stats.late_refreshes == 0, f"{model.stats.late_refreshes} refreshes late"

    # ---- offline checks against the SRAM's logs ------------------------------------------------------
    wl, rl = model.chip.write_log, model.chip.read_log
    cap = amap.feature_words
    # (a camera FIFO that overflowed -- allowed only when measuring the margin -- lost words: its frames
    # no longer match what was sent, so the camera data checks are skipped then; everything else holds)
    lossy = any(c.overflows for c in cams)
    # what each writer (MASTER_TABLE's writers, one double buffer each) was given
    sent = dict(cam0=cams[0].frames, cam1=cams[1].frames, rect=stereo.sent, feat=feats.sent)

    def stored_list(lst):
        return list(lst) if len(lst) <= cap else list(lst[:cap - 1]) + [lst[-1]]

    hist = {k: BufferHistory(k, amap.bases(k), amap.size(k), [] if lossy and k in ("cam0", "cam1") else wl, sent[k],
                             stored=stored_list if k == "feat" else None) for k in WRITERS}
    regions = {k: [(b, b + hi.size) for b in hi.bases] for k, hi in hist.items()}

    def region_of(addr):
        for k, rs in regions.items():
            if any(lo <= addr < hi for lo, hi in rs):
                return k
        return "host" if addr >= amap.host_base else None

    writes_by = {k: 0 for k in (*hist, "host")}
    for e, a, _ in wl:
        r = region_of(a)
        assert r is not None, f"write of edge {e} to {a:#07x} hits no buffer and not the host area"
        writes_by[r] += 1
    # fetch reads: the addresses of the requests, in order, and the words of complete frames
    cam_reads = [(e, a) for e, a in rl if region_of(a) in ("cam0", "cam1")]
    want = []
    for _, x, y, c, m, bufs in fetch.requests:
        want += [a for _, a in fetch_addresses(amap, amap.camera(c, bufs[c]), x, y, m)]
    assert [a for _, a in cam_reads] == want, next(
        f"fetch read {i} went to {g:#07x}, the request asks {e:#07x}"
        for i, (g, e) in enumerate(zip([a for _, a in cam_reads] + [None] * len(want), want)) if g != e)
    assert len(fetch.responses) == len(want), f"{len(fetch.responses)} fetch responses for {len(want)} reads"
    for i, ((e, a), (_, _idx, data)) in enumerate(zip(cam_reads, fetch.responses)):
        if lossy:
            break
        k = region_of(a)
        expect = hist[k].word_at(e, a) & 0xFF
        assert data == expect, f"fetch response {i} (read of {a:#07x} at edge {e}): {data:#04x}, expected {expect:#04x}"
    # host reads of the rectified and feature buffers
    buf_reads = [(e, a) for e, a in rl if region_of(a) in ("rect", "feat")]
    assert [a for _, a in buf_reads] == [a for a, _ in host.buffer_reads], "host buffer reads out of order"
    for (e, a), (_, data) in zip(buf_reads, host.buffer_reads):
        expect = hist[region_of(a)].word_at(e, a)
        assert data == expect, f"host read of {a:#07x} at edge {e}: {data:#06x}, expected {expect:#06x}"
    # counters
    moved = dict(writes_by, fetch=len(cam_reads), host=host.accesses)
    for i, m in enumerate(MASTERS):
        assert stat[i] == moved[m] & 0xFFFFFFFF, \
            f"status word {i} ({STAT[i]}) is {stat[i]}, the bench counted {moved[m]}"
    for i, k in enumerate(WRITERS):
        if lossy and k in ("cam0", "cam1"):
            continue
        published = stat[2 * len(MASTERS) + 1 + i] & 0xFFFF
        complete = len(hist[k].complete_runs())
        assert published == complete, \
            f"{k}: {published} frames published, {complete} complete in the {memory.upper()}"
    assert stat[19] >> 16 == 0, f"the rectified writer lost {stat[19] >> 16} words"
    for k in ("cam0", "cam1")[:0 if lossy else 2]:
        runs = hist[k].runs
        assert not runs or runs[-1].complete, f"{k}: the last frame was not finished"
    if not cfg.get("allow_overflow"):
        for c in cams:
            assert not c.overflows

    st = model.chip.stats
    total = clock
    measured = None
    if window and window in snap and clocks in snap:
        e0, e1 = snap[window]["edge"], snap[clocks]["edge"]
        per = {m: 0 for m in MASTERS}
        for e, a, _ in wl:
            if e0 <= e < e1:
                per[region_of(a)] += 1
        for e, a in rl:
            if e0 <= e < e1:
                per["fetch" if region_of(a) in ("cam0", "cam1") else "host"] += 1
        s0, s1 = snap[window]["stats"], snap[clocks]["stats"]
        n_clk = e1 - e0
        bus_keys = (("read_words", "write_words", "refreshes") if sdram else
                    ("reads", "writes", "sram_drive_cycles", "fpga_drive_cycles", "idle_bus_cycles"))
        measured = dict(clocks=n_clk, words=per, words_per_clock={m: per[m] / n_clk for m in MASTERS},
                        total_per_clock=sum(per.values()) / n_clk,
                        bus={k: (s1[k] - s0[k]) / n_clk for k in bus_keys},
                        fetch_held=snap[clocks]["held"] - snap[window]["held"],
                        cam_max_fill=[c.max_fill for c in cams])
    report = dict(
        clocks=total, edges=st.edges, **{memory: vars(st)}, stat={STAT[k]: v for k, v in stat.items()},
        moved=moved, waited={m: stat[len(MASTERS) + i] for i, m in enumerate(MASTERS)},
        frames={k: len(hist[k].complete_runs()) for k in hist},
        frames_sent={k: len(sent[k]) for k in WRITERS},
        cam_max_fill=[c.max_fill for c in cams], cam_fifo=cams[0].depth,
        fetch_requests=len(fetch.requests), fetch_reads=len(cam_reads), fetch_held_clocks=fetch_held_clocks,
        fetch_latency=[fetch.first_rsp[i] - fetch.requests[i][0] for i in sorted(fetch.first_rsp)][:2000],
        takes=ctl.takes, arms=ctl.arms, host_area_reads=host.area_reads, host_buffer_reads=len(host.buffer_reads),
        measured=measured, cam_overflow=[bool(c.overflows) for c in cams], host_latency=host.latency[:2000])
    write_report(cfg, report)
