"""The backward look-up table as a C header, for a software rectifier (thesis Table A.1, create_c_lut).

One header holds all four tables. Format::

    #ifndef <GUARD>                       guard from the file name, e.g. RECT_LUT_H for rect_lut.h
    #define <GUARD>
    #include <stdint.h>
    #define <P>_WIDTH 352                 rectified image size (P = upper-case prefix)
    #define <P>_HEIGHT 288
    #define <P>_SOURCE_WIDTH 352          camera image size the coordinates point into
    #define <P>_SOURCE_HEIGHT 288
    #define <P>_FRAC_BITS 5               value = code / 2^FRAC_BITS pixels
    #define <P>_INVALID (-32768)          code of a non-finite map entry
    static const int16_t <p>_left_x[<P>_HEIGHT * <P>_WIDTH] = { ... };   entry [y * WIDTH + x]
    static const int16_t <p>_left_y[...], <p>_right_x[...], <p>_right_y[...]
    #endif

Codes are ``floor(v * 2^FRAC_BITS + 0.5)`` (round half up) of the 0-based source coordinate, saturated
to -32767..32767 (saturated codes lie far outside the image, so a reader still sees them as out of
range). Five fraction bits are the thesis's choice for coordinates (ufix[14,5], thesis 4); they
leave +-1023 pixels of range, enough for images up to 1024 pixels wide, and ``frac_bits`` can be
lowered for larger ones. The prefix must give usable C names (:func:`check_prefix`: no keyword, no
reserved ``_`` name, no clash with a standard macro). Map entries may be NaN (no source pixel:
``INVALID``) but not infinite (:func:`~eyestereo.tools.rectify.maps.check_map_entries`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from eyestereo.tools.io import atomic_output
from eyestereo.tools.rectify.maps import MAP_KEYS, Maps, check_map_entries

__all__ = ["INT16_INVALID", "check_prefix", "create_c_lut", "lut_codes"]

INT16_INVALID = -32768
_INT16_MAX = 32767


def lut_codes(values: np.ndarray, frac_bits: int = 5) -> np.ndarray:
    """int16 codes of coordinates: round half up to ``2^-frac_bits``, saturate, non-finite -> INVALID."""
    v = np.asarray(values, dtype=np.float64)
    finite = np.isfinite(v)
    scaled = np.floor(np.where(finite, v, 0.0) * (1 << frac_bits) + 0.5)
    codes = np.clip(scaled, -_INT16_MAX, _INT16_MAX).astype(np.int16)
    return np.where(finite, codes, np.int16(INT16_INVALID)).astype(np.int16)


#: C's keywords, C89 to C23 (those starting with ``_`` are refused as reserved names anyway).
C_KEYWORDS = frozenset("""
    auto break case char const continue default do double else enum extern float for goto if inline int long
    register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while
    alignas alignof bool constexpr false nullptr static_assert thread_local true typeof typeof_unqual
