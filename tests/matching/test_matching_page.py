"""docs/matching.md is rewritten whole by tools/reports/bench_matching.py; its hardware part (the matcher on the
FPGA, filled by sim/measure/bench_matcher.py) must survive that."""

from pathlib import Path

from eyestereo.tools.reports import bench_matching as B

ROOT = Path(__file__).resolve().parents[2]


def test_the_hardware_part_is_carried_over(tmp_path):
    page = tmp_path / "matching.md"
    page.write_text(f"# old\n\nbefore\n{B.HARDWARE_BEGIN}\n## In hardware\nkept 123\n{B.HARDWARE_END}\nafter\n")
    part = B.hardware_part(page)
    assert part == f"{B.HARDWARE_BEGIN}\n## In hardware\nkept 123\n{B.HARDWARE_END}"
    assert "{hardware}" in B.TEMPLATE  # the page is made with it


def test_a_page_without_the_part_gets_empty_markers(tmp_path):
    assert B.hardware_part(tmp_path / "missing.md") == f"{B.HARDWARE_BEGIN}\n{B.HARDWARE_END}"
    (tmp_path / "plain.md").write_text("# no part\n")
    assert B.hardware_part(tmp_path / "plain.md") == f"{B.HARDWARE_BEGIN}\n{B.HARDWARE_END}"


def test_the_page_has_its_hardware_part_and_the_engines_section():
    text = (ROOT / "docs" / "matching.md").read_text()
    part = B.hardware_part(ROOT / "docs" / "matching.md")
    assert part in text and "match_engine" in part
    assert "<!-- bench_matcher: begin -->" in part and "<!-- bench_matcher: end -->" in part
