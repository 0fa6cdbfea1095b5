"""hdl/common/fifo.py's show_ahead_fifo in MyHDL's simulator against a Python queue: the head, the level
and the order of the words under random pushes and pops, any depth; its parameter checks."""

import random
from collections import deque

import pytest
from myhdl import ResetSignal, Signal, Simulation, delay, instance, intbv

from eyestereo.hdl.common.fifo import show_ahead_fifo


def run_fifo(depth: int, n: int, seed: int) -> int:
    clk, rst = Signal(bool(0)), ResetSignal(1, active=1, isasync=False)
    din, dout = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    push, pop = Signal(bool(0)), Signal(bool(0))
    level = Signal(intbv(0, min=0, max=depth + 1))
    dut = show_ahead_fifo(clk, rst, din, push, dout, pop, level, depth=depth)
    rng = random.Random(seed)
    want: deque = deque()
    checked = [0]

    @instance
    def stimulus():
        for _ in range(2):
            clk.next = 1
            yield delay(5)
            clk.next = 0
            yield delay(5)
        rst.next = 0
        for _ in range(n):
            # decide from the state after the last edge, as a consumer reading the head would
            assert int(level) == len(want), f"level {int(level)}, {len(want)} words held"
            if want:
                assert int(dout) == want[0], f"head {int(dout)}, expected {want[0]}"
                checked[0] += 1
            do_pop = bool(want) and rng.random() < 0.5
            do_push = len(want) < depth and rng.random() < 0.55
            word = rng.randrange(256)
            push.next, pop.next, din.next = do_push, do_pop, word
            yield delay(1)
            clk.next = 1
            yield delay(4)
            clk.next = 0
            yield delay(5)
            if do_pop:
                want.popleft()
            if do_push:
                want.append(word)

    Simulation(dut, stimulus).run(quiet=1)
    return checked[0]


@pytest.mark.parametrize("depth", [1, 3, 4, 16])
def test_show_ahead_fifo_against_a_queue(depth):
    assert run_fifo(depth, 600, depth) > 200


@pytest.mark.parametrize("depth,level_max,match", [
    (0, 2, "depth must be an integer >= 1"),
    (2.0, 3, "depth must be an integer >= 1"),
    (4, 4, r"level must hold 0\.\.4"),
])
def test_show_ahead_fifo_checks(depth, level_max, match):
    s = Signal(intbv(0)[8:])
    with pytest.raises(ValueError, match=match):
        show_ahead_fifo(Signal(bool(0)), ResetSignal(0, active=1, isasync=False), s, Signal(bool(0)),
                        Signal(intbv(0)[8:]), Signal(bool(0)), Signal(intbv(0, min=0, max=level_max)), depth=depth)
