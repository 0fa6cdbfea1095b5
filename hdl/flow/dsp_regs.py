"""Move flip-flops into the ECP5 multipliers' own registers (a netlist pass between Yosys and nextpnr).

Yosys ``synth_ecp5`` maps every ``*`` to a MULT18X18D with its registers off, and leaves the operand and
product registers of the design in slices. A path from such a register through the multiplier into the next
one is then flip-flop, routing to the DSP column, 3.9 ns of multiplier, routing back: in the whole front end
the two routes alone took 5 to 6 ns, more than the multiplier (issue 23). The MULT18X18D has input
registers (A, B) and an output register with clock, clock-enable and reset selects; nextpnr-ecp5 times them
(its ``MULT18X18D_REGS_INPUT / _OUTPUT / _ALL`` classes). This pass, on the JSON netlist of
``synth_ecp5``:

* **inputs**: when every non-constant bit of both A and B comes from a flip-flop (``TRELLIS_FF`` Q) with
  one clock, no reset (LSR tied 0), and per operand one clock enable (or none), and the constant bits are
  0, the multiplier takes the flip-flops' D nets into its input registers; a flip-flop that then drives
  nothing else is removed (one that drives other cells too stays: its copy inside the DSP is a duplicate);
* **output**: when every product bit that is used drives exactly one flip-flop's D and nothing else, with
  one clock and no reset, the output register takes their place and the flip-flops are removed.

A register in the DSP starts at 0 like the slice flip-flops it replaces (``REGSET RESET``, no init value),
takes the same clock and enable, so the design's function is unchanged, cycle for cycle. Only the ECP5
placement of ``make synth`` uses the result; the Spartan-3E counts come from a separate Yosys run.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["ff_kind", "net_maps", "pack_dsp_registers", "pack_file"]

DSP = "MULT18X18D"
FF = "TRELLIS_FF"
WIDTH = 18


def _is_const(bit) -> bool:
    return isinstance(bit, str)


def ff_kind(cell: dict) -> tuple | None:
    """(clock net, enable net, '1' or ('INV', net)) of a plain flip-flop: rising edge, no reset, no initial
    value; else None."""
    p, c = cell["parameters"], cell["connections"]
    if p.get("CLKMUX", "CLK").strip() != "CLK" or c.get("LSR", ["0"]) != ["0"]:
        return None
    if p.get("REGSET", "RESET").strip() != "RESET" or "INIT" in p:
        return None
    ce = p.get("CEMUX", "CE").strip()
    if ce == "1":
        en = "1"
    elif ce == "CE":
        en = c["CE"][0]
    elif ce == "INV":  # enabled while the net is low: the DSP gets an inverter (one LUT) on its CE pin
        en = ("INV", c["CE"][0])
    else:
        return None
    return c["CLK"][0], en


def net_maps(mod: dict) -> tuple[dict, dict]:
    """(drivers, loads) of a Yosys JSON module: net -> (cell, port), net -> [(cell, port, bit index)];
    the module's ports appear as cell ``$port``."""
    drivers: dict = {}
    loads: dict = {}
    for name, cell in mod["cells"].items():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            for i, b in enumerate(bits):
                if _is_const(b):
                    continue
                if dirs.get(port) == "output":
                    drivers[b] = (name, port)
                else:
                    loads.setdefault(b, []).append((name, port, i))
    for pname, port in mod.get("ports", {}).items():
        for b in port["bits"]:
            if _is_const(b):
                continue
            if port["direction"] != "input":  # a top-level output reads the net
                loads.setdefault(b, []).append(("$port", pname, 0))
            if port["direction"] != "output":
                drivers[b] = ("$port", pname)
    return drivers, loads


