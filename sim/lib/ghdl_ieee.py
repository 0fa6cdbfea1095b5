"""A faster ``ieee`` library for GHDL benches: numeric_std's additions and products without per-bit calls.

GHDL simulates ``numeric_std`` from its VHDL source: an addition of two N-bit words is a loop of N
iterations with eight calls of std_logic's ``and``/``or``/``xor`` each, and a product of N x M bits is N
such additions (each with its own ``TO_01`` and ``RESIZE``). In the full-frame harris_mono bench that is
most of GHDL's time (``perf``: the cornerness pipeline's four products alone a fifth).

:func:`library` builds, once per GHDL back end, an ``ieee`` library from GHDL's own sources
(``/usr/lib/ghdl/src/ieee2008``) in which four functions of the numeric_std body take a fast path:

* ``ADD_UNSIGNED`` / ``ADD_SIGNED`` (the core of every ``+`` and ``-``): the carry as an integer;
* ``"*"`` of two UNSIGNED and of two SIGNED: the product bit by bit from column sums with an integer
  carry (signed: both operands sign-extended to the product's width, the product taken modulo
  2**width, which is the two's complement product since it fits).

Each fast path runs only when every operand bit is '0' or '1'; for any other value (U, X, Z, W, -, H, L)
the function falls through to the standard code, so metavalues propagate exactly as in IEEE's package.
The package declarations are not touched: a design analysed against the standard library and against
this one is the same design. ``tests/sim/test_ghdl_ieee.py`` compares the two libraries on every
operand pair of small widths (metavalues included) and on random wide ones; the benches that use it
check their outputs bit for bit against the numpy models like every other bench.

Only for GHDL, only for simulation, and only where asked (``run_bench(..., ieee="fast")`` or
``GHDL_IEEE=fast``): the VHDL itself, synthesis and the standard benches stay on the standard library.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
from pathlib import Path

SRC = Path("/usr/lib/ghdl/src/ieee2008")
#: the library's sources in analysis order (numeric_std's body is patched)
FILES = ("std_logic_1164.vhdl", "std_logic_1164-body.vhdl", "numeric_std.vhdl", "numeric_std-body.vhdl")
CHOICES = ("standard", "fast")

_ADD = """  function ADD_{T} (L, R : UNRESOLVED_{T}; C : STD_LOGIC)
    return UNRESOLVED_{T}
  is
    constant L_LEFT : INTEGER   := L'length-1;
    alias XL        : UNRESOLVED_{T}(L_LEFT downto 0) is L;
    alias XR        : UNRESOLVED_{T}(L_LEFT downto 0) is R;
    variable RESULT : UNRESOLVED_{T}(L_LEFT downto 0);
    variable CBIT   : STD_LOGIC := C;
    variable S      : INTEGER;
    variable CLEAN  : BOOLEAN := (C = '0' or C = '1');
  begin
    -- eyestereo fast path (sim/lib/ghdl_ieee.py): '0'/'1' operands, the carry as an integer
    if CLEAN then
      if C = '1' then S := 1; else S := 0; end if;
      for I in 0 to L_LEFT loop
        case XL(I) is
          when '1' => S := S + 1;
          when '0' => null;
          when others => CLEAN := false; exit;
        end case;
        case XR(I) is
          when '1' => S := S + 1;
          when '0' => null;
          when others => CLEAN := false; exit;
        end case;
        if S = 1 or S = 3 then RESULT(I) := '1'; else RESULT(I) := '0'; end if;
        S := S / 2;
      end loop;
      if CLEAN then return RESULT; end if;
    end if;
    for I in 0 to L_LEFT loop
      RESULT(I) := CBIT xor XL(I) xor XR(I);
      CBIT      := (CBIT and XL(I)) or (CBIT and XR(I)) or (XL(I) and XR(I));
    end loop;
    return RESULT;
  end function ADD_{T};
"""

# Inserted after the X check of "*": XL and XR hold only '0'/'1' there (TO_01 with XMAP 'X').
_MUL_UNSIGNED = """    -- eyestereo fast path (sim/lib/ghdl_ieee.py): column sums with an integer carry
    for K in 0 to RESULT'length-1 loop
      for I in MAXIMUM(0, K-R_LEFT) to MINIMUM(K, L_LEFT) loop
        if XL(I) = '1' and XR(K-I) = '1' then ACC := ACC + 1; end if;
      end loop;
      if ACC mod 2 = 1 then RESULT(K) := '1'; else RESULT(K) := '0'; end if;
      ACC := ACC / 2;
    end loop;
    return RESULT;
