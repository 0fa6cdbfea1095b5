"""The SRAM part model's rules (tools/sram.py) and the controller's cycle-true model, without a simulator.

Each rule is exercised by a hand-written pin sequence that keeps it and one that breaks it; the timing
model is checked against the timing diagram of hdl/interfaces/sram_bus.py.
"""

import re

import pytest

from eyestereo.tools.models.sram_controller import Command, latency, schedule, write_block_window
from eyestereo.tools.sram import Pins, SramChip, SramPart, SramViolation, power_up_word

IDLE = dict(ce_n=1, ld_n=0, we_n=1, bw_n=3, oe_n=1, addr=0, dq_oe=0, dq_o=(0, 0))


def rd(addr, **kw):
    return dict(IDLE, ce_n=0, addr=addr, **kw)


def wr(addr, bw_n=0, **kw):
    return dict(IDLE, ce_n=0, we_n=0, addr=addr, bw_n=bw_n, **kw)


def run(part, edges, *, strict=True):
    """Feed ``edges`` (dicts of pins, or None for idle) from edge 1; returns (chip, driven word per cycle)."""
    chip = SramChip(part, strict=strict)
    out = {}
    for t, e in enumerate(edges, start=1):
        out[t] = chip.edge(t, Pins(**(e or IDLE)))
    return chip, out


def drive(data, **kw):
    """Pins of a cycle in which the FPGA drives DQ with ``data`` (a 16-bit int or a tuple of bytes)."""
    dq = data if isinstance(data, tuple) else (data & 0xFF, data >> 8)
    return dict(kw, dq_oe=1, dq_o=dq)


# --- reads return what was written --------------------------------------------------------------
@pytest.mark.parametrize("lat", [1, 2, 3])
def test_nobl_write_then_read_back_to_back(lat):
    part = SramPart("nobl", lat)
    # write at edge 1 (data sampled at 1 + lat), read at edge 2: the read must see the write (forwarded)
    edges = [wr(5), rd(5)] + [None] * 6
    edges[lat] = drive(0xBEEF, **(edges[lat] or IDLE))
    # OE# low in the read's data cycle, sampled at edge 2 + lat
    edges[1 + lat] = dict(edges[1 + lat] or IDLE, oe_n=0)
    chip, out = run(part, edges)
    assert out[2 + lat - 1] == 0xBEEF
    assert chip.word(5) == 0xBEEF and chip.idle


def test_unwritten_word_reads_its_power_up_pattern():
    part = SramPart("nobl", 2)
    chip, out = run(part, [rd(0x12345), None, dict(IDLE, oe_n=0), None])
    assert out[2] == power_up_word(0x12345)
    assert power_up_word(0x12345) != power_up_word(0x12346)


def test_pipelined_read_then_write_same_address_reads_old():
    part = SramPart("pipelined", 2)
    # read at edge 1 (drives cycle 2); a write at edge 5 (data with the address, driven in cycle 4)
    edges = [rd(7), None, dict(IDLE, oe_n=0), None, drive(0x1111, **wr(7)), rd(7), None, dict(IDLE, oe_n=0)]
    chip, out = run(part, edges)
    assert out[2] == power_up_word(7)
    assert out[7] == 0x1111


def test_byte_writes_merge():
    part = SramPart("pipelined", 2)
    edges = [drive(0xAAAA, **wr(9, bw_n=0)), drive((0x55, None), **wr(9, bw_n=2)), drive((None, 0x77), **wr(9, bw_n=1))]
    chip, _ = run(part, edges)
    assert chip.word(9) == 0x7755


# --- each rule ------------------------------------------------------------------------------------
def expect(part, edges, rule):
    with pytest.raises(SramViolation, match=rule):
        run(part, edges)
    chip, _ = run(part, edges, strict=False)
    assert any(re.search(rule, v) for v in chip.violations)


def test_burst_continue_is_rejected():
    expect(SramPart("nobl", 2), [dict(IDLE, ld_n=1)], "single accesses only")


@pytest.mark.parametrize("pin", ["ce_n", "ld_n", "dq_oe"])
def test_undefined_control_pins(pin):
    expect(SramPart("nobl", 2), [dict(IDLE, **{pin: None})], "inputs defined")


def test_undefined_address_during_access():
    expect(SramPart("nobl", 2), [rd(None)], "addr undefined")


def test_write_without_bytes():
    expect(SramPart("pipelined", 2), [drive(1, **wr(3, bw_n=3))], "byte writes")