""".split())
#: Prefixes ``P`` whose ``P_WIDTH`` is a macro of C23's ``<stdint.h>`` (which the header includes; glibc
#: also defines them with ``_GNU_SOURCE``) or ``<limits.h>``: the header would redefine it.
_STD_WIDTH = re.compile(r"U?INT(_LEAST|_FAST)?(8|16|32|64)|U?INT(PTR|MAX)|PTRDIFF|SIG_ATOMIC|SIZE|WCHAR|WINT"
                        r"|BOOL|[SU]?CHAR|U?SHRT|U?INT|U?L?LONG")
#: Longest prefix: C99 compilers need tell apart only the first 63 characters of a name, and the
#: longest generated name (``P_SOURCE_HEIGHT``) adds 14.
MAX_PREFIX = 49


def check_prefix(prefix: str) -> str:
    """``prefix`` if the names the header makes of it (``prefix_left_x``, ``PREFIX_WIDTH``, ...) are
    usable C names; else ValueError with the reason, in one line.

    Refused: anything that is not a C identifier, longer than :data:`MAX_PREFIX` characters, a C keyword,
    a name starting with ``_`` (the tables are file-scope and the macros upper-case, so every name made
    of it would be reserved for the compiler and the C library), and prefixes whose ``PREFIX_WIDTH`` is a
    standard macro (``int8`` -> ``INT8_WIDTH`` of ``<stdint.h>``)."""
    if not isinstance(prefix, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", prefix):
        raise ValueError(f"prefix must be a C identifier (a letter, then letters, digits or _), got {prefix!r}")
    if len(prefix) > MAX_PREFIX:
        raise ValueError(f"prefix {prefix[:16]}... has {len(prefix)} characters; at most {MAX_PREFIX}, so that every "
                         f"name made of it stays within the 63 characters C compilers must tell apart")
    if prefix in C_KEYWORDS:
        raise ValueError(f"prefix {prefix!r} is a C keyword; give a name such as {prefix}_lut")
    if prefix.startswith("_"):
        raise ValueError(f"prefix {prefix!r} starts with '_': the names made of it ({prefix}_left_x, "
                         f"{prefix.upper()}_WIDTH) are reserved for the C compiler and library")
    if _STD_WIDTH.fullmatch(prefix.upper()):
        raise ValueError(f"prefix {prefix!r} would define {prefix.upper()}_WIDTH, a standard C macro (<stdint.h>, "
                         f"<limits.h>); give a name such as {prefix}_lut")
    return prefix


def _guard(path: Path) -> str:
    g = re.sub(r"[^A-Za-z0-9]", "_", path.name).upper()
    return ("_" + g) if g[0].isdigit() else g


def create_c_lut(maps: Maps, path: str | os.PathLike[str], *, frac_bits: int = 5,
                 prefix: str = "eyestereo_lut", guard: str | None = None) -> None:
    """Write the four backward tables of ``maps`` as a C header (format in the module docstring). Atomic.

    ``guard``: the file name the include guard is made from (default: ``path``'s name; give the final
    name when ``path`` is a temporary). ValueError, before anything is written, for a ``prefix`` that
    :func:`check_prefix` refuses or a map with an infinite entry."""
    check_prefix(prefix)
    if not 0 <= frac_bits <= 14:
        raise ValueError(f"frac_bits must be 0..14, got {frac_bits}")
    check_map_entries(maps)
    src_w, src_h = maps.source_size or (maps.width, maps.height)
    if (max(src_w, src_h) - 1) * (1 << frac_bits) > _INT16_MAX:
        raise ValueError(f"{src_w}x{src_h} images need coordinates beyond int16 with {frac_bits} "
                         f"fraction bits; use fewer")
    p = Path(path)
    g = Path(guard) if guard is not None else p
    P = prefix.upper()
    lines = [
        "/* Backward rectification look-up tables, written by eyestereo (Rectification Toolbox). */",
        f"/* entry [y * {P}_WIDTH + x] = source coordinate * 2^{P}_FRAC_BITS, 0-based pixels. */",
        f"#ifndef {_guard(g)}",
        f"#define {_guard(g)}",
        "#include <stdint.h>",
        f"#define {P}_WIDTH {maps.width}",
        f"#define {P}_HEIGHT {maps.height}",
        f"#define {P}_SOURCE_WIDTH {src_w}",
        f"#define {P}_SOURCE_HEIGHT {src_h}",
        f"#define {P}_FRAC_BITS {frac_bits}",
        f"#define {P}_INVALID ({INT16_INVALID})",
    ]
    for key in MAP_KEYS:
        codes = lut_codes(getattr(maps, key), frac_bits).ravel().tolist()
        lines.append(f"static const int16_t {prefix}_{key}[{P}_HEIGHT * {P}_WIDTH] = {{")
        for i in range(0, len(codes), 16):
            lines.append("  " + ",".join(str(c) for c in codes[i:i + 16]) + ",")
        lines.append("};")
    lines.append(f"#endif /* {_guard(g)} */")
    text = "\n".join(lines) + "\n"
    with atomic_output(p, suffix=".h") as tmp:
        tmp.write_text(text, encoding="ascii")