"""

_MUL_SIGNED = """    -- eyestereo fast path (sim/lib/ghdl_ieee.py): sign-extended operands, the product modulo 2**width
    for K in 0 to RESULT'length-1 loop
      for I in 0 to K loop
        if XL(MINIMUM(I, L_LEFT)) = '1' and XR(MINIMUM(K-I, R_LEFT)) = '1' then ACC := ACC + 1; end if;
      end loop;
      if ACC mod 2 = 1 then RESULT(K) := '1'; else RESULT(K) := '0'; end if;
      ACC := ACC / 2;
    end loop;
    return RESULT;
"""


def _replace_function(text: str, head: str, new: str) -> str:
    i = text.find(head)
    if i < 0 or text.find(head, i + 1) >= 0:
        raise RuntimeError(f"GHDL's numeric_std body: expected one '{head.strip()}'")
    end = re.compile(r"end function \w+;\n").search(text, i)
    return text[:i] + new + text[end.end():]


def _patch_mul(text: str, head: str, x_check_end: str, body: str) -> str:
    i = text.find(head)
    if i < 0:
        raise RuntimeError(f"GHDL's numeric_std body: no '{head.strip()}'")
    j = text.find(x_check_end, i)
    k = text.find("end function", i)
    if j < 0 or j > k:
        raise RuntimeError(f"GHDL's numeric_std body: '{head.strip()}' is not the expected code")
    j += len(x_check_end)
    text = text[:j] + body + text[j:]
    # the accumulator, declared with the function's other variables
    b = text.find("  begin\n", i)
    return text[:b] + "    variable ACC    : NATURAL := 0;\n" + text[b:]


def patched_body(src: str) -> str:
    """GHDL's numeric_std body with the fast paths (RuntimeError if the source is not the one expected)."""
    for t in ("UNSIGNED", "SIGNED"):
        src = _replace_function(src, f"  function ADD_{t} (L, R : UNRESOLVED_{t}; C : STD_LOGIC)\n",
                                _ADD.format(T=t))
    x_end = "      return RESULT;\n    end if;\n"
    src = _patch_mul(src, '  function "*" (L, R : UNRESOLVED_UNSIGNED) return UNRESOLVED_UNSIGNED is\n', x_end,
                     _MUL_UNSIGNED)
    src = _patch_mul(src, '  function "*" (L, R : UNRESOLVED_SIGNED) return UNRESOLVED_SIGNED is\n', x_end,
                     _MUL_SIGNED)
    return src


def _key(backend: str) -> str:
    h = hashlib.sha256(Path(__file__).read_bytes())
    for f in FILES:
        h.update((SRC / f).read_bytes())
    h.update(backend.encode())
    return h.hexdigest()[:16]


def library(root: Path, backend: str) -> Path:
    """The fast ``ieee`` library for ``backend`` under ``root`` (built once; a folder for ``-P``).

    Analysis goes to a temporary folder renamed into place, so parallel benches never see a half-built
    library. RuntimeError with GHDL's messages if it cannot be built.
    """
    if not SRC.is_dir():
        raise RuntimeError(f"GHDL's IEEE sources not found in {SRC}: GHDL_IEEE=fast needs them")
    root = Path(root).resolve()
    out = root / f"{backend}-{_key(backend)}"
    if (out / "ieee" / "v08" / "ieee-obj08.cf").exists():
        return out
    tmp = root / f".tmp-{os.getpid()}-{backend}"
    shutil.rmtree(tmp, ignore_errors=True)
    lib = tmp / "ieee" / "v08"
    lib.mkdir(parents=True)
    files = []
    for f in FILES:
        text = (SRC / f).read_text(encoding="latin-1")
        if f == "numeric_std-body.vhdl":
            text = patched_body(text)
        (lib / f).write_text(text, encoding="latin-1")
        files.append(f)  # relative: the library is renamed into place after analysis
    env = dict(os.environ, GHDL_BACKEND=backend)
    opt = ["-O2"] if backend == "llvm" else []  # as Debian builds its own IEEE libraries
    cmd = ["ghdl", "-a", "--std=08", "--ieee=none", "-frelaxed", *opt, "--work=ieee", "--workdir=.", *files]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=lib)
    if r.returncode != 0:
        shutil.rmtree(tmp, ignore_errors=True)
        raise RuntimeError(f"building the fast ieee library failed:\n{r.stdout}{r.stderr}")
    # GHDL's library index names the folder analysed in: make it name the final one
    cf = lib / "ieee-obj08.cf"
    cf.write_text(cf.read_text(encoding="latin-1").replace(str(tmp), str(out)), encoding="latin-1")
    try:
        tmp.rename(out)
    except OSError:  # another process was first: use its library
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def choice(ieee: str | None) -> str:
    """``ieee``, else ``$GHDL_IEEE``, else standard; ValueError for anything else."""
    value = (ieee or os.environ.get("GHDL_IEEE") or "standard").strip().lower()
    if value not in CHOICES:
        raise ValueError(f"GHDL_IEEE={value!r}: choose one of {', '.join(CHOICES)}")
    return value