def test_write_data_missing():
    expect(SramPart("pipelined", 2), [wr(3)], "write data in the right cycle")
    expect(SramPart("nobl", 2), [wr(3), None, None], "write data in the right cycle")


def test_nobl_write_data_one_cycle_early_is_a_stray_drive():
    expect(SramPart("nobl", 2), [wr(3), drive(1), None], "stray drive")


def test_undefined_enabled_write_byte():
    expect(SramPart("pipelined", 2), [drive((None, 1), **wr(3, bw_n=0))], "byte 0 .* undefined")


def test_contention():
    # pipelined: read at edge 1 drives cycle 2; a write at edge 3 has the FPGA drive cycle 2 as well
    expect(SramPart("pipelined", 2), [rd(1), None, drive(5, **wr(2, oe_n=0))], "no bus contention")


def test_turnaround_part_then_fpga():
    # read data in cycle 2, FPGA drives cycle 3 (write at edge 4): no idle cycle between
    edges = [rd(1), None, dict(IDLE, oe_n=0), drive(5, **wr(2))]
    expect(SramPart("pipelined", 2), edges, "turnaround")
    # one idle cycle: legal
    run(SramPart("pipelined", 2), [rd(1), None, dict(IDLE, oe_n=0), None, drive(5, **wr(2))])
    # a NoBL part needs none: read at 1 drives cycle 2, write at 2 has its data in cycle 3
    run(SramPart("nobl", 2), [rd(1), wr(2), dict(IDLE, oe_n=0), drive(5)])


def test_turnaround_fpga_then_part():
    # pipelined: read at edge 1 drives cycle 2; write at edge 2 drives cycle 1: adjacent the other way
    expect(SramPart("pipelined", 2), [rd(1), drive(5, **wr(2)), dict(IDLE, oe_n=0)], "turnaround")


def test_output_enable_high_during_read_data():
    expect(SramPart("nobl", 2), [rd(1), None, None], "output enable")


def test_edges_must_not_be_skipped_with_accesses_in_flight():
    chip = SramChip(SramPart("nobl", 2))
    chip.edge(1, Pins(**rd(1)))
    with pytest.raises(ValueError, match="skipped"):
        chip.edge(4, Pins(**IDLE))


@pytest.mark.parametrize("kw,msg", [(dict(kind="ddr"), "kind"), (dict(read_latency=0), "read_latency"),
                                    (dict(read_latency=2.0), "read_latency"), (dict(words=1000), "power of two")])
def test_part_parameters_checked(kw, msg):
    with pytest.raises(ValueError, match=msg):
        SramPart(**kw)


# --- the controller's timing model -----------------------------------------------------------------
@pytest.mark.parametrize("kind,lat,window", [("pipelined", 1, (1, 2)), ("pipelined", 2, (1, 3)),
                                             ("pipelined", 3, (2, 4)), ("nobl", 2, (1, 0))])
def test_write_block_window(kind, lat, window):
    assert write_block_window(kind, lat) == window


def test_schedule_matches_the_documented_diagram():
    cmds = [Command(False), Command(False), Command(True), Command(False)]
    assert schedule(cmds, "pipelined", 2) == ([0, 1, 5, 6], [4, 5, 10])
    assert schedule(cmds, "nobl", 2) == ([0, 1, 2, 3], [4, 5, 7])
    assert latency(2) == 4


def test_window_keeps_the_part_rules():
    """Every read/write pattern the window allows is legal for the part model (exhaustive, 5 commands)."""
    import itertools

    for kind, lat in (("pipelined", 1), ("pipelined", 2), ("pipelined", 3), ("nobl", 1), ("nobl", 2)):
        part = SramPart(kind, lat)
        for pattern in itertools.product([False, True], repeat=5):
            cmds = [Command(we, addr=i, data=i + 1) for i, we in enumerate(pattern)]
            taken, _ = schedule(cmds, kind, lat)
            # pins: command taken in clock c is on the pins in clock c+1, sampled at edge c+2
            n = taken[-1] + 12
            edges = [dict(IDLE) for _ in range(n + 2)]
            for c, cmd in zip(taken, cmds):
                e = c + 2
                edges[e] = (wr if cmd.we else rd)(cmd.addr)
            for c, cmd in zip(taken, cmds):
                e = c + 2
                if cmd.we:
                    d = e + part.write_latency
                    edges[d] = drive(cmd.data, **edges[d])
                else:
                    d = e + lat  # the read's data cycle is sampled at edge e + lat
                    edges[d] = dict(edges[d], oe_n=0)
            run(part, edges[1:])
