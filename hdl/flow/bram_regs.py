"""Move the flip-flop after a block-RAM read into the ECP5 block RAM's own output register (a netlist pass).

Yosys ``synth_ecp5`` maps every memory to DP16KDs with ``REGMODE_A/B = NOREG``: the read data leaves the
block RAM 5.8 ns after the clock (nextpnr's figure for the ECP5, speed grade 6) and still has to be routed
to the flip-flop the design puts after it. The line cache (issue 26) reads its banks into such registers on
purpose (one register per bank before the select); at 640x480 the route alone took 3 to 4 ns, and the path
RAM -> register was the slowest of the block (100.8 MHz). The DP16KD has an output register per port
(``REGMODE_x = OUTREG``, with its own clock enable ``OCEx``): data then leaves the block 0.6 ns after the
next clock edge, and nextpnr-ecp5 times it so.

This pass, on the JSON netlist of ``synth_ecp5`` and per port (A, B) of every DP16KD with ``NOREG``:
when every used data-out bit ``DOx<i>`` drives exactly one plain flip-flop's D and nothing else, all of them
clocked by the port's clock (``CLKx``), with no reset (LSR tied 0), no initial value and one enable (or none),
the port's output register takes their place: ``REGMODE_x = OUTREG``, ``OCEx`` = the flip-flops' enable,
``DOx<i>`` connected to the flip-flops' Q nets, the flip-flops removed. The register loads the same data on
the same clock and enable, so the design is unchanged cycle for cycle; it starts at 0 (``RSTx`` stays tied 0,
``GSR`` disabled) as the slice flip-flops (``REGSET RESET``) did. Only the ECP5 placement of ``make synth``
uses the result.

The register inside the block RAM is no flip-flop in a slice: its clock-to-output is 0.97 ns (a slice flip-flop's
0.52 ns) and it sits in the block-RAM column, away from the logic it feeds. Where that logic is deep, moving the
register makes the path after it the slow one (issue 26: a Harris NMS line delay read into an adder and
comparators, 6 levels, lost 7 MHz). So a port's register moves only when every path from it to the next
register, block RAM or port crosses at most :data:`MAX_LEVELS` cells (a LUT, a mux, each carry cell, an
unregistered multiplier or a LUT-RAM read counting one): the line cache's bank select (issue 26) qualifies,
the filters' line delays do not.

A memory named with ``_oreg`` (for instance ``ring_oreg_norw``) moves its registers whatever the logic after
them: the block asks for it where that logic is a short carry chain which the levels overcount and the route out
of the block RAM, not the logic, is what limits the clock (sgm's path rings: a lane's word into the next lane's
``+ P1``, a 9-bit chain, five cells).

A memory that Yosys guarded with a read/write collision LUT (a write and a read of one address in one clock)
is not matched, since the LUT, not a flip-flop, reads the data: such memories can be named ``*_norw`` so
that ``no_rw_check`` (:func:`eyestereo.hdl.flow.netlist.mark_no_rw_check`) lets Yosys leave the LUT out when
the design never reads what it writes in the same clock.
"""

from __future__ import annotations

from eyestereo.hdl.flow.dsp_regs import FF, ff_kind, net_maps

__all__ = ["BRAM", "MAX_LEVELS", "pack_bram_registers"]

BRAM = "DP16KD"
#: data-out bits of one DP16KD port (x36 uses both ports' pins, x18 and narrower one port's)
DO_BITS = 18
#: The deepest logic (cells) after a register that may move into its block RAM.
MAX_LEVELS = 3
#: In a memory's name: move its registers whatever the depth after them (the module docstring).
OREG = "_oreg"


def _is_endpoint(cell: dict) -> bool:
    """A cell whose inputs end a timing path: a flip-flop, a block RAM, a multiplier with input registers."""
    if cell["type"] in (FF, BRAM):
        return True
    return cell["type"] == "MULT18X18D" and cell["parameters"].get("REG_INPUTA_CLK", "NONE").strip() != "NONE"


