"""Critical paths of a nextpnr-ecp5 run, summarised and mapped back to the MyHDL source.

nextpnr's ``--report`` JSON has, besides ``fmax``, a list ``critical_paths``: for every pair of clock
events (``posedge $glbnet$clk$TRELLIS_IO_IN`` to the same, a clock to another clock, ``<async>`` for the
ports) the one worst path of that run, as segments: ``clk-to-q`` (or ``source`` at an input port), then
``routing`` and ``logic`` in turn, then ``setup``. nextpnr 0.11 reports one path per pair and run, so the
worst paths of a block are those of its seeds (:func:`worst`: the distinct ones, slowest first).

:func:`summarize` reduces a path to what a designer re-pipelining it needs: start and end cell, logic
levels (cells entered through routing; a carry chain is one level however many slices it runs through,
its slices are counted in ``carry``), the delay split into logic (clock to output, cells, setup) and
routing, and the total (for a path within one clock: that run's period, ``1000 / total`` its fmax).

:class:`SourceMap` maps the cells and nets back to the MyHDL source. Yosys and nextpnr name cells after
the net they drive plus their own suffixes (``n14503_q_TRELLIS_FF_Q_1``, ``..._LUT4_Z``, ``...$CCU2_COMB0``,
``mem.0.6``); GHDL names a register or an operator ``n<k>_q`` / ``n<k>_o`` and keeps MyHDL's signal names
as aliases of them in its Verilog netlist (``always @* <signal> = n14503_q; // (isignal)``). MyHDL's
signal names are the hierarchy of block instances (``<function><k>_<i>_..._``) and the Python name of the
signal in its block function. So a cell gives a netlist signal, its instances name the block function
(found by ``ast`` in ``hdl/``), and the signal's own name is looked up in that function: the line that
assigns it (``rp = Signal(...)``; ``wp, rp = ...``), else a parameter of the function (a port), else the
interface it is an attribute of (``source_valid``: ``source``), else, by name only, elsewhere in the
function's file. A cell with no such name (logic Yosys made up) is "not found".

``python -m eyestereo.hdl.flow.paths DIR [BLOCK]`` prints the paths of a synthesized block folder
(``build/synth/<label>/``) without placing it again.
"""

from __future__ import annotations

import ast
import json
import re
import statistics
import sys
from functools import cache
from pathlib import Path

#: The package's HDL rooms (``hdl/``) and the repository they sit in (file names are given relative to it).
HDL = Path(__file__).resolve().parents[1]
REPO = HDL.parent

#: Suffixes Yosys (techmap, ``synth_ecp5``) and nextpnr (packing) append to the net a cell drives.
_CELL_SUFFIX = re.compile(r"(_TRELLIS_|_LUT4_|_LUT4$|_CCU2C_|_CCU2C$|_PFUMX_|_PFUMX$|_L6MUX21_|_L6MUX21$|"
                          r"_MULT18X18D_|_MULT18X18D$|_ALU54B_|_DP16KD_|_DPR16X4_|_TRELLIS_DPR16X4)")
_GHDL_NET = re.compile(r"n\d+_[a-z]+")
_ISIGNAL = re.compile(r"^\s*(\w+)\s*=\s*(\w+)\s*;\s*//\s*\(isignal\)", re.M)
#: A GHDL net that only widens or slices one named signal (``assign n2276_o = {8'b0, ..._w1};  //  uext``):
#: Yosys names the flip-flops of that signal after it.
_COPY = re.compile(r"^\s*assign\s+(n\d+_[a-z]+)\s*=\s*([^;]*);\s*(?://\s*(?:[us]ext|ext)\b.*)?$", re.M)


def clock_port(event: str, clocks=()) -> str:
    """The clock port of a nextpnr clock event or net (``posedge $glbnet$clk$TRELLIS_IO_IN`` -> ``clk``).

    ``<async>`` (a path from or to a port) stays ``async``. With ``clocks``, a net whose name continues
    the port's (``clk$...``) is given the port's name.
    """
    net = event.split(" ", 1)[1] if event.startswith(("posedge ", "negedge ")) else event
    if net == "<async>":
        return "async"
    m = re.fullmatch(r"\$glbnet\$(.+?)(?:\$TRELLIS_IO_IN)?", net)
    base = m.group(1) if m else net
    return next((c for c in clocks if base == c or base.startswith(c + "$")), base)


