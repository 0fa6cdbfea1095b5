"""The Gowin placement flow (hdl/flow/gowin.py): its argument errors, the pin and clock constraint writers, the
report parser and the package's pin list. The full flow (python -m eyestereo.hdl.flow.gowin, minutes) is not run
here: its figures are docs/boards.md's."""

from __future__ import annotations

import subprocess
import sys

import pytest

from eyestereo.hdl.flow import gowin


@pytest.mark.parametrize("argv, words", [
    (["--seeds", "0"], "--seeds '0'"),
    (["--seeds", "1,x"], "positive integers"),
    (["--seeds", ""], "positive integers"),
    (["--device", "GW1N-LV9QN48C6/I5"], "unknown device"),
    (["--bogus"], "unrecognized arguments"),
])
def test_bad_arguments_one_line_exit_1(argv, words, tmp_path, capsys):
    out = tmp_path / "g"
    try:
        rc = gowin.main(["--out", str(out), *argv])
    except SystemExit as e:  # argparse's own errors exit through _Parser.error
        rc = e.code
    err = capsys.readouterr().err
    assert rc == 1
    assert err.count("\n") == 1 and err.startswith("error: ") and words in err
    assert not out.exists() and not (tmp_path / "g.partial").exists()  # nothing written


def test_cli_bad_device_as_a_process(tmp_path):
    r = subprocess.run([sys.executable, "-m", "eyestereo.hdl.flow.gowin", "--out", str(tmp_path / "g"), "--device",
                        "nope"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1
    assert r.stderr.strip().splitlines() == [r.stderr.strip()] and "unknown device 'nope'" in r.stderr


def test_build_rejects_bad_input_before_any_tool(tmp_path):
    with pytest.raises(ValueError, match="unknown device"):
        gowin.build(tmp_path / "g", device="GW2A-18")
    with pytest.raises(ValueError, match="positive integers"):
        gowin.build(tmp_path / "g", seeds=[0])
    assert list(tmp_path.iterdir()) == []


def test_cst_small_port_list():
    ports = ["clk", "rx", "led[0]", "led[1]", "d"]
    text = gowin.cst(ports, ["clk"], ["H11", "A9"], ["A2", "A3", "A4", "A5", "A10"])
    # hand-written: the clock on the first clock pin, the rest in order on the other pins
    assert text == (
        "// a placement study's pins (eyestereo.hdl.flow.gowin), not a board's wiring\n"
        'IO_LOC "clk" H11;\nIO_PORT "clk" IO_TYPE=LVCMOS33;\n'
        'IO_LOC "rx" A2;\nIO_PORT "rx" IO_TYPE=LVCMOS33;\n'
        'IO_LOC "led[0]" A3;\nIO_PORT "led[0]" IO_TYPE=LVCMOS33;\n'
        'IO_LOC "led[1]" A4;\nIO_PORT "led[1]" IO_TYPE=LVCMOS33;\n'
        'IO_LOC "d" A5;\nIO_PORT "d" IO_TYPE=LVCMOS33;\n')


@pytest.mark.parametrize("ports, clocks, clock_pins, pins, words", [
    (["a", "b", "c"], [], [], ["P1", "P2"], "needs 0 clock and 3 other pins; the package has 0 and 2 free"),
    (["c1", "c2", "a"], ["c1", "c2"], ["G1"], ["P1"], "needs 2 clock and 1 other pins"),
    (["a"], ["clk"], ["G1"], ["P1"], "clock ports ['clk'] are not ports"),
])
def test_cst_refuses_what_does_not_fit(ports, clocks, clock_pins, pins, words):
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        gowin.cst(ports, clocks, clock_pins, pins)


def test_sdc_periods():
    # 82.5 MHz -> 12.121 ns, 55 MHz -> 18.182 ns (1000 / f, by hand)
    assert gowin.sdc({"mem_clk": 82.5, "harris_clk": 55.0}, {"mem_clk": "m_O", "harris_clk": "harris_clk"}) == (
        "create_clock -name mem_clk -period 12.121 [get_nets m_O]\n"
        "create_clock -name harris_clk -period 18.182 [get_nets harris_clk]\n")


def test_clock_nets_follow_the_input_buffer():
    # a Yosys netlist cut down by hand: mem_clk (bit 2) through an IBUF onto bit 7; hclk has no buffer
    netlist = {"modules": {"top": {
        "ports": {"mem_clk": {"bits": [2]}, "hclk": {"bits": [3]}, "d": {"bits": [4, 5]}},
        "cells": {"mem_clk_IBUF_I": {"type": "IBUF", "connections": {"I": [2], "O": [7]}},
                  "d_IBUF_I": {"type": "IBUF", "connections": {"I": [4], "O": [8]}},
                  "ff": {"type": "DFF", "connections": {"CLK": [7], "D": [8], "Q": [9]}}},
        "netnames": {"mem_clk": {"bits": [2]}, "mem_clk_IBUF_I_O": {"bits": [7]}, "hclk": {"bits": [3]},
                     "x": {"bits": [8, 9]}}}}}
    assert gowin.clock_nets(netlist, "top", ["mem_clk", "hclk"]) == {"mem_clk": "mem_clk_IBUF_I_O", "hclk": "hclk"}


def test_goals_are_the_brief_with_margin():
    assert gowin.GOALS == {"mem_clk": 75.0, "harris_clk": 50.0, "cam_l_pclk": 25.0, "cam_r_pclk": 25.0}
    assert {c: round(g * gowin.MARGIN, 2) for c, g in gowin.GOALS.items()} == {
        "mem_clk": 82.5, "harris_clk": 55.0, "cam_l_pclk": 27.5, "cam_r_pclk": 27.5}


def test_parse_report_judges_each_clock():
    report = {"fmax": {"mem_clk_IBUF_I_O": {"achieved": 90.123, "constraint": 12},
                       "harris_clk_IBUF_I_O": {"achieved": 54.9, "constraint": 18}},
              "utilization": {"LUT4": {"used": 100, "available": 20736}, "DSP": {"used": 0, "available": 48}}}
    fmax, util = gowin.parse_report(report, {"mem_clk": 82.5, "harris_clk": 55.0, "cam_l_pclk": 27.5})
    assert fmax["mem_clk"] == dict(achieved=90.12, constraint=82.5, met=True, net="mem_clk_IBUF_I_O")
    assert fmax["harris_clk"]["met"] is False  # 54.9 < 55.0
    assert fmax["cam_l_pclk"] == dict(achieved=None, constraint=27.5, met=False, net=None)  # not in the report
    assert util == {"LUT4": {"used": 100, "available": 20736}}  # unused cell types left out


def test_top_parameter_check():
    with pytest.raises(ValueError, match="reset_hold"):
        gowin.gowin_frontend(**gowin.top_ports(), reset_hold=1)


def test_package_pins_pg256():
    pytest.importorskip("apycula")
    clock, other = gowin.package_pins("GW2A-LV18PG256C8/I7")
    # the PBGA256's eight GCLKT inputs (Gowin's GW2A-18 pinout: GCLKT_0..7 on H11 K14 N10 T7 L2 J1 C8 A9)
    assert clock == ["A9", "C8", "H11", "J1", "K14", "L2", "N10", "T7"]
    # JTAG (A6 TDI, A7 TCK, B8 TMS, C6 TDO), DONE (C13), READY (A13), RECONFIG_N (B10) stay free
    assert not {"A6", "A7", "B8", "C6", "C13", "A13", "B10"} & set(clock + other)
    assert "A2" in other and len(set(other)) == len(other)


def test_last_build_was_timed_at_the_constraints():
    """The last ``python -m eyestereo.hdl.flow.gowin`` build (skipped if there is none): nextpnr's own reports show
    every clock timed at its goal plus the margin (not at nextpnr's 12 MHz default: a constraint on the port alone
    does not reach the clock net), and the summary's pass/fail is the reports' achieved >= constraint."""
    import json
    from pathlib import Path

    out = Path(__file__).resolve().parents[2] / "build" / "gowin"
    if not (out / "gowin.json").exists():
        pytest.skip("no build/gowin (python -m eyestereo.hdl.flow.gowin --out build/gowin)")
    summary = json.loads((out / "gowin.json").read_text())
    goals = {"mem_clk": 75.0 * 1.1, "harris_clk": 50.0 * 1.1, "cam_l_pclk": 25.0 * 1.1, "cam_r_pclk": 25.0 * 1.1}
    for run in summary["runs"]:
        report = json.loads((out / f"pnr_report_seed{run['seed']}.json").read_text())
        seen = {}
        for net, v in report["fmax"].items():
            port = next(c for c in goals if net.startswith(c))
            assert v["constraint"] == pytest.approx(goals[port], abs=0.01), net
            seen[port] = v["achieved"] >= v["constraint"] - 1e-9
        assert sorted(seen) == sorted(goals)
        assert run["met"] == all(seen.values())
    assert (out / "gowin_frontend.fs").exists() == (summary["chosen_seed"] is not None)
