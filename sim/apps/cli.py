"""The simulation commands of ``eyestereo`` (registered through the ``eyestereo.cli`` entry point).

::

    eyestereo rectifier CALIB -o DIR --vhdl          the toolbox's run, plus DIR/vhdl/: the rectifier's VHDL for
                                                     that calibration, analysed by GHDL (--std=93c and 08)
    eyestereo sim rectify DIR LEFT RIGHT -o OUT      DIR/vhdl/ in GHDL on a stereo pair, a memory model on its
                                                     fetch port -> OUT/left.png, right.png, report.json
    eyestereo sim harris LEFT RIGHT -o OUT           harris_stereo's VHDL in GHDL on a grey pair -> corners.json,
                                                     overlays (eyestereo.sim.apps.cli_harris)

``report.json``: the rectified size, ``clocks`` (from ``start`` to the last output beat), ``clocks_per_pixel``
(per stereo output pixel), ``reads`` and ``reads_per_output_pixel`` (pixels the memory sent, per output
pixel of one camera; the thesis reads 4), ``bit_exact`` (every beat equal to the bit-true model's), the
memory model and the GHDL back end. Outputs are written all or nothing; bad input ends in one line.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from eyestereo.sim.apps.cli_rectify import MANIFEST, VHDL_DIR, add_rectify


# ------------------------------------------------------------------------------------------ VHDL
def write_vhdl(quantizers: str | os.PathLike[str], folder: Path, *, source_width: int, source_height: int,
               frac: int | None = None, depth: int = 4) -> list[str]:
    """The rectifier for ``quantizers`` (camera images ``source_width`` x ``source_height``) as VHDL in
    ``folder`` (package, entity ``rectifier``, manifest), analysed by GHDL with --std=93c and --std=08;
    returns the file names.

    ``frac``: the coordinates' fraction bits, 0..:data:`~eyestereo.tools.models.fetch_interpolate.MAX_FRAC`
    (the interpolation's limit); None takes q24's own (:func:`~eyestereo.tools.models.poly_unit.resolve_frac`),
    which a tight error bound can push beyond that limit: ValueError, in one line, before anything is
    written (as for a missing GHDL)."""
    from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, convert, vhdl_ports
    from eyestereo.hdl.rectify.calibration import calibration_param
    from eyestereo.tools.models.fetch_interpolate import MAX_FRAC
    from eyestereo.tools.models.poly_unit import resolve_frac

    if shutil.which("ghdl") is None:
        raise ValueError("ghdl not found: install GHDL (Debian: apt-get install ghdl) to write the rectifier's VHDL")
    # the calibration the conversion below resolves from the same parameters
    cal = calibration_param(str(quantizers), source_width, source_height)
    given = frac
    frac = resolve_frac(cal, frac)
    if frac > MAX_FRAC:
        what = f"frac={frac}" if given is not None else f"q24's {frac} fraction bits (frac=None)"
        raise ValueError(f"{what}: the rectifier's interpolation takes at most {MAX_FRAC} fraction bits; "
                         f"pass frac=0..{MAX_FRAC}")
    folder.mkdir(parents=True, exist_ok=True)
    files = convert("rectifier", folder, quantizers=str(quantizers), frac=frac, depth=depth,
                    source_width=source_width, source_height=source_height)
    with tempfile.TemporaryDirectory() as tmp:
        for std in GHDL_STDS:
            analyse(files, std, Path(tmp) / std)
    manifest = dict(entity="rectifier", files=[f.name for f in files], frac=frac, depth=depth,
                    width=cal.width, height=cal.height, source_width=cal.source_width,
                    source_height=cal.source_height, ghdl_std=list(GHDL_STDS), ports=vhdl_ports(files[-1]))
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n")
    return [f.name for f in files] + [MANIFEST]


def _owned_with_vhdl(name: str) -> bool:
    from eyestereo.tools.rectify.run import owned

    if name == VHDL_DIR:
        return True
    if name.startswith(VHDL_DIR + "/"):
        rest = name.split("/", 1)[1]
        return "/" not in rest and (rest.endswith(".vhd") or rest == MANIFEST)
    return owned(name)


def _wrap_rectifier(parser: argparse.ArgumentParser) -> None:
    """Add ``--vhdl`` and ``--frac`` to the toolbox's ``rectifier`` command.

    Everything that can be checked before the toolbox's run is: ``--frac`` (argparse, 0..8, the
    interpolation's limit), ``--degree 3`` and no ``--frac`` without ``--vhdl`` (exit 2); GHDL on the
    PATH, the calibration file readable and its camera images within the rectifier's 2..4096 a side
    (exit 1). Only q24's own fraction bits, the default ``frac``, are known after the run: beyond 8 they
    end in one line naming the error bound and suggesting ``--frac``. The toolbox's lines are printed
    only when the VHDL is written too."""
    from eyestereo.tools.cli.common import integer
    from eyestereo.tools.models.fetch_interpolate import MAX_FRAC

    orig = parser.get_default("func")
    parser.add_argument("--vhdl", action="store_true",
                        help="also write OUTDIR/vhdl/: the rectifier's VHDL for this calibration (entity "
                             "rectifier, analysed by GHDL); run it with 'eyestereo sim rectify'")
    parser.add_argument("--frac", type=integer(0, MAX_FRAC, "--frac"), default=None, metavar=f"0..{MAX_FRAC}",
                        help="with --vhdl: fraction bits of the rectifier's coordinates (default: those of the "
                             f"conversion's output q24, which a tight --max-error can push beyond {MAX_FRAC})")

    def cmd(args: argparse.Namespace) -> int:
        if not getattr(args, "vhdl", False):
            if getattr(args, "frac", None) is not None:
                parser.error("argument --frac: only with --vhdl (it sets the rectifier's VHDL)")
            return orig(args)
        if args.degree != 3:
            parser.error(f"argument --vhdl: the rectifier's VHDL needs --degree 3, got --degree {args.degree}")
        if shutil.which("ghdl") is None:
            raise ValueError("ghdl not found: install GHDL (Debian: apt-get install ghdl) to write the rectifier's "
                             "VHDL")
        from eyestereo.hdl.rectify.calibration import calibration_param
        from eyestereo.tools.io import Outputs
        from eyestereo.tools.models.poly_unit import resolve_frac
        from eyestereo.tools.rectify.calib import read_yaml
        from eyestereo.tools.rectify.calibrations import MAX_SIDE, MIN_SIDE

        sw, sh = read_yaml(Path(args.calib)).image_size
        if not (MIN_SIDE <= sw <= MAX_SIDE and MIN_SIDE <= sh <= MAX_SIDE):
            raise ValueError(f"{args.calib}: camera images of {sw}x{sh}; the rectifier's fetch port takes "
                             f"{MIN_SIDE}..{MAX_SIDE} pixels a side")
        outdir = Path(args.output)
        with Outputs() as out:
            tmp = out.folder(outdir, _owned_with_vhdl)
            args_inner = argparse.Namespace(**vars(args))
            args_inner.output = str(tmp)
            text = io.StringIO()
            with contextlib.redirect_stdout(text):
                status = orig(args_inner)
            if status:
                raise ValueError("the toolbox run failed; nothing written")
            if not (tmp / "quantizers.json").exists():
                raise ValueError("no quantizers.json (the VHDL needs degree 3); nothing written")
            if args.frac is None:
                q24 = resolve_frac(calibration_param(str(tmp / "quantizers.json"), sw, sh))
                if q24 > MAX_FRAC:
                    raise ValueError(f"--max-error {args.max_error:g} ({args.measure}) gives the rectifier's "
                                     f"coordinates {q24} fraction bits (q24's); its interpolation takes at most "
                                     f"{MAX_FRAC}: give --frac {MAX_FRAC} (or fewer) or a looser --max-error; "
                                     f"nothing written")
            names = write_vhdl(tmp / "quantizers.json", tmp / VHDL_DIR, source_width=sw, source_height=sh,
                               frac=args.frac)
            print(text.getvalue().replace(str(tmp), str(outdir)).replace(tmp.name, str(outdir)), end="")
            print(f"rectifier VHDL ({', '.join(names)}) analysed by GHDL -> {outdir}/{VHDL_DIR}/")
        return 0

    parser.set_defaults(func=cmd)


def register(sub: Any) -> None:
    """Add the simulation commands (and ``rectifier --vhdl``)."""
    if "rectifier" in sub.choices:
        _wrap_rectifier(sub.choices["rectifier"])
    p = sub.add_parser("sim", help="run generated VHDL in GHDL on your data (rectify, harris, system, dense)",
                       description="Run the generated hardware in GHDL with cocotb.")
    ss = p.add_subparsers(dest="sim_command", metavar="SIMCOMMAND", required=True, parser_class=type(p))
    add_rectify(ss)
    from eyestereo.sim.apps.cli_harris import add_harris

    add_harris(ss)
    from eyestereo.sim.apps.cli_system import add_system

    add_system(ss)
    from eyestereo.sim.apps.cli_dense import add_dense

    add_dense(ss)
