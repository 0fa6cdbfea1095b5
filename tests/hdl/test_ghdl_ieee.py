"""The fast numeric_std body for GHDL (eyestereo.sim.lib.ghdl_ieee) computes what IEEE's computes.

One VHDL testbench reads operand pairs (any std_ulogic values, any widths) and writes the results of
``+``, ``-`` and ``*`` on UNSIGNED and SIGNED; it runs once against GHDL's standard ieee library and once
against the fast one. The two outputs must be equal line for line, and where both operands are plain
'0'/'1' the results must also be Python's integer arithmetic (an independent reference).
"""

import random
import shutil
import subprocess

import pytest

from eyestereo.sim.lib import ghdl_ieee

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None or not ghdl_ieee.SRC.is_dir(),
                                reason="GHDL with its IEEE sources needed")

TB = """
library ieee; use ieee.std_logic_1164.all; use ieee.numeric_std.all; use std.textio.all;
entity ops is end entity;
architecture tb of ops is
begin
  process
    file fi, fo: text;
    variable l, o: line;
    variable wa, wb: integer;
    variable sp: character;
    variable sa, sb: string(1 to 100);
    function suv(s: string) return std_ulogic_vector is
      variable r: std_ulogic_vector(s'length - 1 downto 0);
      variable j: integer := s'length - 1;
    begin
      for i in s'range loop
        r(j) := std_ulogic'value("'" & s(i) & "'");
        j := j - 1;
      end loop;
      return r;
    end function;
    procedure one(a, b: std_ulogic_vector) is
    begin
      write(o, to_string(unsigned(a) + unsigned(b)) & " " & to_string(unsigned(a) - unsigned(b)) & " " &
               to_string(unsigned(a) * unsigned(b)) & " " & to_string(signed(a) + signed(b)) & " " &
               to_string(signed(a) - signed(b)) & " " & to_string(signed(a) * signed(b)));
      writeline(fo, o);
    end procedure;
  begin
    file_open(fi, "ops.txt", read_mode);
    file_open(fo, "out.txt", write_mode);
    while not endfile(fi) loop
      readline(fi, l);
      read(l, wa); read(l, wb); read(l, sp); read(l, sa(1 to wa)); read(l, sp); read(l, sb(1 to wb));
      one(suv(sa(1 to wa)), suv(sb(1 to wb)));
    end loop;
    file_close(fo);
    wait;
  end process;
end architecture;
"""

META = "UXZWLH-"


def _pairs():
    rnd = random.Random(9)
    out = []
    for wa in range(1, 5):  # every pair of plain words up to 4 x 4 bits
        for wb in range(1, 5):
            for a in range(1 << wa):
                for b in range(1 << wb):
                    out.append((format(a, f"0{wa}b"), format(b, f"0{wb}b")))
    for _ in range(600):  # wide plain words: the products of the Harris datapath and more
        wa, wb = rnd.randint(1, 45), rnd.randint(1, 45)
        out.append(("".join(rnd.choice("01") for _ in range(wa)), "".join(rnd.choice("01") for _ in range(wb))))
    for _ in range(600):  # metavalues anywhere, as GHDL's benches meet them before reset
        wa, wb = rnd.randint(1, 9), rnd.randint(1, 9)
        pick = lambda: rnd.choice(META) if rnd.random() < 0.15 else rnd.choice("01")  # noqa: E731
        out.append(("".join(pick() for _ in range(wa)), "".join(pick() for _ in range(wb))))
    return out


def _run(tmp, lib_args, backend="mcode"):
    tmp.mkdir()
    (tmp / "ops.vhd").write_text(TB)
    (tmp / "ops.txt").write_text("".join(f"{len(a)} {len(b)} {a} {b}\n" for a, b in PAIRS))
    env = {"GHDL_BACKEND": backend, "PATH": __import__("os").environ["PATH"]}
    for cmd in (["ghdl", "-a", "--std=08", *lib_args, "ops.vhd"], ["ghdl", "-e", "--std=08", *lib_args, "ops"],
                ["ghdl", "-r", "--std=08", *lib_args, "ops", "--ieee-asserts=disable"]):
        r = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, env=env)
        assert r.returncode == 0, r.stdout + r.stderr
    return (tmp / "out.txt").read_text().splitlines()


PAIRS = _pairs()


def _signed(bits):
    v = int(bits, 2)
    return v - (1 << len(bits)) if bits[0] == "1" else v


def _expected(a, b):
    n, m = len(a), len(b)
    s = max(n, m)
    ua, ub, sa, sb = int(a, 2), int(b, 2), _signed(a), _signed(b)
    words = [(ua + ub, s), (ua - ub, s), (ua * ub, n + m), (sa + sb, s), (sa - sb, s), (sa * sb, n + m)]
    return " ".join(format(v % (1 << w), f"0{w}b") for v, w in words)


@needs_ghdl
def test_fast_numeric_std_equals_ieee(tmp_path):
    lib = ghdl_ieee.library(tmp_path / "lib", "mcode")
    standard = _run(tmp_path / "standard", [])
    fast = _run(tmp_path / "fast", ["--ieee=none", f"-P{lib / 'ieee' / 'v08'}"])
    assert len(standard) == len(fast) == len(PAIRS)
    differ = [(p, s, f) for p, s, f in zip(PAIRS, standard, fast) if s != f]
    assert not differ, f"{len(differ)} pairs differ, first {differ[0]}"
    plain = [(p, f) for p, f in zip(PAIRS, fast) if set(p[0] + p[1]) <= {"0", "1"}]
    assert len(plain) > 1000
    for (a, b), got in plain:
        assert got == _expected(a, b), (a, b)
    # U, X, Z, W, - make every result X (H and L count as 1 and 0, as in IEEE's package)
    metas = [f for p, f in zip(PAIRS, fast) if set(p[0] + p[1]) & set("UXZW-")]
    assert len(metas) > 100 and all(set(f) <= {"X", " "} for f in metas)


def test_patch_touches_only_four_functions():
    src = (ghdl_ieee.SRC / "numeric_std-body.vhdl").read_text(encoding="latin-1") if ghdl_ieee.SRC.is_dir() else None
    if src is None:
        pytest.skip("GHDL's IEEE sources needed")
    out = ghdl_ieee.patched_body(src)
    assert out.count("eyestereo fast path") == 4
    assert len(out.splitlines()) - len(src.splitlines()) < 120
    with pytest.raises(RuntimeError, match="expected one"):
        ghdl_ieee.patched_body(src.replace("function ADD_SIGNED (L, R", "function ADD_SIGNED2 (L, R"))


def test_choice_checks_its_value(monkeypatch):
    monkeypatch.delenv("GHDL_IEEE", raising=False)
    assert ghdl_ieee.choice(None) == "standard" and ghdl_ieee.choice("fast") == "fast"
    monkeypatch.setenv("GHDL_IEEE", "quick")
    with pytest.raises(ValueError, match="GHDL_IEEE='quick': choose one of standard, fast"):
        ghdl_ieee.choice(None)
