"""GHDL's own synthesis of a block's VHDL into a Verilog netlist: what ``make synth`` gives to Yosys.

The VHDL is the product (the GHDL benches verify it), so the resources and fmax figures come from
GHDL's synthesis of exactly that VHDL (``ghdl synth --std=08 --out=verilog``), not from MyHDL's separate
Verilog back end. ``ghdl_netlist`` writes ``<top>_netlist.v`` next to the VHDL files.

GHDL 2.0 (Debian 12's) has two faults in its Verilog writer, both fixed in later GHDL releases and
both repaired here (the netlist is otherwise used as GHDL writes it):

* An arithmetic shift right (VHDL ``shift_right`` of a ``signed``) is written ``$signed(a) >> n``,
  which Verilog evaluates as a *logical* shift: the sign bits come out as zeros. It is rewritten
  ``$signed(a) >>> n``.
* A priority multiplexer (``$pmux``, what a VHDL ``case`` with ``when others`` becomes) is written as
  a Verilog ``case`` **without** its ``default`` branch, so the ``others`` value is lost and Yosys
  infers a latch that holds the previous value instead. GHDL's VHDL writer keeps the branch and both
  writers name the nets alike, so :func:`ghdl_netlist` also writes the VHDL netlist, reads each
  ``with SEL select OUT <= ... X when others;`` and adds ``default: OUT <= X;`` to the Verilog
  ``case`` that drives ``OUT``.

One fault of GHDL 2.0's synthesis proper is refused instead of repaired: a comparison of an
``unsigned``/``signed`` with an integer constant outside its range (``thr_addr < 16`` for a 4-bit
``thr_addr``) is synthesized with the constant cut to the vector's width, not decided by the range as
numeric_std says. :func:`lint_vhdl` finds such comparisons in the VHDL before synthesis; blocks must
not write them (a comparison that is always true or false is better left out at elaboration).

Anything the repair cannot map one to one raises :class:`NetlistError`. The result is then checked by
simulation (``tests/hdl/test_netlist.py`` runs block benches on the netlist in Icarus Verilog, bit for
bit against the models) and by the synthesis refusing latches (:mod:`eyestereo.hdl.flow.synth`).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

__all__ = ["NetlistError", "fix_arithmetic_shifts", "ghdl_netlist", "lint_vhdl", "patch_pmux_defaults", "repair",
           "vhdl_select_defaults"]


class NetlistError(RuntimeError):
    """GHDL's synthesis failed, or its netlist could not be repaired safely."""


_WITH_SELECT = re.compile(r"^\s*with\s+(\w+)\s+select\s+(\w+)\s*<=(.*?);", re.M | re.S)
_OTHERS = re.compile(r"(?:^|,)\s*([^,]+?)\s+when\s+others\s*$", re.S)
_CASE = re.compile(r"(  always @\*\n    case \((\w+)\)\n)((?:      [^\n]*\n)+?)(    endcase\n)")
_ITEM = re.compile(r"^\s+\d+'b[01]+: (\w+) <= .*;$")
_ASR = re.compile(r"(= \$signed\([^()]*\)) >> ")
#: Verilog-writer templates of GHDL 2.0 that come out in VHDL syntax or with the wrong signedness.
_UNSUPPORTED = re.compile(r"// (smod|srem)\b|std_logic_vector|\bwhen\b.*\belse\b")


def _vhdl_expr_to_verilog(expr: str) -> str:
    """A GHDL netlist operand (literal, net, slice of a net) in Verilog syntax."""
    e = expr.strip()
    if m := re.fullmatch(r'"([01XZ]+)"', e):
        bits = m.group(1)
        return f"{len(bits)}'b{bits.lower()}"
    if m := re.fullmatch(r"'([01XZ])'", e):
        return f"1'b{m.group(1).lower()}"
    if re.fullmatch(r"\w+", e):
        return e
    if m := re.fullmatch(r"(\w+)\s*\((\d+)\s+downto\s+(\d+)\)", e):
        return f"{m.group(1)}[{m.group(2)}:{m.group(3)}]"
    if m := re.fullmatch(r"(\w+)\s*\((\d+)\)", e):
        return f"{m.group(1)}[{m.group(2)}]"
    raise NetlistError(f"cannot translate the GHDL netlist operand {expr!r} to Verilog")


