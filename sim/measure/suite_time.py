"""Time ``make test``'s pytest run and write the figures to ``docs/suite.md``.

``python -m eyestereo.sim.measure.suite_time [--out docs/suite.md] [--jobs 2]`` runs the suite exactly as
``make test`` does (``pytest -n JOBS --dist worksteal``), in a child process, and records its wall time,
the CPU time of all its processes (workers and simulators), the number of tests, and the slowest tests
by pytest's own ``--durations``; every test's time (setup, call and teardown) goes to ``tests/durations.json``, by
which ``tests/conftest.py`` starts the longest tests first and ``make test GROUP=k/N`` (pytest-split) balances its
groups. Measure on a quiet machine: tests run beside other
work take several times longer. The document is written only after a run in which every test passed.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

from eyestereo.tools.io import atomic_write_text
from eyestereo.tools.reports import publish

ROOT = Path(__file__).resolve().parents[2]
SLOWEST = 15


def run(jobs: int) -> dict:
    cmd = [sys.executable, "-m", "pytest", "-n", str(jobs), "--dist", "worksteal", "--durations=0",
           "--durations-min=0", "-q", "-p", "no:cacheprovider"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    out = r.stdout
    summary = re.findall(r"^=*\s*(\d+ passed.*?) in ([\d.]+)s", out, re.M)
    slow = re.findall(r"^([\d.]+)s (call|setup|teardown)\s+(\S+)", out, re.M)
    every: dict[str, float] = {}
    for sec, _, test in slow:
        every[test] = round(every.get(test, 0.0) + float(sec), 2)
    return dict(rc=r.returncode, wall=wall, cpu=cpu, summary=summary[-1][0] if summary else "?",
                pytest_s=float(summary[-1][1]) if summary else None, slow=slow[:SLOWEST], every=every,
                cmd=" ".join(cmd[2:]),
                tail=(out + r.stderr).strip().splitlines()[-5:])


def document(res: dict, jobs: int) -> str:
    m, s = divmod(round(res["wall"]), 60)
    cm, cs = divmod(round(res["cpu"]), 60)
    lines = ["# Time of `make test`", "",
             f"Measured by `python -m eyestereo.sim.measure.suite_time` ({Path(__file__).name}) "
             f"on {datetime.date.today()}: "
             f"`pytest {res['cmd']}` as `make test` runs it, {os.cpu_count()} CPUs, "
             f"{platform.python_implementation()} {platform.python_version()}.", "",
             "| figure | value |", "|---|---:|",
             f"| tests | {res['summary']} |",
             f"| wall time | {m} min {s:02d} s |",
             f"| CPU time (all processes: workers and simulators) | {cm} min {cs:02d} s |",
             f"| workers | {jobs} |", "",
             "Set-up (venv, pip, GHDL from apt) is not counted: on a fresh machine `make test` adds it once.", "",
             f"## The {len(res['slow'])} slowest tests (pytest's `--durations`)", "",
             "| seconds | phase | test |", "|---:|---|---|"]
    lines += [f"| {sec} | {phase} | `{test}` |" for sec, phase, test in res["slow"]]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Time make test's pytest run and write docs/suite.md.")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "suite.md")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--durations", type=Path, default=ROOT / "tests" / "durations.json",
                    help="every test's time, which tests/conftest.py orders the suite by and pytest-split groups it by")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        print("suite_time: --jobs must be at least 1", file=sys.stderr)
        return 2
    res = run(args.jobs)
    if res["rc"] != 0:
        print(f"suite_time: the suite failed (exit {res['rc']}); nothing written. Last lines:\n" +
              "\n".join(res["tail"]), file=sys.stderr)
        return 1
    publish(document(res, args.jobs), args.out)
    atomic_write_text(args.durations, json.dumps(dict(sorted(res["every"].items())), indent=0) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
