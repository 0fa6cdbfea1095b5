"""``make test GROUP=k/N``: the regression in N groups for N machines, checked and timed (issue 25, item 4).

The groups are pytest-split's (``--splits N --group k``, algorithm ``least_duration``: the tests taken longest
first, each into the group with the least recorded time so far) over ``tests/durations.json``, every test's time
as ``make test-time`` recorded it; a test without a record counts the mean of the others. The othersims tests are
left out before the split (tests/conftest.py), so the N groups together are exactly ``make test``'s tests.

``python -m eyestereo.sim.measure.test_groups --check k/N``: a one-line error and exit status 2 unless GROUP
is ``k/N`` with 1 <= k <= N (what ``make test`` calls first). ``--collect N``: each group's tests (pytest's
``--collect-only``), checked to be disjoint and together the whole suite. ``--run N [--out docs/suite.md]``:
also runs each group as ``make test GROUP=k/N`` would (one after the other on this machine: the figures are each
group's wall time), and writes the table into its section of ``--out``.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

from eyestereo.tools.reports import markdown_table, publish

ROOT = Path(__file__).resolve().parents[2]
DURATIONS = ROOT / "tests" / "durations.json"
BEGIN, END = "<!-- test_groups: begin -->", "<!-- test_groups: end -->"
MAX_GROUPS = 64


def parse_group(text: str) -> tuple[int, int]:
    """``"k/N"`` -> (k, N); ValueError with the reason for anything else."""
    m = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", str(text))
    if not m:
        raise ValueError(f"GROUP={text!r}: want k/N, e.g. GROUP=2/4 (group 2 of 4)")
    k, n = int(m.group(1)), int(m.group(2))
    if not 1 <= n <= MAX_GROUPS:
        raise ValueError(f"GROUP={text}: N must be 1..{MAX_GROUPS}")
    if not 1 <= k <= n:
        raise ValueError(f"GROUP={text}: k must be 1..{n} (the groups are numbered from 1)")
    return k, n


def split_args(k: int, n: int) -> list[str]:
    """pytest's arguments for group k of n (the Makefile's ``SPLIT``)."""
    return ["--splits", str(n), "--group", str(k), "--splitting-algorithm", "least_duration", "--durations-path",
            str(DURATIONS)]


def collect(k: int | None = None, n: int | None = None) -> list[str]:
    """The node ids ``make test`` (k None) or its group k of n runs, by pytest's ``--collect-only``."""
    cmd = [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"]
    if k is not None:
        cmd += split_args(k, n)
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"pytest --collect-only failed (exit {r.returncode}): {(r.stdout + r.stderr)[-400:]}")
    return [line.strip() for line in r.stdout.splitlines() if "::" in line and not line.startswith(" ")]


def recorded() -> dict[str, float]:
    return json.loads(DURATIONS.read_text()) if DURATIONS.is_file() else {}


def check_groups(n: int, whole: list[str] | None = None) -> dict:
    """Every group of n: its tests, checked disjoint and together the whole suite (``whole``: make test's tests,
    collected when not given); their recorded seconds."""
    whole = collect() if whole is None else whole
    groups = [collect(k, n) for k in range(1, n + 1)]
    seen: dict[str, int] = {}
    for k, g in enumerate(groups, 1):
        for t in g:
            if t in seen:
                raise AssertionError(f"{t} is in groups {seen[t]} and {k} of {n}")
            seen[t] = k
    if set(seen) != set(whole):
        missing, extra = sorted(set(whole) - set(seen)), sorted(set(seen) - set(whole))
        raise AssertionError(f"the {n} groups miss {len(missing)} of make test's tests ({missing[:3]}) and add "
                             f"{len(extra)} ({extra[:3]})")
    dur = recorded()
    mean = sum(dur.values()) / len(dur) if dur else 0.0
    return dict(n=n, tests=[len(g) for g in groups], whole=len(whole),
                recorded_s=[round(sum(dur.get(t, mean) for t in g), 1) for g in groups])


def run_group(k: int, n: int, jobs: int) -> dict:
    """One group as ``make test GROUP=k/n`` runs it (pytest -n jobs --dist worksteal); its wall time and result."""
    cmd = [sys.executable, "-m", "pytest", "-n", str(jobs), "--dist", "worksteal", "-q", "-p", "no:cacheprovider",
           *split_args(k, n)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    summary = re.findall(r"^=*\s*(\d+ passed[^=]*?) in ([\d.]+)s", r.stdout, re.M)
    return dict(k=k, rc=r.returncode, wall=round(wall, 1), summary=summary[-1][0] if summary else "?")


def document(groups: list[dict], runs: list[dict] | None, n_run: int | None, jobs: int) -> str:
    out = ["", "Measured by `python -m eyestereo.sim.measure.test_groups` (generated; do not edit): `make test "
           "GROUP=k/N` for N = 1..4, pytest-split's least-duration groups over tests/durations.json; each N's groups "
           "checked disjoint and together make test's tests.", ""]
    rows = []
    for g in groups:
        lo, hi = min(g["recorded_s"]), max(g["recorded_s"])
        rows.append([g["n"], g["whole"], " / ".join(map(str, g["tests"])),
                     " / ".join(f"{s:.0f}" for s in g["recorded_s"]), f"{100 * (hi - lo) / hi:.0f} %" if hi else "-"])
    out += markdown_table(["N", "tests", "tests per group", "recorded seconds per group", "spread (max - min) / max"],
                          rows)
    if runs:
        walls = [r["wall"] for r in runs]
        out += ["", f"Each group of N = {n_run} run on this machine one after the other as `make test GROUP=k/{n_run}` "
                f"runs it ({jobs} workers):", ""]
        out += markdown_table(["group", "result", "wall (s)"], [[r["k"], r["summary"], r["wall"]] for r in runs])
        out += ["", f"Spread of the wall times: {100 * (max(walls) - min(walls)) / max(walls):.0f} % "
                f"(max {max(walls):.0f} s, min {min(walls):.0f} s)."]
    return "\n".join(out) + "\n\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", metavar="k/N", help="check a GROUP value (exit 2 with the reason when bad)")
    ap.add_argument("--collect", type=int, metavar="N", help="check the groups of N = 1..N (collection only)")
    ap.add_argument("--run", type=int, metavar="N", help="also run every group of this N, one after the other")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="write the table into this page's section (docs/suite.md)")
    args = ap.parse_args(argv)
    if args.check is not None:
        try:
            parse_group(args.check)
        except ValueError as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
        return 0
    top = args.collect or args.run or 4
    if not 1 <= top <= MAX_GROUPS or (args.run is not None and not 1 <= args.run <= MAX_GROUPS):
        print(f"error: N must be 1..{MAX_GROUPS}", file=sys.stderr)
        return 2
    whole = collect()
    groups = [check_groups(n, whole) for n in range(1, top + 1)]
    runs = [run_group(k, args.run, args.jobs) for k in range(1, args.run + 1)] if args.run else None
    if runs and any(r["rc"] for r in runs):
        print(f"error: a group failed: {[r for r in runs if r['rc']]}", file=sys.stderr)
        return 1
    publish(document(groups, runs, args.run, args.jobs), args.out, BEGIN if args.out else None,
            END if args.out else None)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