def vhdl_select_defaults(vhdl_netlist: str) -> dict[str, str]:
    """``{output net: its 'when others' operand (Verilog syntax)}`` of every selected assignment."""
    out = {}
    for m in _WITH_SELECT.finditer(vhdl_netlist):
        target, body = m.group(2), m.group(3)
        o = _OTHERS.search(body)
        if o is None:
            raise NetlistError(f"selected assignment to {target} has no 'when others' branch")
        out[target] = _vhdl_expr_to_verilog(o.group(1))
    return out


def patch_pmux_defaults(verilog: str, defaults: dict[str, str]) -> tuple[str, int]:
    """Add the missing ``default:`` branch to every combinational ``case`` of a GHDL 2.0 netlist.

    Returns the patched text and the number of branches added. Every ``case`` must drive one net that
    the VHDL netlist has a selected assignment for, and every such assignment must have its ``case``.
    """
    seen = set()

    def fix(m: re.Match) -> str:
        head, items, tail = m.group(1), m.group(3), m.group(4)
        lines = items.rstrip("\n").split("\n")
        if any(l.strip().startswith("default") for l in lines):
            return m.group(0)
        targets = set()
        for l in lines:
            im = _ITEM.match(l)
            if im is None:
                raise NetlistError(f"unexpected line in a GHDL netlist case statement: {l.strip()!r}")
            targets.add(im.group(1))
        if len(targets) != 1:
            raise NetlistError(f"a GHDL netlist case statement drives {sorted(targets)}, expected one net")
        (target,) = targets
        if target not in defaults:
            raise NetlistError(f"no 'when others' value for {target} in GHDL's VHDL netlist")
        seen.add(target)
        return f"{head}{items}      default: {target} <= {defaults[target]};\n{tail}"

    text = _CASE.sub(fix, verilog)
    missing = sorted(set(defaults) - seen)
    if missing:
        raise NetlistError(f"selected assignments {missing[:5]} of the VHDL netlist have no Verilog case")
    return text, len(seen)


def fix_arithmetic_shifts(verilog: str) -> tuple[str, int]:
    """``$signed(a) >> n`` (GHDL 2.0's arithmetic shift) rewritten ``$signed(a) >>> n``."""
    return _ASR.subn(r"\1 >>> ", verilog)


#: A memory's declaration whose name ends in ``_norw``: GHDL's netlist (``reg [7:0] x_norw[2047:0] ;``) and MyHDL's
#: Verilog (``reg [7:0] x_norw [0:2048-1];``, a 1-bit memory without the width), which the board flow reads.
_NORW = re.compile(r"^(\s*)(reg (?:\[\d+:\d+\] )?\w+_norw ?\[[\d+:\- ]+\]\s*;)", re.M)


def mark_no_rw_check(verilog: str) -> tuple[str, int]:
    """``(* no_rw_check *)`` on every memory whose MyHDL name ends in ``_norw``: a block promises by that name that
    it never reads an address in the clock it writes it (hdl/rectify/line_cache.py) or never uses such a read, so
    Yosys need not build the logic that emulates such a collision between a block RAM's two ports (a LUT between
    the RAM and its register)."""
    return _NORW.subn(r"\1(* no_rw_check *) \2", verilog)


def repair(verilog: str, vhdl_netlist: str) -> tuple[str, dict[str, int]]:
    """The repairs of a GHDL 2.0 Verilog netlist (and the ``_norw`` memories marked); the text and how many of each
    were made."""
    bad = _UNSUPPORTED.search(verilog)
    if bad:
        raise NetlistError(f"GHDL's Verilog netlist has a construct it writes wrongly: {bad.group(0)!r}")
    text, shifts = fix_arithmetic_shifts(verilog)
    text, defaults = patch_pmux_defaults(text, vhdl_select_defaults(vhdl_netlist))
    text, norw = mark_no_rw_check(text)
    return text, dict(arithmetic_shifts=shifts, case_defaults=defaults, no_rw_check=norw)


_DECL = re.compile(r"^\s*(?:signal\s+|variable\s+)?(\w+)\s*:\s*(?:in\s+|out\s+|inout\s+|buffer\s+)?"
                   r"(unsigned|signed)\s*\((\d+)\s+downto\s+0\)", re.M | re.I)
_COMPARE = re.compile(r"\((\w+)\s*(<=|>=|/=|<|>|=)\s*(-?\d+)\)")


