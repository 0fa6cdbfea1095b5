"""cocotb bench: feature_list against :func:`eyestereo.tools.models.feature_list.feature_list`, word for word.

Stimulus: stereo frames of corner flags (random at a given density, or harris_stereo model flags of
random images), beats with random idle cycles (``duty``), optionally a partial frame cut by a reset
token, then frames back to back; the queue consumer takes words with probability ``ready`` per clock.
Checked: the queue words of every frame equal the model's list (features in stream order, then the
trailer with count and overflow), the token's word where the token was, nothing else and nothing left
in the FIFO at the end; after each ``frame_done`` the published totals, overflow flag and every
(camera, block) count equal the model's; no undefined bit on a valid word or a published count.
"""

from __future__ import annotations

import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from eyestereo.sim.lib.bench import load_config, make_frame, write_report
from eyestereo.sim.lib.stream import BeatSource, IdleGenerator
from eyestereo.tools.constants import K_CODE_DEFAULT, NMS_DEFAULT
from eyestereo.tools.models import feature_list as model
from eyestereo.tools.models import harris_stereo as harris_model
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN

PERIOD_NS = 10


def flag_pair(spec: str, w: int, h: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """``flags:DENSITY`` random flags; ``harris:SEED`` the stereo Harris model's flags of random images.

    The Harris model runs with k code 10 and a 3x3 non-maximum suppression.
    """
    kind, _, arg = spec.partition(":")
    if kind == "flags":
        d = float(arg)
        return (rng.random((h, w)) < d).astype(np.int64), (rng.random((h, w)) < d).astype(np.int64)
    if kind == "harris":
        left, right = make_frame(f"random:{arg}", w, h), make_frame(f"random:{int(arg) + 1}", w, h)
        fl, fr, _ = harris_model.harris_stereo(left, right, K_CODE_DEFAULT, [0], blocks=(1, 1), nms=NMS_DEFAULT)
        return fl, fr
    raise ValueError(f"unknown flag stimulus {spec!r}")


class Consumer:
    def __init__(self, dut, ready: float, seed: int):
        self.dut = dut
        self.ready = ready
        self.rng = random.Random(seed)
        self.words: list[tuple] = []
        self.cycles: list[int] = []  # cycle each word was on the port (taken at the next edge)
        self.undefined: list[str] = []
        self.hold = False  # ready held low (a consumer stalled across several frame ends)
        dut.source_ready.value = 0
        cocotb.start_soon(self._run())

    async def _run(self):
        dut = self.dut
        while True:
            await RisingEdge(dut.clk)
            r = int(not self.hold and (self.ready >= 1.0 or self.rng.random() < self.ready))
            dut.source_ready.value = r
            await ReadOnly()
            v = dut.source_valid.value
            if not v.is_resolvable:
                self.undefined.append("source_valid undefined")
                continue
            if int(v) and r:
                d, l, f = dut.source_data.value, dut.source_eol.value, dut.source_eof.value
                if not (d.is_resolvable and l.is_resolvable and f.is_resolvable):
                    self.undefined.append(f"word {len(self.words)} undefined: {d} {l} {f}")
                    continue
                self.words.append((int(d), bool(int(l)), bool(int(f))))
                from cocotb.utils import get_sim_time

                self.cycles.append(int(get_sim_time(unit="ns") // PERIOD_NS))


@cocotb.test()
async def feature_list_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h = p["width"], p["height"]
    blocks = tuple(p["blocks"])
    nblk = blocks[0] * blocks[1]
    rng = np.random.default_rng(cfg.get("seed", 0))
    Clock(dut.clk, PERIOD_NS, unit="ns").start()
    dut.count_addr.value = 0
    source = BeatSource(dut, "sink", dut.clk, IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0)),
                        period_ns=PERIOD_NS)
    consumer = Consumer(dut, cfg.get("ready", 1.0), cfg.get("seed", 0) + 1)
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)

    published = []

    async def stats():
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if dut.frame_done.value.is_resolvable and int(dut.frame_done.value):
                await RisingEdge(dut.clk)
                await Timer(1, unit="ns")
                vals = {}
                for name in ("total_left", "total_right", "overflow"):
                    v = getattr(dut, name).value
                    vals[name] = int(v) if v.is_resolvable else None
                counts = np.zeros((2, nblk), np.int64)
                for b in range(nblk):
                    for cam in (0, 1):
                        dut.count_addr.value = 2 * b + cam
                        await Timer(1, unit="ns")
                        v = dut.count_data.value
                        counts[cam, b] = int(v) if v.is_resolvable else -1
                vals["counts"] = counts
                published.append(vals)

    cocotb.start_soon(stats())
    pairs = [flag_pair(s, w, h, rng) for s in cfg.get("frames", ["flags:0.05"])]
    beats = []
    expected_words = []
    if cfg.get("token_after") is not None:
        l, r = flag_pair("flags:0.2", w, h, rng)
        cut = frame_beats(l, stereo=True, right=r)[:int(cfg["token_after"])]
        beats += cut + [TOKEN + (0,)]
        # the features of the cut frame before the token, then the token word
        part = model.features(*[np.asarray(f) for f in (l, r)], border=p["border"])
        n_beats = len(cut)
        before = [f for f in part if 2 * (f[1] * w + f[0]) + f[2] < n_beats][:p["max_features"]]
        for x, y, cam in before:
            word = int(model.FEATURE.pack(x=x, cam=cam, y=y))
            expected_words += [(word & 0xFFFF, False, False), (word >> 16, False, False)]
        expected_words.append(model.TOKEN_WORD)
    results = []
    for left, right in pairs:
        beats += frame_beats(left, stereo=True, right=right)
        res = model.feature_list(left, right, blocks=blocks, border=p["border"], max_features=p["max_features"])
        results.append(res)
        expected_words += res["words"]
    source.send_beats(beats)
    if cfg.get("stall"):
        # the consumer takes nothing while every frame goes in: its lists' ends find the FIFO full
        consumer.hold = True
        while source.queue:
            await ClockCycles(dut.clk, 16)
        await ClockCycles(dut.clk, 16)
        consumer.hold = False
    limit = int(len(beats) / cfg.get("duty", 1.0) * 2) + 2000
    waited = 0
    while (source.queue or len(consumer.words) < len(expected_words)) and waited < limit:
        await ClockCycles(dut.clk, 64)
        waited += 64
    await ClockCycles(dut.clk, 200)

    assert not consumer.undefined, consumer.undefined[:3]
    got = consumer.words
    if cfg.get("debug"):
        import json
        open(cfg["report"] + ".debug", "w").write(json.dumps(dict(got=got, exp=expected_words)))
    if cfg.get("stall"):
        # Frame ends during the stall that found the FIFO full: their lists are lost, and the list whose end
        # was the first lost is cut by a reset token, the last word out (never a trailer that closes it
        # with another frame's features, never an overwritten entry). The lists before it are whole: each
        # the model's list with features left out (those that found the FIFO full), the count and flag right.
        lists_got = model.parse_words(got)
        assert lists_got and lists_got[-1].get("aborted"), f"the last list must be cut by a token: {lists_got}"
        whole = lists_got[:-1]
        assert all(not lst.get("aborted") for lst in whole), f"a token before the end: {lists_got}"
        assert 1 <= len(whole) < len(results), f"{len(whole)} whole lists of {len(results)} frames"
        for i, (lst, res) in enumerate(zip(whole, results)):
            it = iter(res["features"])
            assert all(f in it for f in lst["features"]), f"list {i}: not a subsequence of the model's"
            assert lst["count"] == len(lst["features"]), f"list {i}: count {lst['count']}"
            missing = len(lst["features"]) < len(res["features"])
            assert lst["overflow"] == (missing or res["overflow"]), f"list {i}: overflow {lst['overflow']}"
        assert not lists_got[-1]["features"], "features listed after a lost end"
        # the counts are published for every frame; a lost list's flag says its list was cut
        for i in range(len(whole), len(results)):
            results[i] = dict(results[i], overflow=results[i]["overflow"] or bool(results[i]["features"]))
        for i, lst in enumerate(whole):
            results[i] = dict(results[i], overflow=lst["overflow"])
    elif cfg.get("lossy"):
        # A consumer that stalls too long: the FIFO fills and features are dropped. Each whole list must
        # be the model's list with features left out (order kept), its trailer counting what is listed,
        # and the overflow flag set wherever a feature is missing; the counts below count them all.
        lists_got = [lst for lst in model.parse_words(got) if not lst.get("aborted")]
        assert len(lists_got) == len(results), f"{len(lists_got)} whole lists, {len(results)} frames"
        for i, (lst, res) in enumerate(zip(lists_got, results)):
            it = iter(res["features"])
            assert all(f in it for f in lst["features"]), f"list {i}: not a subsequence of the model's"
            assert lst["count"] == len(lst["features"])
            missing = len(lst["features"]) < len(res["features"])
            assert lst["overflow"] == (missing or res["overflow"]), f"list {i}: overflow {lst['overflow']}"
            results[i] = dict(res, overflow=lst["overflow"])
    else:
        assert len(got) == len(expected_words), f"{len(got)} words out, {len(expected_words)} expected"
        for i, (g, e) in enumerate(zip(got, expected_words)):
            assert g == e, f"word {i}: got {g}, expected {e}"
    assert int(dut.source_valid.value) == 0, "words left in the FIFO"
    assert len(published) == len(pairs), f"{len(published)} frames published, {len(pairs)} sent"
    for i, (pub, res) in enumerate(zip(published, results)):
        assert pub["total_left"] == res["totals"][0] and pub["total_right"] == res["totals"][1], \
            f"frame {i}: totals {pub['total_left']}, {pub['total_right']}, expected {res['totals'].tolist()}"
        assert pub["overflow"] == int(res["overflow"]), f"frame {i}: overflow {pub['overflow']}"
        assert (pub["counts"] == res["counts"]).all(), \
            f"frame {i}: counts {pub['counts'].tolist()} != {res['counts'].tolist()}"
    lists = model.parse_words(got)
    # Latency of the first feature of the first whole frame (FIFO empty, consumer ready): the cycle its
    # first word is on the port minus the cycle its flag's beat was driven.
    latency = None
    first = results[0]["features"]
    if first and cfg.get("ready", 1.0) >= 1.0:
        x, y, cam = first[0]
        n_before = len(beats) - sum(2 * f.size for f in (p_[0] for p_ in pairs))
        beat_index = n_before + 2 * (y * w + x) + cam
        word_index = len(expected_words) - sum(len(r["words"]) for r in results)
        latency = consumer.cycles[word_index] - source.sent_cycles[beat_index]
    write_report(cfg, dict(frames=len(pairs), words=len(got), lists=len(lists), latency=latency,
                           features=[len(r["features"]) for r in results],
                           overflow=[bool(r["overflow"]) for r in results]))
