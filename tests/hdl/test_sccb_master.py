"""sccb_master: the model's bus levels against a hand-worked write, the slave model's rule checks against broken
masters, the block's parameter checks, and the HDL writing the OV7670 table into two slave models (GHDL; Icarus
and Verilator marked othersims, ``make test-sims``).

The HDL runs (sim/benches/tb_sccb_master.py) compare every change of ``sio_c`` / ``sio_d_oe`` with the model's
clock edge, and each slave model records the writes while it checks the SCCB timing in time units, so a
clock-rate or rule slip fails there.
"""

import shutil

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.camera.sccb_master import sccb_master
from eyestereo.hdl.flow.convert import convert
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.sim.lib.runner import run_bench
from eyestereo.sim.lib.sccb import SccbError, SccbSlave
from eyestereo.tools.models import sccb_master as model
from eyestereo.tools.ov7670 import TABLE

# --- the model against hand-worked levels -------------------------------------------------------------------------

#: One write of 0xA5 to register 0x3C, worked by hand from the SCCB specification: (SIO_C, SIO_D) per quarter
#: bit. Start: SIO_D falls while SIO_C is high; each bit: SIO_C low, high, high, low with SIO_D set in the
#: first low quarter; the 9th bit of each phase released (1); stop: SIO_D rises while SIO_C is high.
START = "11 10 10 00"
STOP = "00 10 11 11"


def _bits(byte_bits: str) -> str:
    return " ".join(f"0{b} 1{b} 1{b} 0{b}" for b in byte_bits)


HAND = " ".join([
    "11",  # the fetch quarter (idle)
    START,
    _bits("01000010" "1"),  # ID 0x42, 9th bit released
    _bits("00111100" "1"),  # sub-address 0x3C
    _bits("10100101" "1"),  # data 0xA5
    STOP,
])


def _levels(text: str) -> list[tuple[int, int]]:
    return [(int(w[0]), int(w[1])) for w in text.split()]


def test_one_write_is_the_hand_worked_sequence():
    seq = model.quarters([(0x3C, 0xA5)], clk_hz=4e6, sccb_hz=100e3)
    one = _levels(HAND)
    assert len(one) == 1 + 4 + 27 * 4 + 4
    assert seq[:len(one)] == one
    # then the two ID reads and the final idle quarter: 2 x (fetch + 2 starts, 4 phases, 2 stops)
    assert len(seq) == len(one) + 2 * (1 + 4 * 4 + 4 * 36) + 1


def test_the_model_carries_the_table():
    assert model.decode(model.quarters(TABLE)) == [("w", r, v) for r, v in model.writes(TABLE)] + [
        ("r", 0x0A), ("r", 0x0B)]
    assert len(model.writes(TABLE)) == len(TABLE) - 1  # one delay entry


def test_quarters_per_clock_and_rate():
    # 100 kHz at 4 MHz: 10 clocks a quarter; 400 kHz is held to tLOW = 1.3 us: 650 ns quarters at 20 MHz
    assert model.quarter_clocks(4e6, 100e3) == 10
    assert model.quarter_clocks(20e6, 400e3) == 13
    assert model.quarter_clocks(4e6, 400e3) == 3
    assert model.quarters_per_ms(4e6, 100e3) == 400  # 4000 clocks a millisecond
    ch, done = model.changes([(0x3C, 0xA5)], clk_hz=4e6, sccb_hz=100e3)
    assert ch[0] == (2 * 10 + 1, 1, 0)  # quarter 2 (SIO_D falls: the start) on the pins from edge 21
    assert done == len(model.quarters([(0x3C, 0xA5)], clk_hz=4e6, sccb_hz=100e3)) * 10


def test_a_delay_is_idle_quarters():
    a = model.quarters([(0x12, 0x80), (0xFF, 3), (0x11, 0)], clk_hz=4e6, sccb_hz=100e3)
    b = model.quarters([(0x12, 0x80), (0x11, 0)], clk_hz=4e6, sccb_hz=100e3)
    assert len(a) - len(b) == 1 + 3 * 400


# --- the slave model's checks ---------------------------------------------------------------------------------