def netlist_name(cell: str) -> str:
    """The netlist net a cell or net of nextpnr is named after (its suffixes, bit index and RAM tile gone)."""
    name = cell.split("$", 1)[0] if not cell.startswith("$") else ""
    name = re.sub(r"\[\d+(:\d+)?\]$", "", name)
    m = _CELL_SUFFIX.search(name)
    if m:
        name = name[:m.start()]
    return re.sub(r"\.\d+.*$", "", name)  # Yosys's block/LUT RAM tiles and their outputs: mem.0.6_DO


def cell_kind(cell: str, port: str) -> str:
    """What a path starts or ends at, from the cell's name and port: FF, RAM (block), LUT-RAM, MULT, port."""
    if cell.endswith("$tr_io"):
        return "port"
    if "$DPRAM" in cell or "TRELLIS_DPR16X4" in cell:
        return "LUT-RAM"
    if re.match(r"DO[AB]?\d+$|D[IO]\w*$", port) and "TRELLIS_FF" not in cell:
        return "block RAM"
    if "MULT18X18D" in cell or re.match(r"P\d+$", port):
        return "MULT"
    if "TRELLIS_FF" in cell or port in ("Q", "DI", "M", "CE", "LSR"):
        return "FF"
    return "cell"


def summarize(path: dict, clocks=()) -> dict:
    """One path of nextpnr's ``critical_paths``: ends, levels, delays (ns), nets in order."""
    segs = path["path"]
    logic_types = ("clk-to-q", "source", "logic", "setup")
    first, last = segs[0]["from"], segs[-1]["to"]
    levels = sum(1 for s in segs if s["type"] == "logic" and s["from"]["port"] != "FCI")
    carry = sum(1 for s in segs if s["type"] == "logic" and s["from"]["port"] == "FCI")
    logic = sum(s["delay"] for s in segs if s["type"] in logic_types)
    routing = sum(s["delay"] for s in segs if s["type"] == "routing")
    return dict(from_clock=clock_port(path["from"], clocks), to_clock=clock_port(path["to"], clocks),
                start=first["cell"], start_port=first["port"], start_kind=cell_kind(first["cell"], first["port"]),
                end=last["cell"], end_port=last["port"], end_kind=cell_kind(last["cell"], last["port"]),
                levels=levels, carry=carry, logic_ns=round(logic, 3), routing_ns=round(routing, 3),
                total_ns=round(logic + routing, 3),
                nets=[s["net"] for s in segs if s["type"] == "routing" and s.get("net")],
                cells=[s["to"]["cell"] for s in segs if s["type"] == "logic"])


def parse_report(report: dict, clocks=()) -> list[dict]:
    """Every critical path of a nextpnr report, summarised, slowest first."""
    out = [summarize(p, clocks) for p in report.get("critical_paths", []) if p.get("path")]
    return sorted(out, key=lambda p: -p["total_ns"])


def clock_paths(paths: list[dict]) -> dict[str, dict]:
    """The register-to-register path within each clock (the one that sets its fmax), by clock port."""
    return {p["from_clock"]: p for p in paths if p["from_clock"] == p["to_clock"] != "async"}


# ----------------------------------------------------------------------------------------------- source
#: The Python sources as :func:`block_functions` read them (file -> lines): a snapshot taken when the flow
#: starts (:func:`eyestereo.hdl.flow.synth.prepare`), so that the lines given are those of the source the
#: netlist was converted from, even when the files change while the blocks are placed.
_TEXT: dict[str, tuple[str, ...]] = {}


