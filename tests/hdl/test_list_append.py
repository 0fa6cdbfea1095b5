"""list_append (issue 29, the front end's matcher option) in MyHDL's simulator against its model.

Feature lists of several lengths (one longer than the filler's room: no filler), an aborted one (a reset
token: its frame's match list dropped), match lists of several lengths; both inputs offer their words with
random gaps and the output is stalled at random; the words out equal
:func:`eyestereo.tools.models.list_append.list_append`, and the last list's count and overflow flag are its
trailer's.
"""

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, StopSimulation, always, block, delay, instance, intbv

from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.system.list_append import list_append
from eyestereo.tools.models.list_append import list_append as model
from eyestereo.tools.models.match_engine import MARKER

OFFSET = 10


def feature_list(rng, n, abort=False):
    words = [(int(rng.integers(0, 0xFFFF)), False, False) for _ in range(2 * n)]
    if abort:
        return words[:3] + [(0, False, True)]
    return words + [(0xFFFF, False, False), (n, True, True)]


def match_list(rng, n, overflow=False):
    words = [(int(rng.integers(0, 0x7FFF)), False, False) for _ in range(3 * n)]
    return words + [(MARKER, False, False), (n | overflow << 15, False, False), (17, True, True)]


@block
def bench(frames, want, got, seed):
    clk = Signal(bool(0))
    rst = ResetSignal(1, active=1, isasync=False)
    feats, matches, out = QueuePort(16), QueuePort(16), QueuePort(16)
    count, ovf = Signal(intbv(0)[15:]), Signal(bool(0))
    dut = list_append(clk, rst, feats, matches, out, count, ovf, offset=OFFSET)
    rng = np.random.default_rng(seed)

    @always(delay(5))
    def clock():
        clk.next = not clk

    @block
    def source(port, words):
        @instance
        def play():
            yield clk.negedge
            yield clk.negedge
            rst.next = 0
            for d, eol, eof in words:
                while rng.random() < 0.3:
                    port.valid.next = False
                    yield clk.negedge
                port.valid.next, port.data.next, port.eol.next, port.eof.next = True, d, eol, eof
                yield clk.posedge
                while not port.ready:
                    yield clk.posedge
                yield clk.negedge
            port.valid.next = False
        return play

    @always(clk.posedge)
    def sink():
        if out.valid and out.ready:
            got.append((int(out.data), bool(out.eol), bool(out.eof)))

    @instance
    def stall():
        while True:
            yield clk.negedge
            out.ready.next = rng.random() > 0.25
            if len(got) >= len(want):
                for _ in range(50):
                    yield clk.negedge
                got.append(("count", int(count), bool(ovf)))
                raise StopSimulation

    return (dut, clock, source(feats, [w for f, _ in frames for w in f]),
            source(matches, [w for _, m in frames for w in m]), sink, stall)


@pytest.mark.parametrize("seed", [1, 2])
def test_list_append_equals_its_model(seed):
    rng = np.random.default_rng(seed)
    frames = [(feature_list(rng, 2), match_list(rng, 3)), (feature_list(rng, 0), match_list(rng, 0)),
              (feature_list(rng, 3, abort=True), match_list(rng, 2)),
              (feature_list(rng, 5), match_list(rng, 4, overflow=True))]  # 12 feature words: no filler
    want = model(frames, OFFSET)
    got = []
    bench(frames, want, got, seed).run_sim()
    assert got[:-1] == want
    assert got[-1] == ("count", 4, True)  # the last list's trailer
    assert sum(1 for _, _, eof in want if eof) == 4  # 3 whole lists and the token
    assert want.count((0, False, False)) >= OFFSET - 6  # the filler after the first feature list


def test_list_append_checks_its_offset():
    ports = [Signal(bool(0)), ResetSignal(0, active=1, isasync=False), QueuePort(16), QueuePort(16),
             QueuePort(16), Signal(intbv(0)[15:]), Signal(bool(0))]
    with pytest.raises(ValueError, match="offset"):
        list_append(*ports, offset=1)