def _levels(net, cells: dict, loads: dict, budget: int, memo: dict) -> int:
    """The most cells a path from ``net`` crosses before an endpoint, or ``budget + 1`` when that is more than
    ``budget``. ``memo``: net -> ("exact", depth) or ("over", b) (deeper than b); a loop counts as deep."""
    known = memo.get(net)
    if known is not None:
        kind, v = known
        if kind == "exact":
            return min(v, budget + 1)
        if kind == "over" and v >= budget:
            return budget + 1
        if kind == "active":
            return budget + 1
    if budget < 0:
        return 0  # the caller's cell alone already passes its budget
    memo[net] = ("active", 0)
    deepest = 0
    for name, _, _ in loads.get(net, []):
        if name == "$port" or _is_endpoint(cells[name]):
            continue
        cell = cells[name]
        dirs = cell.get("port_directions", {})
        outs = [b for port, bits in cell["connections"].items() if dirs.get(port) == "output"
                for b in bits if not isinstance(b, str)]
        deepest = max(deepest, 1 + max((_levels(o, cells, loads, budget - 1, memo) for o in outs), default=0))
        if deepest > budget:
            break
    memo[net] = ("exact", deepest) if deepest <= budget else ("over", budget)
    return min(deepest, budget + 1)


def _port_plan(ram: dict, port: str, cells: dict, loads: dict, *, any_depth: bool = False) -> tuple | None:
    """(enable, {bit: FF name}) when port ``port``'s used outputs each feed one plain FF on its clock; else None.
    ``any_depth``: skip the check of the logic after the flip-flops (a memory named with :data:`OREG`)."""
    par, conn = ram["parameters"], ram["connections"]
    if par.get(f"REGMODE_{port}", "NOREG").strip() != "NOREG" or conn.get(f"RST{port}", ["0"]) != ["0"]:
        return None
    if par.get(f"CLK{port}MUX", f"CLK{port}").strip() != f"CLK{port}":
        return None
    clk = conn.get(f"CLK{port}", ["0"])[0]
    enable, ffs = None, {}
    for i in range(DO_BITS):
        net = conn.get(f"DO{port}{i}", [None])[0]
        if net is None or isinstance(net, str) or not loads.get(net):
            continue
        ls = loads[net]
        if len(ls) != 1 or ls[0][0] == "$port" or cells[ls[0][0]]["type"] != FF or ls[0][1] != "DI":
            return None
        kind = ff_kind(cells[ls[0][0]])
        if kind is None or kind[0] != clk or isinstance(kind[1], tuple):
            return None  # another clock, a reset, an initial value, or an inverted enable (OCE has no inverter)
        if enable is not None and kind[1] != enable:
            return None
        enable = kind[1]
        ffs[i] = ls[0][0]
    if not ffs:
        return None
    memo: dict = {}
    if not any_depth and any(_levels(cells[ff]["connections"]["Q"][0], cells, loads, MAX_LEVELS, memo) > MAX_LEVELS
           for ff in ffs.values()):
        return None  # deep logic after the register: it stays a slice flip-flop, next to that logic
    return enable, ffs


def pack_bram_registers(netlist: dict, top: str) -> dict:
    """Give the DP16KDs of module ``top`` their output registers in place where the design has the
    flip-flops for them; returns counts (``ports``: output registers used, ``ffs_removed``)."""
    mod = netlist["modules"][top]
    cells = mod["cells"]
    _, loads = net_maps(mod)
    stats = dict(ports=0, ffs_removed=0)
    for name in sorted(cells):
        ram = cells.get(name)  # None: a flip-flop this pass removed
        if ram is None or ram["type"] != BRAM:
            continue
        for port in ("A", "B"):
            plan = _port_plan(ram, port, cells, loads, any_depth=OREG in name)
            if plan is None:
                continue
            enable, ffs = plan
            for i, ff in ffs.items():
                ram["connections"][f"DO{port}{i}"] = [cells[ff]["connections"]["Q"][0]]
                del cells[ff]
                stats["ffs_removed"] += 1
            ram["parameters"][f"REGMODE_{port}"] = "OUTREG"
            ram["connections"][f"OCE{port}"] = [enable]
            ram.setdefault("port_directions", {})[f"OCE{port}"] = "input"
            stats["ports"] += 1
    return stats