@cache
def block_functions(root: Path = HDL) -> dict[str, list[tuple[str, int, int, tuple[str, ...]]]]:
    """Every function defined in ``root``'s Python files: name -> [(file, first line, last line, params)]."""
    out: dict[str, list] = {}
    for f in sorted(Path(root).rglob("*.py")):
        try:
            text = f.read_text()
            tree = ast.parse(text, str(f))
        except (SyntaxError, UnicodeDecodeError):
            continue
        _TEXT[str(f)] = tuple(text.splitlines())
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef):
                a = node.args
                params = tuple(x.arg for x in a.posonlyargs + a.args + a.kwonlyargs)
                out.setdefault(node.name, []).append((str(f), node.lineno, node.end_lineno or node.lineno, params))
    return out


def _rel(file: str) -> str:
    p = Path(file)
    try:
        return str(p.resolve().relative_to(REPO))
    except ValueError:
        return str(p)


def _lines(file: str) -> tuple[str, ...]:
    if file not in _TEXT:
        _TEXT[file] = tuple(Path(file).read_text().splitlines())
    return _TEXT[file]


def _assigns(line: str, name: str) -> bool:
    """Whether a source line assigns ``name`` (``name = ...``, ``a, name = ...``, ``name: T = ...``)."""
    m = re.match(r"\s*([\w\s,\[\]()*]+?)(?::[^=]+)?=(?!=)", line)
    return bool(m) and name in re.findall(r"\w+", m.group(1))


class SourceMap:
    """Cells and nets of one block's place and route -> netlist signal -> MyHDL file:line.

    ``netlist`` is GHDL's Verilog netlist of the block (``<label>/<block>_netlist.v``), ``top`` the
    block's function (the netlist's top module, whose own signals carry no instance prefix).
    """

    def __init__(self, netlist: Path | str | None, top: str, root: Path = HDL):
        self.top, self.root = top, Path(root)
        self.functions = block_functions(self.root)
        self.alias: dict[str, str] = {}
        text = Path(netlist).read_text(errors="replace") if netlist and Path(netlist).exists() else ""
        for name, src in _ISIGNAL.findall(text):
            # a GHDL register/operator net may be aliased by several signals (the block's, then the ports
            # it is wired to in the parents): the longest name is the innermost block, where it is made
            if _GHDL_NET.fullmatch(src) and len(name) > len(self.alias.get(src, "")):
                self.alias[src] = name
        for src, rhs in _COPY.findall(text):
            ids = list(dict.fromkeys(t for t in re.findall(r"(?<!')\b[A-Za-z_]\w*", rhs) if not _GHDL_NET.fullmatch(t)))
            if src not in self.alias and len(ids) == 1 and re.fullmatch(r"[\s{}\w',\[\]:]*", rhs):
                self.alias[src] = ids[0]
        names = sorted((n for n in self.functions if len(n) > 1), key=len, reverse=True)
        self._instance = re.compile(r"(" + "|".join(map(re.escape, names)) + r")\d+(?:_\d+)*_") if names else None

    def signal(self, cell: str) -> str | None:
        """The netlist signal a cell or net belongs to (a MyHDL name), or None (logic without a name)."""
        n = netlist_name(cell)
        if not n:
            return None
        if _GHDL_NET.fullmatch(n):
            return self.alias.get(n)
        return n

    def split(self, signal: str) -> tuple[list[str], str]:
        """A MyHDL signal name -> (the block functions of its instances, outermost first; its own name)."""
        insts, i = [], 0
        while self._instance:
            m = self._instance.match(signal, i)
            if not m or m.end() >= len(signal):
                break
            insts.append(m.group(1))
            i = m.end()
        return insts, signal[i:]

    def _in_function(self, fn: str, base: str) -> dict | None:
        for file, lo, hi, params in self.functions.get(fn, []):
            lines = _lines(file)
            for k in range(lo, min(hi, len(lines))):
                if _assigns(lines[k], base):
                    return dict(file=_rel(file), line=k + 1, how="assigned")
            if base in params:
                return dict(file=_rel(file), line=lo, how="port")
            for k in range(lo, min(hi, len(lines))):
                if re.search(rf"\b{re.escape(base)}\.next\s*=", lines[k]):
                    return dict(file=_rel(file), line=k + 1, how="first assignment")
        return None

    def locate(self, signal: str | None) -> dict:
        """Where a netlist signal comes from: block function, name, file and line (``file`` None: not found)."""
        if not signal:
            return dict(signal=None, block=None, name=None, file=None, line=None, how="not found")
        insts, base = self.split(signal)
        fn = insts[-1] if insts else self.top
        out = dict(signal=signal, block=fn, name=base)
        tries = [base]
        tries += [re.sub(r"_\d+$", "", base)] if re.search(r"_\d+$", base) else []  # an element of a list
        for name in tries:
            hit = self._in_function(fn, name)
            if hit:
                return dict(out, **hit)
        parts = base.split("_")
        for k in range(len(parts) - 1, 0, -1):  # an interface's member: source_valid -> source
            hit = self._in_function(fn, "_".join(parts[:k]))
            if hit:
                return dict(out, **dict(hit, how=f"{hit['how']} (interface {'_'.join(parts[:k])})"))
        for file in dict.fromkeys(e[0] for e in self.functions.get(fn, [])):  # by name only, in fn's file
            lines = _lines(file)
            for k, line in enumerate(lines):
                if _assigns(line, base):
                    return dict(out, file=_rel(file), line=k + 1, how="by name only")
        return dict(out, file=None, line=None, how="not found")

    def where(self, cell: str) -> str:
        """``file:line`` of a cell's signal, or "not found"."""
        loc = self.locate(self.signal(cell))
        return f"{loc['file']}:{loc['line']}" if loc["file"] else "not found"

    def annotate(self, p: dict) -> dict:
        """A summarised path with its ends and the named signals it runs through mapped to the source."""
        start, end = self.locate(self.signal(p["start"])), self.locate(self.signal(p["end"]))
        through, seen = [], set()
        for net in p["nets"]:
            s = self.signal(net)
            if s and s not in seen:
                seen.add(s)
                loc = self.locate(s)
                through.append(dict(signal=s, block=loc["block"], name=loc["name"],
                                    source=f"{loc['file']}:{loc['line']}" if loc["file"] else "not found"))
        return dict(p, start_source=start, end_source=end, through=through)


