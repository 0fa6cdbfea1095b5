"""SDRAM controller benchmark: bandwidth per access pattern at 100 and 133 MHz, refresh counted; resources.

``python -m eyestereo.sim.measure.bench_sdram --out docs/memory.md [--quick] [--synth]`` runs the SDRAM
controller's bench (:mod:`eyestereo.sim.benches.tb_sdram_controller`) on GHDL with the ULX3S's part as its
datasheet gives it (AS4C32M16SB-7: the 200 us power-up wait, tREFI 7.8 us), at 100 MHz with CAS latency 2
and at 133 MHz with CAS latency 3, each access pattern offered without pause for ``--clocks`` clocks after
the power-up sequence (the model checks every rule and the scoreboard every read word meanwhile):

* ``seq8``: reads in sequential bursts of 8 words (row after row, bank after bank);
* ``row``: reads of whole rows (1024-word bursts);
* ``mixed``: a writer and a reader taking turns with bursts of 8, each sequential, one bank apart;
* ``single``: reads of single words at random addresses (a row miss almost every time);
* ``seq1``, ``wseq1``: reads, writes of single words at sequential addresses (one-word bursts, as
  ``sdram_bridge`` gives the SRAM arbiter's words).

Words per clock count every word the port moved in the window (read words returned, write words taken);
MB/s is that times 2 bytes times the clock. ``--synth`` adds the controller's resources (Yosys: Spartan-3E
and ECP5) and fmax on the ECP5 (LFE5U-25F) over nextpnr seeds 1-4. The tables go into the ``bench_sdram`` section of
the page given by ``--out``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from eyestereo.sim.lib.runner import BUILD, hdl_revision, run_bench
from eyestereo.tools.reports import markdown_table, publish
from eyestereo.tools.sdram import ULX3S, part as sdram_part

NAME = "sdram_controller"

PATTERNS = ("seq8", "row", "mixed", "single", "seq1", "wseq1")
WHAT = {"seq8": "reads, sequential bursts of 8", "row": "reads, whole rows (1024 words)",
        "mixed": "write 8 / read 8 in turn, two sequential streams", "single": "reads, single words, random addresses",
        "seq1": "reads, single words, sequential addresses", "wseq1": "writes, single words, sequential addresses"}
CLOCKS = ((100.0, 2), (133.0, 3))
BEGIN, END = "<!-- bench_sdram: begin -->", "<!-- bench_sdram: end -->"


def bandwidth(clocks: int) -> list[dict]:
    p = sdram_part(ULX3S)
    rows = []
    for mhz, cl in CLOCKS:
        t = time.time()
        rep = run_bench(NAME, "tb_sdram_controller", dict(patterns=list(PATTERNS), seeds=[1], clocks=clocks),
                        name=f"bench_{int(mhz)}mhz_cl{cl}",
                        params=dict(part=ULX3S, clock_mhz=mhz, cas_latency=cl, max_burst=p.columns), sim="ghdl")
        wall = time.time() - t
        for r in rep["runs"]:
            words = r["words_read"] + r["words_written"]
            per = words / r["clocks"]
            rows.append(dict(mhz=mhz, cl=cl, pattern=r["pattern"], clocks=r["clocks"], words=words, per_clock=per,
                             mbs=per * p.data_bits / 8 * mhz, refreshes=r["refreshes"], late=r["late"],
                             max_owed=r["max_owed"], violations=len(r["violations"]), wall_s=wall))
    return rows


def synth(out: Path) -> list[dict]:
    from eyestereo.hdl.flow import synth as flow

    res = []
    for mhz, cl in CLOCKS:
        label = f"sdram_{int(mhz)}mhz_cl{cl}"
        job = flow.prepare(NAME, out, label=label, part=ULX3S, clock_mhz=mhz, cas_latency=cl, max_burst=8)
        r = dict(job, **flow.xc3se(job))
        r.update(flow.ecp5_seeds(job, freq=mhz, seeds=flow.SEEDS))
        res.append(dict(mhz=mhz, cl=cl, xc3se=r["summary"], ecp5=r["ecp5"], fmax=r["fmax"]["clk"]))
    return res


def report(rows: list[dict], syn: list[dict] | None, clocks: int) -> str:
    p = sdram_part(ULX3S)
    lines = [f"Measured by `python -m eyestereo.sim.measure.bench_sdram` (HDL {hdl_revision()}): the ULX3S's "
             f"{p.name} with its datasheet figures (tREFI {p.t_refi:.1f} ns, power-up {p.powerup_us:.0f} us), "
             f"{clocks} clocks per pattern after the power-up sequence, on GHDL with the SDRAM model checking "
             f"every rule and the scoreboard every read word.", ""]
    lines += markdown_table(
        ["pattern", "clock", "words / clock", "MB/s", "of the peak", "refreshes", "late", "rules broken"],
        [[WHAT[r["pattern"]], f"{r['mhz']:.0f} MHz, CL {r['cl']}", f"{r['per_clock']:.3f}", f"{r['mbs']:.0f}",
          f"{100 * r['per_clock']:.1f} %", r["refreshes"], r["late"], r["violations"]] for r in rows])
    lines += ["", "The peak is a word per clock: 200 MB/s at 100 MHz, 266 MB/s at 133 MHz. The bench was built "
              f"with max_burst {p.columns} (a whole row) for every pattern; the other patterns ask for 8 or 1.", ""]
    if syn:
        lines += markdown_table(
            ["configuration", "Spartan-3E LUT / FF", "ECP5 LUT4 / FF", "ECP5 LFE5U-25F fmax min / median / max (seeds 1-4)"],
            [[f"{s['mhz']:.0f} MHz, CL {s['cl']}, max_burst 8", f"{s['xc3se'].get('LUT', 0)} / {s['xc3se'].get('FF', 0)}",
              f"{s['ecp5'].get('TRELLIS_COMB', 0)} / {s['ecp5'].get('TRELLIS_FF', 0)}",
              f"{s['fmax']['min']:.1f} / {s['fmax']['median']:.1f} / {s['fmax']['max']:.1f} MHz"] for s in syn])
        lines.append("")
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="the page whose bench_sdram section to fill (e.g. docs/memory.md)")
    ap.add_argument("--clocks", type=int, default=20000, help="clocks per pattern (default 20000: ~25 refreshes)")
    ap.add_argument("--quick", action="store_true", help="2000 clocks per pattern")
    ap.add_argument("--synth", action="store_true", help="also resources and ECP5 fmax (Yosys, nextpnr seeds 1-4)")
    a = ap.parse_args(argv)
    clocks = 2000 if a.quick else a.clocks
    rows = bandwidth(clocks)
    syn = synth(BUILD.parent / "bench_sdram" / "synth") if a.synth else None
    publish(report(rows, syn, clocks), a.out, BEGIN if a.out else None, END if a.out else None)


if __name__ == "__main__":
    main()
