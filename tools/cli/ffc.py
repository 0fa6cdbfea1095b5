"""``eyestereo ffc`` and ``eyestereo package``: the float-to-fixed conversion on the command line.

``eyestereo.tools.cli.main`` calls :func:`register` with its sub-parsers; this module also runs on its
own (``python -m eyestereo.tools.cli.ffc ffc poly.json -o quantizers.json``)::

    eyestereo ffc poly.json -o quantizers.json [--max-error 0.01] [--measure mse|max] [--low 0 --high 32]
    eyestereo package quantizers.json -o stereo_calibration_pkg.vhd [--name stereo_calibration_pkg]

Each sub-command stores its handler as ``func`` in the parsed namespace; a handler returns the exit
status.  Bad input gives one line ``eyestereo: error: ...`` on stderr, exit status 1, and leaves no
output file behind (outputs are written atomically, only when complete).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from eyestereo.tools.cli.main import _nonneg, _positive  # shared argument types (cli imports this module only lazily)
from eyestereo.tools.rectify.ffc import MEASURES, FFCError, read_poly_json, run_ffc, write_quantizers_json
from eyestereo.tools.rectify.vhdl_package import DEFAULT_NAME, write_package

__all__ = ["cmd_ffc", "cmd_package", "main", "register"]

PROG = "eyestereo"


def _error(msg: str) -> int:
    print(f"{PROG}: error: {' '.join(str(msg).split())}", file=sys.stderr)
    return 1


def _check_output(path: Path) -> None:
    """Fail before a long run when the output cannot be written at all."""
    folder = Path(path).parent
    if not folder.is_dir():
        raise FFCError(f"cannot write {path}: no folder {folder}")


def cmd_ffc(args: argparse.Namespace) -> int:
    """Handler of ``ffc``: poly.json -> quantizers.json."""
    try:
        poly = read_poly_json(args.poly)
        _check_output(args.output)
        t0 = time.perf_counter()
        result = run_ffc(poly.polynomials, poly.width, poly.height, max_error=args.max_error,
                         measure=args.measure, L=args.low, H=args.high)
        write_quantizers_json(result, args.output)
    except FFCError as exc:
        return _error(str(exc))
    except OSError as exc:
        return _error(f"cannot write {args.output}: {exc.strerror or exc}")
    errs = ", ".join(f"{n} {e:.3g}" for n, e in result.merged_errors.items())
    print(f"{args.output}: {result.total_bits} bits in 26 merged quantizers; {result.measure.name} "
          f"({result.measure.unit}) {errs} <= {result.max_error:g}; {time.perf_counter() - t0:.1f} s")
    for w in result.wide_inputs:
        print(f"note: {w} (costs a second MULT18X18)")
    return 0


def cmd_package(args: argparse.Namespace) -> int:
    """Handler of ``package``: quantizers.json -> VHDL package."""
    try:
        _check_output(args.output)
        write_package(args.quantizers, args.output, name=args.name)
    except FFCError as exc:
        return _error(str(exc))
    except OSError as exc:
        return _error(f"cannot write {args.output}: {exc.strerror or exc}")
    print(f"{args.output}: package {args.name}")
    return 0


def register(subparsers: Any) -> None:
    """Add the ``ffc`` and ``package`` sub-commands to an ``argparse`` sub-parsers object."""
    p = subparsers.add_parser(
        "ffc", help="float-to-fixed conversion of the rectification polynomials",
        description="Find the quantizer formats of the degree-3 rectification polynomials (thesis 2.5): "
                    "ranges, coarse search, greedy tuning, merge of the four polynomials.")
    p.add_argument("poly", type=Path, help="poly.json with the four degree-3 polynomials")
    p.add_argument("-o", "--output", type=Path, required=True, help="quantizers.json to write")
    p.add_argument("--max-error", type=_positive, default=0.01,
                   help="error bound per polynomial (mse: px^2, max: px; default 0.01)")
    p.add_argument("--measure", choices=sorted(MEASURES), default="mse",
                   help="mse: mean square difference; max: maximum absolute difference (default mse)")
    p.add_argument("--low", type=_nonneg, default=0, help="L, lowest common extra precision (default 0)")
    p.add_argument("--high", type=_nonneg, default=32, help="H, highest common extra precision (default 32)")
    p.set_defaults(func=cmd_ffc)

    q = subparsers.add_parser(
        "package", help="VHDL package of the quantizers and coefficients",
        description="Write the VHDL package (thesis 4.2.2) of a quantizers.json.")
    q.add_argument("quantizers", type=Path, help="quantizers.json written by 'ffc'")
    q.add_argument("-o", "--output", type=Path, required=True, help="VHDL file to write")
    q.add_argument("--name", default=DEFAULT_NAME, help=f"package name (default {DEFAULT_NAME})")
    q.set_defaults(func=cmd_package)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG)
    register(parser.add_subparsers(dest="command", required=True))
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
