"""hdl/rectify/fetch_gate.py in MyHDL's simulator: requests pass one for one, none moves while the gate is shut,
a request once offered downstream stays offered until it moves, responses pass untouched; its checks."""

import random

import pytest
from myhdl import ResetSignal, Signal, Simulation, StopSimulation, always, delay, instance

from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.rectify.fetch_gate import fetch_gate


def test_requests_wait_while_held_and_an_offer_is_never_withdrawn():
    clk, rst = Signal(bool(0)), ResetSignal(1, active=1, isasync=False)
    up, down, hold = FetchPort(32, 24), FetchPort(32, 24), Signal(bool(0))
    dut = fetch_gate(clk, rst, up, down, hold)
    rng = random.Random(3)
    log = dict(moves=0, held_moves=0, withdrawn=0, responses=0, cycles=0)

    @always(delay(5))
    def clock():
        clk.next = not clk

    @instance
    def run():
        yield clk.negedge
        rst.next = 0
        held_for = 0   # clocks hold has been high
        offered = None  # a request offered downstream and not taken
        for _ in range(3000):
            yield clk.negedge
            # drive the next cycle's inputs (the rectifier offers a request most of the time, with its x)
            hold.next = rng.random() < 0.3 if held_for == 0 else rng.random() < 0.8
            if not (up.req_valid and not up.req_ready):
                up.req_valid.next = rng.random() < 0.8
                up.req_x.next = rng.randrange(32)
            down.req_ready.next = rng.random() < 0.6
            down.rsp_valid.next = rng.random() < 0.5
            down.rsp_data.next = rng.randrange(256)
            yield delay(1)
            # the same cycle, inputs settled
            assert up.rsp_valid == down.rsp_valid and (not down.rsp_valid or up.rsp_data == down.rsp_data)
            log["responses"] += bool(down.rsp_valid)
            assert down.req_x == up.req_x
            assert bool(up.req_valid and up.req_ready) == bool(down.req_valid and down.req_ready)
            if offered is not None and not down.req_valid:
                log["withdrawn"] += 1
            moved = bool(down.req_valid and down.req_ready)
            if moved:
                log["moves"] += 1
                if held_for >= 2 and offered is None:
                    log["held_moves"] += 1  # a new request while hold has been high two clocks
            offered = int(down.req_x) if down.req_valid and not down.req_ready else None
            log["cycles"] += 1
            yield clk.posedge
            held_for = held_for + 1 if hold else 0
        raise StopSimulation

    Simulation(dut, clock, run).run(quiet=1)
    assert log["cycles"] == 3000 and log["moves"] > 300 and log["responses"] > 1000
    assert log["withdrawn"] == 0 and log["held_moves"] == 0, log


def test_one_geometry():
    clk, rst = Signal(bool(0)), ResetSignal(1, active=1, isasync=False)
    with pytest.raises(ValueError, match="one geometry"):
        fetch_gate(clk, rst, FetchPort(32, 24), FetchPort(64, 24), Signal(bool(0)))
