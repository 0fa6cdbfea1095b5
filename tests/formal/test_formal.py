"""``make formal`` in ``make test``: the fast property sets proven and covered, their mutants rejected (docs/formal.md).

The proofs run on MyHDL's Verilog conversion of each block with SymbiYosys (k-induction or a bounded check,
yices); a mutant is an edit of the converted Verilog that the proof must reject, so a vacuous property
fails here. The slow jobs (SLOW) run only in ``make formal``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RUN = ROOT / "formal" / "run.py"
#: the jobs run here: each proof + cover and its mutants take 3 to 9 s (conversion included) on a quiet machine
FAST = ("word_cdc", "async_fifo", "line_delay", "line_delay_stereo", "stream_checker", "stream_checker_repair",
        "cornerness", "prethreshold", "prethreshold_blocks", "stream_to_axis", "axis_to_stream", "stream_cdc",
        "sram_controller", "sobel", "double_buffer", "async_fifo_frames", "stream_cdc_tokens",
        "queue_slice", "stream_checker_stereo", "stream_checker_stereo_repair", "cornerness_stereo",
        "cornerness_stereo_share2", "cornerness_stereo_share3", "prethreshold_stereo", "prethreshold_blocks_stereo",
        "feature_list_fifo", "camera_stream")
#: jobs only in `make formal`, left out so that this file stays under about a minute (about 9 s each with
#: their mutants): register_bank (the whole register map's conversion), frontend_sequencer (k = 20, three
#: mutants); the window filters but sobel (window_props.vh, as sobel: 10 to 90 s each with their mutants, the
#: stereo ones' covers run a whole stereo frame and its tail)
SLOW: tuple[str, ...] = ("register_bank", "frontend_sequencer", "sobel_stereo", "sobel_stereo_share2", "nms",
                         "nms_stereo", "harris_window", "harris_window_stereo", "convolve",
                         # the SRAM arbiter: about 10 s (k = 8 on the whole arbiter) and 45 s (bmc depth 22);
                         # the non-urgent masters' bound and turns: about 1 to 3 min each (bmc depth 28 / 20)
                         "sram_arbiter", "sram_arbiter_wait", "sram_arbiter_fair", "sram_arbiter_turns",
                         # async_fifo_frames' port properties alone: bmc depth 26 (its mutants five times that)
                         "async_fifo_frames_port",
                         # feature_list's lists: the induction step on the whole block, about 20 to 30 s
                         "feature_list")


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(RUN), *args], cwd=ROOT, capture_output=True, text=True, timeout=900)


def test_the_fast_and_slow_lists_name_every_job():
    listed = {ln.split()[0] for ln in run("--list").stdout.splitlines() if ln.strip()}
    assert listed == set(FAST) | set(SLOW), listed ^ (set(FAST) | set(SLOW))


@pytest.mark.sim
def test_every_fast_property_set_is_proven_and_covered():
    r = run(*FAST)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    table = (ROOT / "build" / "formal" / "summary.md").read_text()
    for job in FAST:
        rows = [ln for ln in table.splitlines() if ln.startswith(f"| {job} |")]
        assert len(rows) == 2 and all("| PASS |" in ln for ln in rows), rows
        assert any("| prove, k-induction" in ln or "| bmc, depth" in ln for ln in rows)
        assert any("| cover, depth" in ln for ln in rows)


@pytest.mark.sim
def test_every_fast_mutant_is_rejected():
    r = run("--mutants", *FAST)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    table = (ROOT / "build" / "formal" / "mutants.md").read_text()
    for job in FAST:
        rows = [ln for ln in table.splitlines() if ln.startswith(f"| {job} mutant:")]
        assert rows and all("rejected (FAIL)" in ln for ln in rows), (job, rows)


def test_an_unknown_job_is_one_line_and_status_2():
    r = run("no_such_job")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "no_such_job" in r.stderr, r.stderr
