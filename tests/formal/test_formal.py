"""``make formal`` in ``make test``: every property set proven and covered, every mutant rejected (docs/formal.md).

The proofs run on MyHDL's Verilog conversion of each block with SymbiYosys (k-induction, yices); a
mutant is an edit of the converted Verilog that the proof must reject, so a vacuous property fails here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RUN = ROOT / "formal" / "run.py"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(RUN), *args], cwd=ROOT, capture_output=True, text=True, timeout=900)


@pytest.mark.sim
def test_every_property_set_is_proven_and_covered():
    r = run()
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    table = (ROOT / "build" / "formal" / "summary.md").read_text()
    jobs = run("--list").stdout.split()
    for job in ("word_cdc", "async_fifo", "line_delay"):
        assert job in jobs
        rows = [ln for ln in table.splitlines() if ln.startswith(f"| {job} |")]
        assert len(rows) == 2 and all("| PASS |" in ln for ln in rows), rows
        assert any("prove, k-induction" in ln for ln in rows) and any("cover" in ln for ln in rows)


@pytest.mark.sim
def test_every_mutant_is_rejected():
    r = run("--mutants")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    table = (ROOT / "build" / "formal" / "mutants.md").read_text()
    rows = [ln for ln in table.splitlines() if "mutant:" in ln]
    assert len(rows) >= 6 and all("rejected (FAIL)" in ln for ln in rows), rows


def test_an_unknown_job_is_one_line_and_status_2():
    r = run("no_such_job")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "no_such_job" in r.stderr, r.stderr
