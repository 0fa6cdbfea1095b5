"""Synthesis from GHDL's netlist: the line delay maps to block RAM, Sobel uses no multiplier, fmax from nextpnr."""

import pytest

from eyestereo.hdl.flow.synth import parse_fmax, parse_stat, summarize, synth_block, table, write_doc_section

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


def test_line_delay_whole_flow_gives_fmax(tmp_path):
    """The smallest block through every step: VHDL -> GHDL netlist -> Yosys (xc3se, ecp5) -> nextpnr."""
    r = synth_block("line_delay", tmp_path, pnr=True)
    assert r["summary"]["RAMB16"] == 1, r["cells"]
    assert set(r["fmax"]) == {"clk"}, r["fmax"]
    f = r["fmax"]["clk"]
    assert f["constraint"] == 100.0 and 50.0 < f["achieved"] < 1000.0, f
    assert r["ecp5"]["DP16KD"] == 1 and r["ecp5"]["TRELLIS_FF"] > 0, r["ecp5"]
    assert r["clocks"] == {"clk": 50.0}
    assert (tmp_path / "line_delay" / "line_delay_netlist.v").exists()
    md = table([r])
    assert "| line_delay |" in md and "fmax ECP5" in md


def test_parse_fmax_names_clock_ports():
    rep = {"fmax": {"$glbnet$clk$TRELLIS_IO_IN": {"achieved": 83.4, "constraint": 100},
                    "$glbnet$wr_clk$TRELLIS_IO_IN": {"achieved": 201.0, "constraint": 100}}}
    f = parse_fmax(rep, ["clk", "wr_clk"])
    assert f["clk"]["achieved"] == 83.4 and f["wr_clk"]["achieved"] == 201.0


def test_doc_section_replaced_in_place(tmp_path):
    doc = tmp_path / "b.md"
    doc.write_text("# B\n\nbefore\n\n<!-- synth:begin -->\nold\n<!-- synth:end -->\n\nafter\n")
    write_doc_section(doc, "new table\n")
    assert doc.read_text() == "# B\n\nbefore\n\n<!-- synth:begin -->\nnew table\n<!-- synth:end -->\n\nafter\n"
    other = tmp_path / "c.md"
    other.write_text("# C\n")
    write_doc_section(other, "t\n")
    assert other.read_text() == "# C\n\n<!-- synth:begin -->\nt\n<!-- synth:end -->\n"


def test_block_with_more_ports_than_pins_is_placed_out_of_context(tmp_path):
    """The register bank (613 port bits with the dense and matcher options' fields, more than any ECP5 package's
    I/O) still gets an fmax, marked so."""
    import re

    r = synth_block("register_bank", tmp_path, pnr=True)
    assert "out_of_context" in r, r.get("ecp5_device")
    m = re.match(r"(\d+) port bits, more than the (\d+) I/O", r["out_of_context"])
    assert m and int(m.group(1)) > int(m.group(2)), r["out_of_context"]
    assert "--out-of-context" in r["ecp5_device"]
    f = r["fmax"]["clk"]
    assert f["achieved"] is not None and 50.0 < f["achieved"] < 1000.0, f
    assert r["ecp5"]["TRELLIS_FF"] == r["summary"]["FF"], (r["ecp5"], r["summary"])
    md = table([r])
    assert "(out of context)" in md and "Placed out of context" in md


def test_merged_runs_keep_report_order_and_the_later_result(tmp_path):
    from eyestereo.hdl.flow.synth import merge_input, merge_results

    first = [dict(label="sobel", lut=1), dict(label="line_delay", lut=2)]
    second = [dict(label="sobel", lut=3), dict(label="stereo_frontend single-clock", lut=4)]
    got = merge_results([first, second])
    assert [r["label"] for r in got] == ["line_delay", "sobel", "stereo_frontend single-clock"]
    assert [r["lut"] for r in got] == [2, 3, 4]
    with pytest.raises(ValueError, match="no longer has: gone"):
        merge_results([[dict(label="gone")]])
    bad = tmp_path / "r.json"
    bad.write_text('{"label": 1}')
    with pytest.raises(ValueError, match="not a resources.json of make synth"):
        merge_input(bad)
    with pytest.raises(ValueError, match="not a readable resources.json"):
        merge_input(tmp_path / "missing.json")
