"""``eyestereo ffc`` and ``eyestereo package``: the float-to-fixed conversion on the command line.

::

    eyestereo ffc poly.json -o quantizers.json [--max-error 0.01] [--measure mse|max] [--low 0 --high 32]
    eyestereo package quantizers.json -o stereo_calibration_pkg.vhd [--name stereo_calibration_pkg]

Outputs, errors and exit codes: :mod:`eyestereo.tools.cli.common` (the output is checked before the
conversion starts and written only when complete).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from eyestereo.tools.cli.common import nonneg_bits, positive
from eyestereo.tools.io import Outputs

__all__ = ["cmd_ffc", "cmd_package", "register"]


def cmd_ffc(args: argparse.Namespace) -> int:
    """Handler of ``ffc``: poly.json -> quantizers.json."""
    from eyestereo.tools.rectify.ffc import read_poly_json, run_ffc, write_quantizers_json

    with Outputs() as out:
        tmp = out.file(args.output)
        poly = read_poly_json(args.poly)
        t0 = time.perf_counter()
        result = run_ffc(poly.polynomials, poly.width, poly.height, max_error=args.max_error,
                         measure=args.measure, L=args.low, H=args.high)
        write_quantizers_json(result, tmp)
    errs = ", ".join(f"{n} {e:.3g}" for n, e in result.merged_errors.items())
    print(f"{args.output}: {result.total_bits} bits in 26 merged quantizers; {result.measure.name} "
          f"({result.measure.unit}) {errs} <= {result.max_error:g}; {time.perf_counter() - t0:.1f} s")
    for w in result.wide_inputs:
        print(f"note: {w} (costs a second MULT18X18)")
    return 0


def cmd_package(args: argparse.Namespace) -> int:
    """Handler of ``package``: quantizers.json -> VHDL package."""
    from eyestereo.tools.rectify.vhdl_package import write_package

    with Outputs() as out:
        tmp = out.file(args.output)
        write_package(args.quantizers, tmp, name=args.name)
    print(f"{args.output}: package {args.name}")
    return 0


def register(subparsers: Any) -> None:
    """Add the ``ffc`` and ``package`` sub-commands to an ``argparse`` sub-parsers object."""
    from eyestereo.tools.rectify.ffc import MEASURES
    from eyestereo.tools.rectify.vhdl_package import DEFAULT_NAME

    p = subparsers.add_parser(
        "ffc", help="float-to-fixed conversion of the rectification polynomials",
        description="Find the quantizer formats of the degree-3 rectification polynomials (thesis 2.5): "
                    "ranges, coarse search, greedy tuning, merge of the four polynomials.")
    p.add_argument("poly", type=Path, help="poly.json with the four degree-3 polynomials")
    p.add_argument("-o", "--output", type=Path, required=True, help="quantizers.json to write")
    p.add_argument("--max-error", type=positive, default=0.01,
                   help="error bound per polynomial (mse: px^2, max: px; default 0.01)")
    p.add_argument("--measure", choices=sorted(MEASURES), default="mse",
                   help="mse: mean square difference; max: maximum absolute difference (default mse)")
    p.add_argument("--low", type=nonneg_bits, default=0, help="L, lowest common extra precision (default 0)")
    p.add_argument("--high", type=nonneg_bits, default=32, help="H, highest common extra precision (default 32)")
    p.set_defaults(func=cmd_ffc)

    q = subparsers.add_parser(
        "package", help="VHDL package of the quantizers and coefficients",
        description="Write the VHDL package (thesis 4.2.2) of a quantizers.json.")
    q.add_argument("quantizers", type=Path, help="quantizers.json written by 'ffc'")
    q.add_argument("-o", "--output", type=Path, required=True, help="VHDL file to write")
    q.add_argument("--name", default=DEFAULT_NAME, help=f"package name (default {DEFAULT_NAME})")
    q.set_defaults(func=cmd_package)
