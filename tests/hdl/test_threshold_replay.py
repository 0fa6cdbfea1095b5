"""threshold_replay (hdl/system/threshold_replay.py): the thresholds into the Harris clock, all 32 again after hrst.

In MyHDL's simulator (the block is a part of stereo_frontend; the front end's benches and the soak run its
conversions): the host's writes pass at once, the replay after hrst's fall sends every entry (the written
values, 0 for the others) paced ``gap + 1`` clocks apart, a bus write during the replay goes first, and a
system reset empties the copy.
"""

from __future__ import annotations

import pytest
from myhdl import ResetSignal, Signal, Simulation, StopSimulation, always, block, delay, instance, intbv, now

from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.system.threshold_replay import ENTRIES, threshold_replay


def _run(script, gap=4):
    """Run ``script`` (a generator function of the ports) and return the beats: (time, camera, block, code)."""
    clk, hrst = Signal(bool(0)), Signal(bool(0))
    rst = ResetSignal(0, active=1, isasync=False)
    p = dict(l_we=Signal(bool(0)), l_addr=Signal(intbv(0)[4:]), l_data=Signal(intbv(0)[20:]), r_we=Signal(bool(0)),
             r_addr=Signal(intbv(0)[4:]), r_data=Signal(intbv(0)[20:]))
    src = ImageStream(25)
    beats = []
    dut = threshold_replay(clk, rst, hrst, p["l_we"], p["l_addr"], p["l_data"], p["r_we"], p["r_addr"], p["r_data"],
                           src, gap=gap)

    @block
    def bench():
        @always(delay(5))
        def tick():
            clk.next = not clk

        @always(clk.posedge)
        def watch():
            if src.valid:
                assert src.eol and src.eof
                d = int(src.data)
                beats.append((now(), d >> 24 & 1, d >> 20 & 15, d & 0xFFFFF))

        @instance
        def drive():
            rst.next = 1
            yield clk.negedge
            rst.next = 0
            yield from script(clk, rst, hrst, p)
            raise StopSimulation

        return tick, watch, drive

    Simulation(dut, bench()).run(quiet=1)
    return beats


def _write(clk, p, cam, blk, code):
    we, addr, data = (p["l_we"], p["l_addr"], p["l_data"]) if cam == 0 else (p["r_we"], p["r_addr"], p["r_data"])
    we.next, addr.next, data.next = 1, blk, code
    yield clk.negedge
    we.next = 0


def _pulse(clk, hrst, clocks=2):
    hrst.next = 1
    for _ in range(clocks):
        yield clk.negedge
    hrst.next = 0


def _idle(clk, n):
    for _ in range(n):
        yield clk.negedge


def test_writes_pass_and_the_replay_sends_every_entry():
    def script(clk, rst, hrst, p):
        yield from _write(clk, p, 0, 3, 111)
        yield from _write(clk, p, 0, 15, 222)
        yield from _write(clk, p, 1, 7, 333)
        yield from _idle(clk, 5)
        yield from _pulse(clk, hrst)
        yield from _idle(clk, 40)
        yield from _write(clk, p, 1, 2, 444)  # a host write during the replay
        yield from _idle(clk, 200)

    beats = _run(script)
    assert [b[1:] for b in beats[:3]] == [(0, 3, 111), (0, 15, 222), (1, 7, 333)]
    host = [i for i, b in enumerate(beats) if b[1:] == (1, 2, 444)][0]  # the host's write, in its clock
    replay = beats[3:host] + beats[host + 1:]
    assert len(beats) == 3 + ENTRIES + 1 and len(replay) == ENTRIES
    want = {(c, k): 0 for c in (0, 1) for k in range(16)}
    # right block 2 is replayed after the host wrote it: its new code
    want.update({(0, 3): 111, (0, 15): 222, (1, 7): 333, (1, 2): 444})
    assert [(c, k) for _, c, k, _ in replay] == sorted(want)  # left blocks 0..15, then right
    assert all(v == want[(c, k)] for _, c, k, v in replay)
    gaps = {b[0] - a[0] for a, b in zip(replay, replay[1:])}
    assert gaps <= {50, 60}, gaps  # a beat every gap + 1 = 5 clocks (one more where the host's write went first)


def test_a_system_reset_empties_the_copy():
    def script(clk, rst, hrst, p):
        yield from _write(clk, p, 0, 5, 777)
        rst.next = 1
        yield clk.negedge
        rst.next = 0
        yield from _pulse(clk, hrst)
        yield from _idle(clk, 200)

    beats = _run(script)
    assert beats[0][1:] == (0, 5, 777) and len(beats) == 1 + ENTRIES
    assert all(v == 0 for _, _, _, v in beats[1:])


@pytest.mark.parametrize("gap", [1, 17, 2.5])
def test_gap_is_checked(gap):
    with pytest.raises(ValueError, match="gap"):
        _run(lambda *a: iter(()), gap=gap)
