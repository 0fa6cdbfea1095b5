"""The ULX3S board (Radiona / EMARD, ECP5-85F): its pins, the two cameras' header mapping, the LPF constraints.

Pin sites and I/O settings are those of the board's published constraint file
``ulx3s_v20.lpf`` ("ULX3S v2.x.x and v3.0.x", file version 0a4321a of 24 Feb 2019, in github.com/emard/ulx3s,
``doc/constraints/ulx3s_v20.lpf``): the 25 MHz oscillator, the LEDs and buttons, the FT231X's serial lines,
the 32 MB SDRAM, the GPDI (HDMI) connector and the GPIO headers J1/J2 (``gp[i]``/``gn[i]``, i = 0..27).
:func:`lpf` writes the constraints of the ports the board top has, in that file's form.

The cameras: two OV7670 modules (18-pin, 3.3 V: SIOC, SIOD, VSYNC, HREF, PCLK, XCLK, D7..D0, RESET, PWDN) on
the headers, the left one on J1 and the right one on J2. Each PCLK sits on a pin with a clock input path
(J1's gp[2] and J2's gp[17], the file's GR_PCLK pins). :data:`CAMERA_PINS` is the default mapping; a user with
another adapter gives their own (:func:`camera_mapping` reads a JSON file and checks it).
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["BOARD", "DEVICE", "PINS", "CAMERA_PINS", "CAMERA_SIGNALS", "camera_mapping", "lpf", "SOURCE"]

#: The board name the Makefile takes (BOARD=ulx3s-85f) and the nextpnr-ecp5 device of its FPGA.
BOARD = "ulx3s-85f"
DEVICE = ("--85k", "--package", "CABGA381", "--speed", "6")
#: Where the pin sites come from.
SOURCE = "emard/ulx3s doc/constraints/ulx3s_v20.lpf (file version 0a4321a, 24 Feb 2019)"

_IO = "IO_TYPE=LVCMOS33"
#: port bit -> (site, IOBUF settings): the ports of the board top with the file's sites and settings.
PINS: dict[str, tuple[str, str]] = {
    "clk_25mhz": ("G2", f"PULLMODE=NONE {_IO}"),
    # FT231X: the FPGA receives on ftdi_txd and sends on ftdi_rxd (the names are the FTDI's)
    "ftdi_txd": ("M1", f"PULLMODE=UP {_IO}"),
    "ftdi_rxd": ("L4", f"PULLMODE=UP {_IO} DRIVE=4"),
    **{f"led[{i}]": (s, f"PULLMODE=NONE {_IO} DRIVE=4")
       for i, s in enumerate(("B2", "C2", "C1", "D2", "D1", "E2", "E1", "H3"))},
    # btn[0] is BTN_PWRn (active low, pulled up); btn[1..6] FIRE1, FIRE2, UP, DOWN, LEFT, RIGHT (active high)
    "btn[0]": ("D6", f"PULLMODE=UP {_IO}"),
    **{f"btn[{i}]": (s, f"PULLMODE=DOWN {_IO}") for i, s in enumerate(("R1", "T1", "R18", "V1", "U1", "H16"), 1)},
    # SDRAM
    "sdram_clk": ("F19", f"PULLMODE=NONE {_IO} DRIVE=4"),
    "sdram_cke": ("F20", f"PULLMODE=NONE {_IO} DRIVE=4"),
    "sdram_csn": ("P20", f"PULLMODE=NONE {_IO} DRIVE=4"),
    "sdram_wen": ("T20", f"PULLMODE=NONE {_IO} DRIVE=4"),
    "sdram_rasn": ("R20", f"PULLMODE=NONE {_IO} DRIVE=4"),
    "sdram_casn": ("T19", f"PULLMODE=NONE {_IO} DRIVE=4"),
    **{f"sdram_a[{i}]": (s, f"PULLMODE=NONE {_IO} DRIVE=4") for i, s in enumerate(
        ("M20", "M19", "L20", "L19", "K20", "K19", "K18", "J20", "J19", "H20", "N19", "G20", "G19"))},
    **{f"sdram_ba[{i}]": (s, f"PULLMODE=NONE {_IO} DRIVE=4") for i, s in enumerate(("P19", "N20"))},
    **{f"sdram_dqm[{i}]": (s, f"PULLMODE=NONE {_IO} DRIVE=4") for i, s in enumerate(("U19", "E20"))},
    **{f"sdram_d[{i}]": (s, f"PULLMODE=NONE {_IO} DRIVE=4") for i, s in enumerate(
        ("J16", "L18", "M18", "N18", "P18", "T18", "T17", "U20", "E19", "D20", "D19", "C20", "E18", "F18", "J18",
         "J17"))},
    # GPDI: blue, green, red, clock; LVCMOS33D: the pin pair's negative side follows (the gn sites are not ports)
    **{f"gpdi_dp[{i}]": (s, "IO_TYPE=LVCMOS33D DRIVE=4") for i, s in enumerate(("A16", "A14", "A12", "A17"))},
}

#: The headers' pins (J1: gp/gn 0..13, J2: gp/gn 14..27) and their sites.
HEADER = {
    **{f"gp[{i}]": s for i, s in enumerate(
        ("B11", "A10", "A9", "B9", "A7", "C8", "C6", "A6", "A4", "A2", "C4", "F4", "G3", "H4",
         "U18", "N17", "N16", "L16", "H18", "F17", "D18", "C18", "B15", "B17", "C16", "D14", "B13", "D13"))},
    **{f"gn[{i}]": s for i, s in enumerate(
        ("C11", "A11", "B10", "C10", "A8", "B8", "C7", "B6", "A5", "B1", "B4", "E3", "F3", "G5",
         "U17", "P16", "M17", "L17", "H17", "G18", "E17", "D17", "C15", "C17", "D16", "E14", "C13", "E13"))},
}

#: A camera's signals: (name, direction from the FPGA, bits).
CAMERA_SIGNALS = (("pclk", "in", 1), ("href", "in", 1), ("vsync", "in", 1), ("data", "in", 8), ("xclk", "out", 1),
                  ("sioc", "out", 1), ("siod", "inout", 1), ("resetn", "out", 1), ("pwdn", "out", 1))


def _camera(pins: list[str]) -> dict[str, str]:
    names = ["pclk", "href", "vsync"] + [f"data[{i}]" for i in range(8)] + ["xclk", "sioc", "siod", "resetn", "pwdn"]
    return dict(zip(names, pins))


#: The default header mapping: camera -> signal bit -> header pin. Left on J1 (PCLK on gp[2]), right on J2
#: (PCLK on gp[17]); the data bits and the rest on neighbouring pins, so each module's ribbon stays on one header.
CAMERA_PINS = {
    "l": _camera(["gp[2]", "gn[2]", "gp[3]", "gn[3]", "gp[4]", "gn[4]", "gp[5]", "gn[5]", "gp[6]", "gn[6]", "gp[7]",
                  "gn[7]", "gp[8]", "gn[8]", "gp[9]", "gn[9]"]),
    "r": _camera(["gp[17]", "gn[17]", "gp[18]", "gn[18]", "gp[19]", "gn[19]", "gp[20]", "gn[20]", "gp[21]",
                  "gn[21]", "gp[22]", "gn[22]", "gp[23]", "gn[23]", "gp[24]", "gn[24]"]),
}


def camera_mapping(path: str | Path | None = None) -> dict[str, dict[str, str]]:
    """The cameras' header mapping: :data:`CAMERA_PINS`, or a JSON file of the same shape
    (``{"l": {"pclk": "gp[2]", ...}, "r": {...}}``); every signal of both cameras on a distinct header pin."""
    if path is None:
        mapping = CAMERA_PINS
    else:
        try:
            mapping = json.loads(Path(path).read_text())
        except OSError as e:
            raise ValueError(f"camera mapping {path}: {e.strerror}") from None
        except json.JSONDecodeError as e:
            raise ValueError(f"camera mapping {path}: not JSON ({e.msg}, line {e.lineno})") from None
    want = set(_camera([""] * 16))
    used: dict[str, str] = {}
    if not isinstance(mapping, dict) or set(mapping) != {"l", "r"}:
        raise ValueError("camera mapping: needs exactly the cameras 'l' and 'r'")
    for cam in ("l", "r"):
        m = mapping[cam]
        if not isinstance(m, dict) or set(m) != want:
            missing = sorted(want - set(m)) if isinstance(m, dict) else sorted(want)
            extra = sorted(set(m) - want) if isinstance(m, dict) else []
            raise ValueError(f"camera mapping: camera {cam!r} " + (f"lacks {', '.join(missing)}" if missing else
                                                                   f"has unknown signals {', '.join(extra)}"))
        for sig, pin in m.items():
            if pin not in HEADER:
                raise ValueError(f"camera mapping: {cam}.{sig} on {pin!r}, not a header pin (gp[0..27], gn[0..27])")
            if pin in used:
                raise ValueError(f"camera mapping: {cam}.{sig} and {used[pin]} both on {pin}")
            used[pin] = f"{cam}.{sig}"
    return {c: dict(mapping[c]) for c in ("l", "r")}


def camera_port(cam: str, sig: str) -> str:
    """The board top's port bit of a camera signal: ``cam_l_pclk``, ``cam_r_data[3]``."""
    base, _, idx = sig.partition("[")
    return f"cam_{cam}_{base}" + (f"[{idx}" if idx else "")


