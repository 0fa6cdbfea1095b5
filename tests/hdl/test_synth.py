"""Yosys synthesis for the Spartan-3E: the line delay maps to block RAM, Sobel uses no multiplier."""

import pytest

from eyestereo.hdl.synth import parse_stat, summarize, synth_block, table

pytestmark = pytest.mark.synth

STAT = """
=== sobel ===

        +----------Local Count, excluding submodules.
        |
       75 wires
      202 wire bits
       86 cells
       12   FDRE
        3   FDR
       10   LUT2
        1   LUT4
        2   RAMB16_S9
        1   MULT18X18SIO
        9   XORCY
        8   MUXCY
        4   RAM16X1S
"""


def test_parse_and_summarize_stat():
    cells = parse_stat(STAT)
    assert cells["FDRE"] == 12 and cells["RAMB16_S9"] == 2 and "wires" not in cells
    s = summarize(cells)
    assert s == dict(LUT=11, LUTRAM=4, FF=15, RAMB16=2, MULT18X18=1, carry=17)


def test_line_delay_maps_to_block_ram(tmp_path):
    r = synth_block("line_delay", tmp_path)
    s = r["summary"]
    assert s["RAMB16"] == 1, r["cells"]
    assert s["LUTRAM"] == 0 and s["MULT18X18"] == 0
    assert s["LUT"] < 60  # a counter and flags, not a memory built of LUTs


def test_line_delay_36_bits_still_one_block_ram(tmp_path):
    r = synth_block("line_delay", tmp_path, data_width=36)
    assert r["summary"]["RAMB16"] == 1, r["cells"]


def test_sobel_resources(tmp_path):
    r = synth_block("sobel", tmp_path)
    s = r["summary"]
    assert s["MULT18X18"] == 0, r["cells"]
    assert s["RAMB16"] == 2 and s["LUTRAM"] == 0
    assert s["LUT"] <= 259  # thesis Table 6.1: 259 LUTs for the separable Sobel
    assert "| sobel |" in table([r])