# ------------------------------------------------------------------------------------------------ seeds
def fmax_stats(values: list[float | None]) -> dict:
    """min / median / max of one clock's fmax over seeds (None: no register-to-register path)."""
    v = [x for x in values if x is not None]
    if not v:
        return dict(min=None, median=None, max=None, seeds=len(values))
    return dict(min=round(min(v), 2), median=round(statistics.median(v), 2), max=round(max(v), 2), seeds=len(values))


def margin(fmin: float | None, goal: float | None) -> float | None:
    """The margin of the slowest seed over the goal, in % (``min / goal - 1``)."""
    if fmin is None or not goal:
        return None
    return round((fmin / goal - 1) * 100, 1)


def worst(runs: dict[int, list[dict]], clock: str, n: int = 3) -> list[dict]:
    """The ``n`` slowest distinct paths of one clock over the seeds' runs (``{seed: annotated paths}``).

    Two paths are the same when they start and end at the same signal (bits of one register count as one).
    """
    cands = []
    for seed, paths in runs.items():
        for p in paths:
            if p["from_clock"] == p["to_clock"] == clock:
                cands.append(dict(p, seed=seed))
    out, seen = [], set()
    for p in sorted(cands, key=lambda q: -q["total_ns"]):
        key = (_ends_key(p, "start"), _ends_key(p, "end"))
        if key not in seen:
            seen.add(key)
            out.append(p)
    return out[:n]


def _ends_key(p: dict, end: str) -> str:
    src = p.get(f"{end}_source") or {}
    return src.get("signal") or netlist_name(p[end])


def source_text(loc: dict) -> str:
    """A located signal as text: ``block.name`` (file:line), or the netlist name and "not found"."""
    if not loc or not loc.get("signal"):
        return "not found"
    if not loc.get("file"):
        return f"`{loc['signal']}` (not found)"
    return f"`{loc['block']}.{loc['name']}` ({loc['file']}:{loc['line']})"