def pack_dsp_registers(netlist: dict, top: str) -> dict:
    """Pack flip-flops into the MULT18X18Ds of module ``top`` in place; returns counts
    (``dsps``, ``input_regs``, ``output_regs``: multipliers given input / output registers,
    ``ffs_removed``)."""
    mod = netlist["modules"][top]
    cells = mod["cells"]
    drivers, loads = net_maps(mod)
    stats = dict(dsps=0, input_regs=0, output_regs=0, ffs_removed=0, inverters=0)
    removed: set = set()
    nets = [b for c in cells.values() for bits in c["connections"].values() for b in bits if not _is_const(b)]
    fresh = [max(nets, default=1) + 1]
    inverted: dict = {}

    def inverter(net):
        """A net that is ``not net`` (one LUT4 per inverted enable, shared by the DSPs that use it)."""
        if net not in inverted:
            out = fresh[0]
            fresh[0] += 1
            cells[f"$dsp_regs$ce_inv${out}"] = dict(
                hide_name=1, type="LUT4", parameters=dict(INIT="0101010101010101"), attributes={},
                port_directions=dict(A="input", B="input", C="input", D="input", Z="output"),
                connections=dict(A=[net], B=["0"], C=["0"], D=["0"], Z=[out]))
            inverted[net] = out
            stats["inverters"] += 1
        return inverted[net]

    def operand(dsp: dict, group: str):
        """(clock, enable, {bit index: FF name}) when the operand's bits all come from plain FFs."""
        clk, en, ffs = None, None, {}
        for i in range(WIDTH):
            b = dsp["connections"].get(f"{group}{i}", ["0"])[0]
            if _is_const(b):
                if b != "0":
                    return None
                continue
            drv = drivers.get(b)
            if drv is None or drv[0] == "$port" or drv[0] in removed or cells[drv[0]]["type"] != FF or drv[1] != "Q":
                return None
            kind = ff_kind(cells[drv[0]])
            if kind is None or (clk is not None and kind != (clk, en)):
                return None
            clk, en = kind
            ffs[i] = drv[0]
        return (clk, en, ffs) if ffs else None

    for name in sorted(cells):
        dsp = cells.get(name)
        if dsp is None or dsp["type"] != DSP:
            continue
        par = dsp["parameters"]
        if any(par.get(k, "NONE").strip() != "NONE" for k in ("REG_INPUTA_CLK", "REG_INPUTB_CLK", "REG_OUTPUT_CLK",
                                                               "REG_PIPELINE_CLK")):
            continue  # registers already in use: leave it
        conn = dsp["connections"]
        slots: dict = {}  # enable net -> its CE pin number (CE0..CE2; CE3 is tied high)
        plan = {}

        a, b = operand(dsp, "A"), operand(dsp, "B")
        if a is not None and b is not None and a[0] == b[0]:
            plan["in"] = (a, b)
        # the output: every used product bit drives one plain FF's D and nothing else
        outs, oclk = {}, None
        for i in range(36):
            p = conn.get(f"P{i}", [None])[0]
            if p is None or _is_const(p):
                continue
            ls = loads.get(p, [])
            if not ls:
                continue
            if len(ls) != 1 or ls[0][0] == "$port" or cells[ls[0][0]]["type"] != FF or ls[0][1] != "DI":
                outs = None
                break
            kind = ff_kind(cells[ls[0][0]])
            if kind is None or (oclk is not None and kind != oclk):
                outs = None
                break
            oclk = kind
            outs[i] = ls[0][0]
        if outs:
            plan["out"] = (oclk, outs)
        if not plan:
            continue
        # one clock for the whole DSP (the front end's multipliers each live in one clock domain)
        clocks = {g[0] for g in plan.get("in", ())} | ({plan["out"][0][0]} if "out" in plan else set())
        if len(clocks) != 1:
            plan.pop("out", None)
            clocks = {g[0] for g in plan.get("in", ())}
            if not plan:
                continue
        clk = clocks.pop()
        conn["CLK0"] = [clk]
        for r in ("RST0", "RST1", "RST2", "RST3"):
            conn[r] = ["0"]

        def enable(net, slots=slots) -> str | None:
            if net == "1":
                return "CE3_ONE"
            if isinstance(net, tuple):
                net = inverter(net[1])
            if net not in slots:
                if len(slots) == 3:
                    return None
                slots[net] = len(slots)
            return f"CE{slots[net]}"

        ok = True
        if "in" in plan:
            (ca, ea, fa), (cb, eb, fb) = plan["in"]
            ce_a, ce_b = enable(ea), enable(eb)
            ok = ce_a is not None and ce_b is not None
        if ok and "out" in plan:
            ce_o = enable(plan["out"][0][1])
            ok = ce_o is not None
        if not ok:  # more enables than the DSP has
            for k in ("CLK0", "RST0", "RST1", "RST2", "RST3"):
                conn.pop(k, None)
            continue
        # CE3 is tied high for the registers that always load; CE0..2 carry the design's enables
        conn["CE3"] = ["1"]
        for net, n in slots.items():
            conn[f"CE{n}"] = [net]

        def ce_name(x: str) -> str:
            return "CE3" if x == "CE3_ONE" else x

        if "in" in plan:
            for group, (_, _, ffs), ce in (("A", plan["in"][0], ce_a), ("B", plan["in"][1], ce_b)):
                for i, ff in ffs.items():
                    conn[f"{group}{i}"] = [cells[ff]["connections"]["DI"][0]]
                    q = cells[ff]["connections"]["Q"][0]
                    loads[q] = [x for x in loads.get(q, []) if not (x[0] == name and x[1] == f"{group}{i}")]
                    loads.setdefault(cells[ff]["connections"]["DI"][0], []).append((name, f"{group}{i}", 0))
                par[f"REG_INPUT{group}_CLK"] = "CLK0"
                par[f"REG_INPUT{group}_CE"] = ce_name(ce)
                par[f"REG_INPUT{group}_RST"] = "RST0"
            for ff in {f for g in plan["in"] for f in g[2].values()}:
                q = cells[ff]["connections"]["Q"][0]
                if not loads.get(q) and ff not in removed:
                    di = cells[ff]["connections"]["DI"][0]
                    loads[di] = [x for x in loads.get(di, []) if x[0] != ff]
                    removed.add(ff)
                    del cells[ff]
                    stats["ffs_removed"] += 1
            stats["input_regs"] += 1
        if "out" in plan:
            for i, ff in plan["out"][1].items():
                q = cells[ff]["connections"]["Q"][0]
                conn[f"P{i}"] = [q]
                drivers[q] = (name, f"P{i}")
                removed.add(ff)
                del cells[ff]
                stats["ffs_removed"] += 1
            par["REG_OUTPUT_CLK"] = "CLK0"
            par["REG_OUTPUT_CE"] = ce_name(ce_o)
            par["REG_OUTPUT_RST"] = "RST0"
            stats["output_regs"] += 1
        par["GSR"] = "DISABLED"
        dirs = dsp.setdefault("port_directions", {})
        for port in conn:
            dirs.setdefault(port, "input")  # CLK0, CEn, RSTn added here
        stats["dsps"] += 1
    return stats


def pack_file(path: str | Path, top: str, pack=pack_dsp_registers) -> dict:
    """A netlist pass (``pack``: :func:`pack_dsp_registers` or another with its signature) on a Yosys JSON
    file, rewritten in place; returns the pass's counts."""
    path = Path(path)
    netlist = json.loads(path.read_text())
    stats = pack(netlist, top)
    path.write_text(json.dumps(netlist))
    return stats