def _play(slave: SccbSlave, levels, quarter_ps: int):
    """Feed a slave the quarters' levels, the master's drive only (no slave answers are needed for writes)."""
    prev = (1, 1)
    for k, (c, d) in enumerate(levels):
        if (c, d) != prev:
            if c != prev[0] and d != prev[1]:  # keep the order the master's quarters have: never both at once
                raise AssertionError("test sequence changes both lines at once")
            slave.event(k * quarter_ps, c, d)
            prev = (c, d)


def test_the_slave_accepts_the_model_at_its_limit():
    s = SccbSlave("0", answer=False)
    _play(s, model.quarters(TABLE, clk_hz=20e6, sccb_hz=400e3), 650_000)  # 13 clocks of 50 ns: 650 ns quarters
    assert s.writes == model.writes(TABLE) and not s.errors
    assert s.reads == [(0x0A, 0xFF), (0x0B, 0xFF)]


def test_the_slave_catches_a_too_fast_sio_c():
    with pytest.raises(SccbError, match=r"SCCB slave 0 at .*SIO_C low for 1.2 us < t_low = 1.3 us"):
        _play(SccbSlave("0"), _levels(HAND), 600_000)  # 600 ns quarters: 417 kHz


def test_the_slave_catches_a_period_under_2_5_us():
    # 600 ns quarters with tLOW relaxed to 1.0 us: only the period rule (2.4 us between SIO_C rises) breaks
    from eyestereo.sim.lib.sccb import SccbRules

    rules = SccbRules(t_low=1.0e-6, t_cyc=2.5e-6)
    with pytest.raises(SccbError, match=r"SIO_C period 2.4 us < t_cyc = 2.5 us"):
        _play(SccbSlave("0", rules=rules), _levels(HAND), 600_000)


def test_the_slave_catches_data_changing_while_sio_c_is_high():
    bad = _levels(HAND)
    i = 1 + 4 + 4 * 2 + 1  # the second high quarter of ID bit 2 (a 0): SIO_D released there
    assert bad[i] == (1, 0) and bad[i + 1] == (1, 0)
    bad[i + 1] = (1, 1)
    with pytest.raises(SccbError, match=r"SIO_D rose while SIO_C was high after 2 bits: only a stop may"):
        _play(SccbSlave("0"), bad, 1_000_000)


def test_the_slave_catches_a_short_phase_and_an_early_access_after_reset():
    short = _levels(" ".join(["11", START, _bits("01000010" "1"), _bits("0011110"), STOP]))
    with pytest.raises(SccbError, match=r"after 16 bits"):
        _play(SccbSlave("0"), short, 1_000_000)
    reset_then_write = model.quarters([(0x12, 0x80), (0x11, 0x00)], clk_hz=4e6, sccb_hz=100e3)
    with pytest.raises(SccbError, match=r"after the soft reset \(COM7 bit 7\): the sensor needs 1000 us"):
        _play(SccbSlave("0"), reset_then_write, 2_500_000)


def test_the_slave_catches_a_start_hold_too_short():
    quick = _levels(HAND)
    quick[2:5] = [(1, 0), (0, 0), (0, 0)]  # SIO_C falls one quarter after the start instead of two
    with pytest.raises(SccbError, match=r"start hold .* < t_hd_sta = 0.6 us"):
        _play(SccbSlave("0"), quick, 500_000)


def test_the_slave_catches_the_master_driving_the_dont_care_bit():
    bad = _levels(HAND)
    i = 1 + 4 + 8 * 4  # ID's 9th bit
    bad[i:i + 4] = [(0, 0), (1, 0), (1, 0), (0, 0)]
    with pytest.raises(SccbError, match=r"the master drives SIO_D low during the 9th \(don't care\) bit"):
        prev = (1, 1)
        s = SccbSlave("0", ack=False)
        for k, (c, d) in enumerate(bad):
            if (c, d) != prev:
                s.event(k * 1_000_000, c, d, master_low=not d)
                prev = (c, d)


# --- the block's parameters -----------------------------------------------------------------------------------


