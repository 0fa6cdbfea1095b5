"""README's block table quotes the resources and fmax that make synth measured (docs/benchmarks.md).

Each block row's resources cell opens with the default configuration's figures: the first ``N LUT``,
``N FF`` and ``N RAMB16`` / ``N MULT`` and ``F MHz on ECP5`` it names must be that configuration's row
of the synth table, so a new synthesis run that changes a figure fails here until the README follows.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def synth_rows() -> dict[str, dict]:
    """label -> figures of docs/benchmarks.md's synth table."""
    text = (ROOT / "docs" / "benchmarks.md").read_text()
    section = text[text.index("<!-- synth:begin -->"):text.index("<!-- synth:end -->")]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 10 and cells[1].isdigit():
            rows[cells[0]] = dict(LUT=int(cells[1]), LUTRAM=int(cells[2]), FF=int(cells[3]), RAMB16=int(cells[4]),
                                  MULT=int(cells[5]), fmax=cells[8])
    return rows


def readme_rows() -> dict[str, str]:
    """block -> resources cell of README's block table (rows whose first cell is a catalogue block)."""
    text = (ROOT / "README.md").read_text()
    out = {}
    for line in text.splitlines():
        m = re.match(r"^\| `(\w+)` \|", line)
        if m:
            # a cell may hold an escaped pipe (a backslash before it): split on the others only
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
            if len(cells) == 4:
                out[m.group(1)] = cells[3]
    return out


SYNTH = synth_rows()
README = readme_rows()
BLOCKS = sorted(b for b in README if b in SYNTH)


def test_the_tables_were_found():
    assert len(SYNTH) >= 30 and len(BLOCKS) >= 20, (len(SYNTH), BLOCKS)


def _first(cell: str, unit: str) -> int | None:
    m = re.search(r"(\d+) " + unit + r"\b", cell)
    return int(m.group(1)) if m else None


@pytest.mark.parametrize("block", BLOCKS)
def test_readme_quotes_make_synth(block):
    cell, row = README[block], SYNTH[block]
    lut = _first(cell, "LUT")
    assert lut == row["LUT"], f"README {block}: {lut} LUT, make synth: {row['LUT']} (docs/benchmarks.md)"
    for unit, key in (("FF", "FF"), ("RAMB16", "RAMB16"), ("MULT", "MULT")):
        got = _first(cell, unit)
        if got is not None:
            assert got == row[key], f"README {block}: {got} {unit}, make synth: {row[key]}"
    m = re.search(r"LUT \+ (\d+) LUT-RAM", cell)
    if m:
        assert int(m.group(1)) == row["LUTRAM"], f"README {block}: {m.group(1)} LUT-RAM, make synth: {row['LUTRAM']}"
    for mhz in re.findall(r"(\d+(?:\.\d+)?) MHz on ECP5", cell) + re.findall(r"ECP5 (\d+(?:\.\d+)?) MHz", cell):
        measured = [float(v) for v in re.findall(r"\d+\.\d+", row["fmax"])]
        assert any(abs(float(mhz) - v) < (0.06 if "." in mhz else 0.51) for v in measured), (
            f"README {block}: {mhz} MHz on ECP5, make synth: {row['fmax']}")