def lpf(ports, *, mapping=None, clocks: dict[str, float] | None = None) -> str:
    """The LPF for the board top's port bits ``ports`` (names as Yosys gives them: ``led[3]``, ``cam_l_d[0]``):
    each bit's site and IOBUF settings from :data:`PINS` or, for the cameras, the header mapping (LVCMOS33, pulled
    up: the OV7670 modules' SIOD needs it); ``clocks`` adds a FREQUENCY PORT line per input clock port (MHz).
    ValueError for a port the board has no pin for."""
    mapping = camera_mapping() if mapping is None else mapping
    cams = {camera_port(c, s): HEADER[p] for c in ("l", "r") for s, p in mapping[c].items()}
    lines = [f"# {BOARD}: generated by eyestereo.tools.board.ulx3s from {SOURCE}", "BLOCK RESETPATHS ;",
             "BLOCK ASYNCPATHS ;",
             "SYSCONFIG CONFIG_IOVOLTAGE=3.3 COMPRESS_CONFIG=ON MCCLK_FREQ=62 MASTER_SPI_PORT=DISABLE "
             "SLAVE_SPI_PORT=DISABLE SLAVE_PARALLEL_PORT=DISABLE ;"]
    for p in ports:
        if p in PINS:
            site, io = PINS[p]
        elif p in cams:
            site, io = cams[p], f"PULLMODE=UP {_IO} DRIVE=4"
        else:
            raise ValueError(f"port {p!r} of the board top has no pin on the {BOARD}")
        lines += [f'LOCATE COMP "{p}" SITE "{site}" ;', f'IOBUF PORT "{p}" {io} ;']
    for port, mhz in (clocks or {}).items():
        lines.append(f'FREQUENCY PORT "{port}" {mhz:.6f} MHz ;')
    return "\n".join(lines) + "\n"