def _ports(cameras=2):
    return (Signal(bool(0)), ResetSignal(0, active=1, isasync=False), Signal(bool(0)), Signal(bool(0)),
            Signal(bool(0)), Signal(intbv(0)[cameras:]), Signal(bool(0)), Signal(bool(0)), Signal(intbv(0)[cameras:]))


@pytest.mark.parametrize("kw,match", [
    (dict(table=[(0x12, 0x100)]), r"table entry 0: value 0x100 of register 0x12 is not a byte"),
    (dict(table=[(0xFF, 0)]), r"table entry 0: a delay is 1..255 ms, got 0"),
    (dict(table=[]), r"table is empty"),
    (dict(sccb_hz=1e6), r"parameter sccb_hz=1e\+06 is above the SCCB's 400 kHz"),
    (dict(clk_hz=1e6, sccb_hz=400e3), r"parameter clk_hz=1e\+06 is too slow for sccb_hz=400000"),
    (dict(cameras=9), r"parameter cameras=9 is too large: at most 8"),
])
def test_parameters_are_checked(kw, match):
    cams = kw.get("cameras", 2)
    with pytest.raises(ValueError, match=rf"^sccb_master: {match}"):
        sccb_master(*_ports(min(cams, 8)), **kw)


def test_ports_are_checked():
    p = list(_ports())
    p[5] = Signal(intbv(0)[3:])
    with pytest.raises(ValueError, match=r"^sccb_master: port sio_d_i must be 2 bits wide, got 3"):
        sccb_master(*p)
    p = list(_ports(1))
    p[5] = Signal(bool(0))
    with pytest.raises(ValueError, match=r"^sccb_master: port sio_d_i must be a Signal\(intbv\(0\)\[1:\]\)"):
        sccb_master(*p, cameras=1)


def test_verilog_mixes_no_signedness(tmp_path):
    v = convert("sccb_master", tmp_path, hdl="Verilog")[-1]
    assert mixed_signedness(v.read_text()) == []


# --- HDL runs ---------------------------------------------------------------------------------------------------

SIMS = ["ghdl", pytest.param("icarus", marks=pytest.mark.othersims),
        pytest.param("verilator", marks=pytest.mark.othersims)]


def _run(request, sim="ghdl", *, clk_hz=4e6, sccb_hz=100e3, answer=(True, True), table=TABLE, **cfg):
    present = sum(1 << k for k, a in enumerate(answer) if a)
    params = dict(table=[list(e) for e in table], clk_hz=clk_hz, sccb_hz=sccb_hz, cameras=len(answer))
    return run_bench("sccb_master", "tb_sccb_master", dict(answer=list(answer), present=present, **cfg),
                     name=request.node.name, params=params, sim=sim)


needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")


@pytest.mark.sim
@needs_ghdl
@pytest.mark.parametrize("clk_hz,sccb_hz", [(4e6, 100e3), (20e6, 400e3)], ids=["100k", "400k"])
def test_the_table_reaches_both_cameras(request, clk_hz, sccb_hz):
    rep = _run(request, clk_hz=clk_hz, sccb_hz=sccb_hz)
    assert rep["writes"] == [len(model.writes(TABLE))] * 2 and rep["runs"] == 1


@pytest.mark.sim
@needs_ghdl
def test_a_missing_camera_is_not_present(request):
    rep = _run(request, answer=(True, False))
    assert rep["writes"] == [len(model.writes(TABLE))] * 2  # the absent one's model saw them on its bus too


@pytest.mark.sim
@needs_ghdl
def test_start_rewrites_and_is_ignored_while_busy(request):
    table = [(0x12, 0x80), (0xFF, 1), (0x11, 0x00), (0x6B, 0x0A)]
    rep = _run(request, table=table, clk_hz=4e6, sccb_hz=400e3, restart=True, start_while_busy=True)
    assert rep["runs"] == 2 and rep["writes"] == [6, 6]


@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.sim
def test_other_simulators(request, sim):
    if sim == "ghdl" and shutil.which("ghdl") is None:
        pytest.skip("GHDL not installed")
    table = [(0x12, 0x80), (0xFF, 1), (0x3A, 0x04), (0x3D, 0xC0)]
    rep = _run(request, sim, table=table, answer=(True, False), restart=True)
    assert rep["runs"] == 2