def describe(p: dict) -> str:
    """One line for a path: from -> to, levels, delay split."""
    carry = f" + {p['carry']} carry" if p["carry"] else ""
    return (f"{source_text(p['start_source'])} ({p['start_kind']}) -> "
            f"{source_text(p['end_source'])} ({p['end_kind']}): "
            f"{p['levels']} levels{carry}, {p['total_ns']:.2f} ns = {p['logic_ns']:.2f} logic + "
            f"{p['routing_ns']:.2f} routing")


def markdown(label: str, runs: dict[int, list[dict]], fmax: dict[str, dict], goals: dict, n: int = 3) -> str:
    """``paths.md`` of one block: per clock its fmax over the seeds and its ``n`` worst paths with sources."""
    lines = [f"# Worst paths of {label}", "",
             f"nextpnr-ecp5, seeds {', '.join(map(str, sorted(runs)))}; one worst path per clock and seed "
             "(nextpnr reports one per clock pair and run), the distinct ones slowest first. Levels: cells "
             "entered through routing (a carry chain counts once; its further slices under 'carry'). Logic: "
             "clock to output, cells and setup; routing: the nets.", ""]
    for clk in fmax:
        st = fmax[clk]
        g = goals.get(clk)
        ms = margin(st.get("min"), g)
        lines += [f"## {clk}: fmax {_mhz(st.get('min'))} / {_mhz(st.get('median'))} / {_mhz(st.get('max'))} MHz "
                  f"(min / median / max), goal {f'{g:g}' if g else '-'} MHz" +
                  (f", margin {ms:+.1f} %" if ms is not None else ""), ""]
        ws = worst(runs, clk, n)
        if not ws:
            lines += ["No register-to-register path.", ""]
            continue
        for i, p in enumerate(ws, 1):
            lines.append(f"{i}. seed {p['seed']}, {1000 / p['total_ns']:.1f} MHz: {describe(p)}")
            thr = [f"`{t['block']}.{t['name']}` ({t['source']})" for t in p["through"]]
            if thr:
                lines.append(f"   - through: {' -> '.join(thr)}")
            sig = [(p.get(f"{e}_source") or {}).get("signal") or "-" for e in ("start", "end")]
            lines.append(f"   - netlist signals: `{sig[0]}` -> `{sig[1]}`; cells: `{p['start']}` -> `{p['end']}`")
        lines.append("")
    io = [(s, p) for s, ps in runs.items() for p in ps if "async" in (p["from_clock"], p["to_clock"])]
    xc = [(s, p) for s, ps in runs.items() for p in ps
          if "async" not in (p["from_clock"], p["to_clock"]) and p["from_clock"] != p["to_clock"]]
    for title, group in (("Port paths (not timed against a clock goal)", io),
                         ("Clock-crossing paths (synchronizers; not timed against a goal)", xc)):
        if group:
            s, p = max(group, key=lambda x: x[1]["total_ns"])
            lines += [f"## {title}", "", f"Slowest, seed {s}, {p['from_clock']} -> {p['to_clock']}: {describe(p)}", ""]
    return "\n".join(lines)


def _mhz(v) -> str:
    return f"{v:.1f}" if v is not None else "-"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        print(__doc__.strip().splitlines()[-2])
        return 2
    d = Path(argv[0])
    reports = sorted(d.glob("pnr_report*.json"))
    if not reports:
        print(f"no pnr_report*.json in {d}", file=sys.stderr)
        return 1
    block = argv[1] if len(argv) > 1 else d.name
    smap = SourceMap(d / f"{block}_netlist.v", block)
    runs = {}
    for r in reports:
        m = re.search(r"seed(\d+)", r.name)
        runs[int(m.group(1)) if m else 1] = [smap.annotate(p) for p in parse_report(json.loads(r.read_text()))]
    per_clock: dict[str, list] = {}
    for ps in runs.values():
        for c, p in clock_paths(ps).items():
            per_clock.setdefault(c, []).append(1000 / p["total_ns"])
    fmax = {c: fmax_stats(v) for c, v in per_clock.items()}
    print(markdown(d.name, runs, fmax, {}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
