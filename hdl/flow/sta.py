"""Logic depth and an estimated clock period of a Yosys ``synth_xilinx -family xc3se`` netlist.

There is no open place-and-route for the Spartan-3E, so this is an *estimate*, not a timing sign-off:
the longest register-to-register path of the mapped netlist (Yosys ``write_json``), weighed with the
XC3S500E -4 speed grade's cell delays from its data sheet and one fixed delay per net (no placement,
no fan-out model). It shows how many LUT levels a block has between flip-flops and where its longest
path runs; a real place-and-route adds routing that depends on the placement.

``python -m eyestereo.hdl.flow.sta --block NAME`` prints the estimate and the path.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from functools import cache
from pathlib import Path

#: Spartan-3E -4 cell delays in ns (data sheet DS312 switching characteristics; rounded): LUT input to
#: output (T_ILO), the F5/FX muxes, the carry chain per bit, XOR of the carry chain, a flip-flop's clock
#: to output (T_CKO) and its setup (T_DICK / T_CECK), distributed RAM read (like a LUT).
DELAY = {"LUT": 0.66, "MUXF": 0.45, "MUXCY": 0.08, "MUXCY_IN": 0.70, "XORCY": 0.75, "INV": 0.66,
         "CKO": 0.60, "SETUP": 0.55, "RAM": 0.66}
#: Assumed delay of one net between slices (the part that placement decides).
NET = 0.70

SEQ = ("FDRE", "FDSE", "FDCE", "FDPE", "FD", "FDR", "FDS", "FDE")


def _kind(t: str) -> str:
    if t.startswith("LUT"):
        return "LUT"
    if t.startswith("MUXF"):
        return "MUXF"
    if t.startswith("RAM"):
        return "RAM"
    return t


def analyse(netlist: dict, top: str) -> dict:
    """Longest flip-flop/port to flip-flop/port path of ``top`` (a Yosys JSON netlist)."""
    mod = netlist["modules"][top]
    names = {}
    for n, v in mod["netnames"].items():
        for b in v["bits"]:
            if isinstance(b, int) and (b not in names or not n.startswith("$")):
                names[b] = n
    drivers: dict[int, tuple[str, str]] = {}
    cells = mod["cells"]
    for cn, c in cells.items():
        for port, d in c["port_directions"].items():
            if d == "output":
                for b in c["connections"][port]:
                    if isinstance(b, int):
                        drivers[b] = (cn, port)
    sinks = defaultdict(list)
    for cn, c in cells.items():
        for port, d in c["port_directions"].items():
            if d == "input":
                for b in c["connections"][port]:
                    if isinstance(b, int):
                        sinks[cn].append((port, b))

    @cache
    def arrival(bit: int) -> tuple[float, tuple]:
        """Arrival time at a net and the path (cell names) that sets it."""
        if bit not in drivers:
            return 0.0, ()                      # a top-level input: registered outside
        cn, port = drivers[bit]
        t = cells[cn]["type"]
        k = _kind(t)
        if t in SEQ or t == "BUFG":
            return DELAY["CKO"], (cn,)
        if k == "RAM" and port in ("SPO", "DPO", "O"):
            # asynchronous read: SPO (RAM16X1D) and O (RAM16X1S) from the address A*, DPO from the read
            # address DPRA*; never from D or WE (a read-modify-write through the RAM is no loop)
            pre = "DPRA" if port == "DPO" else "A"
            ins = [b for p, b in sinks[cn] if p.startswith(pre) and not (pre == "A" and p.startswith("ADDR"))]
            best = max((arrival(b) for b in ins), default=(0.0, ()))
            return best[0] + NET + DELAY["RAM"], best[1] + (cn,)
        best = (0.0, ())
        for p, b in sinks[cn]:
            a = arrival(b)
            # carry-chain and in-slice mux inputs need no general routing
            if k == "MUXCY" and p == "CI" or k == "XORCY" and p == "CI" or k == "MUXF" and p in ("I0", "I1"):
                tin = a[0]
            else:
                tin = a[0] + NET
            if tin > best[0]:
                best = (tin, a[1])
        d = DELAY["MUXCY"] if k == "MUXCY" else DELAY.get(k, DELAY["LUT"])
        return best[0] + d, best[1] + (cn,)

    sys.setrecursionlimit(100000)
    worst = (0.0, (), "")
    for cn, c in cells.items():
        if c["type"] in SEQ:
            for p, b in sinks[cn]:
                if p == "C":
                    continue
                a = arrival(b)
                t = a[0] + NET + DELAY["SETUP"]
                if t > worst[0]:
                    worst = (t, a[1] + (cn,), p)
    luts = sum(1 for cn in worst[1] if _kind(cells[cn]["type"]) in ("LUT", "RAM", "INV"))
    path = [f"{cells[cn]['type']}:{cn}" for cn in worst[1]]
    return dict(period_ns=round(worst[0], 2), fmax_mhz=round(1000 / worst[0], 1) if worst[0] else None,
                lut_levels=luts, path=path, endpoint_port=worst[2])


def estimate(name: str, out: Path, *, job: dict | None = None, **params) -> dict:
    """Estimate the clock period of ``name`` on the netlist ``make synth`` maps: the block's VHDL
    synthesized by GHDL (:func:`eyestereo.hdl.flow.synth.prepare`), then Yosys ``synth_xilinx -family xc3se``.
    ``job``: a job :func:`~eyestereo.hdl.flow.synth.prepare` made already (its netlist is reused)."""
    from eyestereo.hdl.flow.synth import prepare, yosys

    if job is None:
        job = prepare(name, Path(out), label=f"sta_{name}", **params)
    d = Path(job["dir"])
    yosys(f"read_verilog {job['netlist']}; synth_xilinx -family xc3se -noiopad -top {name}; "
           f"write_json xc3se_netlist.json", d, "yosys_sta.log")
    res = analyse(json.loads((d / "xc3se_netlist.json").read_text()), name)
    res["block"] = name
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Estimate a block's clock period on the Spartan-3E -4 (no P&R).")
    ap.add_argument("--block", required=True)
    ap.add_argument("--out", default="build/synth", type=Path)
    args = ap.parse_args(argv)
    try:
        res = estimate(args.block, args.out)
    except (RuntimeError, ValueError) as e:
        print(f"timing: {e}", file=sys.stderr)
        return 1
    print(f"{res['block']}: {res['period_ns']} ns ({res['fmax_mhz']} MHz estimated), {res['lut_levels']} LUT levels")
    for p in res["path"]:
        print("   ", p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