def lint_vhdl(files: list[Path]) -> None:
    """Raise NetlistError on a comparison with an integer constant outside the vector's range."""
    for f in files:
        text = Path(f).read_text()
        kinds = {m.group(1).lower(): (m.group(2).lower(), int(m.group(3)) + 1) for m in _DECL.finditer(text)}
        for m in _COMPARE.finditer(text):
            name, value = m.group(1).lower(), int(m.group(3))
            if name not in kinds:
                continue
            kind, w = kinds[name]
            lo, hi = (0, (1 << w) - 1) if kind == "unsigned" else (-(1 << (w - 1)), (1 << (w - 1)) - 1)
            if not lo <= value <= hi:
                line = text.count("\n", 0, m.start()) + 1
                raise NetlistError(f"{Path(f).name}:{line}: {m.group(0)} compares a {w}-bit {kind} with a "
                                   f"constant outside its range, which GHDL 2.0 synthesizes wrongly; leave the "
                                   f"always-true/false test out of the block")


def ghdl_synth(files: list[Path], top: str, out: str, std: str, workdir: Path) -> str:
    """``ghdl synth --out=OUT`` of ``top`` from the VHDL ``files``: the netlist's text (NetlistError on failure)."""
    cmd = ["ghdl", "synth", f"--std={std}", f"--workdir={workdir}", f"--out={out}"] + \
          [str(f) for f in files] + ["-e", top]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise NetlistError(f"ghdl synth --out={out} failed on {top}:\n{r.stderr[-3000:]}")
    return r.stdout


def ghdl_vhdl_netlist(files: list[Path], top: str, build_dir: Path) -> Path:
    """GHDL's synthesized VHDL netlist of ``top`` (``ghdl synth --std=08 --out=vhdl``), as ``<top>_netlist.vhd``.

    The same entity and ports as the VHDL (it still uses the MyHDL package), one architecture of
    GHDL's netlist cells; written next to the VHDL in ``build_dir``.
    """
    lint_vhdl(files)
    work = Path(build_dir) / "ghdl_synth"
    work.mkdir(parents=True, exist_ok=True)
    text = ghdl_synth(files, top, "vhdl", "08", work)
    # GHDL 2.0 writes a 1-bit unsigned/signed port's inner net as a std_logic scalar and converts it
    # with a type conversion its own analyser refuses (``unresolved_unsigned(wrap_x)``): an aggregate.
    scalars = set(re.findall(r"^\s*signal (wrap_\w+): std_logic;", text, re.M))
    text = re.sub(r"\bunresolved_(?:un)?signed\s*\((wrap_\w+)\)",
                  lambda m: f"(0 => {m.group(1)})" if m.group(1) in scalars else m.group(0), text)
    path = Path(build_dir) / f"{top}_netlist.vhd"
    path.write_text(text)
    return path


def ghdl_netlist(files: list[Path], top: str, out_dir: Path, *, std: str = "08") -> Path:
    """GHDL's Verilog netlist of ``top`` from the VHDL ``files`` (package first), repaired; its path.

    Also writes ``<top>_netlist.vhd`` (GHDL's VHDL netlist, where the repair reads its defaults from)
    and ``<top>_netlist.json`` (how many repairs of each kind were made).
    """
    if shutil.which("ghdl") is None:
        raise NetlistError("ghdl not found: install it (Debian: apt-get install ghdl)")
    out_dir = Path(out_dir)
    lint_vhdl(files)
    work = out_dir / "ghdl_synth"
    work.mkdir(parents=True, exist_ok=True)
    verilog = ghdl_synth(files, top, "verilog", std, work)
    vhdl = ghdl_synth(files, top, "vhdl", std, work)
    (out_dir / f"{top}_netlist.vhd").write_text(vhdl)
    text, counts = repair(verilog, vhdl)
    path = out_dir / f"{top}_netlist.v"
    path.write_text(f"// GHDL synthesis of {top} (ghdl synth --std={std} --out=verilog), repaired: "
                    f"{counts['arithmetic_shifts']} arithmetic shift(s), {counts['case_defaults']} case "
                    f"default(s) (see eyestereo.hdl.flow.netlist)\n" + text)
    (out_dir / f"{top}_netlist.json").write_text(json.dumps(counts) + "\n")
    return path
