"""``eyestereo``: the command line (entry point ``eyestereo.tools.cli.main:main``).

::

    eyestereo calibrate | maps | fit | warp | lut | rig | rectifier    the Rectification Toolbox  (cli.rectify)
    eyestereo ffc | package                                            float-to-fixed, VHDL package (cli.ffc)
    eyestereo evaluate | sweep                                         feature matching study      (cli.matching)
    eyestereo board status | set | grab | adapt | program              the board design's host tool (cli.board)
    eyestereo <group from an "eyestereo.cli" entry point>              e.g. the simulation commands of eyestereo.sim

This module only assembles the groups; the shared parser, argument types, one-line errors and exit
codes (0 ok, 1 bad input at run time, 2 bad command line, 3 internal error, 128 + N after signal N)
are :mod:`eyestereo.tools.cli.common`, the all-or-nothing outputs :mod:`eyestereo.tools.io`.

**Groups from outside tools.** ``tools`` may not import the simulation layer (myhdl, cocotb), so a
group living there registers itself through the entry-point group ``eyestereo.cli``::

    [project.entry-points."eyestereo.cli"]
    sim = "eyestereo.sim.apps.cli:register"

``register(subparsers)`` is called like the toolbox's own groups. A group that fails to load does
not break the other commands: its name becomes a command that reports why in one line.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from importlib import metadata
from typing import Any

from eyestereo.tools.cli import board, ffc, matching, rectify
from eyestereo.tools.cli.common import PROG, Parser, run_command

__all__ = ["ENTRY_POINT_GROUP", "GROUPS", "build_parser", "main"]

#: The toolbox's own groups, in the order of ``eyestereo --help``.
GROUPS: tuple[Callable[[Any], None], ...] = (rectify.register, ffc.register, matching.register, board.register)
#: Entry-point group through which other layers add subcommands.
ENTRY_POINT_GROUP = "eyestereo.cli"


def _extension_groups() -> list[Any]:
    try:
        return sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name)
    except Exception:  # noqa: BLE001 - broken metadata must not break the toolbox's own commands
        return []


def _broken_group(sub: Any, name: str, why: str) -> None:
    def fail(args: argparse.Namespace) -> int:
        raise ValueError(f"the '{name}' commands cannot be loaded ({why}); reinstall eyestereo (make setup)")

    p = sub.add_parser(name, help=f"(cannot be loaded: {why})", add_help=False)
    p.add_argument("rest", nargs=argparse.REMAINDER)
    p.set_defaults(func=fail)


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser: the toolbox's groups, then the entry-point groups."""
    parser = Parser(prog=PROG, description="eyestereo's software side: the rectification toolbox (stereo "
                    "calibration, maps, regression polynomials, float-to-fixed conversion, VHDL package, "
                    "warping; thesis 2-4 and Appendix A) and the feature-matching evaluation (thesis 7.3).",
                    epilog="Exit status: 0 ok, 1 bad input found at run time, 2 bad command line, 3 internal "
                    "error, 128+N after signal N. Every error is one line on stderr; no output is left "
                    "half-written.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, parser_class=Parser)
    for register in GROUPS:
        register(sub)
    for ep in _extension_groups():
        try:
            ep.load()(sub)
        except Exception as e:  # noqa: BLE001 - see _broken_group
            if ep.name not in sub.choices:
                _broken_group(sub, ep.name, " ".join(f"{type(e).__name__}: {e}".split())[:160])
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (see the module docstring)."""
    try:
        parser = build_parser()
    except Exception as e:  # noqa: BLE001 - never a traceback
        print(f"{PROG}: error: internal error ({type(e).__name__}: {e}); please report it", file=sys.stderr)
        return 3
    return run_command(parser, argv)


if __name__ == "__main__":
    sys.exit(main())
